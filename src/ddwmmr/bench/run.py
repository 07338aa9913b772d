"""The whole benchmark run: every part measured, the report assembled with the conditions
of the run."""

from __future__ import annotations

import os
import platform
from collections.abc import Sequence
from datetime import UTC, datetime
from typing import Any

import numpy as np

from ddwmmr.bench.baseline import NAIVE_LABEL
from ddwmmr.bench.methods import (
    EXTRA_CASES,
    REFERENCE_LABEL,
    STATE_SOURCE_METHOD,
    STEP_BUDGETS_US,
    TARGET_RATIO,
    ExtraCase,
    benchmark_cases,
    method_rows,
    pair_ratios,
    record_states,
)
from ddwmmr.bench.mpc_floor import (
    FLOOR_SCENARIOS,
    FLOOR_TARGETS,
    FLOOR_TRACKING,
    measure_mpc_floor,
)
from ddwmmr.bench.qp_classes import QP_CLASSES, QP_TARGETS, measure_qp_classes
from ddwmmr.bench.report import REPORT_VERSION, TOOL
from ddwmmr.bench.scenarios import SCENARIO_CONTROLLERS, time_scenarios
from ddwmmr.bench.timing import timer_overhead_ns
from ddwmmr.errors import (
    MAX_JOBS,
    MAX_SCENARIOS,
    MAX_STEPS,
    check_int_at_least,
    check_range,
)
from ddwmmr.model import Robot
from ddwmmr.outputs import package_version
from ddwmmr.progress import ProgressBar, phase
from ddwmmr.provenance import git_record
from ddwmmr.trajectories import Ellipse
from ddwmmr.trajectories.base import resolution_step

#: Most repeats (``--repeats``): each number is a median over repeats, so a thousand is
#: far past the point where more change it; every row keeps repeats x calls timings.
MAX_REPEATS = 1000
#: Most states per timing (``--calls``). The method table's states come from one recorded
#: run of 2001 states and the largest qp class holds 8001 calls: more only repeats states.
MAX_CALLS = 10_000


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
    mpc_floor: bool | None = None,
    floor_scenarios: int = FLOOR_SCENARIOS,
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
        mpc_floor: also measure where the ``mpc`` step's time goes against its HPIPM solve
            (:func:`~ddwmmr.bench.mpc_floor.measure_mpc_floor`: the default rectangle
            and ellipse tracked for ``duration`` s, and the first ``floor_scenarios``
            scenarios on the thesis plant; default: when ``mpc`` is measured).
        floor_scenarios: scenarios of that measurement (default 3; 0 for tracking only).

    Every argument is checked before anything runs (:class:`ParameterError`, one line).
    """
    _check_counts(repeats, calls, scenarios, floor_scenarios, scenario_jobs)
    robot = robot if robot is not None else Robot()
    trajectory = trajectory if trajectory is not None else Ellipse()
    duration = check_duration(trajectory, duration)
    cases, skipped = benchmark_cases(methods, extras)
    labels = {case.label for case in cases}
    if qp_classes is None:
        qp_classes = "qp" in labels
    if mpc_floor is None:
        mpc_floor = "mpc" in labels
    reference = any(case.label == REFERENCE_LABEL for case in cases) or (
        qp_classes and REFERENCE_LABEL not in skipped
    )
    load_start = _load_average()  # before the bench's own processes add to it
    overhead_ns = timer_overhead_ns()
    states = record_states(robot, trajectory, calls)
    total = repeats * (len(cases) + (len(QP_CLASSES) if qp_classes else 0))
    with ProgressBar(total, "bench", enabled=progress) as bar:
        rows = method_rows(cases, robot, trajectory, states, repeats, duration, overhead_ns, bar)
        classes = []
        if qp_classes:
            classes = measure_qp_classes(
                Robot().with_payload(3.0), calls, repeats, overhead_ns, reference, bar
            )
    floor = _mpc_floor(duration, floor_scenarios, progress) if mpc_floor else []
    throughput = _scenario_throughput(scenarios, scenario_jobs, progress) if scenarios > 0 else []
    return {
        "tool": TOOL,
        "version": REPORT_VERSION,
        "baseline": NAIVE_LABEL,
        "target_step_ratio": TARGET_RATIO,
        "step_budgets_us": dict(STEP_BUDGETS_US),
        "rows": rows,
        "pairs": pair_ratios(cases, rows),
        "skipped": skipped,
        "qp_classes": classes,
        "qp_targets": dict(QP_TARGETS),
        "scenarios": throughput,
        "mpc_floor": floor,
        "mpc_floor_targets": dict(FLOOR_TARGETS),
        "config": {
            **_config(repeats, calls, trajectory, duration, overhead_ns),
            "state_spacing_s": states.times[1] - states.times[0] if len(states) > 1 else None,
            "load_average_start": load_start,
        },
    }


def _check_counts(
    repeats: int, calls: int, scenarios: int, floor_scenarios: int, scenario_jobs: int | None
) -> None:
    """:func:`run_benchmark`'s counts checked in its order (:class:`ParameterError`, one
    line naming the count and its range); ``scenario_jobs`` is named ``jobs``, as the
    command line's flag."""
    check_int_at_least("repeats", repeats, 1, MAX_REPEATS)
    check_int_at_least("calls", calls, 1, MAX_CALLS)
    check_int_at_least("scenarios", scenarios, 0, MAX_SCENARIOS)
    check_int_at_least("floor_scenarios", floor_scenarios, 0, MAX_SCENARIOS)
    if scenario_jobs is not None:
        check_int_at_least("jobs", scenario_jobs, 1, MAX_JOBS)


