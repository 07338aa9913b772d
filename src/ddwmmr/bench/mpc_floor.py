"""Where an ``mpc`` step's time goes: the HPIPM solve against everything around it.

:func:`instrumented` times the pieces of every :class:`~ddwmmr.mpc.controller.MPCController`
step of the runs inside it, by wrapping the controller's own methods and the solver's two
CasADi calls (nothing is re-implemented: the controller that runs is the library's), and
:func:`measure_mpc_floor` runs the issue's cases: tracking the default rectangle and ellipse
on the kinematic plant, and the first scenarios of the thesis benchmark on the thesis plant.

The phases of one step (ns of the thread's CPU time by default: on a machine shared with
other jobs, wall time counts the other jobs' turns too; ``clock=time.perf_counter_ns`` for
wall time), which add up to the step:

* ``hpipm``: the conic's solve as it reports it (``t_proc_solver``, or ``t_wall_solver``
  with the wall clock): below CasADi's function interface, the QP data scattered into
  HPIPM's stage blocks, HPIPM's workspace set up, and its interior-point iterations;
* ``conic_call``: the rest of the conic's call (the Python interface, CasADi's checks of
  the arguments and its copies in and out);
* ``qp_data``: the QP data function (Hessian, gradient, Jacobian, constraints) of the
  Gauss-Newton iteration, one CasADi ``Function`` call per iteration;
* ``sqp_loop``: the rest of the Gauss-Newton loop (``w`` and ``p`` copied in, the bounds
  shifted by ``w``, status checks, the step added);
* ``prepare``: the warm start shifted (or the cold guess), the parameters and bounds;
* ``guard``: the exact check of S one step ahead (``safe_arm_scale``);
* ``controller``: everything else in ``command`` (references, stall watch, slack, output).

Apart, ``gc``: the time the garbage collector ran inside the step (a full collection walks
the whole process's heap, the run's records too: 26-64 ms when one falls in a step); it is
inside the phase it interrupted. The step itself is the time of ``command``;
``iterations`` counts the QPs of the step (1 for a real-time iteration, up to 5 at a cold
start) and ``hpipm_iterations`` the interior-point iterations in them.
"""

from __future__ import annotations

import gc
import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ddwmmr.bench.timing import P99_MIN_SAMPLES, p99_judgeable

#: The clock that times the steps by default: the thread's CPU time, except on Windows,
#: where it advances in steps of the 15.6 ms system tick (most steps would take 0): the
#: wall clock there.
DEFAULT_CLOCK: Callable[[], int] = time.perf_counter_ns if os.name == "nt" else time.thread_time_ns

#: The phases of a step, in the order the table prints them (see the module docstring).
FLOOR_PHASES = ("hpipm", "conic_call", "qp_data", "sqp_loop", "prepare", "guard", "controller")


@dataclass
class StepLog:
    """The steps timed inside :func:`instrumented`: one dict per ``command`` call with the
    wall time (ns) of ``step`` and of each of :data:`FLOOR_PHASES`, ``iterations`` (QPs) and
    ``hpipm_iterations``."""

    clock: Callable[[], int] = DEFAULT_CLOCK
    steps: list[dict[str, float]] = field(default_factory=list)
    _current: dict[str, float] | None = None

    @property
    def solver_stat(self) -> str:
        """The conic statistic of HPIPM's solve time on :attr:`clock`."""
        return "t_proc_solver" if self.clock is time.thread_time_ns else "t_wall_solver"

    def add(self, key: str, value: float) -> None:
        if self._current is not None:
            self._current[key] = self._current.get(key, 0.0) + value

    def table(self) -> dict[str, np.ndarray]:
        """Every key as an array over the steps (0 where a step had none of it)."""
        keys = ("step", *FLOOR_PHASES, "gc", "iterations", "hpipm_iterations")
        return {k: np.array([s.get(k, 0.0) for s in self.steps]) for k in keys}


def _timed(function: Callable[..., Any], key: str, log: StepLog) -> Callable[..., Any]:
    """``function`` with its time added to ``key`` of the current step."""

    def timed(*args: Any, **kwargs: Any) -> Any:
        start = log.clock()
        try:
            return function(*args, **kwargs)
        finally:
            log.add(key, float(log.clock() - start))

    return timed


#: Each conic's solve time and calls so far, as its statistics last said (they add up over
#: the calls of its memory), by the conic's id: the difference is one call's.
_SOLVER_TOTALS: dict[int, tuple[float, int]] = {}


