"""The minimum-time OCP checked where the answer is known: the bounded-velocity
differential drive (Balkcom and Mason, "Time optimal trajectories for bounded velocity
differential drive vehicles", IJRR 21(3), 2002).

A differential drive with wheel radius ``r``, half-track ``b`` and each wheel's angular
speed in ``[-u, u]`` (no dynamics, no arm): ``xdot = v cos th``, ``ydot = v sin th``,
``thdot = w`` with ``v = r (u_l + u_r) / 2``, ``w = r (u_r - u_l) / (2 b)``. Balkcom and
Mason prove that every non-trivial time-optimal trajectory alternates straight segments
(both wheels at ``+-u``: speed ``r u``) and turns in place about the axle's centre (the
wheels at ``-+u``: rate ``r u / b``), and that four such actions always suffice. A path
of straight segments ``d_j`` (signed) at headings ``h_j`` and turns between them therefore
takes::

    T = ( sum_j |d_j| + b * sum of the turns ) / (r u)

and the optimum is the least ``T`` over the families with at most two straight segments:
no straight (a turn in place), one straight along the line to the goal (either way), or
two straights at headings ``(h1, h2)`` whose lengths solve ``d1 u(h1) + d2 u(h2) = goal
- start`` (turns into the first, between, and out of the last, each the shorter way).
:func:`optimal_time` evaluates each family's time in closed form and minimises the
two-straight family over ``(h1, h2)`` on a grid refined by Nelder-Mead (to 1e-10 s).

:func:`ocp_time` solves the same problem with :class:`ddwmmr.mpc.min_time.FreeTimeOCP`,
the transcription the scenarios' best-known times come from, specialised to this model:
five phases of free duration (room for Balkcom and Mason's actions and their switches),
the goal pose an equality at the end, a few starts; tests/test_bounds.py asserts that it
matches :func:`optimal_time` within 1 %.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import casadi as ca
import numpy as np

# ignore: scipy ships no type hints (no scipy-stubs in the environment)
from scipy.optimize import minimize

from ddwmmr.mpc.min_time import FreeTimeOCP, Guess, LegEnd, ShootingModel

TWO_PI = 2.0 * math.pi


def _turn(a: float, b: float) -> float:
    """The shorter turn (rad) from heading a to heading b."""
    return abs(math.remainder(b - a, TWO_PI))


def _two_straights(
    h: Sequence[float] | np.ndarray,
    delta: np.ndarray,
    start_heading: float,
    goal_heading: float,
    half_track: float,
) -> float:
    """Wheel-travel units ``sum |d| + b * turns`` of the two-straight family at headings
    ``h`` (inf where the two lines are parallel)."""
    h1, h2 = h
    matrix = np.array([[math.cos(h1), math.cos(h2)], [math.sin(h1), math.sin(h2)]])
    det = np.linalg.det(matrix)
    if abs(det) < 1e-12:
        return math.inf
    d1, d2 = np.linalg.solve(matrix, delta)
    turns = _turn(start_heading, h1) + _turn(h1, h2) + _turn(h2, goal_heading)
    units: float = abs(d1) + abs(d2) + half_track * turns
    return units


def optimal_time(
    start: tuple[float, float, float],
    goal: tuple[float, float, float],
    wheel_radius: float = 1.0,
    half_track: float = 1.0,
    wheel_speed: float = 1.0,
    grid: int = 180,
) -> float:
    """Balkcom and Mason's minimum time (s) from pose ``start`` to ``goal`` (x, y, th)
    (module docstring)."""
    delta = np.array(goal[:2], dtype=float) - np.array(start[:2], dtype=float)
    th0, th1 = float(start[2]), float(goal[2])
    distance = float(np.hypot(*delta))
    best = math.inf
    if distance < 1e-12:
        best = half_track * _turn(th0, th1)
    else:
        line = math.atan2(delta[1], delta[0])
        for h in (line, line + math.pi):
            best = min(best, distance + half_track * (_turn(th0, h) + _turn(h, th1)))

        def cost(h: Sequence[float] | np.ndarray) -> float:
            return _two_straights(h, delta, th0, th1, half_track)

        headings = TWO_PI * np.arange(grid) / grid
        values = [(cost((a, b)), a, b) for a, b in itertools.product(headings, headings)]
        values.sort()
        for value, a, b in values[:12]:
            refined = minimize(
                cost,
                np.array([a, b]),
                method="Nelder-Mead",
                options={"xatol": 1e-11, "fatol": 1e-12, "maxiter": 4000},
            )
            best = min(best, value, float(refined.fun))
    return best / (wheel_radius * wheel_speed)


def diffdrive_model(wheel_radius: float, half_track: float, wheel_speed: float) -> ShootingModel:
    """The kinematic differential drive as a :class:`ShootingModel`: state ``[x, y, th]``,
    inputs the wheel speeds ``[u_l, u_r]`` in ``[-u, u]``."""

    def rhs(x: ca.SX, u: ca.SX) -> ca.SX:
        v = 0.5 * wheel_radius * (u[0] + u[1])
        w = 0.5 * wheel_radius * (u[1] - u[0]) / half_track
        return ca.vertcat(v * ca.cos(x[2]), v * ca.sin(x[2]), w)

    inf = np.full(3, np.inf)
    bound = np.full(2, wheel_speed)
    return ShootingModel(3, 2, rhs, -bound, bound, -inf, inf)


def ocp_time(
    start: tuple[float, float, float],
    goal: tuple[float, float, float],
    wheel_radius: float = 1.0,
    half_track: float = 1.0,
    wheel_speed: float = 1.0,
    phases: int = 5,
    intervals: int = 12,
) -> float:
    """The minimum time (s) found by :class:`FreeTimeOCP` (module docstring): the best
    converged solve over the goal heading's windings ``th1 + 2 pi k``, k in {-1, 0, 1},
    each from turn-drive-turn starts (forwards and backwards)."""
    model = diffdrive_model(wheel_radius, half_track, wheel_speed)
    free = LegEnd(lambda x: x[:0], np.zeros(0), np.zeros(0))
    best = math.inf
    for winding in (-1, 0, 1):
        target = np.array([goal[0], goal[1], goal[2] + TWO_PI * winding])
        end = LegEnd(lambda x, t=target: x - ca.DM(t), np.zeros(3), np.zeros(3))
        ocp = FreeTimeOCP(
            model,
            np.asarray(start, dtype=float),
            [free] * (phases - 1) + [end],
            intervals,
            leg_time_range=(0.0, 100.0),
            ipopt_options={"max_iter": 500},
        )
        for guess in _guesses(start, target, phases, (wheel_radius, half_track, wheel_speed)):
            result = ocp.solve(guess)
            if result.success:
                best = min(best, result.total)
    return best


def _guesses(
    start: Sequence[float] | np.ndarray,
    target: np.ndarray,
    phases: int,
    model_wheels: tuple[float, float, float],
) -> list[Guess]:
    """Starts that turn towards the goal (driving forwards, or backwards), drive, and turn
    to its heading (phases equally long, the wheel speeds to match: a start at rest leaves
    the leg durations without a gradient and IPOPT's restoration fails)."""
    radius, half_track, wheel_speed = model_wheels
    start = np.asarray(start, dtype=float)
    line = math.atan2(target[1] - start[1], target[0] - start[0])
    speed = radius * wheel_speed
    total = max(1.0, 3.0 * float(np.hypot(*(target[:2] - start[:2]))) / speed)
    times = np.linspace(0.0, total, 4)
    samples = np.linspace(0.0, total, 61)
    arrivals = total * np.arange(1, phases + 1) / phases
    guesses: list[Guess] = []
    for backwards in (False, True):
        direction = line + (math.pi if backwards else 0.0)
        heading = start[2] + math.remainder(direction - start[2], TWO_PI)
        knots = np.array([start, [*start[:2], heading], [*target[:2], heading], target])
        states = np.column_stack([np.interp(samples, times, knots[:, i]) for i in range(3)])
        rates = np.diff(states, axis=0) / np.diff(samples)[:, None]
        v = rates[:, 0] * np.cos(states[:-1, 2]) + rates[:, 1] * np.sin(states[:-1, 2])
        w = rates[:, 2]
        wheels = np.column_stack([(v - half_track * w) / radius, (v + half_track * w) / radius])
        wheels = np.clip(wheels, -wheel_speed, wheel_speed)
        guesses.append(Guess(samples, states, wheels, arrivals))
    return guesses
