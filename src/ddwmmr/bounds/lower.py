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

The stops (docs/mpc.md, "Pricing the stops"). Cut the task at the base's reversals (``v``
changes sign): each stretch starts at rest and, but for the last, ends at rest. In stretch
``j`` (time ``t_j``, path ``D_j``, force spent ``U_j = int |F| / (2 F_w)``, rotation budget
``R_j = int |T| / (2 F_w b)``) the budget gives ``t_j >= U_j + R_j``, so for any weight
``lam`` in [0, 1] ``t_j >= (1 - lam) t_j + lam U_j + lam R_j >= D_j / v_top + lag(D_j) +
lam R_j``, where ``D / v_top + lag(D)`` is the least ``(1 - lam) T + lam U`` of any drive
of ``D`` from rest to rest (:class:`Lags`). Summed, with ``sum R_j >= (c2 - k) Phi / (2 F_w
b)``::

    t_f >= c1 P / (2 F_w) + lam (c2 - k) Phi / (2 F_w b) + sum_j lag(D_j).

At ``lam = 1`` the lag is 0 and this is the bound above. :func:`budget_bound` with
``rotation_weight = lam < 1`` minimises it: the programme also tracks, per leg, whether the
base reverses in it (the heading nearest the displacement's line, as above) or not (the
direction of travel nearest the displacement, on the full circle: a sharper geometry), and
whether the open stretch has been charged. A leg without a reversal lies in one stretch,
which it is at most as long as: the stretch is charged the leg's lag if it has not been. A
leg with reversals cuts its path into ``a`` (ending the open stretch), ``m_i`` (whole
stretches) and ``b`` (starting the next): driving them back to back is one drive of the
leg, so ``lag(L) <= lag(a) + sum lag(m_i) + lag(b)`` (the lag grows with the path), and if
the open stretch is uncharged the leg is charged ``lag(L)`` and the next stretch counts as
charged; if it is charged, nothing more is (the charges are never negative). The last
stretch ends free (``lag_free(a + b) <= lag(a) + lag_free(b)`` the same way): it is charged
the rest-to-rest lag less the largest excess of that over the free-end lag.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ddwmmr.errors import (
    MAX_ANGLE_RAD,
    MAX_COORDINATE_M,
    ParameterError,
    check_instance,
    check_int_at_least,
    check_range,
    list_items,
    shown,
    xy_pairs,
)
from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym

TWO_PI = 2.0 * math.pi

#: Allowed waypoint tolerance (m). The bound stands for the arm reaching at most ``L1 + L2``
#: plus this margin; up to ten times the scenarios' 1 cm it is still a margin, while one
#: comparable to the reach turns the waypoints into regions and the bound into 0.
TOLERANCE_RANGE_M = (0.0, 0.1)
#: Allowed side (m) of the position cells. The cells per waypoint are about ``pi (reach /
#: cell)^2`` (13 900 at 1 cm for the thesis arm) and the time grows as their square: below
#: 1 cm the memory and time get out of hand for no gain (1 cm already brings the bound
#: within a few hundredths of a second of the relaxation's continuous minimum); above
#: 0.5 m a cell is as wide as the thesis arm's reach and the bound is close to 0. The
#: bounds tool's grids (0.05 and 0.07 m) sit well inside. MAX_BLOCK_VALUES bounds the
#: memory of the finer end.
CELL_RANGE_M = (0.01, 0.5)
#: Most heading arcs over the circle (a quarter of a degree each): the memory and time are
#: linear in them, and finer arcs than the cells' own spread of directions gain nothing.
MAX_ARCS = 1440
#: Most values of one block of the programme (start cells x cells x arcs, each float64):
#: its temporaries peak at 45-70 bytes per value, so about 1 GiB at the cap. The block's
#: start cells are ``chunk`` (1 at the first waypoint, the start), its cells the
#: ``(2 ceil(reach / cell))^2`` squares :func:`disc_cells` looks at.
MAX_BLOCK_VALUES = 2**24
#: Start cells per block by default (and always in :func:`lower_bound`).
CHUNK = 24


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