def _timed_qp(buffers: Any, log: StepLog) -> Callable[[], None]:
    """The QP solve of ``buffers`` (:class:`~ddwmmr.mpc.solvers.QPBuffers`) with its time
    split into HPIPM's own (the conic's statistics, which add up over its calls: the
    difference) and the rest of the call; its statistics are read outside the timing."""
    solve = buffers.solve_qp

    def timed() -> None:
        start = log.clock()
        solve()
        elapsed = float(log.clock() - start)
        stats = buffers.qp_stats()
        total, calls = float(stats.get(log.solver_stat, 0.0)), int(stats.get("n_call_solver", 1))
        key = id(buffers._qp_function)
        before, calls_before = _SOLVER_TOTALS.get(key, (0.0, 0))
        if calls == calls_before + 1:
            solver = 1e9 * (total - before)
        else:  # a call outside the log in between: HPIPM's part of this one is unknown
            solver = 1e9 * total if calls == 1 else math.nan
        _SOLVER_TOTALS[key] = (total, calls)
        log.add("hpipm", solver)
        log.add("conic_call", elapsed - solver)
        log.add("hpipm_iterations", float(stats.get("iter_count", 0)))
        log.add("iterations", 1.0)

    return timed


def _instrument_solver(solver: Any, log: StepLog) -> None:
    """Wrap a Gauss-Newton solver's data function and QP (once), and time its loop."""
    buffers = getattr(solver, "_qp_buffers", None)
    if buffers is None or getattr(solver, "_floor_log", None) is log:
        return
    solver._floor_log = log
    buffers.evaluate_data = _timed(buffers.evaluate_data, "qp_data", log)
    buffers.solve_qp = _timed_qp(buffers, log)
    solver.solve = _timed(solver.solve, "_solver", log)


@contextmanager
def instrumented(clock: Callable[[], int] = DEFAULT_CLOCK) -> Iterator[StepLog]:
    """Time every ``mpc`` step run inside the block, by phase (:class:`StepLog`).

    Wraps ``MPCController.command`` and ``_problem``, ``Problem.solve`` and the
    exact-S guard for the block's duration (restored after it); the solvers of the
    problems the controllers use are wrapped per instance. Not thread-safe: one run at a
    time, in this process.
    """
    from ddwmmr.mpc import controller as controller_module
    from ddwmmr.mpc.problem import Problem

    cls = controller_module.MPCController
    log = StepLog(clock)
    command, problem_of, problem_solve = cls.command, cls._problem, Problem.solve
    # ignore: the guard mpc.controller imports (and calls by its module name) is patched
    # there, where it is not re-exported (also below)
    guard = controller_module.safe_arm_scale  # type: ignore[attr-defined]

    def timed_command(self: Any, *args: Any, **kwargs: Any) -> Any:
        log._current = {}
        start = clock()
        try:
            return command(self, *args, **kwargs)
        finally:
            step = log._current
            log._current = None
            step["step"] = float(clock() - start)
            problem = step.pop("_problem", 0.0)
            solver = step.pop("_solver", 0.0)
            around = sum(step.get(k, 0.0) for k in ("hpipm", "conic_call", "qp_data"))
            step["sqp_loop"] = solver - around
            step["prepare"] = problem - solver
            step["controller"] = step["step"] - problem - step.get("guard", 0.0)
            log.steps.append(step)

    def instrumented_problem(self: Any, mode: str) -> Any:
        problem = problem_of(self, mode)
        _instrument_solver(problem.solver, log)
        _instrument_solver(problem.cold, log)
        return problem

    def timed_problem_solve(self: Any, *args: Any, **kwargs: Any) -> Any:
        start = clock()
        try:
            return problem_solve(self, *args, **kwargs)
        finally:
            log.add("_problem", float(clock() - start))

    def timed_guard(*args: Any, **kwargs: Any) -> Any:
        start = clock()
        try:
            return guard(*args, **kwargs)
        finally:
            log.add("guard", float(clock() - start))

    collecting: list[int] = []

    def timed_collection(phase: str, info: dict[str, Any]) -> None:
        if phase == "start":
            collecting.append(clock())
        elif collecting:
            log.add("gc", float(clock() - collecting.pop()))

    gc.callbacks.append(timed_collection)
    cls.command = timed_command  # type: ignore[method-assign]
    cls._problem = instrumented_problem  # type: ignore[method-assign]
    Problem.solve = timed_problem_solve  # type: ignore[method-assign]
    controller_module.safe_arm_scale = timed_guard  # type: ignore[attr-defined]
    try:
        yield log
    finally:
        gc.callbacks.remove(timed_collection)
        cls.command = command  # type: ignore[method-assign]
        cls._problem = problem_of  # type: ignore[method-assign]
        Problem.solve = problem_solve  # type: ignore[method-assign]
        controller_module.safe_arm_scale = guard  # type: ignore[attr-defined]


