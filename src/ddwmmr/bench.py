"""Benchmark: control-step latency of every method, the qp step by state class and phase,
full-run throughput; the report goes to ``bench.json``.

Three parts (docs/api.md, "Benchmark", explains the method):

* **methods**: the naive baseline ``naive-pinv``, every registered method and the extra
  rows of :data:`EXTRA_CASES`, each timed call by call over states recorded from a
  ``clrrmc-ts`` run of the default ellipse (median, 90th and 99th percentile over states of
  each state's median over the repeats), and the steps per second of a full
  :func:`ddwmmr.simulate` run;
* **qp by state class**: ``qp`` (3 kg payload) over states recorded from its own runs in
  four situations (:data:`QP_CLASSES`: tracking, at the stability floor, at the shoulder
  singularity, beside an obstacle), next to the same controller through the generic
  path, with a user task and limit, its naive twin ``qp-naive`` and the reference a user
  would otherwise pick, roboticstoolbox-python's holistic QP step (``rtb-holistic``,
  skipped with the reason when the ``bench`` extra is not installed); plus the cost of
  each phase of a qp step (build, solve, check) and how often the exact look-ahead ran;
* **scenarios**: simulated seconds per wall-clock second of the thesis benchmark's
  scenarios with the thesis controller and with ``qp`` (:func:`time_scenarios`, on by
  default in the command-line run without ``--method``).

Targets (issue 14): qp median <= 20 us and p99 <= 40 us in every class; rtb-holistic
at least 40x slower than qp. Timing thresholds are never unit tests: they are reported.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import json
import math
import os
import platform
import stat
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from ddwmmr.cli.common import ArgumentParser
from ddwmmr.controllers.base import Controller, StepInfo, available_methods, make_controller
from ddwmmr.errors import (
    MAX_JOBS,
    MAX_SCENARIOS,
    MAX_STEPS,
    ParameterError,
    check_int_at_least,
    check_range,
    read_text_file,
    shown,
)
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import u_from_qdot
from ddwmmr.model.stability import STABILITY_FLOOR
from ddwmmr.outputs import check_output_file, check_writable
from ddwmmr.progress import ProgressBar, phase
from ddwmmr.sim import simulate
from ddwmmr.sim.result import write_atomic
from ddwmmr.trajectories import Ellipse
from ddwmmr.trajectories.base import resolution_step

#: Label of the naive pseudoinverse baseline row.
NAIVE_LABEL = "naive-pinv"
#: Target: every method's median step at most this fraction of the naive step.
TARGET_RATIO = 0.25
#: Absolute step budgets (us) replacing the ratio target for methods that solve an
#: optimisation every step (``qp``: issue 3's budget, ``mpc``: issue 11's 2 ms; issue 14's
#: qp targets are judged per state class, see :data:`QP_TARGETS`).
STEP_BUDGETS_US: dict[str, float] = {"qp": 60.0, "mpc": 2000.0}
#: Issue 14 targets of the qp step, judged in every state class.
QP_TARGETS = {"median_us": 20.0, "p99_us": 40.0, "reference_ratio": 40.0}
#: Controllers of the scenario-throughput section (issue 14, target 3) and its default size.
SCENARIO_CONTROLLERS = ("thesis", "qp")
SCENARIO_COUNT = 100
#: What the scenario section takes from the scenarios tool's summary.
SCENARIO_KEYS = ("failed", "sim_time_s", "wall_time_s", "sim_seconds_per_wall_second")
#: Method whose run provides the states of the method table.
STATE_SOURCE_METHOD = "clrrmc-ts"
#: Marker of a report written by this tool (an existing ``--out`` file must carry it).
TOOL = "ddwmmr.bench"
#: Version of the report layout.
REPORT_VERSION = 2
#: Most repeats (``--repeats``): each number is a median over repeats, so a thousand is
#: far past the point where more change it; every row keeps repeats x calls timings.
MAX_REPEATS = 1000
#: Most states per timing (``--calls``). The method table's states come from one recorded
#: run of 2001 states and the largest qp class holds 8001 calls: more only repeats states.
MAX_CALLS = 10_000
#: Label of the reference row (roboticstoolbox-python's holistic QP step).
REFERENCE_LABEL = "rtb-holistic"
#: Factory of the reference row and the extra that installs it.
REFERENCE_FACTORY = "ddwmmr.qp.rtb_reference:HolisticController"

Clock = Callable[[], int]


class NaivePseudoinverseController:
    """Naive baseline: ``qdot = pinv(J(q)) [Xd_dot; 0]`` with a fresh SVD every step.

    ``J`` is the 4x5 Jacobian from :meth:`Robot.jacobian`; the result is projected on the
    inputs ``u = (v, w, th1dot, th2dot)`` and the sideways base speed (m/s) is reported.
    No damping: this is the textbook formula the closed-form kernels replace.
    """

    name = NAIVE_LABEL

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.last = StepInfo()

    def reset(self, trajectory: object, q0: np.ndarray) -> None:
        """Nothing to prepare (memoryless)."""
        self.last = StepInfo()

    def command(
        self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray
    ) -> np.ndarray:
        """Input for the desired end-effector velocity (m/s, m/s, rad/s), world frame."""
        task_rate = np.append(velocity_d, 0.0)
        qdot = np.linalg.pinv(self.robot.jacobian(q)) @ task_rate
        u, residual = u_from_qdot(float(q[2]), qdot)
        self.last = StepInfo(nonholonomic_residual=residual)
        return u


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


# -- timing ---------------------------------------------------------------------------
def timer_overhead_ns(clock: Clock = time.perf_counter_ns, samples: int = 2001) -> float:
    """Median cost (ns) of one pair of clock reads: subtracted from every timed call."""
    gaps = []
    for _ in range(samples):
        start = clock()
        gaps.append(clock() - start)
    return float(statistics.median(gaps))


def time_calls(
    command: Callable[..., Any],
    calls: Sequence[tuple],
    repeats: int,
    clock: Clock = time.perf_counter_ns,
    overhead_ns: float = 0.0,
    between: Callable[[], None] | None = None,
) -> np.ndarray:
    """Wall time (us) of every call, shape ``(repeats, len(calls))``: each repeat replays the
    calls in their recorded order (garbage collector paused), ``between`` runs after each
    repeat (e.g. a controller reset). The clock-read overhead is subtracted."""
    times = np.zeros((repeats, len(calls)))
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        for r in range(repeats):
            row = times[r]
            for i, args in enumerate(calls):
                start = clock()
                command(*args)
                row[i] = clock() - start
            if between is not None:
                between()
    finally:
        if gc_was_enabled:
            gc.enable()
    return np.maximum(times - overhead_ns, 0.0) / 1000.0


def summarize_times(times: np.ndarray) -> dict[str, float]:
    """Median, 90th and 99th percentile over states of each state's median over the
    repeats (``times``: repeats x states, us), and the median of each repeat's median."""
    per_state = np.median(times, axis=0)
    return {
        "median_us": float(np.median(per_state)),
        "p90_us": float(np.percentile(per_state, 90)),
        "p99_us": float(np.percentile(per_state, 99)),
        "max_us": float(np.max(per_state)),
        "repeat_medians_us": [float(v) for v in np.median(times, axis=1)],
    }


