"""The best-known minimum time of a scenario: a systematic multistart of the OCP.

One scenario (:func:`best_known`):

1. **screen** on a coarse grid (:data:`Settings.coarse` intervals per leg) from every start
   of :func:`ddwmmr.bounds.starts.all_patterns` (each leg forwards or backwards: 32
   starts on one elbow branch, the best of them on the other too), then, for the best
   patterns, each leg's turn the long way round and the arm stretched ahead instead of
   held; the controllers' own runs on the thesis plant (thesis controller, ``qp``,
   ``mpc``, the ``mpc`` planning through the next waypoint); the straight-line starts of
   :func:`ddwmmr.mpc.min_time.solve_minimum_time`;
   and a continuation for the best ones (solved first with ``S >= 1`` and a 5 cm
   tolerance, then tightened);
2. **refine** the best distinct screened optima on the fine grid (:data:`Settings.fine`);
3. **certify** the best on a finer grid (:data:`Settings.final`, then each of
   :data:`Settings.also_final`) with a margin on the waypoint tolerance and on S, and
   replay each open-loop on the thesis plant (:mod:`ddwmmr.bounds.replay`): the fastest
   replay that passes counts (a finer grid can fall into another local optimum); the next
   best is tried if none passes; a certified solution is solved once more on its grid with
   smaller margins and kept if that replays too;
4. **the controllers' runs** count too: where a run's recorded wheel forces and joint
   rates, replayed open-loop at the run's own step, pass the same check in less time,
   that time is the best known (``start`` ``run-<controller>``);
5. **the plan followed**: the ``mpc`` with ``lookahead`` run with the best found so far
   as its ``plan`` (:data:`Settings.guided`: the plan as cold starts alone, and arriving
   at each waypoint as the plan does, the option's default; each as it is and with a
   smaller floor margin and input cost), its runs candidates as in 4 (``run-mpc-plan``,
   ``run-mpc-plan-margin``, ``run-mpc-plan-arrive``, ``run-mpc-plan-arrive-margin``): the
   closed loop sometimes beats the plan it follows. While a round beats it, the faster run
   is followed in turn (at most :data:`Settings.guided_rounds` rounds; the later rounds'
   labels end in ``-round<k>``).

The result is the replayed time: a trajectory the plant itself drives, so an upper bound on
the true minimum. ``spread_s`` is the range of the screened local optima.
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ddwmmr.behaviours.objective import default_pose
from ddwmmr.bounds.replay import Replay, replay
from ddwmmr.bounds.starts import all_patterns, controller_guess, pattern_guess, turn_variants
from ddwmmr.model import Robot
from ddwmmr.mpc.min_time import Guess, MinimumTime, MinimumTimeProblem

if TYPE_CHECKING:
    from ddwmmr.bounds.starts import Pattern
    from ddwmmr.scenarios.generator import Scenario

#: The smaller floor margin and input cost of the plan-following runs' second variant.
SMALL_MARGIN = (("stability_margin", 0.001), ("input_weight", 0.001))


@dataclass(frozen=True)
class Settings:
    """How hard :func:`best_known` looks.

    Attributes:
        coarse, fine, final: intervals per leg of the screening, refining and certifying
            grids; also_final: more certifying grids (the fastest replay of all counts).
        refine: distinct screened optima refined; elbow_top, turn_top, arm_top,
            continuation_top: best patterns also tried on the other elbow branch, with
            turn variants, with the arm stretched ahead, continued.
        controllers: controllers whose runs are starts.
        guided: ``(name, mpc options)`` of the plan-following runs of step 5 (each the
            ``mpc`` with ``lookahead`` and the best found as its ``plan``, besides these
            options); empty: no step 5. guided_rounds: most rounds of step 5 (a round
            follows the fastest run of the round before, if that beat its plan).
        stability_min: the S floor; tolerance: waypoint radius (m); margin_s, margin_m:
            margins on both in the certifying solve (the replay must hold the floor and
            reach within the tolerance); tight_margin_s, tight_margin_m: the smaller
            margins tried next from a certified solution (kept if it replays too).
    """

    coarse: int = 8
    fine: int = 24
    final: int = 60
    also_final: tuple[int, ...] = (40, 24)
    refine: int = 4
    elbow_top: int = 6
    turn_top: int = 2
    arm_top: int = 2
    continuation_top: int = 2
    controllers: tuple[str, ...] = ("thesis", "qp", "mpc", "mpc-lookahead")
    guided: tuple[tuple[str, tuple[tuple[str, Any], ...]], ...] = (
        ("mpc-plan", (("plan_weight", 0.0),)),
        ("mpc-plan-margin", (("plan_weight", 0.0), *SMALL_MARGIN)),
        ("mpc-plan-arrive", ()),
        ("mpc-plan-arrive-margin", SMALL_MARGIN),
    )
    guided_rounds: int = 8
    stability_min: float = 1.25
    tolerance: float = 0.01
    margin_s: float = 0.0005
    margin_m: float = 0.001
    tight_margin_s: float = 0.0001
    tight_margin_m: float = 0.0003


#: A lighter search (46 starts instead of 59-60; its CPU time in docs/mpc.md): a coarser
#: screening grid, the mpc's run the only controller start; still certified on 60
#: intervals (only).
QUICK = Settings(
    coarse=6,
    fine=16,
    final=60,
    also_final=(),
    refine=2,
    elbow_top=2,
    turn_top=1,
    arm_top=1,
    continuation_top=1,
    controllers=("mpc",),
    guided=(("mpc-plan-arrive", ()),),
)


@dataclass
class Found:
    """The best-known time of one scenario and how it was found."""

    best_s: float
    replay_ok: bool
    start: str
    starts: int
    spread_s: float
    screened: dict[str, float] = field(default_factory=dict)
    refined: dict[str, float] = field(default_factory=dict)
    ocp_s: float = math.nan
    min_stability: float = math.nan
    wall_s: float = 0.0
    solution: MinimumTime | None = None

    def record(self) -> dict[str, Any]:
        """JSON-ready summary (no trajectory)."""
        return {
            "best_known_s": self.best_s,
            "replay_ok": self.replay_ok,
            "start": self.start,
            "starts": self.starts,
            "spread_s": self.spread_s,
            "ocp_s": self.ocp_s,
            "min_stability": self.min_stability,
            "wall_s": self.wall_s,
            "screened": self.screened,
            "refined": self.refined,
        }


def start_state(robot: Robot) -> np.ndarray:
    """The scenarios' start: at the origin heading +x, at rest, in the default pose."""
    return np.array([0.0, 0.0, 0.0, *default_pose(robot), 0.0, 0.0])