def floor_summary(log: StepLog) -> dict[str, Any]:
    """The step's median, p99 and max (us; the max also without the garbage collector's
    time, and over the cold-started steps, more than one QP, and the others), each
    phase's median (us) and share of the total time, and the step's median over HPIPM's
    median (the issue's first target); the phases over the steps whose HPIPM time is
    known (``split_steps``: all but a first QP after calls outside the instrumentation)."""
    table = log.table()
    step = table["step"] / 1000.0
    # the steps whose HPIPM time is known (not: a call on the same conic outside the
    # instrumentation came between two of its calls; the first QP after such a call)
    split = ~np.isnan(table["hpipm"])
    total = float(np.sum(table["step"][split]))
    hpipm = table["hpipm"][split] / 1000.0
    cold = table["iterations"] > 1
    row: dict[str, Any] = {
        "steps": int(step.size),
        "median_us": float(np.median(step)),
        "p99_us": float(np.percentile(step, 99)),
        "max_us": float(np.max(step)),
        "max_without_gc_us": float(np.max(step - table["gc"] / 1000.0)),
        "gc_steps": int(np.sum(table["gc"] > 0)),
        "split_steps": int(np.sum(split)),
        "hpipm_median_us": float(np.median(hpipm)),
        "step_over_hpipm": _ratio(np.median(step[split]), np.median(hpipm)),
        "qps_per_step": float(np.mean(table["iterations"])),
        "hpipm_iterations_per_qp": float(
            np.sum(table["hpipm_iterations"]) / max(1.0, float(np.sum(table["iterations"])))
        ),
        "p99_over_median": _ratio(np.percentile(step, 99), np.median(step)),
        "cold_steps": int(np.sum(cold)),
        "cold_max_us": float(np.max(step[cold])) if np.any(cold) else 0.0,
        "warm_max_us": float(np.max(step[~cold])) if np.any(~cold) else 0.0,
    }
    for phase in FLOOR_PHASES:
        row[f"{phase}_median_us"] = float(np.median(table[phase][split])) / 1000.0
        row[f"{phase}_share"] = _ratio(np.sum(table[phase][split]), total)
    return row


def _ratio(value: float, reference: float) -> float:
    """``value / reference``; NaN where ``reference`` is not positive (a clock too coarse
    for the steps, or no steps: the ratio or share is unknown, not infinite)."""
    return float(value) / float(reference) if reference > 0 else math.nan


#: The tracking cases of the floor (trajectory name, simulated seconds); the scenarios'.
FLOOR_TRACKING = (("rectangle", 40.0), ("ellipse", 40.0))
FLOOR_SCENARIOS = 3

#: The floor's targets, each a row key and its largest value: the median step at most
#: twice HPIPM's median solve inside it, p99 at most twice the median (ratios measured in
#: one run), and the slowest step at most 5 ms (us; the one absolute number, for a 10 ms
#: control period with room to spare; it counts the garbage collector's pauses).
FLOOR_TARGETS = {"step_over_hpipm": 2.0, "p99_over_median": 2.0, "max_us": 5000.0}


def floor_verdicts(row: dict[str, Any]) -> dict[str, bool | None]:
    """Which of :data:`FLOOR_TARGETS` a :func:`floor_summary` row meets; a target is None
    (not judged) when its value is unknown (NaN), and the p99 target when the row's
    ``steps`` are too few for a p99 (:func:`~ddwmmr.bench.timing.p99_judgeable`; a row
    without ``steps`` is judged)."""
    verdicts: dict[str, bool | None] = {
        key: None if math.isnan(row[key]) else bool(row[key] <= limit)
        for key, limit in FLOOR_TARGETS.items()
    }
    if "steps" in row and not p99_judgeable(int(row["steps"])):
        verdicts["p99_over_median"] = None
    return verdicts


