"""Kinematics of the planar differential-drive mobile manipulator (docs/theory.md, "Model").

Configuration ``q = [x, y, phi, th1, th2]`` in the world frame (metres, radians): base
position at the wheel-axle midpoint (where the arm is mounted), base heading, then the arm
joint angles (``th1`` relative to the base heading). Inputs ``u = [v, w, th1dot, th2dot]``:
forward speed (m/s), yaw rate (rad/s), joint rates (rad/s).

The functions here take plain floats or small arrays and are written for speed: they are
called every control step.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, NoReturn

import numpy as np

from ddwmmr.errors import ParameterError, float_values, shown

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt

    #: A configuration ``[x, y, phi, th1, th2]`` or a vector of 4 inputs / 5 rates (floats).
    Vector = Sequence[float] | npt.NDArray[np.float64]

#: Names of the configuration coordinates, in order.
Q_NAMES = ("x", "y", "phi", "th1", "th2")
#: Names of the input coordinates, in order.
U_NAMES = ("v", "w", "th1dot", "th2dot")


#: Largest |phi|, |th1|, |th2| (rad) of a configuration. The kinematics form the link
#: headings phi + th1 and phi + th1 + th2, and three angles within a third of the largest
#: float (1.8e308) always sum to a finite one; beyond, cos and sin of an overflowed sum
#: fail. Angles that large carry no direction (past 2.8e16 rad the float spacing exceeds a
#: turn), but the maths takes them: ``qp`` and ``mpc`` still return a finite command.
MAX_CONFIGURATION_ANGLE_RAD = 5e307


def angles_in_range(phi: float, th1: float, th2: float) -> bool:
    """Whether the angles of a configuration (rad, finite floats) are each within
    +-:data:`MAX_CONFIGURATION_ANGLE_RAD`."""
    bound = MAX_CONFIGURATION_ANGLE_RAD
    return -bound <= phi <= bound and -bound <= th1 <= bound and -bound <= th2 <= bound


def refuse_angles(phi: float, th1: float, th2: float, name: str = "q") -> NoReturn:
    """Raise the one-line :class:`ParameterError` naming ``name`` for angles outside
    +-:data:`MAX_CONFIGURATION_ANGLE_RAD`."""
    raise ParameterError(
        f"{name} must be 5 finite numbers [x, y, phi, th1, th2] (m, rad) with |phi|, |th1|, "
        f"|th2| <= {MAX_CONFIGURATION_ANGLE_RAD:g} rad "
        f"(got phi, th1, th2 = {phi:g}, {th1:g}, {th2:g})"
    )


def check_angles(values: list[float], name: str = "q") -> list[float]:
    """``values``, a configuration of 5 finite floats, if its angles phi, th1, th2 are
    within +-:data:`MAX_CONFIGURATION_ANGLE_RAD` rad, else :class:`ParameterError` naming
    ``name`` and that range."""
    _, _, phi, th1, th2 = values
    if not angles_in_range(phi, th1, th2):
        refuse_angles(phi, th1, th2, name)
    return values


def check_configuration(q0: Any, name: str = "q0") -> list[float]:
    """``q0`` as a list of 5 floats if it is a flat sequence of 5 finite numbers
    ``[x, y, phi, th1, th2]`` (m, m, rad, rad, rad) whose angles are within
    +-:data:`MAX_CONFIGURATION_ANGLE_RAD`, else :class:`ParameterError` naming ``name``:
    a start configuration (``simulate``'s ``q0``, ``Plant.reset``, ``Controller.reset``)."""
    values = float_values(q0, 5)
    if values is None or not all(map(math.isfinite, values)):
        raise ParameterError(
            f"{name} must be 5 finite numbers [x, y, phi, th1, th2] (m, rad) (got {shown(q0, 60)})"
        )
    return check_angles(values, name)


def wrap_angle(angle: float) -> float:
    """Angle wrapped to [-pi, pi) (rad), as ``(angle + pi) mod 2 pi - pi``.

    The laws that have always wrapped their orientation error with this formula keep it
    (its rounding is part of their recorded results); an error that was not wrapped
    before is wrapped with :func:`principal_angle`, which leaves an angle already in
    range untouched.
    """
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


_TWO_PI = 2.0 * math.pi


def principal_angle(angle: float) -> float:
    """The same direction as ``angle`` in (-pi, pi] (rad).

    An angle already in (-pi, pi] is returned unchanged, bit for bit; any other is reduced
    by the exact floating-point remainder of 2 pi, so whole turns are removed without the
    rounding of adding and subtracting pi (1e6 rad keeps all its significant digits).
    """
    if -math.pi < angle <= math.pi:
        return angle
    reduced = math.remainder(angle, _TWO_PI)
    return math.pi if reduced <= -math.pi else reduced


def whole_turns(angle: float) -> float:
    """``angle - principal_angle(angle)`` (rad): the whole turns in ``angle``, exactly 0.0
    for an angle in (-pi, pi]. A potential on a continuous angle counts the angle from its
    start's own turn by subtracting this, taken once at the start."""
    return angle - principal_angle(angle)


def forward_kinematics(L1: float, L2: float, q: Vector) -> tuple[float, float, float]:
    """End-effector pose ``(xE, yE, phiE)`` in the world frame (m, m, rad)."""
    x, y, phi, th1, th2 = (float(v) for v in q)
    a1 = phi + th1
    a12 = a1 + th2
    return (
        x + L1 * math.cos(a1) + L2 * math.cos(a12),
        y + L1 * math.sin(a1) + L2 * math.sin(a12),
        a12,
    )


def _arm_rates(L1: float, L2: float, q: Vector) -> tuple[float, float, float, float, float]:
    """``(phi, dx, dy, dx2, dy2)``: the heading and the end effector's rates (world frame,
    m/rad) per unit of shoulder (and heading) rate, ``(dx, dy)``, and of elbow rate."""
    _, _, phi, th1, th2 = (float(v) for v in q)
    s1, c1 = math.sin(phi + th1), math.cos(phi + th1)
    s12, c12 = math.sin(phi + th1 + th2), math.cos(phi + th1 + th2)
    return phi, -L1 * s1 - L2 * s12, L1 * c1 + L2 * c12, -L2 * s12, L2 * c12


def jacobian(L1: float, L2: float, q: Vector) -> np.ndarray:
    """The 4x5 task Jacobian: rows xE, yE, phiE and the nonholonomic constraint.

    docs/theory.md, "Configuration, forward kinematics, Jacobian".
    """
    phi, dx, dy, dx2, dy2 = _arm_rates(L1, L2, q)
    return np.array(
        [
            [1.0, 0.0, dx, dx, dx2],
            [0.0, 1.0, dy, dy, dy2],
            [0.0, 0.0, 1.0, 1.0, 1.0],
            [-math.sin(phi), math.cos(phi), 0.0, 0.0, 0.0],
        ]
    )


#: Auxiliary rows of the augmented task space method (docs/theory.md, "Methods").
AUX_ROWS = {
    "sum": (0.0, 0.0, 0.0, 1.0, 1.0),  # th1dot + th2dot = 0
    "shoulder": (0.0, 0.0, 0.0, 1.0, 0.0),  # th1dot = 0
}


def augmented_jacobian(L1: float, L2: float, q: Vector, aux: str) -> np.ndarray:
    """The square 5x5 augmented Jacobian: :func:`jacobian` plus the auxiliary row ``aux``."""
    return np.vstack([jacobian(L1, L2, q), np.array(AUX_ROWS[aux])])


def input_matrix(phi: float) -> np.ndarray:
    """The 5x4 matrix B with ``qdot = B(phi) u``; its columns are orthonormal."""
    c, s = math.cos(phi), math.sin(phi)
    return np.array(
        [
            [c, 0.0, 0.0, 0.0],
            [s, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def base_motion(
    phi: float, v: float, w: float, th1dot: float, th2dot: float
) -> tuple[float, float, float, float, float]:
    """``qdot = B(phi) u`` on floats: ``(xdot, ydot, phidot, th1dot, th2dot)`` (m/s, rad/s)
    at base heading ``phi`` (rad, world) for inputs ``v`` (m/s), ``w``, ``th1dot``,
    ``th2dot`` (rad/s); the form the integrators call at every stage."""
    return (v * math.cos(phi), v * math.sin(phi), w, th1dot, th2dot)


def qdot_from_u(phi: float, u: Vector) -> np.ndarray:
    """Configuration rate ``qdot`` (5,) produced by inputs ``u = [v, w, th1dot, th2dot]``
    (:func:`base_motion` as an array)."""
    v, w, t1, t2 = (float(a) for a in u)
    return np.array(base_motion(phi, v, w, t1, t2))


def u_from_qdot(phi: float, qdot: Vector) -> tuple[np.ndarray, float]:
    """Project a configuration rate on the inputs.

    Returns ``(u, residual)`` where ``residual = -xdot sin(phi) + ydot cos(phi)`` (m/s) is
    the sideways base velocity the differential drive cannot produce.
    """
    xd, yd, pd, t1, t2 = (float(a) for a in qdot)
    c, s = math.cos(phi), math.sin(phi)
    return np.array([xd * c + yd * s, pd, t1, t2]), -xd * s + yd * c


def end_effector_jacobian_u(L1: float, L2: float, q: Vector) -> np.ndarray:
    """The 3x4 Jacobian ``A = J_E B`` mapping inputs u to end-effector rates."""
    phi, dx, dy, dx2, dy2 = _arm_rates(L1, L2, q)
    return np.array(
        [
            [math.cos(phi), dx, dx, dx2],
            [math.sin(phi), dy, dy, dy2],
            [0.0, 1.0, 1.0, 1.0],
        ]
    )