def _mpc_floor(duration: float, floor_scenarios: int, progress: bool) -> list[dict[str, Any]]:
    """The report's ``mpc_floor`` rows: the ``mpc`` step against its HPIPM solve on the
    :data:`FLOOR_TRACKING` trajectories tracked for ``duration`` (s) and the first
    ``floor_scenarios`` scenarios (:func:`measure_mpc_floor`)."""
    with phase("bench: the mpc step against its HPIPM solve", enabled=progress):
        tracking = [(name, duration) for name, _ in FLOOR_TRACKING]
        return measure_mpc_floor(tracking, floor_scenarios)


def _scenario_throughput(
    scenarios: int, scenario_jobs: int | None, progress: bool
) -> list[dict[str, Any]]:
    """The report's ``scenarios`` rows: simulated seconds per wall-clock second of the
    first ``scenarios`` scenarios with each of :data:`SCENARIO_CONTROLLERS`, on
    ``scenario_jobs`` processes (:func:`time_scenarios`)."""
    with phase(f"bench: {scenarios} scenarios x {len(SCENARIO_CONTROLLERS)}", enabled=progress):
        return time_scenarios(scenarios, scenario_jobs)


def check_duration(trajectory: Any, duration: float | None) -> float:
    """The simulated time (s) of each full run: ``duration`` (default one period of
    ``trajectory``) if :func:`ddwmmr.simulate` can run it at the trajectory's step, i.e.
    from one step to :data:`ddwmmr.errors.MAX_STEPS` steps; else :class:`ParameterError`
    (checked before the benchmark starts, not in its first full run)."""
    if duration is None:
        return float(trajectory.duration)
    dt = resolution_step(trajectory)  # simulate's default
    return check_range("duration", duration, dt, MAX_STEPS * dt, "s")


def _config(
    repeats: int, calls: int, trajectory: Any, duration: float, overhead: float
) -> dict[str, Any]:
    """Conditions of the run (to compare runs over time), with the package's version and
    its source's commit as every tool's run record gives them
    (:func:`ddwmmr.provenance.git_record`): ``package_version``, because the report's own
    ``version`` is its layout's (:data:`~ddwmmr.bench.report.REPORT_VERSION`)."""
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
        "load_average": _load_average(),
        "timestamp": datetime.now(UTC).isoformat(timespec="seconds"),
        "package_version": package_version(),
        **git_record(),
    }


def _load_average() -> list[float] | None:
    """The system's 1, 5 and 15 minute load averages (runnable processes), None where the
    platform has none."""
    return list(os.getloadavg()) if hasattr(os, "getloadavg") else None