def measure_mpc_floor(
    tracking: Sequence[tuple[str, float]] = FLOOR_TRACKING,
    scenarios: int = FLOOR_SCENARIOS,
    clock: Callable[[], int] = DEFAULT_CLOCK,
) -> list[dict[str, Any]]:
    """The floor of every case in one process (:func:`floor_summary` per case): the
    default trajectories tracked on the kinematic plant with the default ``mpc``, and the
    first ``scenarios`` thesis-benchmark scenarios (seed 0) with ``mpc`` on the thesis
    plant, run one after the other."""
    from ddwmmr.model import Robot
    from ddwmmr.scenarios.generator import generate
    from ddwmmr.scenarios.protocol import RunConfig, run_scenario
    from ddwmmr.sim import simulate
    from ddwmmr.trajectories import Ellipse, Rectangle

    trajectories = {"rectangle": Rectangle, "ellipse": Ellipse}
    rows = []
    for name, duration in tracking:
        with instrumented(clock) as log:
            simulate(Robot(), trajectories[name](), "mpc", duration=duration)
        rows.append({"case": f"tracking {name} (kinematic plant)", **floor_summary(log)})
    if scenarios > 0:
        config = RunConfig(controller="mpc")
        # the OCP built (and shared, ddwmmr.mpc.cache) before the timing: set-up, not a step
        run_scenario(generate(1, 0)[0], RunConfig(controller="mpc", time_limit=0.02))
        with instrumented(clock) as log:
            for scenario in generate(scenarios, 0):
                run_scenario(scenario, config)
        label = f"scenarios 1-{scenarios} (thesis plant)"
        rows.append({"case": label, **floor_summary(log)})
    return rows


def format_floor_lines(rows: Sequence[dict[str, Any]]) -> list[str]:
    """The floor as the bench table's section: per case the step's median, p99 and max
    (us), HPIPM's median and each target's ratio with its verdict."""
    clock = "thread CPU time" if DEFAULT_CLOCK is time.thread_time_ns else "wall time"
    lines = [
        f"mpc step against its HPIPM solve in mpc's own closed-loop runs ({clock}, "
        "not the method table's wall time on replayed states; one run; targets: median step "
        f"<= {FLOOR_TARGETS['step_over_hpipm']:g} x HPIPM, p99 <= "
        f"{FLOOR_TARGETS['p99_over_median']:g} x median, max <= "
        f"{FLOOR_TARGETS['max_us'] / 1000:g} ms)",
        f"  {'case':<38} {'median':>7} {'p99':>7} {'max':>7} {'HPIPM':>7} "
        f"{'step/HPIPM':>11} {'p99/median':>11} {'max':>5}",
    ]
    unjudged = []
    for row in rows:
        verdicts = floor_verdicts(row)
        verdict = {
            key: {True: "ok", False: "MISS", None: "-"}[met] for key, met in verdicts.items()
        }
        if not p99_judgeable(int(row["steps"])):
            unjudged.append(f"{row['case']} has {row['steps']}")
        lines.append(
            f"  {row['case']:<38} {row['median_us']:>7.0f} {row['p99_us']:>7.0f} "
            f"{row['max_us']:>7.0f} {row['hpipm_median_us']:>7.0f} "
            f"{row['step_over_hpipm']:>6.2f} {verdict['step_over_hpipm']:<4} "
            f"{row['p99_over_median']:>6.2f} {verdict['p99_over_median']:<4} "
            f"{verdict['max_us']:>5}"
        )
    if unjudged:
        lines.append(
            f"  -: p99 needs >= {P99_MIN_SAMPLES} steps, not judged ({'; '.join(unjudged)})"
        )
    return lines


def format_floor_table(rows: Sequence[dict[str, Any]]) -> str:
    """The floor as a markdown table: step statistics, HPIPM's share and each phase's."""
    header = (
        "| case | steps | median step | p99 | max (without GC) | HPIPM (median) | step / HPIPM | "
        + " | ".join(FLOOR_PHASES)
        + " |"
    )
    lines = [header, "| " + " | ".join(["---"] * (7 + len(FLOOR_PHASES))) + " |"]
    for row in rows:
        shares = " | ".join(f"{100 * row[f'{p}_share']:.0f} %" for p in FLOOR_PHASES)
        lines.append(
            f"| {row['case']} | {row['steps']} | {row['median_us']:.0f} us | "
            f"{row['p99_us']:.0f} us | {row['max_us']:.0f} ({row['max_without_gc_us']:.0f}) us | "
            f"{row['hpipm_median_us']:.0f} us | {row['step_over_hpipm']:.2f} | {shares} |"
        )
    return "\n".join(lines)
