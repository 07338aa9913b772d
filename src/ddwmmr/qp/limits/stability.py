"""Tip-over stability ``S >= S_min`` as a velocity damper with the exact gradient.

``S = min(S_lon, S_lat)`` on the support polygon (:mod:`ddwmmr.model.stability`): on the
default rectangle ``S_lon = hl / |x_com|`` and ``S_lat = hw / |y_com|``, on another polygon
``S`` is the least ``S_e = d_e / (n_e . c)`` over its edges. ``S >= S_min`` holds exactly
when every such term does, so the limit has one row per term: the two of the rectangle
(each group has one edge facing the centre of mass, so they are every edge that can be
active), every edge of another polygon (where two edges of a group meet in a ridge of S, a
row on the active edge alone would let the other fall through the floor within a step).
Each term is smooth below the cap, with ``dS_e/dth = -S_e (n . dc/dth) / (n . c)`` (``n``
the edge's outward normal, ``c`` the centre of mass; ``-S_i c_i' / c_i`` on the
rectangle), so the rows have no kink where the minimum switches between terms:

    dS_e/dt = g_e . (th1dot, th2dot) >= -gain (S_e - S_min - margin)

Above ``S_min + margin`` a term may fall at most exponentially towards the floor; below
it, the term must rise. The right-hand side is capped at half of what the joint-speed box
can deliver, so each row alone is always feasible. :func:`safe_arm_scale` then checks the
exact (nonlinear) S one control step ahead. The formulation: docs/theory.md, "The QP
controller".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from ddwmmr.errors import check_positive
from ddwmmr.gains import check_gain
from ddwmmr.model.stability import (
    STABILITY_CAP,
    STABILITY_FLOOR,
    ComCoefficients,
    check_stability_floor,
    edge_gradients,
    stability_terms,
    stability_terms_from_trig,
)
from ddwmmr.qp.blocks import LimitBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import INF, Limit

if TYPE_CHECKING:
    import numpy as np


def stability_terms_gradient(
    k: ComCoefficients, th1: float, th2: float
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """``((S_lon, dS_lon/dth1, dS_lon/dth2), (S_lat, dS_lat/dth1, dS_lat/dth2))`` (1/rad).

    A capped term (``S_i >= STABILITY_CAP``) has zero gradient.
    """
    return stability_terms_from_trig(
        k, math.sin(th1), math.cos(th1), math.sin(th1 + th2), math.cos(th1 + th2)
    )


def stability_rows(
    k: ComCoefficients, th1: float, th2: float
) -> tuple[tuple[float, float, float], ...]:
    """``(S_e, dS_e/dth1, dS_e/dth2)`` (1/rad) of every term :class:`StabilityLimit` has a
    row for: ``(lon, lat)`` of :func:`stability_terms_gradient` on the rectangle, every
    edge (:func:`~ddwmmr.model.stability.edge_gradients`) on another polygon. ``S`` is
    their least ``S_e``; a capped term has zero gradient."""
    return stability_rows_from_trig(
        k, math.sin(th1), math.cos(th1), math.sin(th1 + th2), math.cos(th1 + th2)
    )


def stability_rows_from_trig(
    k: ComCoefficients, s1: float, c1: float, s12: float, c12: float
) -> tuple[tuple[float, float, float], ...]:
    """:func:`stability_rows` from ``sin/cos th1`` and ``sin/cos (th1 + th2)``."""
    if k.edges is None:
        return stability_terms_from_trig(k, s1, c1, s12, c12)
    return edge_gradients(k, s1, c1, s12, c12)


def stability_row_count(k: ComCoefficients) -> int:
    """How many rows :func:`stability_rows` has for ``k``'s support polygon."""
    return 2 if k.edges is None else len(k.edges.lon) + len(k.edges.lat)


def ascent_direction(
    terms: tuple[tuple[float, float, float], ...], target: float
) -> tuple[float, float]:
    """A joint-rate direction ``(d1, d2)`` (not normalised) that raises every term ``(S_e,
    g1, g2)`` below ``target`` (``g_e . d > 0``), or ``(0, 0)`` when none is below it or no
    direction raises them all (S is then at a local maximum of its least terms).

    It is the sum of those terms' unit gradients, which raises each of two terms unless
    their gradients are opposite (``u_1 . (u_1 + u_2) = 1 + cos`` of their angle) and
    weighs them alike whatever their gradients' scale. When three or more terms are below
    the target that sum may lower one; then it is the least-norm ``d`` with ``g_e . d >=
    1`` for every such term, found among the candidates the optimum can be (one
    constraint active: ``g_e / |g_e|^2``; two: their intersection)."""
    gradients = [(g1, g2) for s_e, g1, g2 in terms if s_e < target and (g1 or g2)]
    d1 = d2 = 0.0
    for g1, g2 in gradients:
        norm = math.hypot(g1, g2)
        d1 += g1 / norm
        d2 += g2 / norm
    if all(g1 * d1 + g2 * d2 > 0.0 for g1, g2 in gradients):
        return d1, d2
    return _least_raising(gradients)


