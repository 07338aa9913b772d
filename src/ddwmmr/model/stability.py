"""Static tip-over stability and manipulability of the planar arm (thesis 4.1).

The formulas: docs/theory.md, "Tip-over stability" and "Manipulability".

The arm is horizontal and mounted at the base centre. In the base frame the combined centre
of mass of links (their midpoints) and payload (at the end effector) is

    x_com = A cos(th1) + B cos(th1 + th2),   y_com = A sin(th1) + B sin(th1 + th2)

with ``A = (m1/2 + m2 + mp) L1 / M`` and ``B = (m2/2 + mp) L2 / M`` (the base's own centre of
mass is at the origin and contributes nothing). The stability margin is the ratio of the
counter moment to the tipping moment about each footprint edge:

    S_lon = (length/2) / |x_com|,   S_lat = (width/2) / |y_com|,   S = min(S_lon, S_lat)

``S > 1`` is statically stable. Values are capped at :data:`STABILITY_CAP` where the
tipping moment vanishes.

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
import warnings
from dataclasses import dataclass

import numpy as np

from ddwmmr.errors import MASS_RANGE_KG, ParameterError, check_finite
from ddwmmr.model.mass import total_mass

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


def warn_start_below_floor(method: str, robot, q0, floor: float) -> None:
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
    warnings.warn(
        f"stability_min: the start pose has S = {s:.4g}, below the {method}'s stability "
        f"floor stability_min = {floor:g}, which the run starts by breaking; lower the floor "
        f"(stability_min={lower:g}) or start where S >= {floor:g}",
        UserWarning,
        stacklevel=3,
    )


@dataclass(frozen=True)
class ComCoefficients:
    """Coefficients ``A``, ``B`` (m) of the arm+payload centre of mass in the base frame."""

    A: float
    B: float
    half_length: float
    half_width: float


def com_coefficients(
    L1: float,
    L2: float,
    m1: float,
    m2: float,
    payload: float,
    base_mass: float,
    base_length: float,
    base_width: float,
) -> ComCoefficients:
    """Precompute the centre-of-mass coefficients for :func:`stability_terms`."""
    total = total_mass(base_mass, m1, m2, payload)
    return ComCoefficients(
        A=(0.5 * m1 + m2 + payload) * L1 / total,
        B=(0.5 * m2 + payload) * L2 / total,
        half_length=0.5 * base_length,
        half_width=0.5 * base_width,
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
    """``(S_lon, S_lat, S)`` for a centre of mass ``(x_com, y_com)`` (m, base frame): each
    term ``half extent / |offset|``, capped at :data:`STABILITY_CAP`."""
    offset, half = abs(x_com), k.half_length
    s_lon = STABILITY_CAP if offset * STABILITY_CAP <= half else half / offset
    offset, half = abs(y_com), k.half_width
    s_lat = STABILITY_CAP if offset * STABILITY_CAP <= half else half / offset
    return s_lon, s_lat, min(s_lon, s_lat)


def tips_in_every_pose(k: ComCoefficients) -> bool:
    """Whether no arm pose (joint limits aside) has ``S > 1``: the centre of mass is at
    least ``|A - B|`` from the base centre in every pose, and a point inside the footprint
    is closer than its half-diagonal. A sufficient test, not a necessary one: False does
    not promise that some pose stands."""
    return abs(k.A - k.B) >= math.hypot(k.half_length, k.half_width)


def max_payload(robot, th1: float, th2: float) -> float:
    """The heaviest payload (kg) with which ``robot`` (a :class:`~ddwmmr.model.Robot`)
    stands (static S > 1) with its arm at ``th1``, ``th2`` (rad), rounded down to the gram
    so that the payload it names stands: 0 where the robot tips even unloaded, the top of
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
    return math.floor(low * 1e3) / 1e3


def stability_gradient(k: ComCoefficients, th1: float, th2: float) -> tuple[float, float, float]:
    """``(S, dS/dth1, dS/dth2)`` of the capped margin ``S`` (zero gradient where capped).

    At a tie between ``S_lon`` and ``S_lat`` the lateral term's gradient is returned.
    """
    s1, c1 = math.sin(th1), math.cos(th1)
    s12, c12 = math.sin(th1 + th2), math.cos(th1 + th2)
    x_com = k.A * c1 + k.B * c12
    y_com = k.A * s1 + k.B * s12
    s_lon, s_lat, _ = margins(k, x_com, y_com)
    if s_lat <= s_lon:
        if s_lat >= STABILITY_CAP:
            return s_lat, 0.0, 0.0
        # S = h / |y|  =>  dS = -S * dy / y
        factor = -s_lat / y_com
        return s_lat, factor * (k.A * c1 + k.B * c12), factor * (k.B * c12)
    if s_lon >= STABILITY_CAP:
        return s_lon, 0.0, 0.0
    factor = -s_lon / x_com
    return s_lon, factor * (-k.A * s1 - k.B * s12), factor * (-k.B * s12)


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


def inertial_terms(robot) -> InertialTerms:
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
    th1,
    th2,
    rate1,
    rate2,
    v,
    w,
    v_dot,
    w_dot,
    acc1=0.0,
    acc2=0.0,
    cos=math.cos,
    sin=math.sin,
):
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
    s_lon = _ratio_array(k.half_length, x_com)
    s_lat = _ratio_array(k.half_width, y_com)
    return s_lon, s_lat, np.minimum(s_lon, s_lat)


def _ratio_array(half_extent: float, offset: np.ndarray) -> np.ndarray:
    magnitude = np.abs(offset)
    capped = magnitude * STABILITY_CAP <= half_extent
    with np.errstate(divide="ignore"):
        return np.where(capped, STABILITY_CAP, half_extent / np.where(capped, 1.0, magnitude))
