"""Closed-form redundancy-resolution kernels, in input form.

All kernels return ``u = (v, w, th1dot, th2dot)`` and a flag telling whether damping was
applied. They work in the input form ``qdot = B(phi) u`` (docs/theory.md, "Input form"),
which satisfies the
nonholonomic row of J exactly; three facts make them cheap (all tested against the matrix
formulations in ``tests/test_resolution.py``):

1. **Augmented task space.** With either auxiliary row the 5x5 system reduces to the 2x2
   system ``M z = r`` with ``M = [[cos phi, -L1 sin(phi+th1)], [sin phi, L1 cos(phi+th1)]]``
   and ``det M = L1 cos(th1)``: the unknowns are ``(v, th1dot)`` for ``aux="sum"`` (then
   ``w = phiEdot``, ``th2dot = -th1dot``) and ``(v, w)`` for ``aux="shoulder"`` (then
   ``th1dot = 0``, ``th2dot = phiEdot - w``).
2. **Pseudoinverse.** ``J^# Xdot = B A^# XEdot`` with ``A = J_E B`` (3x4), because ``B`` has
   orthonormal columns and the nonholonomic row forces ``qdot = B u``. ``A`` loses rank
   exactly where ``M`` does: ``cos(th1) = 0``.
3. **Null space.** Away from that singularity the null space of J is spanned by
   ``z = [0, 0, 1, -1, 0] / sqrt(2)``: yawing the base about the arm mount while counter-
   rotating the shoulder leaves the end effector still. So ``I - J^# J = z z^T``.

**Damping** (Nakamura & Hanafusa 1986; Chiaverini 1997). Every inverse is a damped least
squares ``(M^T M + lambda^2 I)^-1 M^T`` (resp. ``A^T (A A^T + lambda^2 I)^-1``) with

    lambda^2 = damping^2 (1 - (sigma / threshold)^2)   for sigma < threshold, else 0

where ``sigma`` is the smallest singular value of the matrix inverted (exact for ``M``; for
``A`` the lower bound ``2 sqrt(det A A^T) / trace(A A^T) = 2 sqrt(2) L1 |cos th1| /
trace(A A^T)``, 0.73-0.88 of it). The damping rises continuously from 0 as ``sigma`` falls
below ``threshold``. A singular value ``s`` of the matrix is mapped to the gain
``s / (s^2 + lambda^2)``; with ``damping >= threshold`` (the defaults are equal) that gain
is at most ``s / threshold^2`` inside the band and ``1 / s`` outside it, so it never exceeds
``1 / threshold`` at any state (no cliff at the band edge). Hence the documented bounds
(``sigma0 = threshold``, ``|.|`` the Euclidean norm, ``Xdot = (xEdot, yEdot, phiEdot)``,
lengths in the robot's own unit: m on the default robot, see "Scale invariance")::

    pseudoinverse:  |u| <= |Xdot| / sigma0                                 (pi_gain)
    ats:            |u| <= (2 sqrt(1 + (L1 + L2)^2) / sigma0 + 1) |Xdot|    (ats_gain)

(``ats``: ``|z| <= |r| / sigma0`` and ``|r| <= sqrt(1 + (L1+L2)^2) |Xdot|``; the other
entries of ``u`` add at most ``|z| + |phiEdot|``.) With the defaults: 20 and 48.7 for the
default robot. The threshold is chosen from that bound; ``sigma0 = 0.05`` damps only where
``|cos th1| < 0.15`` for ``ats`` (``< 0.21-0.25`` for the pseudoinverse, depending on th2),
so runs that stay away from the singularity are not changed by it.

**Scale invariance.** The singular values are absolute numbers of matrices that mix m/s and
rad/s, and the isotropic damping ``lambda^2 I`` weighs metres against radians: measured in
metres, a robot scaled in every length by ``s`` (on a trajectory scaled by ``s``) would be
damped in another band and to another solution than the default robot (no single factor
on ``sigma0`` fixes that: the columns of ``M`` and ``A`` scale differently, and the lower
bound for ``A`` grows looser with the links). So the kernels measure lengths in the robot's
own unit :func:`length_unit`, ``L1 / 0.35`` m (its first link counts as the default
robot's 0.35): they divide the lengths and the task's linear rates by it, solve, and
multiply ``v`` by it. ``sigma``, ``sigma0``, ``lambda`` and the bounds above are then
numbers of that unit, the same on every robot of the default proportions, and the scaled
robot is damped on the states, and to the commands (``v`` times ``s``), of the default
robot, to rounding. The unit of the default robot is 1 m exactly, so its numbers are
unchanged; ``ats`` starts damping at ``|cos th1| = 0.151`` on every robot, whatever ``L2``.
"""

