"""Closed-form redundancy-resolution kernels (SPEC §3), in input form.

All kernels return ``u = (v, w, th1dot, th2dot)`` and a flag telling whether damping was
applied. They work in the input form ``qdot = B(phi) u`` (SPEC §1), which satisfies the
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

Near ``cos(th1) = 0`` the inverses are damped least squares with a damping that grows
smoothly from 0 at ``|cos th1| = threshold`` to ``damping`` at ``cos th1 = 0``.
"""

from __future__ import annotations

import math

#: Default |cos(th1)| below which damping starts.
SINGULARITY_THRESHOLD = 0.05
#: Default maximum damping factor lambda (applied at cos(th1) = 0).
MAX_DAMPING = 0.05


def damping_squared(cos_th1: float, threshold: float, damping: float) -> float:
    """``lambda^2`` of the damped least squares: 0 when ``|cos th1| >= threshold``."""
    ratio = abs(cos_th1) / threshold
    if ratio >= 1.0:
        return 0.0
    return damping * damping * (1.0 - ratio * ratio)


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
    """Augmented task space resolution ``qdot = J_aug^-1 [Xdot; 0; 0]`` in input form."""
    c, s = math.cos(phi), math.sin(phi)
    a1 = phi + th1
    s1, c1 = math.sin(a1), math.cos(a1)
    s12, c12 = math.sin(a1 + th2), math.cos(a1 + th2)
    lam2 = damping_squared(math.cos(th1), threshold, damping)
    m12, m22 = -L1 * s1, L1 * c1
    if aux == "sum":
        w = phidot_e
        r1 = xdot + (L1 * s1 + L2 * s12) * w
        r2 = ydot - (L1 * c1 + L2 * c12) * w
        v, t1 = _solve2(c, m12, s, m22, r1, r2, lam2)
        return (v, w, t1, -t1), lam2 > 0.0
    if aux == "shoulder":
        r1 = xdot + L2 * s12 * phidot_e
        r2 = ydot - L2 * c12 * phidot_e
        v, w = _solve2(c, m12, s, m22, r1, r2, lam2)
        return (v, w, 0.0, phidot_e - w), lam2 > 0.0
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
    """Minimum-norm resolution ``qdot = J^# [Xdot; 0]`` in input form (damped near cos th1 = 0)."""
    c, s = math.cos(phi), math.sin(phi)
    a1 = phi + th1
    s12, c12 = math.sin(a1 + th2), math.cos(a1 + th2)
    dx = -L1 * math.sin(a1) - L2 * s12
    dy = L1 * math.cos(a1) + L2 * c12
    ex, ey = -L2 * s12, L2 * c12
    lam2 = damping_squared(math.cos(th1), threshold, damping)
    # Gram matrix G = A A^T of A = [[c, dx, dx, ex], [s, dy, dy, ey], [0, 1, 1, 1]].
    g11 = c * c + 2.0 * dx * dx + ex * ex + lam2
    g12 = c * s + 2.0 * dx * dy + ex * ey
    g13 = 2.0 * dx + ex
    g22 = s * s + 2.0 * dy * dy + ey * ey + lam2
    g23 = 2.0 * dy + ey
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
    return (c * y1 + s * y2, w, w, ex * y1 + ey * y2 + y3), lam2 > 0.0


def null_space_rate(phi: float, th1: float, gradient_phi: float, gradient_th1: float) -> float:
    """Coefficient ``k`` of the null-space motion ``k [0, 0, 1, -1, 0]``.

    For a potential gradient ``g = grad V`` the projected descent ``(I - J^# J)(-g)`` equals
    ``k [0, 0, 1, -1, 0]`` with ``k = (g_th1 - g_phi) / 2``.
    """
    return 0.5 * (gradient_th1 - gradient_phi)