# -- the method table -------------------------------------------------------------------
def _method_factory(name: str) -> Callable[[Robot], Controller]:
    def make(robot: Robot) -> Controller:
        return make_controller(name, robot)

    return make


def _extra_factory(case: ExtraCase) -> Callable[[Robot], Controller] | str:
    """The factory of an extra case, or the reason it cannot be loaded."""
    module_name, _, attribute = case.factory.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        return f"{module_name} not importable ({exc})"
    target = getattr(module, attribute, None)
    if target is None:
        return f"{module_name} has no attribute {attribute!r}"
    reason = getattr(module, "unavailable_reason", lambda: None)()
    if reason:
        return reason

    def make(robot: Robot) -> Controller:
        return target(robot, **case.options)

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
        factory = _extra_factory(extra)
        if isinstance(factory, str):
            skipped[extra.label] = factory
        else:
            extra_cases.append(BenchCase(extra.label, factory, kind="extra", pair=extra.pair))
    taken = {case.label for case in extra_cases}
    names = available_methods() if methods is None else list(dict.fromkeys(methods))
    cases = [BenchCase(NAIVE_LABEL, NaivePseudoinverseController, kind="baseline")]
    cases += [BenchCase(name, _method_factory(name)) for name in names if name not in taken]
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
    return result.summary["steps"] / elapsed


def _meets_target(case: BenchCase, step: float, naive_step: float) -> bool | None:
    """Whether a method row meets its budget (absolute if listed, else the ratio target)."""
    if case.kind != "method":
        return None
    budget = STEP_BUDGETS_US.get(case.label)
    return step <= budget if budget is not None else step <= TARGET_RATIO * naive_step