def circular(a: float | np.ndarray, b: float | np.ndarray) -> np.ndarray | np.float64:
    """Distance (rad) between angles on the circle, in [0, pi]: ``|((a - b + pi) mod 2 pi)
    - pi|``.

    Where every ``x = a - b + pi`` lies in (-pi, 3 pi) (angles in [-pi, pi], as the
    programme's are) the ``mod`` is done in place, bit for bit what ``np.remainder`` gives
    without its division, on the programme's (cells, cells, arcs) blocks: there
    ``np.remainder(x, 2 pi)`` (fmod, then ``+ 2 pi`` if negative) is ``x`` on [0, 2 pi),
    ``x - 2 pi`` on [2 pi, 3 pi) (exact: fmod is exact, and so is the difference of numbers
    within a factor of 2 of each other) and ``x + 2 pi`` rounded on (-pi, 0)."""
    x = np.asarray(np.asarray(a) - b + math.pi, dtype=float)
    if x.size and not (x.min() > -math.pi and x.max() < 3.0 * math.pi):
        wrapped: np.ndarray | np.float64 = np.abs(np.remainder(x, TWO_PI) - math.pi)
        return wrapped  # NaN, inf or far apart
    np.subtract(x, TWO_PI, out=x, where=x >= TWO_PI)
    np.add(x, TWO_PI, out=x, where=x < 0.0)
    x -= math.pi
    # a scalar for scalar angles, as np.remainder gives
    out: np.ndarray | np.float64 = np.abs(x, out=x)[()]
    return out


def turn_transform(cost: np.ndarray, step: float) -> np.ndarray:
    """``out[:, j] = min_i cost[:, i] + step * max(0, d(i, j) - 1)`` over arcs on the circle
    (``d`` the circular index distance, ``step`` the price of one arc): the least cost of
    reaching arc j from any arc i, the turn between two arcs being at least their centres'
    distance less one width. An erosion by one arc, then an L1 distance transform of slope
    ``step`` by passes both ways around the circle (twice, for the wrap)."""
    n = cost.shape[1]
    out: np.ndarray = np.minimum(
        cost, np.minimum(np.roll(cost, 1, axis=1), np.roll(cost, -1, axis=1))
    )
    for _ in range(2):
        for j in range(n):
            np.minimum(out[:, j], out[:, j - 1] + step, out=out[:, j])
        for j in range(n - 1, -1, -1):
            np.minimum(out[:, j], out[:, (j + 1) % n] + step, out=out[:, j])
    return out


def disc_cells(
    centre: Sequence[float], radius: float, cell: float
) -> tuple[np.ndarray, np.ndarray]:
    """Lower-left corners (x, y) of the squares of side ``cell`` on a grid about
    ``centre`` that meet the disc of ``radius`` (m): together they cover it."""
    count = math.ceil(radius / cell)
    edges = cell * np.arange(-count, count)
    xs, ys = np.meshgrid(edges, edges, indexing="ij")
    x0, y0 = xs.ravel(), ys.ravel()
    nearest = np.hypot(np.clip(0.0, x0, x0 + cell), np.clip(0.0, y0, y0 + cell))
    keep = nearest <= radius
    return x0[keep] + centre[0], y0[keep] + centre[1]


@dataclass(frozen=True)
class Lags:
    """What the speed's lag adds to a stretch of driving, for one weight ``lam``.

    A drive of the path ``D`` along ``m vdot + c1 v = F``, ``|F| <= 2 F_w``, taking ``T``
    and spending ``U = int |F| dt / (2 F_w)``: its cost ``(1 - lam) T + lam U`` is least
    (Pontryagin: the switching function is monotone) when it accelerates with full force
    for ``t1``, coasts for ``tc`` and, from rest to rest, brakes for ``t2 = tau ln(1 + (1 -
    exp(-t1 / tau)) exp(-tc / tau))`` (``tau = m / c1``); then ``D = v_top (t1 - t2)`` and
    the cost less ``D / v_top`` is the lag ``2 t2 + (1 - lam) tc``. To a free end it
    coasts to the end and the lag is ``v_end tau / v_top + (1 - lam) tc``. Both lags grow
    with ``D``; they are tabulated at paths ``D_k`` as lower bounds, each the least over
    coast times ``tc`` in steps, on each step the lag's first term at its longer end
    (it falls as the coast grows, for the same path) and the coast term at its shorter.

    Attributes:
        weight: ``lam``; distance: the tabulated paths (m), increasing from 0; rest: the
            rest-to-rest lag's lower bound (s) at each; free_excess: the largest of the
            tabulated rest-to-rest lag less the free-end lag's lower bound (s).
    """

    weight: float
    distance: np.ndarray
    rest: np.ndarray
    free_excess: float

    @classmethod
    def from_robot(cls, robot: Robot, weight: float) -> Lags:
        """The thesis plant's lags for the weight ``lam`` in [0, 1]."""
        check_instance("robot", robot, Robot)
        weight = check_range("weight", weight, 0.0, 1.0)
        d = sym.ThesisDynamics.from_robot(robot)
        if d.c1 <= 0.0:
            raise ParameterError("c1 must be > 0 to price the stops (an undamped base)")
        return _lags(d.mass / d.c1, d.top_speed, weight)

    def at_rest(self, length: np.ndarray) -> np.ndarray:
        """A lower bound (s) on the rest-to-rest lag of any path at least ``length`` (m)
        long: the table's value at the longest tabulated path not above it."""
        index = np.searchsorted(self.distance, length, side="right") - 1
        lag: np.ndarray = self.rest[np.clip(index, 0, self.rest.size - 1)]
        return lag


