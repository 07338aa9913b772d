"""Replay an offline minimum-time solution open-loop on the thesis plant.

The OCP (:mod:`ddwmmr.mpc.min_time`) integrates its model by RK4 on its own grid; the
thesis plant (:class:`~ddwmmr.plants.thesis.ThesisPlant`) integrates the base exactly
under held forces and moves the arm by its servo. A solution counts only if the plant,
fed the solution's wheel forces and joint rates (each OCP interval cut into equal plant
steps of at most ``dt``, the joint targets ``th + rate step``), takes the end effector
within the waypoint tolerance of every waypoint in order with ``S`` held above its floor
at every step. The time is the plant's: the end of the step at which the last waypoint
was reached.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from ddwmmr.commands import WheelForces
from ddwmmr.model import Robot
from ddwmmr.mpc.min_time import MinimumTime
from ddwmmr.plants.thesis import ThesisPlant

#: Plant step (s) of the replay.
REPLAY_DT = 0.001


@dataclass(frozen=True)
class Replay:
    """Result of :func:`replay`.

    Attributes:
        ok: every waypoint reached in order and ``S >= stability_min`` throughout.
        time_s: time (s) the last waypoint was reached (inf if not all were).
        reached: waypoints reached; arrivals: their times (s).
        min_stability: lowest S over the steps; closest_m: closest approach (m) to each
            waypoint while it was the current one.
    """

    ok: bool
    time_s: float
    reached: int
    arrivals: tuple[float, ...]
    min_stability: float
    closest_m: tuple[float, ...]


def replay(
    robot: Robot,
    result: MinimumTime,
    waypoints: Sequence[Sequence[float]],
    stability_min: float = 1.25,
    tolerance: float = 0.01,
    dt: float = REPLAY_DT,
) -> Replay:
    """Replay ``result`` on :class:`ThesisPlant` with steps of at most ``dt`` (s) from its
    first state (at rest) and judge it (module docstring). Runs until the last waypoint is
    reached or the solution's inputs end (the last held 0.2 s longer)."""
    plant = ThesisPlant(robot)
    plant.reset(np.asarray(result.states[0][:5], dtype=float), dt)
    times = np.asarray(result.times, dtype=float)
    index, arrivals = 0, []
    closest = [math.inf] * len(waypoints)
    lowest = robot.stability(np.asarray(result.states[0][:5]))[2]
    t = 0.0
    for command, step in held_commands(plant, times, result.inputs, dt):
        plant.step(t, command, step)
        t += step
        q = np.asarray(plant.state.q)
        lowest = min(lowest, robot.stability(q)[2])
        xe, ye, _ = robot.fk(q)
        while index < len(waypoints):
            distance = math.hypot(xe - waypoints[index][0], ye - waypoints[index][1])
            closest[index] = min(closest[index], distance)
            if distance > tolerance:
                break
            arrivals.append(float(t))
            index += 1
        if index == len(waypoints):
            break
    done = index == len(waypoints)
    ok = done and lowest >= stability_min
    return Replay(
        ok,
        arrivals[-1] if done else math.inf,
        index,
        tuple(arrivals),
        float(lowest),
        tuple(float(c) for c in closest),
    )


def held_commands(
    plant: ThesisPlant, times: np.ndarray, inputs: np.ndarray, dt: float
) -> Iterator[tuple[WheelForces, float]]:
    """The replay's plant commands and step lengths (s): each interval of ``times`` cut into
    equal steps of at most ``dt``, its wheel forces held and the joint targets ``th + rate
    step`` from ``plant``'s state at each step (read when the command is drawn); the last
    input is held 0.2 s longer."""
    held = [*inputs, inputs[-1]]
    spans = [*np.diff(times), 0.2]
    for (f_left, f_right, rate1, rate2), span in zip(held, spans):
        count = max(1, math.ceil(span / dt - 1e-9))
        step = span / count
        for _ in range(count):
            state = plant.state
            target1, target2 = state.th1 + rate1 * step, state.th2 + rate2 * step
            yield WheelForces(f_left, f_right, target1, target2), step
