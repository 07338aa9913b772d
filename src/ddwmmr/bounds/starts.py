"""Starts for the minimum-time OCP: the structures a local optimum can take.

A local optimum of :class:`~ddwmmr.mpc.min_time.MinimumTimeProblem` is mostly fixed by
discrete choices its start makes for it: on each leg whether the base drives forwards or
backwards, which way it turns into the leg, which elbow branch the arm keeps, and whether
the arm reaches ahead early or late. :func:`pattern_guess` draws one start per choice:
the base turns in place into the leg's direction (``turn_rate``), drives straight at
``speed`` and stops ``reach`` short of the waypoint, the arm holding one pose
(the start pose, or stretched towards the direction of travel with ``arm="ahead"``).
:func:`controller_guess` turns a controller's run on the thesis plant into a start.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc.min_time import Guess

if TYPE_CHECKING:
    from ddwmmr.plants.base import Observation, Plant, PlantDivergedError
    from ddwmmr.scenarios.generator import Scenario

#: Samples of a pattern guess.
SAMPLES = 600


@dataclass(frozen=True)
class Pattern:
    """Discrete choices of a start.

    Attributes:
        directions: per leg, +1 drive forwards, -1 backwards.
        long_turns: per leg, True turns into the leg the long way round.
        elbow: sign of th2 (+1 or -1).
        arm: ``"start"`` (the start pose throughout) or ``"ahead"`` (stretched towards the
            direction of travel, S permitting).
    """

    directions: tuple[int, ...]
    long_turns: tuple[bool, ...]
    elbow: int
    arm: str = "start"

    @property
    def label(self) -> str:
        signs = "".join("f" if d > 0 else "b" for d in self.directions)
        turns = "".join("L" if t else "s" for t in self.long_turns)
        elbow = "up" if self.elbow > 0 else "down"
        return f"{signs}-{turns}-{elbow}-{self.arm}"


def all_patterns(legs: int, arms: Sequence[str] = ("start",)) -> list[Pattern]:
    """Every direction pattern with the shorter turns, both elbows, the given arm poses."""
    return [
        Pattern(directions, (False,) * legs, elbow, arm)
        for directions in itertools.product((1, -1), repeat=legs)
        for elbow in (1, -1)
        for arm in arms
    ]


def turn_variants(pattern: Pattern) -> list[Pattern]:
    """The pattern with one leg's turn the long way round, for each leg."""
    out = []
    for i in range(len(pattern.long_turns)):
        turns = tuple(t != (j == i) for j, t in enumerate(pattern.long_turns))
        out.append(Pattern(pattern.directions, turns, pattern.elbow, pattern.arm))
    return out


def arm_pose(
    robot: Robot, start_pose: tuple[float, float], elbow: int, arm: str, backwards: bool
) -> tuple[float, float]:
    """Joint angles of a pattern's arm: the start pose on the elbow branch, or stretched
    forwards/backwards (th1 = 0 or pi, a slight bend on the elbow branch)."""
    th1, th2 = start_pose
    if arm == "start":
        return (th1, th2) if elbow * th2 >= 0 else (-th1, -th2)
    bend = 0.3 * elbow
    base = (math.pi - 0.15) if backwards else 0.0
    return (base - 0.5 * bend, bend)


def pattern_guess(
    robot: Robot,
    start: Sequence[float] | np.ndarray,
    waypoints: Sequence[tuple[float, float]],
    pattern: Pattern,
    speed: float = 1.0,
    turn_rate: float = 0.6,
    reach: float = 0.4,
) -> Guess:
    """A start of the minimum-time OCP following ``pattern`` (module docstring).

    ``start`` is the state ``[x, y, phi, th1, th2, v, w]``; speed (m/s), turn rate
    (rad/s) and the reach the base stops short by (m)."""
    base = np.array(start[:2], dtype=float)
    heading, t = float(start[2]), 0.0
    knots: list[tuple[float, float, float, float, int]] = [(0.0, base[0], base[1], heading, 0)]
    arrivals: list[float] = []
    for i, (wx, wy) in enumerate(waypoints):
        delta = np.array([wx, wy]) - base
        direction = math.atan2(delta[1], delta[0])
        backwards = pattern.directions[i] < 0
        target = direction + (math.pi if backwards else 0.0)
        change = math.remainder(target - heading, 2.0 * math.pi)
        if pattern.long_turns[i]:
            change -= math.copysign(2.0 * math.pi, change)
        t += abs(change) / turn_rate
        heading += change
        knots.append((t, base[0], base[1], heading, i))
        distance = max(float(np.hypot(*delta)) - reach, 0.05)
        base = base + distance * np.array([math.cos(direction), math.sin(direction)])
        t += distance / speed + 0.5
        knots.append((t, base[0], base[1], heading, i))
        arrivals.append(t)
    table = np.array(knots)
    times = np.linspace(0.0, t, SAMPLES)
    states = np.zeros((SAMPLES, sym.NX_FORCE))
    for j, column in enumerate((1, 2, 3)):
        states[:, j] = np.interp(times, table[:, 0], table[:, column])
    leg = np.minimum(np.searchsorted(arrivals, times), len(waypoints) - 1)
    start_pose = (float(start[3]), float(start[4]))
    for i in range(len(waypoints)):
        pose = arm_pose(robot, start_pose, pattern.elbow, pattern.arm, pattern.directions[i] < 0)
        states[leg == i, 3:5] = pose
    states[:, 5] = np.gradient(states[:, 0], times) * np.cos(states[:, 2]) + np.gradient(
        states[:, 1], times
    ) * np.sin(states[:, 2])
    states[:, 6] = np.gradient(states[:, 2], times)
    return Guess(times, states, np.zeros((SAMPLES, sym.NU_FORCE)), np.array(arrivals))