def _least_raising(gradients: list[tuple[float, float]]) -> tuple[float, float]:
    """The least-norm ``d`` with ``g . d >= 1`` for every ``g`` of ``gradients``, or ``(0,
    0)`` when there is none (in the plane the optimum has one or two constraints active)."""
    candidates = [(g1 / (g1 * g1 + g2 * g2), g2 / (g1 * g1 + g2 * g2)) for g1, g2 in gradients]
    for i, (a1, a2) in enumerate(gradients):
        for b1, b2 in gradients[i + 1 :]:
            det = a1 * b2 - a2 * b1
            if det != 0.0:
                candidates.append(((b2 - a2) / det, (a1 - b1) / det))
    feasible = [
        d for d in candidates if all(g1 * d[0] + g2 * d[1] >= 1.0 - 1e-9 for g1, g2 in gradients)
    ]
    return min(feasible, key=lambda d: math.hypot(*d), default=(0.0, 0.0))


def exact_stability(k: ComCoefficients, th1: float, th2: float) -> float:
    """The capped margin ``S = min(S_lon, S_lat)`` (dimensionless; the model's own
    :func:`~ddwmmr.model.stability.stability_terms`)."""
    return stability_terms(k, th1, th2)[2]


def safe_arm_scale(
    k: ComCoefficients,
    th1: float,
    th2: float,
    rate1: float,
    rate2: float,
    dt: float,
    stability_min: float,
    halvings: int = 8,
) -> float:
    """Largest of 1, 1/2, 1/4, ... (or 0) scaling the joint rates so that the exact S after
    one step ``dt`` (s) stays >= ``min(S_min, S_now)``: the linearised limit's second-order
    error cannot take the robot below the floor. The base does not enter S."""
    floor = min(stability_min, exact_stability(k, th1, th2))
    scale = 1.0
    for _ in range(halvings):
        if exact_stability(k, th1 + scale * dt * rate1, th2 + scale * dt * rate2) >= floor:
            return scale
        scale *= 0.5
    return 0.0


def full_step_is_safe(
    k: ComCoefficients,
    trig: tuple[float, float, float, float],
    th1: float,
    th2: float,
    rate1: float,
    rate2: float,
    dt: float,
    stability_min: float,
) -> bool:
    """True when a bound proves that :func:`safe_arm_scale` would return 1 (no exact
    look-ahead needed); False means "not proven", not "unsafe".

    ``trig`` is ``(sin th1, cos th1, sin(th1 + th2), cos(th1 + th2))``. With ``a = dt rate1``
    and ``b = dt rate2`` each centre-of-mass coordinate moves by at most
    ``delta = |A| |a| + |B| |a + b|`` in one step (``|d cos| <= 1``), and ``S_i >= S_min``
    exactly when ``|c_i| <= h_i / S_min``. So ``|c_i| + delta + slack <= h_i / S_min`` for
    both terms proves the exact ``S >= S_min = min(S_min, S_now)`` after the step; the slack
    (1e-9 m per metre of lever) covers the rounding of the look-ahead's own evaluation,
    and angles beyond 1e3 rad (where adding the step loses digits) are left to it. On
    another polygon the same holds edge by edge, ``n_e . c + delta + slack <= d_e / S_min``
    (``n_e`` a unit vector moves ``n_e . c`` by at most ``delta`` too).
    """
    if not (abs(th1) <= 1e3 and abs(th2) <= 1e3):
        return False
    s1, c1, s12, c12 = trig
    a = dt * rate1
    b = dt * rate2
    lever_a, lever_b = abs(k.A), abs(k.B)
    reach = lever_a * abs(a) + lever_b * abs(a + b) + 1e-9 * (1.0 + lever_a + lever_b)
    if k.edges is not None:
        x_com, y_com = k.A * c1 + k.B * c12, k.A * s1 + k.B * s12
        return all(
            n_x * x_com + n_y * y_com + reach <= d / stability_min
            for n_x, n_y, d in (*k.edges.lon, *k.edges.lat)
        )
    return (
        abs(k.A * c1 + k.B * c12) + reach <= k.half_length / stability_min
        and abs(k.A * s1 + k.B * s12) + reach <= k.half_width / stability_min
    )


