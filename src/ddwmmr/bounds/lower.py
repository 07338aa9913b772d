"""A true lower bound on a scenario's minimum time: the wheels' shared force budget.

Each wheel's force is limited, ``|F_l|, |F_r| <= F_w``. With the sum ``F = F_l + F_r`` and
the yaw torque ``T = (F_r - F_l) b`` (``b`` the wheels' lever) that is exactly
``|F| / (2 F_w) + |T| / (2 F_w b) <= 1`` at every instant, so over the whole task::

    t_f >= int |F| dt / (2 F_w) + int |T| dt / (2 F_w b).

The base's laws turn both integrals into geometry (docs/mpc.md, "The physical limit,
bracketed"):

* ``m vdot + c1 v = F``: on every stretch between two stops (``v = 0``; the first starts
  at rest) ``int F = m v_end + c1 (signed path)``, so ``int |F| >= c1 P``, ``P`` the path
  length of the base centre;
* ``I(th2) wdot + c2 w = T`` with ``|dI/dt| <= k = I_cos * joint speed`` and ``w(0) = 0``:
  ``int |T| >= (c2 - k) Phi``, ``Phi = int |w|`` the total rotation.

Hence ``t_f >= c1 P / (2 F_w) + (c2 - k) Phi / (2 F_w b)``: driving costs 0.75 s/m and
turning 0.72 s/rad whatever the speeds, so no path of the real robot is faster than the
cheapest path under this price. The geometry the path must have:

* at waypoint ``i`` the base centre ``p_i`` is within ``L1 + L2 + tolerance`` of it (the
  end effector is there, the arm reaches at most ``L1 + L2``);
* on leg ``i`` the base moves along its heading (or against it): if every heading of the
  leg stays at least ``beta_i`` from the line of the displacement ``p_i - p_{i-1}``, the
  path is at least ``|p_i - p_{i-1}| / cos(beta_i)``; the heading ``X_i`` of the leg
  closest to that line is passed in order, from ``X_0 = 0``, so ``Phi >= sum_i
  circ(X_{i-1}, X_i)``.

:func:`budget_bound` minimises ``0.75 sum |dp_i| / cos(beta_i) + 0.72 sum circ(X_{i-1},
X_i)`` globally by dynamic programming over cells of ``p_i`` (squares of side
``cell``, those meeting the disc) and ``X_i`` (arcs), each term taken at its least over
the cells (distance between the squares, angles less the cells' half-widths and the
direction's spread), so the result is at most the minimum of the continuous problem:
a lower bound on the time of every trajectory of the model and of the thesis plant
(whose exact base steps keep both identities).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Prices:
    """Seconds per metre driven and per radian turned, and the reach (m).

    ``drive = c1 / (2 F_w)``, ``turn = (c2 - k) / (2 F_w b)`` with ``k = |I_cos| *
    joint speed`` (the fastest the yaw inertia changes), ``reach = L1 + L2 + tolerance``.
    """

    drive: float
    turn: float
    reach: float

    @classmethod
    def from_robot(cls, robot: Robot, tolerance: float = 0.01) -> Prices:
        d = sym.ThesisDynamics.from_robot(robot)
        force = 2.0 * d.force_limit
        joint = min(d.joint_speed, robot.joint_speed_limit)
        inertia_rate = abs(d.inertia_cos) * joint
        return cls(
            drive=d.c1 / force,
            turn=max(0.0, d.c2 - inertia_rate) / (force * d.half_width),
            reach=robot.L1 + robot.L2 + tolerance,
        )


@dataclass(frozen=True)
class Bound:
    """A lower bound (s) and what it took: cells per waypoint, heading arcs, wall time (s)."""

    value: float
    cells: int
    arcs: int
    wall_s: float


def circular(a, b):
    """Distance (rad) between angles on the circle, in [0, pi]."""
    return np.abs(np.remainder(np.asarray(a) - b + math.pi, TWO_PI) - math.pi)


def turn_transform(cost: np.ndarray, step: float) -> np.ndarray:
    """``out[:, j] = min_i cost[:, i] + step * max(0, d(i, j) - 1)`` over arcs on the circle
    (``d`` the circular index distance, ``step`` the price of one arc): the least cost of
    reaching arc j from any arc i, the turn between two arcs being at least their centres'
    distance less one width. An erosion by one arc, then an L1 distance transform of slope
    ``step`` by passes both ways around the circle (twice, for the wrap)."""
    n = cost.shape[1]
    out = np.minimum(cost, np.minimum(np.roll(cost, 1, axis=1), np.roll(cost, -1, axis=1)))
    for _ in range(2):
        for j in range(n):
            np.minimum(out[:, j], out[:, j - 1] + step, out=out[:, j])
        for j in range(n - 1, -1, -1):
            np.minimum(out[:, j], out[:, (j + 1) % n] + step, out=out[:, j])
    return out


def disc_cells(centre, radius: float, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Lower-left corners (x, y) of the squares of side ``cell`` on a grid about
    ``centre`` that meet the disc of ``radius`` (m): together they cover it."""
    count = math.ceil(radius / cell)
    edges = cell * np.arange(-count, count)
    xs, ys = np.meshgrid(edges, edges, indexing="ij")
    x0, y0 = xs.ravel(), ys.ravel()
    nearest = np.hypot(np.clip(0.0, x0, x0 + cell), np.clip(0.0, y0, y0 + cell))
    keep = nearest <= radius
    return x0[keep] + centre[0], y0[keep] + centre[1]