def _accelerate_for(
    target: np.ndarray | float, tc: np.ndarray | float, tau: float, brakes: bool
) -> np.ndarray:
    """``t1`` (s) with ``t1 - t2 = target`` (rest to rest, ``brakes``) or ``t1 - tau (1 -
    exp(-t1 / tau)) exp(-tc / tau) = target`` (free end), for each coast time ``tc`` (a row)
    and each ``target`` (s; a column, or one number): both sides grow with ``t1``, so
    bisection on ``[target, target + tau]``, returning the end below (the lags it gives
    are then rounded down, never up). Shape: ``target`` and ``tc`` broadcast."""
    target = np.asarray(target, dtype=float)
    shape = np.broadcast_shapes(target.shape, np.shape(tc))
    low = np.array(np.broadcast_to(target, shape))
    high = np.array(np.broadcast_to(target + tau, shape))
    coast = np.exp(-tc / tau)
    for _ in range(60):
        middle = 0.5 * (low + high)
        speed = -np.expm1(-middle / tau) * coast
        gone = tau * np.log1p(speed) if brakes else tau * speed
        short = middle - gone < target
        low, high = np.where(short, middle, low), np.where(short, high, middle)
    return low


@functools.lru_cache(maxsize=2)
def _lag_terms(
    tau: float, top: float
) -> tuple[np.ndarray, float, np.ndarray, np.ndarray, np.ndarray]:
    """What :func:`_lags` needs that no weight changes, for ``tau = m / c1`` (s) and
    ``v_top`` (m/s): the tabulated paths ``D`` (m), the longest coast (s), the coast times
    ``tc`` (s), and per path (rows) and coast time (columns) the rest-to-rest ``2 t2`` and
    the free end's ``v_end tau / v_top`` (s). Read-only arrays (shared by the weights)."""
    distance = np.concatenate([np.linspace(0.0, 2.0, 201), np.linspace(2.05, 25.0, 460)])
    limit = 12.0 * tau
    tc = np.linspace(0.0, limit, 1201)
    target = (distance / top)[:, None]
    braking = 2.0 * (_accelerate_for(target, tc, tau, brakes=True) - target)
    ending = _accelerate_for(target, tc, tau, brakes=False) - target
    for array in (distance, tc, braking, ending):
        array.flags.writeable = False
    return distance, limit, tc, braking, ending


@functools.lru_cache(maxsize=16)
def _lags(tau: float, top: float, weight: float) -> Lags:
    """:class:`Lags` for ``tau = m / c1`` (s), ``v_top`` (m/s) and ``lam``."""
    distance, limit, tc, braking, ending = _lag_terms(tau, top)
    slope = 1.0 - weight
    coast = slope * tc[:-1]
    rest = np.minimum(np.min(braking[:, 1:] + coast, axis=1), slope * limit)
    free = np.minimum(np.min(ending[:, 1:] + coast, axis=1), slope * limit)
    return Lags(weight, distance, rest, float(np.max(rest - free)))