def best_known(
    robot: Robot,
    scenario: Scenario,
    settings: Settings = Settings(),
    log: Callable[[str], None] | None = None,
) -> Found:
    """The best-known minimum time (s) of ``scenario`` (module docstring)."""
    began = time.perf_counter()
    say = log or (lambda message: None)
    waypoints = list(scenario.waypoints)
    start = start_state(robot)
    s = settings

    built: dict[tuple[int, float, float], MinimumTimeProblem] = {}

    def problem(intervals: int, margin_s: float = 0.0, margin_m: float = 0.0) -> MinimumTimeProblem:
        key = (intervals, margin_s, margin_m)
        if key not in built:
            built[key] = MinimumTimeProblem(
                robot,
                waypoints,
                start,
                intervals_per_leg=intervals,
                stability_min=s.stability_min + margin_s,
                tolerance=s.tolerance - margin_m,
            )
        return built[key]

    screened, runs, starts = _screened(robot, scenario, waypoints, start, problem(s.coarse), s)
    say(f"screened {len(screened)} of {starts} starts")
    refined = _refined(problem(s.fine), screened, s)
    best_refined = min((r.total for r in refined.values()), default=math.inf)
    say(f"refined {len(refined)}: best {best_refined:.3f} s")

    found, grid = certify(robot, refined, waypoints, s, problem, say)
    if found is not None:
        tight = problem(grid, s.tight_margin_s, s.tight_margin_m)
        found = _tightened(robot, found, tight, waypoints, s, say)
    found = _faster_run(robot, runs, waypoints, s, found)
    found = follow_plan(robot, scenario, found, s, say)
    return _result(found, starts, screened, refined, began)