def _pairs(cases: Sequence[BenchCase], rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """``pair / counterpart`` step ratios for extra cases that declare a pair."""
    steps = {row["label"]: row["step_us"] for row in rows}
    return [
        {"method": c.pair, "naive": c.label, "step_ratio": steps[c.pair] / steps[c.label]}
        for c in cases
        if c.pair is not None and c.pair in steps
    ]


def _method_rows(
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


# -- qp by state class ------------------------------------------------------------------
#: Phases of a qp step reported by :func:`time_qp_phases` (plus the rest of the step).
PHASES = ("build", "solve", "check", "rest")
#: The obstacle of the "obstacles" class: trajectories/obstacles/ellipse_post.toml (m).
POST = (-0.2, 1.05, 0.3)


@dataclass(frozen=True)
class StateClass:
    """States of one situation, recorded from a ``qp`` run of ``trajectory``.

    ``options`` configure the controller both in the run and in the timing; ``select``
    keeps the recorded calls of interest (all when None); ``start`` gives the start
    configuration from the trajectory and the robot (default: simulate's own).
    """

    name: str
    trajectory: str
    description: str
    options: dict[str, Any] = field(default_factory=dict)
    select: Callable[[Robot, dict[str, Any], tuple], bool] | None = None
    start: Callable[[Robot, Any], np.ndarray] | None = None


def _near_floor(robot: Robot, options: dict[str, Any], call: tuple) -> bool:
    from ddwmmr.qp.limits import exact_stability

    q = call[1]
    floor = options.get("stability_min", STABILITY_FLOOR)
    return exact_stability(robot.com_coefficients, float(q[3]), float(q[4])) < floor + 0.05


def _near_singularity(robot: Robot, options: dict[str, Any], call: tuple) -> bool:
    margin = options.get("singularity_margin", 0.25)
    return math.cos(float(call[1][3])) ** 2 - math.sin(margin) ** 2 < 0.05


def _near_obstacle(robot: Robot, options: dict[str, Any], call: tuple) -> bool:
    from ddwmmr.qp.limits import footprint_clearances

    q = call[1]
    clearance = footprint_clearances(
        0.5 * robot.base_length, 0.5 * robot.base_width, q[0], q[1], q[2], options["obstacles"]
    )
    return float(clearance) < 0.6  # within the obstacle limit's influence


def _reach_start(robot: Robot, trajectory: Any) -> np.ndarray:
    return robot.base_for_end_effector(trajectory.pose(0.0), 1.0, 1.6)


#: The qp state classes (docs/qp.md, "Demonstrations", runs them too).
QP_CLASSES: tuple[StateClass, ...] = (
    StateClass("tracking", "ellipse", "ellipse, default options: every call of the run"),
    StateClass(
        "stability floor",
        "sideways_reach",
        "sideways reach from the arm-out start: calls with S < S_min + 0.05",
        select=_near_floor,
        start=_reach_start,
    ),
    StateClass(
        "shoulder singularity",
        "ellipse",
        "ellipse, manipulability weight 1: calls within 0.05 of the singularity margin",
        options={"manipulability_weight": 1.0},
        select=_near_singularity,
    ),
    StateClass(
        "obstacles",
        "ellipse",
        "ellipse with the post obstacle: calls within the obstacle's influence",
        options={"obstacles": [POST]},
        select=_near_obstacle,
    ),
)


class _Recorder:
    """Wraps a controller and records the inputs of every ``command`` call."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner
        self.name = inner.name
        self.calls: list[tuple[float, np.ndarray, np.ndarray, np.ndarray]] = []

    @property
    def last(self) -> StepInfo:
        return self.inner.last

    def reset(self, trajectory: Any, q0: np.ndarray) -> None:
        self.inner.reset(trajectory, q0)

    def command(self, t, q, pose_d, velocity_d):
        self.calls.append(
            (float(t), np.array(q, float), np.array(pose_d, float), np.array(velocity_d, float))
        )
        return self.inner.command(t, q, pose_d, velocity_d)

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        return self.inner.summarize(timeseries)


def record_class_states(
    state_class: StateClass, robot: Robot, count: int
) -> tuple[Any, list[tuple]]:
    """The trajectory and up to ``count`` evenly spaced selected calls of its qp run."""
    from ddwmmr.trajectories import load_trajectory

    trajectory = load_trajectory(state_class.trajectory)
    options = _resolve_options(state_class.options)
    recorder = _Recorder(make_controller("qp", robot, **options))
    q0 = state_class.start(robot, trajectory) if state_class.start else None
    simulate(robot, trajectory, recorder, q0=q0)
    calls = recorder.calls
    if state_class.select is not None:
        calls = [c for c in calls if state_class.select(robot, options, c)]
    if len(calls) > count:
        index = np.linspace(0, len(calls) - 1, count).round().astype(int)
        calls = [calls[i] for i in index]
    return trajectory, calls


def _resolve_options(options: dict[str, Any]) -> dict[str, Any]:
    resolved = dict(options)
    if "obstacles" in resolved:
        from ddwmmr.qp.limits import Circle

        resolved["obstacles"] = [Circle(*o) for o in resolved["obstacles"]]
    return resolved


class _UserSpin:
    """Factories of a user task and a user limit (generic path only) for the "+user" row."""

    @staticmethod
    def pieces():
        from ddwmmr.qp.limits import INF, Limit
        from ddwmmr.qp.tasks import Task

        class SpinTask(Task):
            """A user task: yaw at 0.5 rad/s (tiny weight: timing only)."""

            name = "spin"

            def compute(self, ctx, jac, error):
                jac[:] = (0.0, 1.0, 0.0, 0.0)
                error[0] = 0.5

        class ArmSumLimit(Limit):
            """A user limit: one row on th1dot + th2dot, never binding."""

            rows = 1

            def compute(self, ctx, G, lower, upper, lb, ub):
                G[0] = (0.0, 0.0, 1.0, 1.0)
                lower[0], upper[0] = -INF, INF

        return [SpinTask(1e-6)], [ArmSumLimit()]


def qp_class_cases(robot: Robot, options: dict[str, Any], reference: bool) -> dict[str, Any]:
    """The controllers timed in one class: qp, its generic path, qp with a user task and
    limit, qp-naive and (if available) the reference."""
    from ddwmmr.qp import QPProblem
    from ddwmmr.qp.naive import NaiveQPController

    cases: dict[str, Any] = {"qp": make_controller("qp", robot, **options)}
    generic = make_controller("qp", robot, **options)
    generic.problem = QPProblem(generic.tasks, generic.limits, compiled=False)
    cases["qp (generic path)"] = generic
    tasks, limits = _UserSpin.pieces()
    cases["qp + user task, limit"] = make_controller(
        "qp", robot, tasks=tasks, limits=limits, **options
    )
    cases["qp-naive"] = NaiveQPController(robot, **options)
    if reference:
        factory = _extra_factory(ExtraCase(REFERENCE_LABEL, REFERENCE_FACTORY))
        if not isinstance(factory, str):
            cases[REFERENCE_LABEL] = factory(robot)
    return cases


def time_qp_phases(
    controller: Any,
    calls: Sequence[tuple],
    repeats: int,
    clock: Clock = time.perf_counter_ns,
    overhead_ns: float = 0.0,
) -> tuple[dict[str, np.ndarray], float]:
    """Per-call time (us, repeats x calls) of each phase of the weighted qp step, and the
    fraction of calls in which the exact stability look-ahead ran:

    * ``build``: refresh the step context and fill the problem (tasks, limits, cost);
    * ``solve``: the solver call on the problem's arrays;
    * ``check``: the one-step stability check (its bound, and the exact look-ahead when
      the bound cannot prove the full step safe).

    The rest of a step (reading the answer, the step report, the command array) is the
    step's total minus these.
    """
    from ddwmmr.qp.limits import full_step_is_safe

    ctx, problem, backend = controller.ctx, controller.problem, controller.backend
    phases = {name: np.zeros((repeats, len(calls))) for name in ("build", "solve", "check")}
    exact = 0
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        for r in range(repeats):
            for i, (t, q, pose_d, velocity_d) in enumerate(calls):
                t0 = clock()
                ctx.update(t, q, pose_d, velocity_d)
                problem.build(ctx)
                t1 = clock()
                x = backend(problem) if problem.box_ok else None
                t2 = clock()
                if x is None:
                    t3 = t2
                else:
                    _, _, r1, r2 = x[:4].tolist()
                    t2 = clock()
                    controller.arm_scale(ctx, r1, r2)
                    t3 = clock()
                    if r == 0:
                        trig = (ctx.sin_th1, ctx.cos_th1, ctx.sin_th12, ctx.cos_th12)
                        exact += not full_step_is_safe(
                            controller._com,
                            trig,
                            ctx.th1,
                            ctx.th2,
                            r1,
                            r2,
                            ctx.dt,
                            controller.stability_min,
                        )
                phases["build"][r, i] = t1 - t0
                phases["solve"][r, i] = t2 - t1
                phases["check"][r, i] = t3 - t2
    finally:
        if gc_was_enabled:
            gc.enable()
    scaled = {k: np.maximum(v - overhead_ns, 0.0) / 1000.0 for k, v in phases.items()}
    return scaled, exact / max(len(calls), 1)


def _qp_classes(
    robot: Robot,
    calls: int,
    repeats: int,
    overhead_ns: float,
    reference: bool,
    bar: ProgressBar,
) -> list[dict[str, Any]]:
    """Measure every qp state class (see :data:`QP_CLASSES`)."""
    results = []
    for state_class in QP_CLASSES:
        try:
            trajectory, recorded = record_class_states(state_class, robot, calls)
        except ParameterError as exc:
            results.append({"name": state_class.name, "skipped": str(exc)})
            bar.advance(repeats)
            continue
        options = _resolve_options(state_class.options)
        cases = qp_class_cases(robot, options, reference)
        samples: dict[str, list[np.ndarray]] = {label: [] for label in cases}
        q0 = recorded[0][1].copy()
        for controller in cases.values():  # warm-up
            controller.reset(trajectory, q0)
            time_calls(controller.command, recorded[:20], 1)
        for _ in range(repeats):
            for label, controller in cases.items():
                controller.reset(trajectory, q0)
                samples[label].append(
                    time_calls(controller.command, recorded, 1, overhead_ns=overhead_ns)
                )
            bar.advance()
        qp = cases["qp"]
        qp.reset(trajectory, q0)
        phases, exact = time_qp_phases(qp, recorded, repeats, overhead_ns=overhead_ns)
        rows = {label: summarize_times(np.vstack(s)) for label, s in samples.items()}
        total = rows["qp"]["median_us"]
        phase_stats = {name: summarize_times(values) for name, values in phases.items()}
        known = sum(p["median_us"] for p in phase_stats.values())
        entry = {
            "name": state_class.name,
            "description": state_class.description,
            "trajectory": state_class.trajectory,
            "options": {
                k: (v if k != "obstacles" else [list(POST)]) for k, v in state_class.options.items()
            },
            "states": len(recorded),
            "rows": rows,
            "phases": {
                **{name: stats["median_us"] for name, stats in phase_stats.items()},
                "rest": max(total - known, 0.0),
            },
            "phase_percentiles": phase_stats,
            "exact_check_fraction": exact,
            "ratios": _class_ratios(rows),
            "meets_targets": rows["qp"]["median_us"] <= QP_TARGETS["median_us"]
            and rows["qp"]["p99_us"] <= QP_TARGETS["p99_us"],
        }
        results.append(entry)
    return results


def _class_ratios(rows: dict[str, dict[str, Any]]) -> dict[str, dict[str, float]]:
    """Each row's median over qp's, and the range of that ratio over the repeats."""
    qp = rows["qp"]
    ratios = {}
    for label, stats in rows.items():
        if label == "qp":
            continue
        per_repeat = [
            a / b for a, b in zip(stats["repeat_medians_us"], qp["repeat_medians_us"]) if b > 0
        ]
        ratios[label] = {
            "median": stats["median_us"] / qp["median_us"],
            "min_over_repeats": min(per_repeat),
            "max_over_repeats": max(per_repeat),
        }
    return ratios


# -- the whole run ---------------------------------------------------------------------
def run_benchmark(
    repeats: int = 5,
    calls: int = 500,
    duration: float | None = None,
    methods: Sequence[str] | None = None,
    extras: Sequence[ExtraCase] = EXTRA_CASES,
    robot: Robot | None = None,
    trajectory: Any = None,
    qp_classes: bool | None = None,
    progress: bool = False,
    scenarios: int = 0,
    scenario_jobs: int | None = None,
) -> dict[str, Any]:
    """Measure every case; returns the report (see :func:`format_table` for the columns).

    Args:
        repeats: timings per number (medians over states of per-state medians), >= 1.
        calls: ``command`` calls per timing (states from one recorded run), >= 1.
        duration: simulated time (s) of each full run; default one trajectory period.
        methods: registered methods to measure (default all).
        extras: extra rows of the method table (default :data:`EXTRA_CASES`).
        robot, trajectory: of the method table; default ``Robot()`` and ``Ellipse()``.
        qp_classes: also measure the qp state classes (default: when ``qp`` is measured).
        progress: a progress bar on stderr (terminals only).
        scenarios: also run the first ``scenarios`` thesis benchmark scenarios (seed 0)
            with each of :data:`SCENARIO_CONTROLLERS` and report simulated seconds per
            wall-clock second (:func:`time_scenarios`); 0 (default) skips it.
        scenario_jobs: worker processes for them (default: the CPUs available; never
            more than ``scenarios``).

    Every argument is checked before anything runs (:class:`ParameterError`, one line).
    """
    check_int_at_least("repeats", repeats, 1, MAX_REPEATS)
    check_int_at_least("calls", calls, 1, MAX_CALLS)
    check_int_at_least("scenarios", scenarios, 0, MAX_SCENARIOS)
    if scenario_jobs is not None:
        check_int_at_least("jobs", scenario_jobs, 1, MAX_JOBS)
    robot = robot if robot is not None else Robot()
    trajectory = trajectory if trajectory is not None else Ellipse()
    duration = check_duration(trajectory, duration)
    cases, skipped = benchmark_cases(methods, extras)
    labels = {case.label for case in cases}
    if qp_classes is None:
        qp_classes = "qp" in labels
    reference = any(case.label == REFERENCE_LABEL for case in cases) or (
        qp_classes and REFERENCE_LABEL not in skipped
    )
    overhead_ns = timer_overhead_ns()
    states = record_states(robot, trajectory, calls)
    total = repeats * (len(cases) + (len(QP_CLASSES) if qp_classes else 0))
    with ProgressBar(total, "bench", enabled=progress) as bar:
        rows = _method_rows(cases, robot, trajectory, states, repeats, duration, overhead_ns, bar)
        classes = []
        if qp_classes:
            classes = _qp_classes(
                Robot().with_payload(3.0), calls, repeats, overhead_ns, reference, bar
            )
    throughput = []
    if scenarios > 0:
        with phase(f"bench: {scenarios} scenarios x {len(SCENARIO_CONTROLLERS)}", enabled=progress):
            throughput = time_scenarios(scenarios, scenario_jobs)
    return {
        "tool": TOOL,
        "version": REPORT_VERSION,
        "baseline": NAIVE_LABEL,
        "target_step_ratio": TARGET_RATIO,
        "step_budgets_us": dict(STEP_BUDGETS_US),
        "rows": rows,
        "pairs": _pairs(cases, rows),
        "skipped": skipped,
        "qp_classes": classes,
        "qp_targets": dict(QP_TARGETS),
        "scenarios": throughput,
        "config": _config(repeats, calls, trajectory, duration, overhead_ns),
    }


def check_duration(trajectory: Any, duration: float | None) -> float:
    """The simulated time (s) of each full run: ``duration`` (default one period of
    ``trajectory``) if :func:`ddwmmr.simulate` can run it at the trajectory's step, i.e.
    from one step to :data:`ddwmmr.errors.MAX_STEPS` steps; else :class:`ParameterError`
    (checked before the benchmark starts, not in its first full run)."""
    if duration is None:
        return float(trajectory.duration)
    dt = resolution_step(trajectory)  # simulate's default
    return check_range("duration", duration, dt, MAX_STEPS * dt, "s")


def scenario_workers(count: int, jobs: int | None = None) -> int:
    """Worker processes for ``count`` scenarios: ``jobs`` (default: the CPUs available),
    never more than the scenarios (an idle worker only adds start-up time to the wall time)."""
    from ddwmmr.scenarios.executors import default_jobs

    jobs = default_jobs() if jobs is None else check_int_at_least("jobs", jobs, 1, MAX_JOBS)
    return max(1, min(jobs, count))


def time_scenarios(count: int, jobs: int | None = None) -> list[dict[str, Any]]:
    """Simulated seconds per wall-clock second of the first ``count`` scenarios (seed 0,
    the defaults of ``python -m ddwmmr.scenarios``) for each controller of
    :data:`SCENARIO_CONTROLLERS`, on ``jobs`` worker processes (default: the CPUs; at
    most ``count``, see :func:`scenario_workers`)."""
    from ddwmmr.scenarios.executors import run_many
    from ddwmmr.scenarios.generator import generate
    from ddwmmr.scenarios.protocol import RunConfig
    from ddwmmr.scenarios.report import summarize

    check_int_at_least("scenarios", count, 1, MAX_SCENARIOS)
    jobs = scenario_workers(count, jobs)
    batch = generate(count, 0)
    rows = []
    for controller in SCENARIO_CONTROLLERS:
        start = time.perf_counter()
        outcomes = run_many(batch, RunConfig(controller=controller), jobs=jobs)
        # The numbers the scenarios tool writes to its summary.json.
        summary = summarize(outcomes, time.perf_counter() - start)
        rows.append(
            {
                "controller": controller,
                "scenarios": count,
                "jobs": jobs,
                **{key: summary[key] for key in SCENARIO_KEYS},
            }
        )
    return rows


def _config(repeats: int, calls: int, trajectory: Any, duration: float, overhead: float):
    """Conditions of the run (to compare runs over time)."""
    return {
        "repeats": repeats,
        "calls": calls,
        "trajectory": getattr(trajectory, "name", type(trajectory).__name__),
        "run_duration_s": duration,
        "integrator": "rk4",
        "state_source": STATE_SOURCE_METHOD,
        "timer_overhead_ns": overhead,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "machine": platform.machine(),
        "processor": platform.processor() or "unknown",
        "cpus": os.cpu_count(),
        "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        "timestamp": datetime.now(UTC).isoformat(timespec="seconds"),
        "git_commit": _git_commit(),
    }


def _git_commit() -> str | None:
    """The source checkout's commit, when this is one."""
    root = Path(__file__).resolve().parents[2]
    try:
        out = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            timeout=5,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None


# -- reporting --------------------------------------------------------------------------
def format_table(report: dict[str, Any]) -> str:
    """A readable text table of :func:`run_benchmark`'s report."""
    config = report["config"]
    lines = [
        f"ddwmmr bench: {config['trajectory']}, {config['calls']} states per timing, "
        f"{config['run_duration_s']:g} s runs ({config['integrator']}), {config['repeats']} "
        "repeats; step times in us over states (median of each state's repeats)",
        f"{'method':<14} {'median':>8} {'p90':>8} {'p99':>8} {'vs naive':>9} {'steps/s':>9} "
        f"{'run x naive':>11}  target",
    ]
    for row in report["rows"]:
        verdict = {True: "ok", False: "MISS", None: "-"}[row["meets_target"]]
        lines.append(
            f"{row['label']:<14} {row['step_us']:>8.2f} {row['step_p90_us']:>8.2f} "
            f"{row['step_p99_us']:>8.2f} {row['step_ratio']:>9.3f} {row['steps_per_s']:>9.0f} "
            f"{row['run_speedup']:>11.2f}  {verdict}"
        )
    lines.append(
        f"target: step <= {report['target_step_ratio']:g} x {report['baseline']} step "
        "('vs naive' = step / naive step; 'run x naive' = steps/s / naive steps/s)"
    )
    for label, budget in report["step_budgets_us"].items():
        lines.append(f"target for {label}: step <= {budget:g} us (absolute budget)")
    for pair in report["pairs"]:
        lines.append(f"{pair['method']} / {pair['naive']} step ratio: {pair['step_ratio']:.3f}")
    for label, reason in report["skipped"].items():
        lines.append(f"skipped {label}: {reason}")
    if report.get("qp_classes"):
        lines += ["", *format_qp_classes(report)]
    if report.get("scenarios"):
        lines += ["", *format_scenarios(report)]
    return "\n".join(lines)


def format_scenarios(report: dict[str, Any]) -> list[str]:
    """The scenario-throughput section of the table."""
    first = report["scenarios"][0]
    lines = [
        f"scenario benchmark ({first['scenarios']} scenarios, seed 0, {first['jobs']} "
        "workers; simulated s per wall s, wall time includes the worker pool)"
    ]
    for row in report["scenarios"]:
        lines.append(
            f"  {row['controller']:<8} {row['sim_seconds_per_wall_second']:>8.0f}   "
            f"({row['sim_time_s']:.0f} simulated s in {row['wall_time_s']:.2f} s, "
            f"{row['failed']} failed)"
        )
    return lines


def format_qp_classes(report: dict[str, Any]) -> list[str]:
    """The qp state-class section of the table."""
    lines = [
        "qp step by state class (3 kg payload; states recorded from qp runs; us: "
        "median / p90 / p99 over states)"
    ]
    for entry in report["qp_classes"]:
        if "skipped" in entry:
            lines.append(f"  {entry['name']}: skipped ({entry['skipped']})")
            continue
        lines.append(
            f"  {entry['name']} ({entry['states']} states, exact look-ahead in "
            f"{100 * entry['exact_check_fraction']:.1f} %)"
        )
        for label, stats in entry["rows"].items():
            ratio = entry["ratios"].get(label)
            versus = (
                ""
                if ratio is None
                else (
                    f"  {ratio['median']:7.1f}x qp (repeats {ratio['min_over_repeats']:.1f}"
                    f"-{ratio['max_over_repeats']:.1f})"
                )
            )
            lines.append(
                f"    {label:<22} {stats['median_us']:>8.2f} {stats['p90_us']:>8.2f} "
                f"{stats['p99_us']:>8.2f}{versus}"
            )
        phases = entry["phases"]
        lines.append(
            "    qp phases (median): "
            + ", ".join(
                f"{name} {phases[name]:.2f}" for name in ("build", "solve", "check", "rest")
            )
        )
    lines.append(format_qp_verdict(report))
    return lines


def format_qp_verdict(report: dict[str, Any]) -> str:
    """One line: the issue 14 targets, met or missed, in every measured class."""
    targets = report["qp_targets"]
    measured = [e for e in report["qp_classes"] if "skipped" not in e]
    if not measured:
        return "qp targets: no class measured"
    worst_median = max(e["rows"]["qp"]["median_us"] for e in measured)
    worst_p99 = max(e["rows"]["qp"]["p99_us"] for e in measured)
    ok = worst_median <= targets["median_us"] and worst_p99 <= targets["p99_us"]
    text = (
        f"qp targets: median <= {targets['median_us']:g} us and p99 <= {targets['p99_us']:g} us"
        f" in every class: {'ok' if ok else 'MISS'} (worst {worst_median:.2f} / {worst_p99:.2f})"
    )
    ratios = [e["ratios"][REFERENCE_LABEL] for e in measured if REFERENCE_LABEL in e["ratios"]]
    if ratios:
        lowest = min(r["min_over_repeats"] for r in ratios)
        verdict = "ok" if lowest >= targets["reference_ratio"] else "MISS"
        text += (
            f"; {REFERENCE_LABEL} / qp >= {targets['reference_ratio']:g}: {verdict} "
            f"(lowest over classes and repeats {lowest:.1f})"
        )
    else:
        text += f"; {REFERENCE_LABEL}: not measured"
    return text


def format_comparison(report: dict[str, Any], previous: dict[str, Any]) -> str:
    """Median step of each row and qp class against a previous report (new / old)."""
    lines = [
        f"against {previous['config'].get('timestamp', '?')} "
        f"(commit {previous['config'].get('git_commit') or '?'}): median step new / old"
    ]
    old_rows = {row["label"]: row for row in previous.get("rows", [])}
    for row in report["rows"]:
        old = old_rows.get(row["label"])
        if old:
            lines.append(
                f"  {row['label']:<14} {old['step_us']:>8.2f} -> {row['step_us']:>8.2f} us "
                f"({row['step_us'] / old['step_us']:.2f}x)"
            )
    old_classes = {e["name"]: e for e in previous.get("qp_classes", []) if "rows" in e}
    for entry in report.get("qp_classes", []):
        old = old_classes.get(entry["name"])
        if old and "rows" in entry:
            new_us, old_us = entry["rows"]["qp"]["median_us"], old["rows"]["qp"]["median_us"]
            lines.append(
                f"  qp, {entry['name']:<20} {old_us:>8.2f} -> {new_us:>8.2f} us "
                f"({new_us / old_us:.2f}x)"
            )
    old_scenarios = {row["controller"]: row for row in previous.get("scenarios", [])}
    for row in report.get("scenarios", []):
        old = old_scenarios.get(row["controller"])
        if old:
            new_rate, old_rate = (
                row["sim_seconds_per_wall_second"],
                old["sim_seconds_per_wall_second"],
            )
            lines.append(
                f"  scenarios, {row['controller']:<14} {old_rate:>8.0f} -> {new_rate:>8.0f} "
                f"simulated s per wall s ({new_rate / old_rate:.2f}x)"
            )
    return "\n".join(lines)


def write_report(report: dict[str, Any], path: str | Path, force: bool = False) -> None:
    """Write ``report`` to ``path`` atomically; an existing file is replaced only when it
    is a report of this tool (or with ``force``)."""
    path = Path(path)
    check_out(path, force)
    try:
        write_atomic(path, json.dumps(report, indent=2) + "\n")
    except OSError as exc:
        raise ParameterError(f"out: cannot write {path} ({exc.strerror or exc})") from None


def check_out(path: Path, force: bool = False) -> None:
    """Refuse, before the run, an output path that cannot be written or that is not a
    report of this tool (unless ``force``): see :func:`ddwmmr.outputs.check_output_file`.
    Something that is not a regular file (a device, a FIFO) is never replaced, not even
    with ``force``: the report is moved into place by a rename, which would replace it.
    That is said first, so that the message does not suggest ``--force``."""
    try:
        info = os.stat(path)
    except (OSError, ValueError):
        info = None  # absent (check_output_file checks its folder) or not a path at all
    if info is not None and not stat.S_ISREG(info.st_mode) and not stat.S_ISDIR(info.st_mode):
        raise ParameterError(f"out: {path} exists and is not a regular file; give a file name")
    check_output_file(path, TOOL, _is_report, force)


def probe_out(path: str | Path) -> None:
    """Create and remove a temporary file where the report will go (the first existing
    folder on the way to ``path``, missing parents are created when the report is
    written): catches what permission bits do not show (``/proc``, a read-only mount, a
    full disk of inodes) before a long run rather than after it."""
    check_writable("out", Path(os.path.abspath(path)).parent)


def read_report(path: str | Path) -> dict[str, Any]:
    """A report written by :func:`write_report` (for ``--compare``), checked to hold every
    field :func:`format_comparison` reads; else one-line :class:`ParameterError`s naming
    ``compare`` and what is wrong (missing, unreadable, not JSON, nested too deeply, not
    a report of this tool, a field of the wrong type)."""
    if not str(path):
        raise ParameterError("compare: no file name given")
    path = Path(path)
    text = read_text_file(path, "compare")  # missing, permission, FIFO, size, UTF-8
    try:
        data = json.loads(text)
    except RecursionError:
        raise ParameterError(f"compare: {path} is not valid JSON (nested too deeply)") from None
    except ValueError as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ParameterError(f"compare: {path} is not valid JSON ({message})") from None
    if not isinstance(data, dict) or data.get("tool") != TOOL:
        raise ParameterError(f'compare: {path} is not a {TOOL} report (no "tool": "{TOOL}")')
    problem = _layout_problem(data)
    if problem:
        raise ParameterError(f"compare: {path} is not a usable {TOOL} report: {problem}")
    return data


def _type_name(value: Any) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean"}.get(
        type(value), "null" if value is None else "a number"
    )


def _positive_number(value: Any) -> bool:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(float(value)) and value > 0
    except OverflowError:  # an integer beyond float
        return False


def _entries_problem(data: dict[str, Any], key: str, fields: dict[str, str]) -> str | None:
    """What is wrong with ``data[key]`` as a list of objects with ``fields`` (name ->
    "text" or "number"; a number must be finite and > 0); None if nothing."""
    entries = data.get(key, [])
    if not isinstance(entries, list):
        return f'"{key}" must be a list (got {_type_name(entries)})'
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict):
            return f'"{key}"[{i}] must be an object (got {_type_name(entry)})'
        for name, kind in fields.items():
            value = entry.get(name)
            if kind == "text" and not isinstance(value, str):
                return f'"{key}"[{i}].{name} must be a string (got {_type_name(value)})'
            if kind == "number" and not _positive_number(value):
                got = shown(value) if isinstance(value, int | float) else _type_name(value)
                return f'"{key}"[{i}].{name} must be a number > 0 (got {got})'
    return None