def _drive_costs(
    ax: np.ndarray,
    ay: np.ndarray,
    a_size: float,
    bx: np.ndarray,
    by: np.ndarray,
    b_size: float,
    centres: np.ndarray,
    half_arc: float,
    price: float,
    travel: bool,
    with_path: bool,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Least driving time (s) at ``price`` (s/m) from each square of A to each of B for each
    arc of the leg, and (``with_path``, else None: the force budget alone needs the time
    only) the least path (m) it stands for: (len(A), len(B), arcs) each.

    ``|dp|`` is at least the distance between the squares; the angle ``beta`` between the
    displacement and the arc at least their centres' angle less the arc's half-width and
    the direction's spread over the squares. ``travel=False``: the arcs are headings and
    the base may drive either way along them (the angle to the displacement's line, at
    most 90 degrees); ``travel=True``: the arcs are directions of travel (the angle on the
    full circle; from 90 degrees the leg cannot make progress: infinite)."""
    dx = np.maximum(0.0, np.maximum(bx - (ax[:, None] + a_size), ax[:, None] - (bx + b_size)))
    dy = np.maximum(0.0, np.maximum(by - (ay[:, None] + a_size), ay[:, None] - (by + b_size)))
    length = np.hypot(dx, dy)[:, :, None]
    cx = bx + 0.5 * b_size - (ax[:, None] + 0.5 * a_size)
    cy = by + 0.5 * b_size - (ay[:, None] + 0.5 * a_size)
    centre = np.hypot(cx, cy)
    radius = (a_size + b_size) / math.sqrt(2.0)
    ratio = np.clip(radius / np.maximum(centre, 1e-300), 0.0, 1.0)
    spread = np.where(centre > radius, np.arcsin(ratio), math.pi)
    direction = np.arctan2(cy, cx)
    angle = circular(centres, direction[:, :, None])
    if not travel:
        angle = np.minimum(angle, math.pi - angle)  # forwards or backwards along the line
    beta = np.clip(angle - half_arc - spread[:, :, None], 0.0, 0.5 * math.pi)
    cos = np.cos(beta)
    moving = length > 0.0
    with np.errstate(divide="ignore"):
        drive = np.where(moving, price * length / cos, 0.0)
        path = np.where(moving, length / cos, 0.0) if with_path else None
    if travel:
        blocked = moving & (beta >= 0.5 * math.pi)
        drive[blocked] = np.inf
        if path is not None:
            path[blocked] = np.inf
    return drive, path


def opposite(cost: np.ndarray) -> np.ndarray:
    """``min(cost[:, j], cost[:, j + arcs / 2])``: a heading and its reverse as one."""
    out: np.ndarray = np.minimum(cost, np.roll(cost, cost.shape[1] // 2, axis=1))
    return out


# the programme's states: (kind, charged). kind "line": the leg's heading nearest the line
# of its displacement, the base possibly reversing in the leg; "travel": the leg's direction
# of travel nearest its displacement, no reversal in the leg. charged: the open stretch
# (since the last reversal) has been charged the lag of one of its legs.
State = tuple[str, bool]


def _entries(
    states: dict[State, np.ndarray], turn_step: float, first: bool, kinds: tuple[str, ...]
) -> dict[State, np.ndarray]:
    """The least cost of entering the next leg at each of its arcs, per kind and charge,
    the turn from the last leg's arc included (``turn_step`` per arc). Between two legs
    without a reversal the direction of travel turns as the heading does, and headings turn
    as headings; from a heading to a direction of travel either sign is possible
    (``opposite``). ``first``: the states are the start's, its turn already in the cost."""
    out: dict[State, np.ndarray] = {}
    for (kind, charged), cost in states.items():
        for target in kinds:
            source = cost if kind == target else opposite(cost)
            entry = source if first else turn_transform(source, turn_step)
            key = (target, charged)
            out[key] = entry if key not in out else np.minimum(out[key], entry)
    return out


def _leg_costs(
    entries: dict[State, np.ndarray],
    drive: np.ndarray,
    charge: np.ndarray | float,
    kind: str,
    stops: bool,
) -> dict[State, np.ndarray]:
    """Each state's cost at the leg's end over (start cells, end cells, arcs), before the
    least over the start cells: the entry, the drive, and the lag charged (module
    docstring). A leg without a reversal lies in the open stretch, which is charged the
    leg's lag unless it has been. A leg with reversals closes the open stretch and opens a
    new one: if the open stretch was charged, nothing is and the new one opens uncharged;
    if not, the leg's lag is charged and the new one counts as charged."""
    uncharged = entries[(kind, False)]
    if not stops:
        return {(kind, False): uncharged[:, None, :] + drive}
    charged = entries.get((kind, True), np.full_like(uncharged, np.inf))  # none at the start
    paying = uncharged[:, None, :] + drive + charge
    if kind == "travel":
        return {("travel", True): np.minimum(paying, charged[:, None, :] + drive)}
    return {("line", True): paying, ("line", False): charged[:, None, :] + drive}


def _numbers(
    name: str, value: Any, fields: tuple[tuple[str, float, str], ...], wanted: str
) -> tuple[float, ...]:
    """``value`` as one float per ``(field, cap, unit)``, each finite and within ``+-cap``."""
    items = list_items(name, value, wanted, len(fields))
    return tuple(
        check_range(f"{name} {field}", item, -cap, cap, unit)
        for (field, cap, unit), item in zip(fields, items)
    )


_XY = (("x", MAX_COORDINATE_M, "m"), ("y", MAX_COORDINATE_M, "m"))
_POSE = (*_XY, ("heading", MAX_ANGLE_RAD, "rad"))


def _arcs(name: str, value: Any) -> int:
    """``value`` as an even integer in [2, :data:`MAX_ARCS`] (:func:`opposite` pairs each
    arc with the one half the circle away)."""
    try:
        arcs = check_int_at_least(name, value, 2, MAX_ARCS)
    except ParameterError:
        arcs = 1  # one message for every fault, its range saying "even" too
    if arcs % 2:
        raise ParameterError(
            f"{name} must be an even integer in [2, {MAX_ARCS}] (got {shown(value)})"
        )
    return arcs


def _check_block(
    reach: float,
    grid: tuple[str, float, str, int],
    chunk: int,
    several: bool,
    chunk_name: str | None,
) -> None:
    """Refuse a grid whose blocks exceed :data:`MAX_BLOCK_VALUES`, before anything is
    allocated, naming the largest chunk or the smallest cell that fits. ``grid``: ``(cell
    name, cell, arcs name, arcs)``; ``several``: more than one waypoint (the first leg's
    blocks start at the start alone); ``chunk_name``: the caller's parameter that sets
    ``chunk``, or None (fixed)."""
    cell_name, cell, arcs_name, arcs = grid
    squares = (2 * math.ceil(reach / cell)) ** 2
    rows = chunk if several else 1

    def values(squares: int) -> int:
        return min(rows, squares) * squares * arcs

    if values(squares) <= MAX_BLOCK_VALUES:
        return
    cap = f"blocks of at most {MAX_BLOCK_VALUES} values"
    if chunk_name is not None and squares * arcs <= MAX_BLOCK_VALUES:
        most = MAX_BLOCK_VALUES // (squares * arcs)
        raise ParameterError(
            f"{chunk_name} must be an integer in [1, {most}] for {cell_name} = {cell:g} m and "
            f"{arcs_name} = {arcs} ({cap}) (got {chunk})"
        )
    # the most squares that fit across the disc's radius, ceil(reach / cell)
    across = math.isqrt(MAX_BLOCK_VALUES // arcs) // 2
    while across > 0 and values((2 * across) ** 2) > MAX_BLOCK_VALUES:
        across -= 1
    finest = math.ceil(1e3 * reach / across) / 1e3 if across else math.inf  # rounded up to the mm
    if finest > CELL_RANGE_M[1]:
        raise ParameterError(
            f"robot: a reach L1 + L2 + tolerance of {reach:g} m is too long for the bound's "
            f"grid ({cap} with {cell_name} <= {CELL_RANGE_M[1]:g} m and {arcs_name} = {arcs})"
        )
    raise ParameterError(
        f"{cell_name} must be in [{finest:g}, {CELL_RANGE_M[1]:g}] m for {arcs_name} = {arcs} "
        f"and a reach L1 + L2 + tolerance of {reach:g} m ({cap}) (got {cell:g})"
    )


def _checked(
    robot: Robot,
    waypoints: Any,
    start: Any,
    tolerance: float,
    grids: Sequence[tuple[str, Any, str, Any]],
    chunk: int,
    chunk_name: str | None,
) -> tuple[
    tuple[tuple[float, ...], ...], tuple[float, ...], float, list[tuple[str, float, str, int]], int
]:
    """The inputs :func:`budget_bound` and :func:`lower_bound` share, checked before any
    work: ``(waypoints, start, tolerance, grids, chunk)`` as floats and ints, or the first
    fault as one :class:`ParameterError`. ``grids``: ``(cell name, cell, arcs name,
    arcs)`` each; ``chunk_name``: as in :func:`_check_block`."""
    check_instance("robot", robot, Robot)
    points = xy_pairs("waypoints", waypoints)
    start = _numbers("start", start, _POSE, "(x, y, heading): 3 numbers in m, m, rad")
    tolerance = check_range("tolerance", tolerance, *TOLERANCE_RANGE_M, "m")
    grids = [
        (
            cell_name,
            check_range(cell_name, cell, *CELL_RANGE_M, "m"),
            arcs_name,
            _arcs(arcs_name, arcs),
        )
        for cell_name, cell, arcs_name, arcs in grids
    ]
    chunk = check_int_at_least(chunk_name or "chunk", chunk, 1)
    reach = Prices.from_robot(robot, tolerance).reach
    for grid in grids:
        _check_block(reach, grid, chunk, len(points) > 1, chunk_name)
    return points, start, tolerance, grids, chunk


def budget_bound(
    robot: Robot,
    waypoints: Iterable[Sequence[float]],
    start: Sequence[float] = (0.0, 0.0, 0.0),
    tolerance: float = 0.01,
    cell: float = 0.05,
    arcs: int = 180,
    chunk: int = CHUNK,
    rotation_weight: float = 1.0,
) -> Bound:
    """A lower bound (s) on the time to take the end effector through ``waypoints`` in
    order from the base pose ``start`` (x, y, heading) at rest (module docstring).

    Args:
        robot: a :class:`~ddwmmr.model.Robot`.
        waypoints: a non-empty list of (x, y) pairs (m), each coordinate finite and within
            +-``MAX_COORDINATE_M`` (1e6 m) (:func:`~ddwmmr.errors.xy_pairs`; no set).
        start: the base's (x, y, heading) in m, m, rad: x and y within +-1e6 m, the heading
            within +-``MAX_ANGLE_RAD`` (1e6 rad).
        tolerance: waypoint radius (m), in :data:`TOLERANCE_RANGE_M` ([0, 0.1] m).
        cell: side (m) of the position cells, in :data:`CELL_RANGE_M` ([0.01, 0.5] m).
        arcs: heading arcs over the circle, an even integer in [2, :data:`MAX_ARCS`].
        chunk: start cells per block (memory), an integer >= 1.
        rotation_weight: the weight ``lam`` in [0, 1] of the rotation's budget against the
            stops' lag (1: the force budget alone).

    A block (``chunk`` start cells, 1 with a single waypoint, x the ``(2 ceil(reach /
    cell))^2`` squares about a waypoint x ``arcs``, ``reach = L1 + L2 + tolerance``) holds
    at most :data:`MAX_BLOCK_VALUES` values (about 1 GiB at the peak): a finer grid is
    refused, the message naming the largest ``chunk`` or the smallest ``cell`` that fits.
    The time grows as the squares' square times ``arcs`` per waypoint: seconds on the
    bounds tool's grids, hours at 1 cm. Bad input raises
    :class:`~ddwmmr.errors.ParameterError` naming the parameter and its range.
    """
    began = time.perf_counter()
    waypoints, start, tolerance, grids, chunk = _checked(
        robot, waypoints, start, tolerance, [("cell", cell, "arcs", arcs)], chunk, "chunk"
    )
    ((_, cell, _, arcs),) = grids
    weight = check_range("rotation_weight", rotation_weight, 0.0, 1.0)
    stops = weight < 1.0
    kinds = ("line", "travel") if stops else ("line",)
    prices = Prices.from_robot(robot, tolerance)
    lags = Lags.from_robot(robot, weight) if stops else None
    width = TWO_PI / arcs
    centres = -math.pi + width * (0.5 + np.arange(arcs))
    half = 0.5 * width
    turn = weight * prices.turn
    # layer 0: the start exactly; its heading is start[2] exactly
    ax, ay, a_size = np.array([start[0]]), np.array([start[1]]), 0.0
    heading = turn * np.maximum(0.0, circular(start[2], centres) - half)
    states: dict[State, np.ndarray] = {("line", False): heading[None, :]}
    for index, w in enumerate(waypoints):
        entries = _entries(states, turn * width, index == 0, kinds)
        bx, by = disc_cells(w, prices.reach, cell)
        states = {}
        for first in range(0, ax.size, chunk):
            rows = slice(first, first + chunk)
            block = {key: entry[rows] for key, entry in entries.items()}
            for kind in kinds:
                drive, path = _drive_costs(
                    ax[rows],
                    ay[rows],
                    a_size,
                    bx,
                    by,
                    cell,
                    centres,
                    half,
                    prices.drive,
                    travel=kind == "travel",
                    with_path=stops,
                )
                # ignore: with lags (stops) _drive_costs returns the path
                charge = lags.at_rest(path) if lags is not None else 0.0  # type: ignore[arg-type]
                for key, cost in _leg_costs(block, drive, charge, kind, stops).items():
                    least = np.min(cost, axis=0)
                    states[key] = least if key not in states else np.minimum(states[key], least)
        ax, ay, a_size = bx, by, cell
    # the last stretch ends free: its charge was the rest-to-rest lag
    end = lags.free_excess if lags is not None else 0.0
    value = min(
        float(np.min(cost)) - (end if charged else 0.0) for (_, charged), cost in states.items()
    )
    return Bound(value, int(ax.size), arcs, time.perf_counter() - began)


#: The weights ``lam`` the stop-pricing bound is solved at, and its cells (m) and arcs:
#: the bound peaks near ``lam`` = 0.4-0.6 on seed 0's scenarios 5-20, and is coarser
#: than the force budget's own grid because it costs about five times as much per cell.
STOP_WEIGHTS = (0.4, 0.6)
STOP_GRID = (0.07, 120)
#: The force budget's own cells (m) and arcs.
BUDGET_GRID = (0.05, 144)


def lower_bound(
    robot: Robot,
    waypoints: Iterable[Sequence[float]],
    tolerance: float = 0.01,
    grid: tuple[float, int] = BUDGET_GRID,
    stop_weights: tuple[float, ...] = STOP_WEIGHTS,
    stop_grid: tuple[float, int] = STOP_GRID,
) -> Bound:
    """The best of :func:`budget_bound` on ``grid`` (cell in m, arcs) and the stop-pricing
    bounds at ``stop_weights`` on ``stop_grid`` (s); each is a lower bound, so is their
    greatest. ``cells`` and ``arcs`` are the winner's; the wall time is the sum.

    ``robot``, ``waypoints`` and ``tolerance`` as in :func:`budget_bound` (the start: the
    origin, heading 0, at rest); ``grid`` and ``stop_grid`` each a (cell, arcs) pair, the
    cell in :data:`CELL_RANGE_M` ([0.01, 0.5] m) and the arcs an even integer in [2,
    :data:`MAX_ARCS`], with blocks of :data:`CHUNK` start cells within
    :data:`MAX_BLOCK_VALUES`; ``stop_weights`` a list, possibly empty, of weights in
    [0, 1]. All are checked before the first bound is solved."""
    pairs: list[tuple[str, Any, str, Any]] = []
    for name, pair in (("grid", grid), ("stop_grid", stop_grid)):
        cell, arcs = list_items(name, pair, "a (cell, arcs) pair", 2)
        pairs.append((f"{name} cell", cell, f"{name} arcs", arcs))
    # the checked waypoints go on: a generator would be spent by the check
    waypoints, _, tolerance, pairs, _ = _checked(
        robot, waypoints, (0.0, 0.0, 0.0), tolerance, pairs, CHUNK, None
    )
    weights = tuple(
        check_range(f"stop_weights[{i}]", weight, 0.0, 1.0)
        for i, weight in enumerate(
            list_items("stop_weights", stop_weights, "a list of weights in [0, 1]"), start=1
        )
    )
    (_, cell, _, arcs), (_, stop_cell, _, stop_arcs) = pairs
    bounds = [budget_bound(robot, waypoints, tolerance=tolerance, cell=cell, arcs=arcs)]
    for weight in weights:
        bounds.append(
            budget_bound(
                robot,
                waypoints,
                tolerance=tolerance,
                cell=stop_cell,
                arcs=stop_arcs,
                rotation_weight=weight,
            )
        )
    best = max(bounds, key=lambda bound: bound.value)
    return Bound(best.value, best.cells, best.arcs, sum(bound.wall_s for bound in bounds))