def _screened(
    robot: Robot,
    scenario: Scenario,
    waypoints: list[tuple[float, float]],
    start: np.ndarray,
    coarse: MinimumTimeProblem,
    s: Settings,
) -> tuple[dict[str, MinimumTime], dict[str, Guess], int]:
    """Step 1 of :func:`best_known` on the ``coarse`` problem: the successful solves by
    start label, the controllers' runs that were starts (by controller name) and the
    number of starts tried. ``start`` is the robot's state at rest at the origin
    (:func:`start_state`), ``waypoints`` the scenario's (x, y) in m."""
    screened: dict[str, MinimumTime] = {}

    def screen(
        label: str, guess: Guess, lbg: np.ndarray | None = None, ubg: np.ndarray | None = None
    ) -> None:
        result = coarse.solve(guess, label, lbg, ubg)
        if result.success:
            screened[label] = result

    patterns = [p for p in all_patterns(len(waypoints)) if p.elbow > 0]
    for pattern in patterns:
        screen(pattern.label, pattern_guess(robot, start, waypoints, pattern))
    ranked = _ranked_patterns(screened, patterns)
    other_elbow = [replace(p, elbow=-p.elbow) for p in ranked[: s.elbow_top]]
    for pattern in other_elbow:
        screen(pattern.label, pattern_guess(robot, start, waypoints, pattern))
    ranked = _ranked_patterns(screened, patterns + other_elbow)
    for pattern in ranked[: s.turn_top]:
        for variant in turn_variants(pattern):
            screen(variant.label, pattern_guess(robot, start, waypoints, variant))
    for pattern in ranked[: s.arm_top]:
        ahead = replace(pattern, arm="ahead")
        screen(ahead.label, pattern_guess(robot, start, waypoints, ahead))
    runs: dict[str, Guess] = {}
    for name in s.controllers:
        guess = controller_guess(scenario, name, payload=robot.payload)
        if guess is not None:
            runs[name] = guess
            screen(f"controller-{name}", guess)
    for label, reverse, elbow in _straight_starts():
        screen(label, coarse.straight_line_guess(reverse=reverse, elbow=elbow))
    loose = coarse.row_bounds(stability_min=1.0, tolerance=0.05)
    for label in _best(screened, s.continuation_top):
        relaxed = coarse.solve(screened[label].as_guess(), label, *loose)
        if relaxed.success:
            screen(f"continued-{label}", relaxed.as_guess())
    starts = len(patterns) + len(other_elbow) + min(s.turn_top, len(ranked)) * len(waypoints)
    starts += min(s.arm_top, len(ranked)) + len(s.controllers) + 4 + s.continuation_top
    return screened, runs, starts


def _refined(
    fine: MinimumTimeProblem, screened: dict[str, MinimumTime], s: Settings
) -> dict[str, MinimumTime]:
    """Step 2 of :func:`best_known`: the best ``s.refine`` distinct ``screened`` optima
    and the straight-line starts (``fine-<label>``) solved on the ``fine`` problem, the
    successful solves by label."""
    refined: dict[str, MinimumTime] = {}
    for label in _distinct(screened, s.refine):
        result = fine.solve(screened[label].as_guess(), label)
        if result.success:
            refined[label] = result
    # The straight-line starts solved on the fine grid as well, whatever their coarse
    # rank: screened on 8 intervals per leg they can rank low and still refine to the
    # best optimum (their coarse solutions turn too early to leave the grid room).
    for label, reverse, elbow in _straight_starts():
        result = fine.solve(fine.straight_line_guess(reverse=reverse, elbow=elbow), label)
        if result.success:
            refined[f"fine-{label}"] = result
    return refined


