"""The method table: the naive baseline, every registered tracking method and the extra
rows, timed call by call over recorded states and in full runs."""

from __future__ import annotations

import importlib
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ddwmmr.bench.baseline import NAIVE_LABEL, NaivePseudoinverseController
from ddwmmr.bench.timing import summarize_times, time_calls
from ddwmmr.controllers.base import Controller, available_methods, make_controller
from ddwmmr.errors import shown
from ddwmmr.model import Robot
from ddwmmr.progress import ProgressBar
from ddwmmr.sim import simulate

#: Target: every method's median step at most this fraction of the naive step.
TARGET_RATIO = 0.25
#: Absolute step budgets (us) replacing the ratio target for methods that solve an
#: optimisation every step (docs/api.md, "Benchmark"; the qp step's stricter targets are
#: judged per state class, see :data:`ddwmmr.bench.qp_classes.QP_TARGETS`).
STEP_BUDGETS_US: dict[str, float] = {"qp": 60.0, "mpc": 2000.0}
#: Method whose run provides the states of the method table.
STATE_SOURCE_METHOD = "clrrmc-ts"
#: Label of the reference row (roboticstoolbox-python's holistic QP step).
REFERENCE_LABEL = "rtb-holistic"
#: Factory of the reference row and the extra that installs it.
REFERENCE_FACTORY = "ddwmmr.qp.rtb_reference:HolisticController"


@dataclass(frozen=True)
class ExtraCase:
    """An additional benchmark row built from ``"module:attribute"``.

    ``attribute`` is called as ``attribute(robot, **options)`` and must return a controller
    (``reset`` and ``command`` as in :mod:`ddwmmr.controllers.base`). If the module or the
    attribute does not exist the row is skipped and listed under ``skipped``. ``pair`` names
    the row this one is the naive counterpart of: the report then gives ``pair / label``.
    """

    label: str
    factory: str
    options: dict[str, Any] = field(default_factory=dict)
    pair: str | None = None


#: Extra rows (hook): naive variants and other non-method cases, built from an import path.
#: A registered method whose name equals an extra case's label is measured once, as that
#: extra row (reported next to its pair and not judged against the target).
EXTRA_CASES: tuple[ExtraCase, ...] = (
    ExtraCase("qp-naive", "ddwmmr.qp.naive:NaiveQPController", pair="qp"),
    ExtraCase(REFERENCE_LABEL, REFERENCE_FACTORY, pair="qp"),
)


@dataclass(frozen=True)
class BenchCase:
    """One benchmark row: a label and a factory ``make(robot) -> controller``."""

    label: str
    make: Callable[[Robot], Controller]
    kind: str = "method"  # "method", "baseline" or "extra"
    pair: str | None = None


@dataclass(frozen=True)
class BenchStates:
    """Recorded inputs of ``command``: times (s), configurations, desired poses/velocities."""

    times: list[float]
    configurations: list[np.ndarray]
    poses: list[np.ndarray]
    velocities: list[np.ndarray]

    def __len__(self) -> int:
        return len(self.times)

    def calls(self) -> list[tuple[float, np.ndarray, np.ndarray, np.ndarray]]:
        """``(t, q, pose_d, velocity_d)`` of every state."""
        return list(zip(self.times, self.configurations, self.poses, self.velocities))


def _method_factory(name: str) -> Callable[[Robot], Controller]:
    def make(robot: Robot) -> Controller:
        return make_controller(name, robot)

    return make


def extra_factory(case: ExtraCase) -> Callable[[Robot], Controller] | str:
    """The factory of an extra case, or the reason it cannot be loaded."""
    module_name, _, attribute = case.factory.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        return f"{module_name} not importable ({exc})"
    target = getattr(module, attribute, None)
    if target is None:
        return f"{module_name} has no attribute {shown(attribute)}"
    reason: str | None = getattr(module, "unavailable_reason", lambda: None)()
    if reason:
        return reason

    def make(robot: Robot) -> Controller:
        controller: Controller = target(robot, **case.options)
        return controller

    return make


def benchmark_cases(
    methods: Sequence[str] | None = None, extras: Sequence[ExtraCase] = EXTRA_CASES
) -> tuple[list[BenchCase], dict[str, str]]:
    """Rows to measure and the skipped extra cases (label -> reason).

    ``methods`` defaults to every registered method; when given, an extra case is kept only
    if its label or its ``pair`` is among them.
    """
    if methods is not None:
        wanted = set(methods)
        extras = [e for e in extras if e.label in wanted or e.pair in wanted]
    extra_cases: list[BenchCase] = []
    skipped: dict[str, str] = {}
    for extra in extras:
        factory = extra_factory(extra)
        if isinstance(factory, str):
            skipped[extra.label] = factory
        else:
            extra_cases.append(BenchCase(extra.label, factory, kind="extra", pair=extra.pair))
    taken = {case.label for case in extra_cases}
    names = available_methods() if methods is None else list(dict.fromkeys(methods))
    cases = [BenchCase(NAIVE_LABEL, NaivePseudoinverseController, kind="baseline")]
    # an extra row's label is never a method of its own: a skipped one (its package is
    # not installed) stays skipped, with its reason, instead of an "unknown method"
    cases += [
        BenchCase(name, _method_factory(name))
        for name in names
        if name not in taken and name not in skipped
    ]
    return cases + extra_cases, skipped