class RecordingTask:
    """The waypoint task for a controller's run that keeps its states and inputs.

    Reference: the current waypoint (orientation free, at rest); the run ends when the
    end effector has been within ``tolerance`` of every waypoint in order, or when S <= 1.
    Keeps every sample's state ``[x, y, phi, th1, th2, v, w]``, the wheel forces the plant
    applied over the step and the joint rates (N, N, rad/s, rad/s; ``dt`` is the loop's
    step), and the times the waypoints were reached."""

    trajectory = None

    def __init__(
        self,
        robot: Robot,
        plant: Plant,
        waypoints: Iterable[Sequence[float]],
        dt: float,
        tolerance: float = 0.01,
    ) -> None:
        self.robot, self.plant, self.dt = robot, plant, dt
        self.waypoints = [tuple(w) for w in waypoints]
        self.tolerance = tolerance
        self.index = 0
        self.times: list[float] = []
        self.states: list[list[float]] = []
        self.inputs: list[list[float]] = []
        self.arrivals: list[float] = []

    def start(self, obs: Observation) -> bool:
        return False

    def finished(self, k: int, t: float, obs: Observation) -> bool:
        xe, ye, _ = self.robot.fk(np.asarray(obs.values))
        while self.index < len(self.waypoints):
            wx, wy = self.waypoints[self.index]
            if math.hypot(xe - wx, ye - wy) > self.tolerance:
                break
            self.arrivals.append(t)
            self.index += 1
        done = self.index == len(self.waypoints)
        if done:
            self.times.append(t)
            self.states.append([*obs.values, obs.v, obs.w])
        return done

    def reference(self, t: float, obs: Observation) -> tuple[np.ndarray, np.ndarray]:
        wx, wy = self.waypoints[min(self.index, len(self.waypoints) - 1)]
        return np.array([wx, wy, 0.0]), np.zeros(3)

    def record(
        self,
        k: int,
        t: float,
        obs: Observation,
        command: Any,
        applied: Any,
        saturated: bool,
        info: Any,
        step_ns: int,
    ) -> None:
        self.times.append(t)
        self.states.append([*obs.values, obs.v, obs.w])

    def after_step(self, k: int, t: float, obs: Observation, applied: Any) -> bool:
        before, after = self.states[-1], obs.values
        left, right = self.plant.extra_values()
        rates = ((after[3] - before[3]) / self.dt, (after[4] - before[4]) / self.dt)
        self.inputs.append([left, right, *rates])
        return self.robot.stability(np.asarray(after))[2] <= 1.0

    def controller_error(self, k: int, error: Exception) -> bool:
        return True

    def diverged(self, k: int, error: PlantDivergedError) -> None:
        return None

    def guess(self) -> Guess | None:
        """The run as a start, or None if it did not reach every waypoint."""
        if len(self.arrivals) < len(self.waypoints):
            return None
        return Guess(
            np.array(self.times),
            np.array(self.states),
            np.array(self.inputs),
            np.array(self.arrivals),
        )


def controller_guess(
    scenario: Scenario,
    controller: str,
    payload: float = 3.0,
    dt: float = 0.01,
    options: tuple[tuple[str, Any], ...] = (),
) -> Guess | None:
    """A start from a controller's run of ``scenario`` on the thesis plant (the scenario
    protocol's controllers: ``"thesis"``, ``"competitive"`` (the thesis controller with
    the competitive arbiter), ``"qp"``, ``"mpc"`` or ``"mpc-lookahead"`` (the mpc
    planning through the next waypoint)), with the controller ``options`` (``(name,
    value)`` pairs) besides; None if it did not finish."""
    from ddwmmr.behaviours.objective import default_pose
    from ddwmmr.scenarios.protocol import (
        RunConfig,
        make_scenario_controller,
        make_scenario_plant,
    )
    from ddwmmr.sim.loop import run_loop

    arbiter = "competitive" if controller == "competitive" else "state-machine"
    kind = {"competitive": "thesis", "mpc-lookahead": "mpc"}.get(controller, controller)
    options = ((("lookahead", True),) if controller == "mpc-lookahead" else ()) + tuple(options)
    config = RunConfig(
        controller=kind,
        plant="thesis",
        payload=payload,
        dt=dt,
        arbiter=arbiter,
        controller_options=options,
    )
    robot = Robot().with_payload(payload)
    plant = make_scenario_plant(robot, config)
    ctl = make_scenario_controller(robot, scenario, config, plant)
    task = RecordingTask(robot, plant, scenario.waypoints, dt, config.tolerance)
    q0 = np.array([0.0, 0.0, 0.0, *default_pose(robot)])
    run_loop(plant, ctl, task, q0, dt, round(config.limit_for(scenario) / dt))
    return task.guess()


__all__ = [
    "Pattern",
    "RecordingTask",
    "all_patterns",
    "controller_guess",
    "pattern_guess",
    "turn_variants",
]