class StabilityLimit(Limit):
    """One row ``dS_e/dt >= damper bound`` per term of :func:`stability_rows` (see module
    docstring): ``dS_lon/dt`` and ``dS_lat/dt`` on the rectangle, one per edge on another
    support polygon.

    Args:
        robot_com: the robot's centre-of-mass coefficients (``Robot.com_coefficients``).
        stability_min: the floor S_min (> 1 keeps a safety factor against tipping).
        gain: damper gain (1/s): how fast S may approach the floor.
        margin: the damper aims at ``S_min + margin`` so the floor itself is not grazed.
        joint_speed: the joint-speed limit (rad/s), used to keep the row feasible.
    """

    rows = 2
    name = "stability"
    unit = None  # rows on rates only: any problem's length unit

    def __init__(
        self,
        robot_com: ComCoefficients,
        stability_min: float = STABILITY_FLOOR,
        gain: float = 5.0,
        margin: float = 0.01,
        joint_speed: float = 2.0,
    ) -> None:
        self.com = robot_com
        self.rows = stability_row_count(robot_com)
        self.stability_min = check_stability_floor(stability_min)
        self.gain = check_gain("stability gain", gain)
        self.margin = check_positive("stability margin", margin)
        self.joint_speed = check_positive("joint speed", joint_speed)

    def lower_bound(self, s_i: float, g1: float, g2: float) -> float:
        """The damper bound of one term's row (-INF for a capped term)."""
        if s_i >= STABILITY_CAP:
            return -INF
        achievable = 0.5 * self.joint_speed * (abs(g1) + abs(g2))
        damper = -self.gain * (s_i - (self.stability_min + self.margin))
        return achievable if achievable < damper else damper  # min(damper, achievable)

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Rows ``[0, 0, dS_e/dth1, dS_e/dth2]`` with lower bound ``-gain (S_e - floor)``."""
        for row, (s_i, g1, g2) in enumerate(stability_rows(self.com, ctx.th1, ctx.th2)):
            G[row, 0] = G[row, 1] = 0.0
            G[row, 2], G[row, 3] = g1, g2
            upper[row] = INF
            lower[row] = self.lower_bound(s_i, g1, g2)

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Writer for the gradient entries and the lower bounds (the gradient from the
        context's arm trigonometry, the bounds from :meth:`lower_bound`); the rest is
        constant."""
        if overrides(self, StabilityLimit) or overrides(self, StabilityLimit, "lower_bound"):
            return None
        block.write_constant_rows([[0.0] * 4] * self.rows)
        block.write_constant_bounds((-INF,) * self.rows, (INF,) * self.rows)
        if self.com.edges is not None:
            return self._polygon_writer(block)
        G, lower = block.matrix, block.lower
        (lon_row, lat_row), (lon_bound, lat_bound) = block.rows, block.bounds
        com, bound = self.com, self.lower_bound

        def write(ctx: StepContext) -> None:
            (s_lon, g1, g2), (s_lat, h1, h2) = stability_terms_from_trig(
                com, ctx.sin_th1, ctx.cos_th1, ctx.sin_th12, ctx.cos_th12
            )
            G[lon_row + 2], G[lon_row + 3] = g1, g2
            G[lat_row + 2], G[lat_row + 3] = h1, h2
            lower[lon_bound] = bound(s_lon, g1, g2)
            lower[lat_bound] = bound(s_lat, h1, h2)

        return write

    def _polygon_writer(self, block: LimitBlock) -> Callable[[StepContext], None]:
        """The writer on a polygon other than the rectangle: one row per edge."""
        G, lower = block.matrix, block.lower
        slots = list(zip(block.rows, block.bounds))
        com, bound = self.com, self.lower_bound

        def write(ctx: StepContext) -> None:
            terms = edge_gradients(com, ctx.sin_th1, ctx.cos_th1, ctx.sin_th12, ctx.cos_th12)
            for (row, index), (s_e, g1, g2) in zip(slots, terms):
                G[row + 2], G[row + 3] = g1, g2
                lower[index] = bound(s_e, g1, g2)

        return write