def record_states(robot: Robot, trajectory: Any, count: int) -> BenchStates:
    """``count`` evenly spaced states of a ``clrrmc-ts`` run of ``trajectory``."""
    result = simulate(robot, trajectory, STATE_SOURCE_METHOD)
    ts = result.timeseries
    index = np.linspace(0, len(ts["t"]) - 1, count).round().astype(int)
    q = result.configurations()
    times = [float(ts["t"][i]) for i in index]
    return BenchStates(
        times=times,
        configurations=[q[i].copy() for i in index],
        poses=[trajectory.pose(t) for t in times],
        velocities=[trajectory.velocity(t) for t in times],
    )


def time_steps(controller: Controller, states: BenchStates, trajectory: Any) -> float:
    """Mean time (us) of one ``command`` call over all states (garbage collector paused)."""
    controller.reset(trajectory, states.configurations[0].copy())
    times = time_calls(controller.command, states.calls(), 1)
    return float(np.mean(times))


def time_run(robot: Robot, trajectory: Any, controller: Controller, duration: float) -> float:
    """Simulated steps per wall-clock second of one :func:`simulate` run."""
    start = time.perf_counter()
    result = simulate(robot, trajectory, controller, duration=duration)
    elapsed = time.perf_counter() - start
    steps: int = result.summary["steps"]
    return steps / elapsed


def _meets_target(case: BenchCase, step: float, naive_step: float) -> bool | None:
    """Whether a method row meets its budget (absolute if listed, else the ratio target)."""
    if case.kind != "method":
        return None
    budget = STEP_BUDGETS_US.get(case.label)
    return step <= budget if budget is not None else step <= TARGET_RATIO * naive_step


def pair_ratios(cases: Sequence[BenchCase], rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """``pair / counterpart`` step ratios for extra cases that declare a pair."""
    steps = {row["label"]: row["step_us"] for row in rows}
    return [
        {"method": c.pair, "naive": c.label, "step_ratio": steps[c.pair] / steps[c.label]}
        for c in cases
        if c.pair is not None and c.pair in steps
    ]


def method_rows(
    cases: Sequence[BenchCase],
    robot: Robot,
    trajectory: Any,
    states: BenchStates,
    repeats: int,
    duration: float,
    overhead_ns: float,
    bar: ProgressBar,
) -> list[dict[str, Any]]:
    """Time every case (interleaved per repeat, so load drift hits all rows alike)."""
    calls = states.calls()
    controllers = {case.label: case.make(robot) for case in cases}
    samples: dict[str, list[np.ndarray]] = {case.label: [] for case in cases}
    rates: dict[str, list[float]] = {case.label: [] for case in cases}
    for controller in controllers.values():  # warm-up: imports, caches
        controller.reset(trajectory, states.configurations[0].copy())
        time_calls(controller.command, calls[:20], 1)
    for repeat in range(repeats):
        for case in cases:
            controller = controllers[case.label]
            controller.reset(trajectory, states.configurations[0].copy())
            samples[case.label].append(
                time_calls(controller.command, calls, 1, overhead_ns=overhead_ns)
            )
            # The extra rows' full runs (20-50x slower than a method's) only once.
            if repeat == 0 or case.kind != "extra":
                rates[case.label].append(time_run(robot, trajectory, case.make(robot), duration))
            bar.advance()
    naive = summarize_times(np.vstack(samples[NAIVE_LABEL]))["median_us"]
    naive_rate = statistics.median(rates[NAIVE_LABEL])
    rows = []
    for case in cases:
        stats = summarize_times(np.vstack(samples[case.label]))
        rate = statistics.median(rates[case.label])
        rows.append(
            {
                "label": case.label,
                "kind": case.kind,
                "step_us": stats["median_us"],
                "step_p90_us": stats["p90_us"],
                "step_p99_us": stats["p99_us"],
                "steps_per_s": rate,
                "step_ratio": stats["median_us"] / naive,
                "run_speedup": rate / naive_rate,
                "meets_target": _meets_target(case, stats["median_us"], naive),
            }
        )
    return rows
