"""The qp step by state class: states recorded from qp runs in four situations, the
controllers timed on them, and the phases of a qp step."""

from __future__ import annotations

import gc
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ddwmmr.bench.methods import REFERENCE_FACTORY, REFERENCE_LABEL, ExtraCase, extra_factory
from ddwmmr.bench.timing import Clock, p99_judgeable, summarize_times, time_calls
from ddwmmr.controllers.base import StepInfo, make_controller
from ddwmmr.errors import (
    ParameterError,
)
from ddwmmr.model import Robot
from ddwmmr.model.stability import STABILITY_FLOOR
from ddwmmr.progress import ProgressBar
from ddwmmr.sim import simulate

if TYPE_CHECKING:
    import numpy.typing as npt

    from ddwmmr.commands import WheelForces
    from ddwmmr.qp.context import StepContext
    from ddwmmr.qp.controller import QPController
    from ddwmmr.qp.limits import Limit
    from ddwmmr.qp.tasks import Task

    #: One recorded ``command`` call: ``(t, q, pose_d, velocity_d)`` (s, m, rad).
    RecordedCall = tuple[float, np.ndarray, np.ndarray, np.ndarray]

#: Targets of the qp step, judged in every state class (docs/api.md, "Benchmark").
QP_TARGETS = {"median_us": 20.0, "p99_us": 40.0, "reference_ratio": 40.0}


def qp_target_verdict(qp: dict[str, Any], states: int) -> bool | None:
    """Whether one class's qp step (``qp``: :func:`summarize_times` over ``states`` states,
    us) meets :data:`QP_TARGETS`: False if its median or a judgeable p99 misses; None if
    the median holds but the p99 is over too few states to judge
    (:func:`~ddwmmr.bench.timing.p99_judgeable`); else True."""
    if qp["median_us"] > QP_TARGETS["median_us"]:
        return False
    if not p99_judgeable(states):
        return None
    meets: bool = qp["p99_us"] <= QP_TARGETS["p99_us"]
    return meets


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
    select: Callable[[Robot, dict[str, Any], RecordedCall], bool] | None = None
    start: Callable[[Robot, Any], np.ndarray] | None = None


def _near_floor(robot: Robot, options: dict[str, Any], call: RecordedCall) -> bool:
    from ddwmmr.qp.limits import exact_stability

    q = call[1]
    floor: float = options.get("stability_min", STABILITY_FLOOR)
    return exact_stability(robot.com_coefficients, float(q[3]), float(q[4])) < floor + 0.05


def _near_singularity(robot: Robot, options: dict[str, Any], call: RecordedCall) -> bool:
    margin = options.get("singularity_margin", 0.25)
    return math.cos(float(call[1][3])) ** 2 - math.sin(margin) ** 2 < 0.05


def _near_obstacle(robot: Robot, options: dict[str, Any], call: RecordedCall) -> bool:
    from ddwmmr.qp.limits import footprint_clearances
    from ddwmmr.qp.limits.obstacles import INFLUENCE_M

    q = call[1]
    clearance = footprint_clearances(
        0.5 * robot.base_length, 0.5 * robot.base_width, q[0], q[1], q[2], options["obstacles"]
    )
    return float(clearance) < INFLUENCE_M  # within the obstacle limit's influence


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
        self.calls: list[RecordedCall] = []

    @property
    def last(self) -> StepInfo:
        info: StepInfo = self.inner.last
        return info

    def reset(self, trajectory: Any, q0: np.ndarray) -> None:
        self.inner.reset(trajectory, q0)

    def command(
        self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray
    ) -> npt.ArrayLike | WheelForces:
        self.calls.append(
            (float(t), np.array(q, float), np.array(pose_d, float), np.array(velocity_d, float))
        )
        u: npt.ArrayLike | WheelForces = self.inner.command(t, q, pose_d, velocity_d)
        return u

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        summary: dict[str, Any] = self.inner.summarize(timeseries)
        return summary


