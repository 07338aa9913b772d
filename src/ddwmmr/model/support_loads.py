"""Normal loads on the edges of the support polygon, from the robot's motion (Newton-Euler).

The base stands on its wheels and casters; the convex hull of their contact points is the
*support polygon* (base frame: origin at the axle midpoint, x along the heading, y to the
left). The base can pivot about an edge e of it only when the supports *off* e carry no
load. Six supports on a plane are statically indeterminate, but the moment of their loads
about each edge line is not: with ``d_e(p)`` the distance of a point from e's line
(inside > 0), the floor's normal forces ``F_i >= 0`` satisfy

    sum_i F_i d_e(p_i) = N d_e(c)

with ``N`` their sum and ``c`` the centre of pressure. Neglecting the vertical
accelerations, ``N = M g`` (the weight) and ``c`` is the zero moment point of the robot's
motion (:func:`ddwmmr.model.stability.zero_moment_point`: the moment balance of the lumped
masses about the floor, the arm's and the base's inertial forces included). The **edge
load** is that moment over the depth ``D_e`` of the polygon behind e (the distance of the
farthest support from e's line)::

    L_e = M g d_e(c) / D_e     (N)

It is the least load the supports off e can carry with that moment (each sits at most
``D_e`` from the line), so ``L_e <= sum_{i off e} F_i`` and both vanish together: ``L_e
> 0`` on every edge is "every edge loaded". Where every support off e lies at depth
``D_e`` (the side edges of the default layout: a wheel and two casters on each side) it is
exactly the load on the far side; at rest it is ``W (1 - 1/S) / 2`` there, the static
margin S in newtons. On the front and back edges the wheels sit at half the depth, and the
supports off the edge carry between ``L_e`` and ``2 L_e``.

The base acceleration is an input ``(a_x, a_y)`` (the axle midpoint's, in the base frame):
``(vdot, v w)`` for a base that rolls without slipping (:meth:`EdgeLoadModel.loads_of_motion`),
what a physics engine measures otherwise. Every function is plain arithmetic on its
arguments: with ``cos=casadi.cos, sin=casadi.sin`` it builds the same expression
symbolically (:func:`ddwmmr.model.symbolic.edge_loads`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ddwmmr.errors import ParameterError, real_number, shown
from ddwmmr.model.stability import (
    ComCoefficients,
    InertialTerms,
    centre_of_mass,
    inertial_terms,
    zero_moment_point,
)

if TYPE_CHECKING:
    import numpy.typing as npt

    from ddwmmr.model.robot import Robot

#: A support lies on an edge of the polygon when closer to its line than this (m).
ON_EDGE_TOLERANCE_M = 1e-9
#: Default least load the optimisers keep on every edge, as a share of the weight: the
#: static floor S = 1.25's own load on a side edge, ``(1 - 1/1.25) / 2`` (14.7 N with
#: 3 kg), above the force model's 95th-percentile error on the scenarios (9.2 N,
#: docs/physics.md).
DEFAULT_MIN_EDGE_LOAD = 0.1


def check_min_edge_load(value: Any) -> float:
    """The ``min_edge_load`` option: a share of the robot's weight in [0, 0.5) (at rest an
    edge carries at most half the weight, with the centre of mass at the polygon's
    middle); raises :class:`~ddwmmr.errors.ParameterError` (one line) otherwise."""
    share = real_number(value)  # None for text, booleans and integers beyond a float
    if share is None or not (math.isfinite(share) and 0.0 <= share < 0.5):
        raise ParameterError(
            f"min_edge_load must be a share of the weight in [0, 0.5) (got {shown(value)})"
        )
    return share


def support_points(robot: Robot) -> tuple[tuple[float, float], ...]:
    """Base-frame floor contact points (m) of a :class:`~ddwmmr.model.Robot`'s supports:
    the left and right wheel ``(0, +-track_width/2)``, then its casters
    (:attr:`~ddwmmr.model.Robot.casters`)."""
    half_track = 0.5 * robot.track_width
    return ((0.0, half_track), (0.0, -half_track), *robot.casters)


def convex_hull(
    points: Iterable[Sequence[float]] | npt.NDArray[np.float64],
) -> npt.NDArray[np.float64]:
    """Vertices (k, 2) of the convex hull of 2-D points, counter-clockwise (monotone chain).

    Points on an edge are dropped; fewer than 3 non-collinear points give a degenerate hull
    (fewer than 3 vertices).
    """
    pts = sorted({(float(x), float(y)) for x, y in points})
    if len(pts) < 3:
        return np.array(pts, dtype=float).reshape(-1, 2)
    # Collinear below a cross product of 1e-12 of the squared extent: the test is the same
    # for a robot of any size (lengths from 1e-6 m to 1e3 m are allowed).
    extent = max(max(abs(x), abs(y)) for x, y in pts)
    collinear = 1e-12 * extent * extent

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def chain(seq: Iterable[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in seq:
            while len(out) >= 2 and cross(out[-2], out[-1], p) <= collinear:
                out.pop()
            out.append(p)
        return out

    lower, upper = chain(pts), chain(reversed(pts))
    return np.array(lower[:-1] + upper[:-1], dtype=float)


@dataclass(frozen=True)
class SupportPolygon:
    """The support polygon's edges as lines, and the depth behind each.

    Attributes:
        vertices: (k, 2) counter-clockwise (m, base frame); edge e runs from vertex e to
            vertex e + 1.
        normals: (k, 2) inward unit normals; offsets: (k,) so that ``d_e(p) = normals[e]
            . p - offsets[e]`` is the signed distance of p from edge e's line (m, inside
            > 0).
        depths: (k,) the largest ``d_e`` of a support point (m): the lever of the
            farthest support behind edge e.
    """

    vertices: npt.NDArray[np.float64]
    normals: npt.NDArray[np.float64]
    offsets: npt.NDArray[np.float64]
    depths: npt.NDArray[np.float64]

    @classmethod
    def from_points(
        cls, points: Sequence[Sequence[float]] | npt.NDArray[np.float64]
    ) -> SupportPolygon:
        """The polygon of base-frame support points (n, 2) in m (at least three not on a
        line)."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        hull = convex_hull(points)
        if len(hull) < 3:
            raise ValueError("the support points must span a polygon (3 not on a line)")
        start, end = hull, np.roll(hull, -1, axis=0)
        edge = end - start
        length = np.hypot(edge[:, 0], edge[:, 1])
        normals = np.column_stack([-edge[:, 1], edge[:, 0]]) / length[:, None]
        offsets = np.sum(normals * start, axis=1)
        depths = np.max(points @ normals.T - offsets, axis=0)
        return cls(hull, normals, offsets, depths)

    def distances(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Signed distances (n, k) of points (n, 2) from each edge line (inside > 0), m."""
        return np.asarray(points, dtype=float).reshape(-1, 2) @ self.normals.T - self.offsets

    def off_edge(self, points: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """(k, n) booleans: point i lies off edge e (farther than
        :data:`ON_EDGE_TOLERANCE_M` from its line), so its load holds e down."""
        return (np.abs(self.distances(points)) > ON_EDGE_TOLERANCE_M).T


def support_polygon(robot: Robot) -> SupportPolygon:
    """The :class:`SupportPolygon` of a :class:`~ddwmmr.model.Robot`'s wheels and casters
    (the footprint ``base_length x base_width`` with the default casters)."""
    return SupportPolygon.from_points(support_points(robot))


def edge_loads_at(polygon: SupportPolygon, weight: float, x: Any, y: Any) -> list[Any]:
    """Edge loads ``weight d_e(c) / D_e`` (N) for a normal force ``weight`` (N) acting at
    the centre of pressure ``c = (x, y)`` (m, base frame); plain arithmetic (numbers or
    CasADi symbols)."""
    return [
        weight * (float(n[0]) * x + float(n[1]) * y - float(offset)) / float(depth)
        for n, offset, depth in zip(polygon.normals, polygon.offsets, polygon.depths)
    ]


@dataclass(frozen=True)
class EdgeLoadModel:
    """Edge loads of a robot's support polygon from its configuration and motion.

    Build it with :meth:`from_robot`. All loads are in N, one per edge of
    :attr:`polygon` (in its order); see the module docstring for the definition.

    Attributes:
        com: centre-of-mass coefficients; terms: the mass moments of the zero moment
            point (:func:`~ddwmmr.model.stability.inertial_terms`); polygon: the support
            polygon.
    """

    com: ComCoefficients
    terms: InertialTerms
    polygon: SupportPolygon

    @classmethod
    def from_robot(cls, robot: Robot) -> EdgeLoadModel:
        """The model of a :class:`~ddwmmr.model.Robot` (masses lumped as
        :mod:`ddwmmr.model.stability` has them)."""
        return cls(robot.com_coefficients, inertial_terms(robot), support_polygon(robot))

    @property
    def weight(self) -> float:
        """The robot's weight ``M g`` (N)."""
        return self.terms.weight

    def static_loads(self, th1: float, th2: float) -> list[float]:
        """Edge loads at rest (N) at joint angles th1, th2 (rad): the weight at the centre
        of mass."""
        return edge_loads_at(self.polygon, self.weight, *centre_of_mass(self.com, th1, th2))

    def centre_of_pressure(
        self,
        # Any: floats, or casadi symbols (ddwmmr.model.symbolic builds the same loads)
        th1: Any,
        th2: Any,
        rates: Sequence[Any],
        accelerations: Sequence[Any],
        base_acceleration: Sequence[Any],
        w: Any,
        w_dot: Any,
        cos: Callable[[Any], Any] = math.cos,
        sin: Callable[[Any], Any] = math.sin,
    ) -> tuple[Any, Any]:
        """The zero moment point ``(x, y)`` (m, base frame) of a general planar motion:
        joints th1, th2 (rad), their ``rates`` (rad/s) and ``accelerations`` (rad/s^2),
        the axle midpoint's ``base_acceleration = (a_x, a_y)`` (m/s^2, base frame), the
        yaw rate w (rad/s) and its rate w_dot (rad/s^2).

        :func:`~ddwmmr.model.stability.zero_moment_point` is linear in the base
        acceleration, which enters it as ``(vdot, v w)``: it is evaluated without it
        (``v = vdot = 0``) and ``H a / (M g)`` taken off."""
        x, y = zero_moment_point(
            self.com,
            self.terms,
            th1,
            th2,
            rates[0],
            rates[1],
            0.0,
            w,
            0.0,
            w_dot,
            accelerations[0],
            accelerations[1],
            cos=cos,
            sin=sin,
        )
        lever = self.terms.height_moment / self.terms.weight
        return x - lever * base_acceleration[0], y - lever * base_acceleration[1]

    def loads(
        self,
        # Any: floats, or casadi symbols (ddwmmr.model.symbolic builds the same loads)
        th1: Any,
        th2: Any,
        rates: Sequence[Any],
        accelerations: Sequence[Any],
        base_acceleration: Sequence[Any],
        w: Any,
        w_dot: Any,
        cos: Callable[[Any], Any] = math.cos,
        sin: Callable[[Any], Any] = math.sin,
    ) -> list[Any]:
        """Edge loads (N) of the motion of :meth:`centre_of_pressure` (same arguments)."""
        x, y = self.centre_of_pressure(
            th1, th2, rates, accelerations, base_acceleration, w, w_dot, cos=cos, sin=sin
        )
        return edge_loads_at(self.polygon, self.weight, x, y)

    def loads_of_motion(
        self,
        # Any: floats, or casadi symbols (ddwmmr.model.symbolic builds the same loads)
        th1: Any,
        th2: Any,
        rates: Sequence[Any],
        accelerations: Sequence[Any],
        v: Any,
        w: Any,
        v_dot: Any,
        w_dot: Any,
        cos: Callable[[Any], Any] = math.cos,
        sin: Callable[[Any], Any] = math.sin,
    ) -> list[Any]:
        """Edge loads (N) of a base that rolls without slipping: forward speed v (m/s) and
        its rate v_dot (m/s^2), so that ``base_acceleration = (v_dot, v w)``."""
        return self.loads(
            th1, th2, rates, accelerations, (v_dot, v * w), w, w_dot, cos=cos, sin=sin
        )


__all__ = [
    "DEFAULT_MIN_EDGE_LOAD",
    "EdgeLoadModel",
    "SupportPolygon",
    "check_min_edge_load",
    "convex_hull",
    "edge_loads_at",
    "support_points",
    "support_polygon",
]