from __future__ import annotations

import math

from ddwmmr.errors import LENGTH_RANGE_M, ParameterError, check_finite, check_range
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import angles_in_range, refuse_angles

#: Smallest singular value below which damping starts (``sigma0``) by default, in the
#: robot's :func:`length_unit` (so the same band of ``|cos th1|`` on every robot size).
SINGULARITY_THRESHOLD = 0.05
#: Damping factor lambda at the singularity by default, in the robot's :func:`length_unit`
#: (``>= sigma0``: the gain bound holds).
MAX_DAMPING = 0.05
#: The values ``sigma0`` and ``lambda`` may take. Both enter squared, so they stay where
#: the squares neither overflow nor underflow (``sigma0 = 1e200`` squared to inf and
#: switched the damping off); 1e-6 still bounds the gain (at about 1e6 times the desired
#: speed) and 1e3 damps wherever ``sigma < sigma0``.
THRESHOLD_RANGE = (1e-6, 1e3)
DAMPING_RANGE = (1e-6, 1e3)
_SQRT2 = math.sqrt(2.0)
#: The default robot's first link (m): one :func:`length_unit` of every robot.
_DEFAULT_L1 = Robot.L1
#: The range of :func:`length_unit` over the robot's ``LENGTH_RANGE_M``.
_LOWEST_UNIT, _HIGHEST_UNIT = (length / _DEFAULT_L1 for length in LENGTH_RANGE_M)


def check_threshold(threshold: float) -> float:
    """``singularity_threshold`` (``sigma0``) as a float if it is in
    :data:`THRESHOLD_RANGE`, else a one-line ParameterError."""
    return check_range("singularity_threshold", threshold, *THRESHOLD_RANGE)


def check_damping(damping: float) -> float:
    """``damping`` (``lambda``) as a float if it is in :data:`DAMPING_RANGE`, else a
    one-line ParameterError (undamped, the inverse is unbounded at the singularity,
    ``cos th1 = 0``)."""
    low, high = DAMPING_RANGE
    value = check_finite("damping", damping, f"in [{low:g}, {high:g}]")
    if not value > 0.0:
        raise ParameterError(
            f"damping must be in [{low:g}, {high:g}] (got {value:g}): undamped, the inverse "
            "is unbounded at cos th1 = 0; a small value gives an almost undamped one"
        )
    return check_range("damping", value, low, high)


def length_unit(L1: float) -> float:
    """The robot's length unit (m) in which the kernels measure lengths and linear rates:
    ``L1 / Robot.L1``, so that its first link is the default robot's (exactly 1.0 for the
    default robot). ``L1`` (m) must be in ``LENGTH_RANGE_M``, the robot's, else a one-line
    ParameterError."""
    return check_range("L1", L1, *LENGTH_RANGE_M, "m") / _DEFAULT_L1


def _in_length_unit(
    L1: float, L2: float, xdot: float, ydot: float
) -> tuple[float, float, float, float]:
    """``(unit, L2 / unit, xdot / unit, ydot / unit)`` with ``unit = length_unit(L1)``
    (inlined but for the refusal: the kernels are the controllers' hot path)."""
    unit = L1 / _DEFAULT_L1
    if not _LOWEST_UNIT <= unit <= _HIGHEST_UNIT:
        length_unit(L1)
    return unit, L2 / unit, xdot / unit, ydot / unit


def damping_options(
    L1: float, threshold: float | None = None, damping: float | None = None
) -> tuple[float, float]:
    """``(threshold, damping)`` for a robot with first link ``L1`` (m, checked by
    :func:`length_unit`), checked by :func:`check_threshold` and :func:`check_damping`.
    None stands for the default, :data:`SINGULARITY_THRESHOLD` resp. :data:`MAX_DAMPING`:
    both are numbers of the robot's :func:`length_unit`, so the default needs no scaling
    and a given value means the same on every robot size."""
    length_unit(L1)
    if threshold is None:
        threshold = SINGULARITY_THRESHOLD
    if damping is None:
        damping = MAX_DAMPING
    return check_threshold(threshold), check_damping(damping)


def damping_squared(sigma: float, threshold: float, damping: float) -> float:
    """``lambda^2`` of the damped least squares for smallest singular value ``sigma``.

    ``damping^2 (1 - (sigma/threshold)^2)`` below ``threshold``, 0 at and above it.
    """
    ratio = sigma / threshold
    if ratio >= 1.0:
        return 0.0
    return damping * damping * (1.0 - ratio * ratio)