def _tightened(
    robot: Robot,
    found: tuple[MinimumTime, Replay],
    tight: MinimumTimeProblem,
    waypoints: list[tuple[float, float]],
    s: Settings,
    say: Callable[[str], None],
) -> tuple[MinimumTime, Replay]:
    """The certified ``found`` solved once more on ``tight`` (its grid, the smaller
    margins) from itself: that solution and its replay if it replays and is faster (s),
    else ``found``."""
    closer = tight.solve(found[0].as_guess(), found[0].start)
    if closer.success:
        check = replay(robot, closer, waypoints, s.stability_min, s.tolerance)
        say(f"tighter margins: {closer.total:.3f} s, replay {check.ok} {check.time_s:.3f} s")
        if check.ok and check.time_s < found[1].time_s:
            return (closer, check)
    return found


def _result(
    found: tuple[MinimumTime, Replay] | None,
    starts: int,
    screened: dict[str, MinimumTime],
    refined: dict[str, MinimumTime],
    began: float,
) -> Found:
    """The search's :class:`Found`: the certified solution's replayed time (s) if any
    (else inf), the spread (s) of the screened optima, and the wall time (s) since the
    ``began`` perf_counter stamp."""
    times = [r.total for r in screened.values()]
    spread = max(times) - min(times) if times else math.nan
    base = Found(
        math.inf,
        False,
        "",
        starts,
        spread,
        {k: v.total for k, v in screened.items()},
        {k: v.total for k, v in refined.items()},
    )
    if found is not None:
        certified, check = found
        base.best_s, base.replay_ok, base.start = check.time_s, True, certified.start
        base.ocp_s, base.min_stability = certified.total, check.min_stability
        base.solution = certified
    base.wall_s = time.perf_counter() - began
    return base


def certify(
    robot: Robot,
    refined: dict[str, MinimumTime],
    waypoints: Sequence[Sequence[float]],
    s: Settings,
    problem: Callable[[int, float, float], MinimumTimeProblem],
    say: Callable[[str], None] = lambda message: None,
) -> tuple[tuple[MinimumTime, Replay] | None, int]:
    """Step 3 (module docstring): the refined optima in order of their times, each solved
    on every certifying grid (``problem(intervals, margin_s, margin_m)``, :data:`Settings.final`
    first) and replayed; the first optimum with a passing replay gives the fastest of its
    passing replays. Returns ``((solution, replay), intervals)``, or ``(None, final)`` if
    no replay passes."""
    for label in _best(refined, len(refined)):
        passed = []
        for intervals in (s.final, *s.also_final):
            certified = problem(intervals, s.margin_s, s.margin_m).solve(
                refined[label].as_guess(), label
            )
            if not certified.success:
                continue
            check = replay(robot, certified, waypoints, s.stability_min, s.tolerance)
            say(
                f"certify {label} on {intervals}: {certified.total:.3f} s, replay {check.ok} "
                f"{check.time_s:.3f} s"
            )
            if check.ok:
                passed.append((check.time_s, intervals, certified, check))
        if passed:
            _, intervals, certified, check = min(passed, key=lambda item: item[0])
            return (certified, check), intervals
    return None, s.final


def follow_plan(
    robot: Robot,
    scenario: Scenario,
    found: tuple[MinimumTime, Replay] | None,
    s: Settings,
    say: Callable[[str], None] = lambda message: None,
) -> tuple[MinimumTime, Replay] | None:
    """Step 5: ``found`` (solution, replay) or the fastest run of the plan-following
    ``mpc`` that beats it, following each round's winner in the next round while one
    beats its plan (at most ``s.guided_rounds`` rounds): the closed loop can improve on
    the trajectory it follows more than once."""
    for round_ in range(1, s.guided_rounds + 1):
        if found is None:
            break
        guided = plan_runs(scenario, found[0], s, robot.payload)
        if round_ > 1:
            guided = {f"{name}-round{round_}": run for name, run in guided.items()}
        faster = _faster_run(robot, guided, list(scenario.waypoints), s, found)
        if faster is found:
            break
        # ignore: given a found solution, _faster_run returns one
        say(f"step 5, round {round_}: {faster[1].time_s:.3f} s ({faster[0].start})")  # type: ignore[index]
        found = faster
    return found