def _layout_problem(data: dict[str, Any]) -> str | None:
    """The first field :func:`format_comparison` would trip over, or None."""
    if not isinstance(data.get("config"), dict):
        return f'"config" must be an object (got {_type_name(data.get("config"))})'
    if "rows" not in data:
        return 'no "rows"'
    problem = _entries_problem(data, "rows", {"label": "text", "step_us": "number"})
    problem = problem or _entries_problem(data, "qp_classes", {"name": "text"})
    problem = problem or _entries_problem(
        data, "scenarios", {"controller": "text", "sim_seconds_per_wall_second": "number"}
    )
    if problem:
        return problem
    for i, entry in enumerate(data.get("qp_classes", [])):
        if "rows" in entry:
            rows = entry["rows"]
            qp = rows.get("qp") if isinstance(rows, dict) else None
            if not isinstance(qp, dict) or not _positive_number(qp.get("median_us")):
                return f'"qp_classes"[{i}].rows.qp.median_us must be a number > 0'
    return None


def _is_report(path: Path) -> bool:
    """Whether ``path`` is a report of this tool (a regular file of at most
    :data:`ddwmmr.errors.MAX_INPUT_BYTES` is read; a device such as /dev/zero never)."""
    try:
        data = json.loads(read_text_file(path, "out"))
    except (ParameterError, ValueError, RecursionError):
        return False
    return isinstance(data, dict) and data.get("tool") == TOOL