def _drive_costs(ax, ay, a_size, bx, by, b_size, centres, half_arc, price):
    """Least driving time (s) from each square of A to each of B for each heading arc of
    the leg: (len(A), len(B), arcs).

    ``|dp|`` is at least the distance between the squares; ``beta`` at least the line
    distance between the arc's centre and the direction between the squares' centres,
    less the arc's half-width and the direction's spread over the squares."""
    dx = np.maximum(0.0, np.maximum(bx - (ax[:, None] + a_size), ax[:, None] - (bx + b_size)))
    dy = np.maximum(0.0, np.maximum(by - (ay[:, None] + a_size), ay[:, None] - (by + b_size)))
    length = np.hypot(dx, dy)
    cx = bx + 0.5 * b_size - (ax[:, None] + 0.5 * a_size)
    cy = by + 0.5 * b_size - (ay[:, None] + 0.5 * a_size)
    centre = np.hypot(cx, cy)
    radius = (a_size + b_size) / math.sqrt(2.0)
    ratio = np.clip(radius / np.maximum(centre, 1e-300), 0.0, 1.0)
    spread = np.where(centre > radius, np.arcsin(ratio), 0.5 * math.pi)
    direction = np.arctan2(cy, cx)
    line = circular(centres, direction[:, :, None])
    line = np.minimum(line, math.pi - line)  # forwards or backwards along the line
    beta = np.clip(line - half_arc - spread[:, :, None], 0.0, 0.5 * math.pi)
    cos = np.cos(beta)
    with np.errstate(divide="ignore"):
        cost = price * length[:, :, None] / cos
    return np.where(length[:, :, None] > 0.0, cost, 0.0)


def budget_bound(
    robot: Robot,
    waypoints,
    start: tuple[float, float, float] = (0.0, 0.0, 0.0),
    tolerance: float = 0.01,
    cell: float = 0.05,
    arcs: int = 180,
    chunk: int = 24,
) -> Bound:
    """A lower bound (s) on the time to take the end effector through ``waypoints`` in
    order from the base pose ``start`` (x, y, heading) at rest (module docstring).

    ``cell``: side (m) of the position cells; ``arcs``: heading arcs over the circle;
    ``chunk``: start cells per block (memory)."""
    began = time.perf_counter()
    prices = Prices.from_robot(robot, tolerance)
    width = TWO_PI / arcs
    centres = -math.pi + width * (0.5 + np.arange(arcs))
    half = 0.5 * width
    # layer 0: the start exactly; its heading X_0 is start[2] exactly
    ax, ay, a_size = np.array([start[0]]), np.array([start[1]]), 0.0
    entry = (prices.turn * np.maximum(0.0, circular(start[2], centres) - half))[None, :]
    cost = None
    for w in waypoints:
        bx, by = disc_cells(w, prices.reach, cell)
        cost = np.full((bx.size, arcs), np.inf)
        for first in range(0, ax.size, chunk):
            rows = slice(first, first + chunk)
            drive = _drive_costs(
                ax[rows], ay[rows], a_size, bx, by, cell, centres, half, prices.drive
            )
            np.minimum(cost, np.min(entry[rows][:, None, :] + drive, axis=0), out=cost)
        # the next leg's entry: the least over this leg's arc of the cost plus the turn
        entry = turn_transform(cost, prices.turn * width)
        ax, ay, a_size = bx, by, cell
    value = float(np.min(cost))
    return Bound(value, int(ax.size), arcs, time.perf_counter() - began)