def plan_runs(
    scenario: Scenario, plan: MinimumTime, s: Settings, payload: float
) -> dict[str, Guess]:
    """Step 5: the recorded runs of the ``mpc`` with ``lookahead`` following ``plan``
    (one per :data:`Settings.guided` entry; those that did not finish left out)."""
    runs: dict[str, Guess] = {}
    if not s.guided:
        return runs
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "plan.npz"
        # ignore: the plan's array names (times, states...) are none of savez's keywords
        np.savez(path, **plan.plan_arrays())  # type: ignore[arg-type]
        for name, options in s.guided:
            extra = (("plan", str(path)), *options)
            guess = controller_guess(scenario, "mpc-lookahead", payload=payload, options=extra)
            if guess is not None:
                runs[name] = guess
    return runs


def _faster_run(
    robot: Robot,
    runs: dict[str, Guess],
    waypoints: Sequence[Sequence[float]],
    s: Settings,
    found: tuple[MinimumTime, Replay] | None,
) -> tuple[MinimumTime, Replay] | None:
    """``found`` (certified solution, replay), or a controller's recorded run on the thesis
    plant where replaying its wheel forces and joint rates open loop at the run's own step
    (which reproduces the run) passes the same check in less time: the plant did the task
    that fast, so the minimum is no longer (the certified optima can miss the replay where
    a closed-loop run does not). At 1 ms steps a run's held commands drift: 1 mm past the
    tolerance in scenario 2 of seed 0."""
    for name, run in runs.items():
        result, check = replay_run(robot, name, run, waypoints, s)
        if check.ok and (found is None or check.time_s < found[1].time_s):
            found = (result, check)
    return found


def replay_run(
    robot: Robot, name: str, run: Guess, waypoints: Sequence[Sequence[float]], s: Settings
) -> tuple[MinimumTime, Replay]:
    """``(solution, replay check)`` of a controller's recorded run
    (:func:`~ddwmmr.bounds.starts.controller_guess`): its wheel forces and joint rates
    replayed open loop on the thesis plant at the run's own step, checked against the
    waypoints, the tolerance and the S floor of ``s``; the solution's start is
    ``run-<name>``."""
    result = MinimumTime(
        float(run.arrivals[-1]), run.legs, True, run.times, run.states, run.inputs, f"run-{name}"
    )
    step = float(run.times[1] - run.times[0])
    return result, replay(robot, result, waypoints, s.stability_min, s.tolerance, dt=step)


def _straight_starts() -> list[tuple[str, str, float]]:
    """``(label, reverse, elbow)`` of the four straight-line starts
    (:meth:`~ddwmmr.mpc.min_time.MinimumTimeProblem.straight_line_guess`): never or at a
    turn reversing, elbow up (+1) or down (-1)."""
    return [
        (f"straight-{reverse}-{'up' if elbow > 0 else 'down'}", reverse, elbow)
        for reverse in ("never", "turn")
        for elbow in (1.0, -1.0)
    ]


def _best(results: dict[str, MinimumTime], count: int) -> list[str]:
    return sorted(results, key=lambda k: results[k].total)[:count]


def _distinct(results: dict[str, MinimumTime], count: int, gap: float = 1e-3) -> list[str]:
    """The ``count`` best labels whose times differ by more than ``gap`` (s) from each
    other (one per local optimum)."""
    chosen: list[str] = []
    for label in _best(results, len(results)):
        if all(abs(results[label].total - results[c].total) > gap for c in chosen):
            chosen.append(label)
        if len(chosen) == count:
            break
    return chosen


def _ranked_patterns(results: dict[str, MinimumTime], patterns: list[Pattern]) -> list[Pattern]:
    """Patterns in the order of their screened times (converged ones only)."""
    by_label = {p.label: p for p in patterns}
    return [by_label[k] for k in _best(results, len(results)) if k in by_label]