# -- command line -----------------------------------------------------------------------
DESCRIPTION = """\
Time every control method step by step and in full runs, and the qp step by state class
and phase against its naive twin and roboticstoolbox-python's holistic QP step (install
with pip install -e '.[bench]'). Prints a table and writes the report to --out.
"""


class _Parser(ArgumentParser):
    """The tools' parser (one-line errors, negative numbers in any notation) with the
    prefix ``bench: error: ...`` (exit status 2)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"bench: error: {message}\n")


def _integer(low: int, high: int | None = None) -> Callable[[str], int]:
    """An argparse type: an integer >= ``low`` (and <= ``high``)."""
    allowed = f">= {low}" if high is None else f"in [{low}, {high}]"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"must be an integer {allowed} (got {text!r})")
        return value

    return parse


_repeat_count = _integer(1, MAX_REPEATS)
_call_count = _integer(1, MAX_CALLS)
_job_count = _integer(1, MAX_JOBS)
_scenario_count = _integer(0, MAX_SCENARIOS)


def _seconds(low: float, high: float) -> Callable[[str], float]:
    """An argparse type: a finite number; the range [``low``, ``high``] s is stated when the
    text is not one (:func:`check_duration` then checks the range itself)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(
                f"must be a number in [{low:g}, {high:g}] s (got {text!r})"
            )
        return value

    return parse