def record_class_states(
    state_class: StateClass, robot: Robot, count: int
) -> tuple[Any, list[RecordedCall]]:
    """The trajectory and up to ``count`` evenly spaced selected calls of its qp run."""
    from ddwmmr.trajectories import load_trajectory

    trajectory = load_trajectory(state_class.trajectory)
    options = _resolve_options(state_class.options)
    recorder = _Recorder(make_controller("qp", robot, **options))
    q0 = state_class.start(robot, trajectory) if state_class.start else None
    # ignore: _Recorder's last is a read-only forward of the inner controller's; the
    # Controller protocol declares a plain attribute, which simulate only reads
    simulate(robot, trajectory, recorder, q0=q0)  # type: ignore[arg-type]
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


#: The module the "+user" row's pieces say they come from: not a ``ddwmmr`` one, so
#: :func:`~ddwmmr.inheritance.from_library` takes them for a user's, and the row times the
#: guard and the per-step check of what they write that a user's pieces pay.
USER_MODULE = "bench_user_pieces"


class _UserSpin:
    """Factories of a user task and a user limit (generic path only) for the "+user" row."""

    @staticmethod
    def pieces() -> tuple[list[Task], list[Limit]]:
        from ddwmmr.qp.limits import INF, Limit
        from ddwmmr.qp.tasks import Task

        class SpinTask(Task):
            """A user task: yaw at 0.5 rad/s (tiny weight: timing only)."""

            __module__ = USER_MODULE
            name = "spin"

            def compute(self, ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
                jac[:] = (0.0, 1.0, 0.0, 0.0)
                error[0] = 0.5

        class ArmSumLimit(Limit):
            """A user limit: one row on th1dot + th2dot, never binding."""

            __module__ = USER_MODULE
            rows = 1

            def compute(
                self,
                ctx: StepContext,
                G: np.ndarray,
                lower: np.ndarray,
                upper: np.ndarray,
                lb: np.ndarray,
                ub: np.ndarray,
            ) -> None:
                G[0] = (0.0, 0.0, 1.0, 1.0)
                lower[0], upper[0] = -INF, INF

        return [SpinTask(1e-6)], [ArmSumLimit()]


def qp_class_cases(robot: Robot, options: dict[str, Any], reference: bool) -> dict[str, Any]:
    """The controllers timed in one class: qp, its generic path, qp with a user task and
    limit, qp-naive and (if available) the reference."""
    from ddwmmr.qp import QPProblem
    from ddwmmr.qp.naive import NaiveQPController

    cases: dict[str, Any] = {"qp": make_controller("qp", robot, **options)}
    # ignore: make_controller("qp") builds a QPController (the generic path is set on it)
    generic = cast("QPController", make_controller("qp", robot, **options))
    generic.problem = QPProblem(generic.tasks, generic.limits, compiled=False, unit=generic.unit)
    cases["qp (generic path)"] = generic
    tasks, limits = _UserSpin.pieces()
    cases["qp + user task, limit"] = make_controller(
        "qp", robot, tasks=tasks, limits=limits, **options
    )
    cases["qp-naive"] = NaiveQPController(robot, **options)
    if reference:
        factory = extra_factory(ExtraCase(REFERENCE_LABEL, REFERENCE_FACTORY))
        if not isinstance(factory, str):
            cases[REFERENCE_LABEL] = factory(robot)
    return cases


def time_qp_phases(
    controller: Any,
    calls: Sequence[RecordedCall],
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


def measure_qp_classes(
    robot: Robot,
    calls: int,
    repeats: int,
    overhead_ns: float,
    reference: bool,
    bar: ProgressBar,
) -> list[dict[str, Any]]:
    """Measure every qp state class (see :data:`QP_CLASSES`)."""
    results: list[dict[str, Any]] = []
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
                # medians do not add: the phases' can exceed the step's (the table shows
                # that rest negative, see report.format_qp_phases)
                "rest": max(total - known, 0.0),
            },
            "phase_percentiles": phase_stats,
            "exact_check_fraction": exact,
            "ratios": _class_ratios(rows),
            "meets_targets": qp_target_verdict(rows["qp"], len(recorded)),
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
