"""Static tip-over stability and manipulability of the planar arm (thesis 4.1).

The formulas: docs/theory.md, "Tip-over stability" and "Manipulability".

The arm is horizontal and mounted at the base centre. In the base frame the combined centre
of mass of links (their midpoints) and payload (at the end effector) is

    x_com = A cos(th1) + B cos(th1 + th2),   y_com = A sin(th1) + B sin(th1 + th2)

with ``A = (m1/2 + m2 + mp) L1 / M`` and ``B = (m2/2 + mp) L2 / M`` (the base's own centre of
mass is at the origin and contributes nothing). The stability margin is the ratio of the
counter moment to the tipping moment about the edges of the support polygon (the convex
hull of wheels and casters, which holds the base centre strictly inside): with ``n_e`` an
edge's outward unit normal and ``d_e > 0`` its line's distance from the base centre,

    S = min over the edges e with n_e . c > 0 of  d_e / (n_e . c)

the factor by which the centre of mass c could move away from the base centre before it
reaches an edge. ``S_lon`` is that minimum over the edges facing front or back (``|n_x| >=
|n_y|``), ``S_lat`` over the others, ``S = min(S_lon, S_lat)``. For the rectangle ``|x| <=
length/2, |y| <= width/2`` (the default: casters at the footprint's corners) it is

    S_lon = (length/2) / |x_com|,   S_lat = (width/2) / |y_com|

and this closed form is what is evaluated there. ``S > 1`` is statically stable. Values are
capped at :data:`STABILITY_CAP` where the tipping moment vanishes.

**Dynamic margin** (:func:`zero_moment_point`, :func:`dynamic_stability`): when the robot
accelerates, the floor's centre of pressure is not below the centre of mass but at the zero
moment point. With the masses lumped as the model has them (base box at its centre
``BASE_CLEARANCE_M + base_height/2`` above the floor, the wheels at their axle height, links
and payload in the arm's plane at ``arm_height``) and the vertical accelerations and the
bodies' roll/pitch inertia neglected, in the base frame::

    x_zmp = x_com - (H a_x0 + h M (-wdot y_com - w^2 x_com - 2 w ydot_com + xddot_com)) / (M g)
    y_zmp = y_com - (H a_y0 + h M ( wdot x_com - w^2 y_com + 2 w xdot_com + yddot_com)) / (M g)

with ``(a_x0, a_y0) = (vdot, v w)`` the acceleration of the axle midpoint (base frame),
``H = sum m_i h_i`` over all masses (kg m), ``h`` the arm height, ``M`` the total mass and
the centre-of-mass rates and accelerations from the joint rates and accelerations.
``S_dyn`` is ``S``'s formula at the zero moment point; at rest it is S. (The arm's own
angular momentum about z and the wheels' gyroscopic moment, about 0.02 N m at 1.5 rad/s,
are left out.)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ddwmmr.errors import MASS_RANGE_KG, ParameterError, check_finite
from ddwmmr.model.mass import total_mass
from ddwmmr.user_warnings import warn_user

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt

    from ddwmmr.model.robot import Robot

#: Reported stability is capped here: a vanishing tipping moment gives an infinite ratio.
STABILITY_CAP = 10.0
#: Default hard floor S_min on S of the controllers that hold one (``qp``, ``mpc``, the
#: minimum-time study): a quarter above tipping, the thesis's stability threshold.
STABILITY_FLOOR = 1.25
#: Height of the base box's bottom above the floor (m): its mass sits at this height plus
#: half the box (the physics plant builds the same box).
BASE_CLEARANCE_M = 0.05
#: Standard gravity (m/s^2), as the physics plant has it.
GRAVITY_M_S2 = 9.81


def valid_stability_floor(value: float) -> bool:
    """Whether ``value`` can be a floor on S: in ``(0, STABILITY_CAP)`` (S is capped
    there, so a floor at the cap could never be met)."""
    return 0.0 < value < STABILITY_CAP


def check_stability_floor(value: float, name: str = "stability_min") -> float:
    """``value`` as a floor on S (float, :func:`valid_stability_floor`), or
    :class:`~ddwmmr.errors.ParameterError` naming ``name``."""
    allowed = f"in (0, {STABILITY_CAP:g})"
    floor = check_finite(name, value, allowed)
    if not valid_stability_floor(floor):
        raise ParameterError(f"{name} must be {allowed} (got {floor:g})")
    return floor


def warn_start_below_floor(
    method: str, robot: Robot, q0: Sequence[float] | npt.NDArray[np.float64], floor: float
) -> None:
    """Warn (:class:`UserWarning`, one line) when the controller ``method``, holding the
    floor ``floor`` on S (``stability_min``), starts ``robot`` (a
    :class:`~ddwmmr.model.Robot`) in a configuration ``q0`` (``[x, y, phi, th1, th2]``, m
    and rad) whose static S is below it: the run begins by breaking that constraint (the
    ``mpc``'s verdict is "did not track", the ``qp``'s tracking yields until S is back
    up). The line names S, the floor and a floor just below S. A start with S <= 1 has
    tipped over and is warned about (or refused) as such instead
    (:func:`ddwmmr.sim.simulate.tipping_message`)."""
    s = stability_terms(robot.com_coefficients, float(q0[3]), float(q0[4]))[2]
    if not 1.0 < s < floor:
        return
    lower = math.floor(s * 100.0 - 1e-9) / 100.0  # strictly below s, as a short number
    warn_user(
        f"stability_min: the start pose has S = {s:.4g}, below the {method}'s stability "
        f"floor stability_min = {floor:g}, which the run starts by breaking; lower the floor "
        f"(stability_min={lower:g}) or start where S >= {floor:g}"
    )


#: An edge of the support polygon as S measures it, ``(n_x, n_y, d)``: its outward unit
#: normal (base frame) and the distance ``d > 0`` (m) of its line from the base centre. The
#: centre of mass c reaches the edge's line when ``n . c = d``.
Edge = tuple[float, float, float]


def is_longitudinal(n_x: float, n_y: float) -> bool:
    """Whether an edge with normal ``(n_x, n_y)`` faces front or back (``|n_x| >= |n_y|``):
    it belongs to ``S_lon``, else to ``S_lat``."""
    return abs(n_x) >= abs(n_y)


@dataclass(frozen=True)
class SupportEdges:
    """The edges of a support polygon that holds the base centre strictly inside, as S
    measures them (module docstring). Build it with :meth:`from_lines`.

    Attributes:
        lon: the edges facing front or back (:func:`is_longitudinal`), ``S_lon``'s; may be
            empty (a diamond, whose normals all have ``|n_y| > |n_x|``): ``S_lon`` is then
            the cap, :data:`STABILITY_CAP`, in every pose.
        lat: the other edges, ``S_lat``'s (may be empty alike).
        radius: the largest distance (m) of a vertex from the base centre.
        rectangle: ``(half_length, half_width)`` (m) when the polygon is exactly the
            rectangle ``|x| <= half_length, |y| <= half_width`` (S's closed form), else None.
    """

    lon: tuple[Edge, ...]
    lat: tuple[Edge, ...]
    radius: float
    rectangle: tuple[float, float] | None

    @classmethod
    def from_lines(
        cls,
        normals: npt.NDArray[np.float64],
        offsets: npt.NDArray[np.float64],
        vertices: npt.NDArray[np.float64],
    ) -> SupportEdges:
        """The edges of a convex polygon given as :class:`~ddwmmr.model.support_loads.
        SupportPolygon` has it: inward unit normals (k, 2) and offsets (k,) with ``d_e(p) =
        normal . p - offset`` (m, inside > 0), and its vertices (k, 2) in m.

        Raises:
            ValueError: when the base centre is not strictly inside (some ``d_e(0) <= 0``):
                S is not defined there (docs/theory.md, "Tip-over stability").
        """
        edges = [(-float(n[0]), -float(n[1]), -float(o)) for n, o in zip(normals, offsets)]
        if not all(d > 0.0 for _, _, d in edges):
            raise ValueError("the base centre must lie strictly inside the support polygon")
        lon = tuple(e for e in edges if is_longitudinal(e[0], e[1]))
        lat = tuple(e for e in edges if not is_longitudinal(e[0], e[1]))
        radius = max(math.hypot(float(x), float(y)) for x, y in vertices)
        return cls(lon, lat, radius, _rectangle(lon, lat))


def _rectangle(lon: tuple[Edge, ...], lat: tuple[Edge, ...]) -> tuple[float, float] | None:
    """``(half_length, half_width)`` of edges that bound exactly ``|x| <= half_length, |y|
    <= half_width``, else None."""
    if len(lon) != 2 or len(lat) != 2:
        return None
    if sorted((n_x, n_y) for n_x, n_y, _ in lon) != [(-1.0, 0.0), (1.0, 0.0)]:
        return None
    if sorted((n_x, n_y) for n_x, n_y, _ in lat) != [(0.0, -1.0), (0.0, 1.0)]:
        return None
    if lon[0][2] != lon[1][2] or lat[0][2] != lat[1][2]:
        return None
    return lon[0][2], lat[0][2]


@dataclass(frozen=True)
class ComCoefficients:
    """Coefficients ``A``, ``B`` (m) of the arm+payload centre of mass in the base frame,
    and the support polygon S is measured on.

    Attributes:
        A, B: the centre of mass's levers (m; module docstring).
        half_length, half_width: the rectangle ``|x| <= half_length, |y| <= half_width``
            (m) S is measured on when ``edges`` is None (closed form); the footprint's
            half extents otherwise, which S does not use.
        edges: the support polygon's edges when it is not such a rectangle, else None.
    """

    A: float
    B: float
    half_length: float
    half_width: float
    edges: SupportEdges | None = None


def com_coefficients(
    L1: float,
    L2: float,
    m1: float,
    m2: float,
    payload: float,
    base_mass: float,
    base_length: float,
    base_width: float,
    support: SupportEdges | None = None,
) -> ComCoefficients:
    """Precompute the centre-of-mass coefficients for :func:`stability_terms`: S on the
    polygon ``support`` (:class:`SupportEdges`; None: the footprint ``base_length x
    base_width``, m, centred on the base centre)."""
    total = total_mass(base_mass, m1, m2, payload)
    half_length, half_width, edges = 0.5 * base_length, 0.5 * base_width, None
    if support is not None:
        if support.rectangle is None:
            edges = support
        else:
            half_length, half_width = support.rectangle
    return ComCoefficients(
        A=(0.5 * m1 + m2 + payload) * L1 / total,
        B=(0.5 * m2 + payload) * L2 / total,
        half_length=half_length,
        half_width=half_width,
        edges=edges,
    )


def centre_of_mass(k: ComCoefficients, th1: float, th2: float) -> tuple[float, float]:
    """Combined centre of mass ``(x_com, y_com)`` in the base frame (m)."""
    return (
        k.A * math.cos(th1) + k.B * math.cos(th1 + th2),
        k.A * math.sin(th1) + k.B * math.sin(th1 + th2),
    )


def stability_terms(k: ComCoefficients, th1: float, th2: float) -> tuple[float, float, float]:
    """``(S_lon, S_lat, S)``, each capped at :data:`STABILITY_CAP` (dimensionless)."""
    return margins(k, *centre_of_mass(k, th1, th2))


def margins(k: ComCoefficients, x_com: float, y_com: float) -> tuple[float, float, float]:
    """``(S_lon, S_lat, S)`` for a centre of mass ``(x_com, y_com)`` (m, base frame) on
    ``k``'s support polygon, each capped at :data:`STABILITY_CAP` (module docstring)."""
    if k.edges is not None:
        return polygon_margins(k.edges, x_com, y_com)
    offset, half = abs(x_com), k.half_length
    s_lon = STABILITY_CAP if offset * STABILITY_CAP <= half else half / offset
    offset, half = abs(y_com), k.half_width
    s_lat = STABILITY_CAP if offset * STABILITY_CAP <= half else half / offset
    return s_lon, s_lat, min(s_lon, s_lat)


def support_margins(support: SupportEdges, x: float, y: float) -> tuple[float, float, float]:
    """:func:`margins` of a point ``(x, y)`` (m, base frame) on the polygon ``support``:
    the rectangle's closed form where it is one."""
    if support.rectangle is None:
        return polygon_margins(support, x, y)
    return margins(ComCoefficients(0.0, 0.0, *support.rectangle), x, y)


def polygon_margins(support: SupportEdges, x: float, y: float) -> tuple[float, float, float]:
    """``(S_lon, S_lat, S)`` of a point ``(x, y)`` (m, base frame) on any polygon: each
    term the least ``d / (n . c)`` of its edges, capped at :data:`STABILITY_CAP`."""
    s_lon = edge_margin(support.lon, x, y)[0]
    s_lat = edge_margin(support.lat, x, y)[0]
    return s_lon, s_lat, min(s_lon, s_lat)


def edge_margin(edges: tuple[Edge, ...], x: float, y: float) -> tuple[float, Edge | None]:
    """The least capped ratio ``d / (n . c)`` over ``edges`` at ``c = (x, y)`` (m), and the
    edge that has it (None when capped: no edge is within :data:`STABILITY_CAP`)."""
    least, active = STABILITY_CAP, None
    for edge in edges:
        reach = edge[0] * x + edge[1] * y  # n . c, the offset towards the edge (m)
        if reach * STABILITY_CAP > edge[2]:
            ratio = edge[2] / reach
            if ratio < least:
                least, active = ratio, edge
    return least, active


def tips_in_every_pose(k: ComCoefficients) -> bool:
    """Whether no arm pose (joint limits aside) has ``S > 1``: the centre of mass is at
    least ``|A - B|`` from the base centre in every pose, and a point inside the support
    polygon is closer than its farthest vertex. A sufficient test, not a necessary one:
    False does not promise that some pose stands."""
    radius = math.hypot(k.half_length, k.half_width) if k.edges is None else k.edges.radius
    return abs(k.A - k.B) >= radius


def max_payload(robot: Robot, th1: float, th2: float) -> float:
    """The heaviest payload (kg) with which ``robot`` (a :class:`~ddwmmr.model.Robot`)
    stands (static S > 1) with its arm at ``th1``, ``th2`` (rad), rounded down so that the
    payload it names stands (:func:`_round_down_payload`: to the gram from 1 kg, to four
    significant digits below): 0 where the robot tips even unloaded, the top of
    :data:`~ddwmmr.errors.MASS_RANGE_KG` where it stands with that.

    As the payload ``p`` grows the centre of mass moves along a line toward the end
    effector, each coordinate ``(first moment + p e) / (M + p)`` monotonic in ``p``: the
    payloads that stand are one interval from 0, whose end a bisection finds."""

    def stands(payload: float) -> bool:
        k = robot.with_payload(payload).com_coefficients
        return stability_terms(k, th1, th2)[2] > 1.0

    low, high = 0.0, MASS_RANGE_KG[1]
    if not stands(low):
        return 0.0
    if stands(high):
        return high
    for _ in range(80):
        middle = 0.5 * (low + high)
        if stands(middle):
            low = middle
        else:
            high = middle
    return _round_down_payload(low, stands)


def _round_down_payload(limit: float, stands: Callable[[float], bool]) -> float:
    """``limit`` (kg, >= 0) rounded down to the gram, or to four significant digits where
    that is finer (below 1 kg), so that a small robot's limit of some tenths of a gram does
    not read 0 kg. The result is a bound a user may type back: it never exceeds ``limit``
    and ``stands(result)`` holds (one step lower where the decimal product rounded up)."""
    if limit <= 0.0:
        return 0.0
    decimals = max(3, 3 - math.floor(math.log10(limit)))
    scale = 10.0**decimals
    result = math.floor(limit * scale) / scale
    if result > 0.0 and not stands(result):
        result = (math.floor(limit * scale) - 1) / scale
    return result


def stability_gradient(k: ComCoefficients, th1: float, th2: float) -> tuple[float, float, float]:
    """``(S, dS/dth1, dS/dth2)`` of the capped margin ``S`` (zero gradient where capped).

    At a tie between ``S_lon`` and ``S_lat`` the lateral term's gradient is returned; within
    a term, the gradient of the edge that has its minimum (:func:`edge_margin`).
    """
    lon, lat = stability_terms_from_trig(
        k, math.sin(th1), math.cos(th1), math.sin(th1 + th2), math.cos(th1 + th2)
    )
    return lat if lat[0] <= lon[0] else lon


def stability_terms_from_trig(
    k: ComCoefficients, s1: float, c1: float, s12: float, c12: float
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """``((S_lon, dS_lon/dth1, dS_lon/dth2), (S_lat, dS_lat/dth1, dS_lat/dth2))`` (1/rad)
    from ``sin/cos th1`` and ``sin/cos (th1 + th2)``: the terms of :func:`margins` with
    their gradients; a capped term (``S_i >= STABILITY_CAP``) reads ``(STABILITY_CAP, 0,
    0)``. On a polygon other than the rectangle, :func:`polygon_terms_gradient`."""
    if k.edges is not None:
        return polygon_terms_gradient(k, s1, c1, s12, c12)
    x_com = k.A * c1 + k.B * c12
    y_com = k.A * s1 + k.B * s12
    s_lon, s_lat, _ = margins(k, x_com, y_com)
    # S_i = h / |c_i|  =>  dS_i = -S_i dc_i / c_i; zero where capped
    if s_lon >= STABILITY_CAP:
        lon = (STABILITY_CAP, 0.0, 0.0)
    else:
        factor = -s_lon / x_com
        lon = (s_lon, factor * (-k.A * s1 - k.B * s12), factor * (-k.B * s12))
    if s_lat >= STABILITY_CAP:
        lat = (STABILITY_CAP, 0.0, 0.0)
    else:
        factor = -s_lat / y_com
        lat = (s_lat, factor * x_com, factor * (k.B * c12))
    return lon, lat


def support_edges(k: ComCoefficients) -> SupportEdges:
    """The edges of ``k``'s support polygon: ``k.edges``, or those of the rectangle
    ``|x| <= half_length, |y| <= half_width`` (m) when ``k`` measures S on it in closed
    form (outward unit normals, offsets in m)."""
    if k.edges is not None:
        return k.edges
    front, side = k.half_length, k.half_width
    lon = ((1.0, 0.0, front), (-1.0, 0.0, front))
    lat = ((0.0, 1.0, side), (0.0, -1.0, side))
    return SupportEdges(lon, lat, math.hypot(front, side), (front, side))


def polygon_terms_gradient(
    k: ComCoefficients, s1: float, c1: float, s12: float, c12: float
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """``((S_lon, dS_lon/dth1, dS_lon/dth2), (S_lat, ...))`` (1/rad) on ``k``'s support
    polygon (:func:`support_edges`) from ``sin/cos th1`` and ``sin/cos (th1 + th2)``: each
    term's gradient is its active edge's (the first of its least, :func:`edge_gradients`);
    zero where capped."""
    terms = edge_gradients(k, s1, c1, s12, c12)
    split = len(support_edges(k).lon)
    capped = (STABILITY_CAP, 0.0, 0.0)
    lon = min(terms[:split], key=lambda term: term[0], default=capped)
    lat = min(terms[split:], key=lambda term: term[0], default=capped)
    return lon, lat


def edge_gradients(
    k: ComCoefficients, s1: float, c1: float, s12: float, c12: float
) -> tuple[tuple[float, float, float], ...]:
    """``(S_e, dS_e/dth1, dS_e/dth2)`` (1/rad) of every edge of ``k``'s support polygon
    (:func:`support_edges`; the ``lon`` edges, then the ``lat`` ones) from ``sin/cos th1``
    and ``sin/cos (th1 + th2)``.
    ``S = min_e S_e``. An edge the centre of mass c faces within :data:`STABILITY_CAP` has
    ``S_e = d / (n . c)`` and ``dS_e/dth = -S_e (n . dc/dth) / (n . c)``; any other reads
    ``(STABILITY_CAP, 0, 0)`` (capped, as :func:`edge_margin` has it)."""
    x_com = k.A * c1 + k.B * c12
    y_com = k.A * s1 + k.B * s12
    dx1, dy1 = -k.A * s1 - k.B * s12, x_com
    dx2, dy2 = -k.B * s12, k.B * c12
    edges = support_edges(k)
    terms = []
    for n_x, n_y, d in (*edges.lon, *edges.lat):
        reach = n_x * x_com + n_y * y_com  # n . c, the offset towards the edge (m)
        s = d / reach if reach * STABILITY_CAP > d else STABILITY_CAP
        if s < STABILITY_CAP:
            factor = -s / reach
            terms.append((s, factor * (n_x * dx1 + n_y * dy1), factor * (n_x * dx2 + n_y * dy2)))
        else:
            terms.append((STABILITY_CAP, 0.0, 0.0))
    return tuple(terms)


@dataclass(frozen=True)
class InertialTerms:
    """Mass moments of the dynamic margin (:func:`zero_moment_point`).

    Attributes:
        height_moment: ``H = sum m_i h_i`` over every mass (kg m).
        arm_moment: ``h M``, the arm height times the total mass (kg m): the arm's masses
            are ``M (x_com, y_com)`` as first moments.
        weight: ``M g`` (N).
    """

    height_moment: float
    arm_moment: float
    weight: float


def inertial_terms(robot: Robot) -> InertialTerms:
    """:class:`InertialTerms` of a :class:`~ddwmmr.model.Robot` (lumped as the module
    docstring says)."""
    m1, m2 = robot.link_masses
    arm = m1 + m2 + robot.payload
    box = robot.base_body_mass
    total = robot.total_mass
    height = (
        box * (BASE_CLEARANCE_M + 0.5 * robot.base_height)
        + 2.0 * robot.wheel_mass * robot.wheel_radius
        + arm * robot.arm_height
    )
    return InertialTerms(height, robot.arm_height * total, total * GRAVITY_M_S2)


def zero_moment_point(
    k: ComCoefficients,
    terms: InertialTerms,
    # Any: floats, or casadi expressions for the symbolic twin (docstring); cos and sin are
    # Any too because dynamic_stability forwards its *motion floats positionally.
    th1: Any,
    th2: Any,
    rate1: Any,
    rate2: Any,
    v: Any,
    w: Any,
    v_dot: Any,
    w_dot: Any,
    acc1: Any = 0.0,
    acc2: Any = 0.0,
    cos: Any = math.cos,
    sin: Any = math.sin,
) -> tuple[Any, Any]:
    """Zero moment point ``(x, y)`` in the base frame (m) at joints (rad), joint rates
    (rad/s), forward speed v (m/s), yaw rate w (rad/s), their rates (m/s^2, rad/s^2) and
    the joint accelerations ``acc1``, ``acc2`` (rad/s^2).

    Plain arithmetic on its arguments: with ``cos=casadi.cos, sin=casadi.sin`` it builds the
    same expression symbolically (:func:`ddwmmr.model.symbolic.zero_moment_point`).
    """
    th12, rate12 = th1 + th2, rate1 + rate2
    c1, s1, c12, s12 = cos(th1), sin(th1), cos(th12), sin(th12)
    x = k.A * c1 + k.B * c12
    y = k.A * s1 + k.B * s12
    x_rate = -k.A * s1 * rate1 - k.B * s12 * rate12
    y_rate = k.A * c1 * rate1 + k.B * c12 * rate12
    acc12 = acc1 + acc2
    x_acc = -k.A * (c1 * rate1**2 + s1 * acc1) - k.B * (c12 * rate12**2 + s12 * acc12)
    y_acc = -k.A * (s1 * rate1**2 - c1 * acc1) - k.B * (s12 * rate12**2 - c12 * acc12)
    arm_x = -w_dot * y - w**2 * x - 2.0 * w * y_rate + x_acc
    arm_y = w_dot * x - w**2 * y + 2.0 * w * x_rate + y_acc
    return (
        x - (terms.height_moment * v_dot + terms.arm_moment * arm_x) / terms.weight,
        y - (terms.height_moment * v * w + terms.arm_moment * arm_y) / terms.weight,
    )


def dynamic_stability(
    k: ComCoefficients, terms: InertialTerms, *motion: float
) -> tuple[float, float, float]:
    """``(S_lon, S_lat, S)`` at the zero moment point (capped like :func:`margins`);
    ``motion`` is :func:`zero_moment_point`'s ``th1, th2, rate1, rate2, v, w, v_dot, w_dot``
    and optionally ``acc1, acc2``."""
    return margins(k, *zero_moment_point(k, terms, *motion))


def manipulability(th2: float) -> float:
    """Normalised manipulability ``eta = |sin(th2)|`` in [0, 1] (thesis 4.1.1)."""
    return abs(math.sin(th2))


def stability_arrays(
    k: ComCoefficients, th1: np.ndarray, th2: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`stability_terms` over arrays of joint angles: ``(S_lon, S_lat, S)``."""
    th1 = np.asarray(th1, dtype=float)
    th2 = np.asarray(th2, dtype=float)
    x_com = k.A * np.cos(th1) + k.B * np.cos(th1 + th2)
    y_com = k.A * np.sin(th1) + k.B * np.sin(th1 + th2)
    if k.edges is not None:
        s_lon = _edge_array(k.edges.lon, x_com, y_com)
        s_lat = _edge_array(k.edges.lat, x_com, y_com)
    else:
        s_lon = _ratio_array(k.half_length, x_com)
        s_lat = _ratio_array(k.half_width, y_com)
    return s_lon, s_lat, np.minimum(s_lon, s_lat)


def _edge_array(edges: tuple[Edge, ...], x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """:func:`edge_margin`'s value over arrays of centre-of-mass coordinates (m)."""
    least = np.full(np.broadcast(x, y).shape, STABILITY_CAP)
    for n_x, n_y, d in edges:
        least = np.minimum(least, _ratio_array(d, n_x * x + n_y * y, signed=True))
    return least


def _ratio_array(half_extent: float, offset: np.ndarray, signed: bool = False) -> np.ndarray:
    """``half_extent / |offset|`` capped at :data:`STABILITY_CAP` (``half_extent /
    offset``, capped where ``offset <= 0`` too, when ``signed``)."""
    magnitude = offset if signed else np.abs(offset)
    capped = magnitude * STABILITY_CAP <= half_extent
    with np.errstate(divide="ignore"):
        return np.where(capped, STABILITY_CAP, half_extent / np.where(capped, 1.0, magnitude))