def method_names() -> list[str]:
    """What ``--method`` accepts: the registered methods and the extra rows."""
    return sorted(set(available_methods()) | {extra.label for extra in EXTRA_CASES})


def build_parser() -> argparse.ArgumentParser:
    """The ``python -m ddwmmr.bench`` argument parser."""
    parser = _Parser(
        prog="python -m ddwmmr.bench",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ellipse = Ellipse()
    dt = resolution_step(ellipse)
    parser.add_argument(
        "--repeats",
        type=_repeat_count,
        default=5,
        metavar="N",
        help=f"repeats (default 5, at most {MAX_REPEATS})",
    )
    parser.add_argument(
        "--calls",
        type=_call_count,
        default=500,
        metavar="N",
        help=f"states per timing (default 500, at most {MAX_CALLS})",
    )
    parser.add_argument(
        "--duration",
        type=_seconds(dt, MAX_STEPS * dt),
        default=None,
        metavar="S",
        help=f"simulated time of each full run in s (default: one trajectory period, "
        f"{ellipse.duration:g}; {dt:g} to {MAX_STEPS * dt:g}: 1 to {MAX_STEPS} steps of {dt:g} s)",
    )
    parser.add_argument(
        "--method",
        action="append",
        dest="methods",
        metavar="NAME",
        help=f"measure only this method (and its extra rows; the {NAIVE_LABEL} baseline is "
        f"always measured); repeatable or comma separated; one of "
        f"{', '.join(method_names())} (default: all)",
    )
    parser.add_argument(
        "--out", default="bench.json", metavar="FILE", help="report file (default bench.json)"
    )
    parser.add_argument(
        "--force", action="store_true", help="replace --out even if it is not a bench report"
    )
    parser.add_argument(
        "--compare",
        metavar="FILE",
        help="also print medians against an earlier report (read and checked before the run)",
    )
    parser.add_argument(
        "--scenarios",
        type=_scenario_count,
        default=None,
        metavar="N",
        help=f"also time the first N benchmark scenarios with {' and '.join(SCENARIO_CONTROLLERS)} "
        f"(simulated s per wall s; default {SCENARIO_COUNT} without --method, else 0; 0: skip; "
        f"at most {MAX_SCENARIOS})",
    )
    parser.add_argument(
        "--jobs",
        type=_job_count,
        default=None,
        metavar="N",
        help=f"worker processes of the scenario timing (default: the CPUs available; at most "
        f"{MAX_JOBS}, and never more than the scenarios)",
    )
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    parser.add_argument("--no-progress", action="store_true", help="no progress output on stderr")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point: print the table (or JSON) and write the report.

    Ctrl-C and SIGTERM stop it with one line (exit 130 / 143), as for every tool."""
    from ddwmmr.cli.common import run_main  # the CLI layer; bench is importable without it

    return run_main(_main, argv)


def _main(argv: Sequence[str] | None = None) -> int:
    """The tool; bad input prints one line and returns 2."""
    args = build_parser().parse_args(argv)
    if args.methods is not None:  # repeated and/or comma separated, as compare's --methods
        empty = next((v for v in args.methods if not v.replace(",", "").strip()), None)
        if empty is not None:
            print(f"bench: error: --method: no name given (got {empty!r})", file=sys.stderr)
            return 2
        names = [n.strip() for v in args.methods for n in v.split(",") if n.strip()]
        args.methods = list(dict.fromkeys(names))
    unknown = sorted(set(args.methods or ()) - set(method_names()))
    if unknown:
        choices = ", ".join(method_names())
        print(
            f"bench: error: unknown method {unknown[0]!r} (choose from {choices})",
            file=sys.stderr,
        )
        return 2
    try:
        # Everything that can be checked is checked before a minute-long run.
        previous = read_report(args.compare) if args.compare is not None else None
        out = Path(args.out)
        check_out(out, force=args.force)
        check_duration(Ellipse(), args.duration)
        probe_out(out)
        scenarios = args.scenarios
        if scenarios is None:
            scenarios = SCENARIO_COUNT if args.methods is None else 0
        report = run_benchmark(
            args.repeats,
            args.calls,
            args.duration,
            args.methods,
            progress=not args.no_progress,
            scenarios=scenarios,
            scenario_jobs=args.jobs,
        )
        write_report(report, out, force=args.force)
    except ParameterError as exc:
        print(f"bench: error: {exc}", file=sys.stderr)
        return 2
    print(json.dumps(report, indent=2) if args.json else format_table(report))
    if previous is not None:
        print(format_comparison(report, previous))
    return 0


if __name__ == "__main__":
    sys.exit(main())