def pi_gain(threshold: float = SINGULARITY_THRESHOLD) -> float:
    """Bound of ``|u| / |Xdot|`` of :func:`pseudoinverse` (when damping >= threshold),
    lengths in the robot's :func:`length_unit`."""
    return 1.0 / threshold


def ats_gain(L1: float, L2: float, threshold: float = SINGULARITY_THRESHOLD) -> float:
    """Bound of ``|u| / |Xdot|`` of :func:`ats` (when damping >= threshold) for links
    ``L1``, ``L2`` (m), lengths in the robot's :func:`length_unit`."""
    reach = (L1 + L2) / length_unit(L1)
    return 2.0 * math.sqrt(1.0 + reach**2) / threshold + 1.0


def smallest_singular_value_m(L1: float, cos_th1: float) -> float:
    """Smallest singular value of the 2x2 ``M`` of the augmented system.

    ``|M|_F^2 = 1 + L1^2`` and ``|det M| = L1 |cos th1|``, so
    ``sigma_min^2 = 2 det^2 / (T + sqrt(T^2 - 4 det^2))`` with ``T = 1 + L1^2`` (the form
    without cancellation near the singularity).
    """
    return math.sqrt(_sigma_min_squared_m(1.0 + L1 * L1, (L1 * cos_th1) ** 2))


def _sigma_min_squared_m(total: float, det2: float) -> float:
    return 2.0 * det2 / (total + math.sqrt(max(total * total - 4.0 * det2, 0.0)))


def _ats_damping_squared(L1: float, cos_th1: float, threshold: float, damping: float) -> float:
    """:func:`damping_squared` of ``M`` at ``sigma = sigma_min(M)``, without the square roots
    outside the band: ``sigma_min(M) < threshold`` exactly when ``threshold^2 > T / 2`` (then
    everywhere: ``sigma_min^2 <= T / 2``) or ``det^2 < threshold^2 (T - threshold^2)``
    (``sigma_1^2 = T - sigma_min^2``)."""
    total = 1.0 + L1 * L1
    det2 = (L1 * cos_th1) ** 2
    threshold2 = threshold * threshold
    if 2.0 * threshold2 <= total and det2 >= threshold2 * (total - threshold2):
        return 0.0
    return damping * damping * (1.0 - _sigma_min_squared_m(total, det2) / threshold2)


def _solve2(
    m11: float, m12: float, m21: float, m22: float, r1: float, r2: float, lam2: float
) -> tuple[float, float]:
    """Solve ``M z = r`` (lam2 = 0) or the damped ``(M^T M + lam2 I) z = M^T r``."""
    if lam2 == 0.0:
        det = m11 * m22 - m12 * m21
        return (m22 * r1 - m12 * r2) / det, (m11 * r2 - m21 * r1) / det
    a11 = m11 * m11 + m21 * m21 + lam2
    a12 = m11 * m12 + m21 * m22
    a22 = m12 * m12 + m22 * m22 + lam2
    b1 = m11 * r1 + m21 * r2
    b2 = m12 * r1 + m22 * r2
    det = a11 * a22 - a12 * a12
    return (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det


def ats(
    L1: float,
    L2: float,
    phi: float,
    th1: float,
    th2: float,
    xdot: float,
    ydot: float,
    phidot_e: float,
    aux: str = "shoulder",
    threshold: float = SINGULARITY_THRESHOLD,
    damping: float = MAX_DAMPING,
) -> tuple[tuple[float, float, float, float], bool]:
    """Augmented task space resolution ``qdot = J_aug^-1 [Xdot; 0; 0]`` in input form.

    Links ``L1``, ``L2`` in m (``L1 > 0``), angles in rad, ``Xdot`` in m/s and rad/s, in the
    world frame; ``threshold`` and ``damping`` in the robot's :func:`length_unit`. Angles
    beyond +-``MAX_CONFIGURATION_ANGLE_RAD`` (their sums could overflow) are a
    :class:`ParameterError` naming q."""
    if not angles_in_range(phi, th1, th2):
        refuse_angles(phi, th1, th2)
    unit, l2, xdot, ydot = _in_length_unit(L1, L2, xdot, ydot)
    l1 = _DEFAULT_L1  # L1 in its own length unit, by definition
    c, s = math.cos(phi), math.sin(phi)
    a1 = phi + th1
    s1, c1 = math.sin(a1), math.cos(a1)
    s12, c12 = math.sin(a1 + th2), math.cos(a1 + th2)
    lam2 = _ats_damping_squared(l1, c * c1 + s * s1, threshold, damping)  # cos(a1 - phi)
    m12, m22 = -l1 * s1, l1 * c1
    if aux == "sum":
        w = phidot_e
        r1 = xdot + (l1 * s1 + l2 * s12) * w
        r2 = ydot - (l1 * c1 + l2 * c12) * w
        v, t1 = _solve2(c, m12, s, m22, r1, r2, lam2)
        return (v * unit, w, t1, -t1), lam2 > 0.0
    if aux == "shoulder":
        r1 = xdot + l2 * s12 * phidot_e
        r2 = ydot - l2 * c12 * phidot_e
        v, w = _solve2(c, m12, s, m22, r1, r2, lam2)
        return (v * unit, w, 0.0, phidot_e - w), lam2 > 0.0
    raise ValueError(f"aux must be 'sum' or 'shoulder' (got {aux!r})")


def pseudoinverse(
    L1: float,
    L2: float,
    phi: float,
    th1: float,
    th2: float,
    xdot: float,
    ydot: float,
    phidot_e: float,
    threshold: float = SINGULARITY_THRESHOLD,
    damping: float = MAX_DAMPING,
) -> tuple[tuple[float, float, float, float], bool]:
    """Minimum-norm resolution ``qdot = J^# [Xdot; 0]`` in input form (damped near cos th1 = 0).

    Units as in :func:`ats`; the minimum norm is that of ``u`` with ``v`` in the robot's
    :func:`length_unit` per second (m/s on the default robot). Angles beyond
    +-``MAX_CONFIGURATION_ANGLE_RAD`` are a :class:`ParameterError` naming q."""
    if not angles_in_range(phi, th1, th2):
        refuse_angles(phi, th1, th2)
    unit, l2, xdot, ydot = _in_length_unit(L1, L2, xdot, ydot)
    l1 = _DEFAULT_L1  # L1 in its own length unit, by definition
    c, s = math.cos(phi), math.sin(phi)
    a1 = phi + th1
    s1, c1 = math.sin(a1), math.cos(a1)
    s12, c12 = math.sin(a1 + th2), math.cos(a1 + th2)
    dx = -l1 * s1 - l2 * s12
    dy = l1 * c1 + l2 * c12
    ex, ey = -l2 * s12, l2 * c12
    # Gram matrix G = A A^T of A = [[c, dx, dx, ex], [s, dy, dy, ey], [0, 1, 1, 1]].
    g11 = c * c + 2.0 * dx * dx + ex * ex
    g12 = c * s + 2.0 * dx * dy + ex * ey
    g13 = 2.0 * dx + ex
    g22 = s * s + 2.0 * dy * dy + ey * ey
    g23 = 2.0 * dy + ey
    # det G = 2 L1^2 cos^2 th1 and sigma_1 sigma_2 <= trace(G) / 2 give the lower bound
    # sigma_min(A) >= 2 sqrt(2) L1 |cos th1| / trace(G).
    sigma = 2.0 * _SQRT2 * l1 * abs(c * c1 + s * s1) / (g11 + g22 + 3.0)
    lam2 = damping_squared(sigma, threshold, damping)
    g11 += lam2
    g22 += lam2
    g33 = 3.0 + lam2
    # Solve G y = XEdot by the adjugate (G is symmetric positive definite).
    k11 = g22 * g33 - g23 * g23
    k12 = g13 * g23 - g12 * g33
    k13 = g12 * g23 - g13 * g22
    k22 = g11 * g33 - g13 * g13
    k23 = g12 * g13 - g11 * g23
    k33 = g11 * g22 - g12 * g12
    det = g11 * k11 + g12 * k12 + g13 * k13
    y1 = (k11 * xdot + k12 * ydot + k13 * phidot_e) / det
    y2 = (k12 * xdot + k22 * ydot + k23 * phidot_e) / det
    y3 = (k13 * xdot + k23 * ydot + k33 * phidot_e) / det
    # u = A^T y
    w = dx * y1 + dy * y2 + y3
    return ((c * y1 + s * y2) * unit, w, w, ex * y1 + ey * y2 + y3), lam2 > 0.0


def null_space_rate(phi: float, th1: float, gradient_phi: float, gradient_th1: float) -> float:
    """Coefficient ``k`` of the null-space motion ``k [0, 0, 1, -1, 0]``.

    For a potential gradient ``g = grad V`` the projected descent ``(I - J^# J)(-g)`` equals
    ``k [0, 0, 1, -1, 0]`` with ``k = (g_th1 - g_phi) / 2``.
    """
    return 0.5 * (gradient_th1 - gradient_phi)
