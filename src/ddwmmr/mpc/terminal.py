"""LQR terminal cost of the MPC, designed with python-control on the linearised model.

Beyond the horizon the MPC assumes the linearised end-effector error dynamics, regulated by
the LQR law of the same stage cost; the terminal cost is that law's cost-to-go
``z' P z``. The error ``z`` is written in the base frame (``R(-phi) (p_E - p_ref)``, plus
the orientation error when tracked), so one design holds at every heading:

* kinematic model, inputs ``u = (v, w, th1dot, th2dot)``: ``zdot = A_B(th1, th2) u`` with
  ``A_B`` the end-effector Jacobian in the base frame (``J_E G`` at phi = 0);
* thesis model, inputs ``(F_left, F_right, th1dot, th2dot)``, state ``z = [e, v, w]``:
  ``edot = A_B [v, w, th1dot, th2dot]``, ``m vdot = F_l + F_r - c1 v``,
  ``I wdot = (F_r - F_l) width/2 - c2 w``.

Both are discretised with a zero-order hold over the last shooting interval h
(``control.c2d``) and solved with ``control.dlqr`` with ``Q = h diag(Wp, Wp[, Wo], 0, 0)``
and ``R = h Wu diag(1/u_scale^2)``: the same weights as the OCP's stage cost.

A zero weight (``position_weight=0`` or ``orientation_weight=0``) leaves those error
components out of the design: nothing in the error dynamics depends on an error component
(its column of ``A`` is zero) and the stage cost does not charge it, so the LQR's
cost-to-go does not depend on it either. The design is then made on the other components
(exactly: ``P`` is the least positive semidefinite solution of the Riccati equation, with
zero rows and columns for the unweighted errors, and ``K`` does not feed them back); the
terminal cost, like the stage cost, ignores them. With no error component weighted at all
the cost-to-go is zero (``P = 0``, ``K = 0``). This is not a regularisation: a plain
``dlqr`` on the full error would have no stabilising solution there (an unweighted
integrator is neither regulated nor seen by the cost).

A weight below :data:`NEGLIGIBLE` times the design's largest weight (of ``Q`` and ``R``)
is left out the same way: the Riccati solver cannot resolve it in double precision (a
``position_weight`` of 1e-100 or an ``orientation_weight`` of 1e-40 made ``dlqr`` fail),
and its share of the cost-to-go is below that rounding anyway.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.model import kinematics as kin
from ddwmmr.mpc.models import PredictionModel, ThesisPrediction
from ddwmmr.mpc.ocp import OCPConfig

#: Added to R's diagonal so the design stays well posed with a zero input weight.
R_FLOOR = 1e-9

#: Error weights below this share of the design's largest weight (of Q and R) are left out
#: of the design as zero weights are (module docstring).
NEGLIGIBLE = 1e-12


@dataclass(frozen=True)
class TerminalDesign:
    """One LQR design: the discrete system, the weights and the results.

    Attributes:
        A, B: discretised error dynamics (nz x nz, nz x nu); Q, R: weights.
        P: Riccati solution (cost-to-go ``z' P z``); K: gain ``u = -K z``.
        poles: closed-loop eigenvalues of ``A - B K`` (discrete, |.| < 1, but 1 for each
            error component a zero weight leaves out); factor: ``L`` with
            ``L L' = P + 1e-12 I``.
    """

    A: np.ndarray
    B: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    P: np.ndarray
    K: np.ndarray
    poles: np.ndarray
    factor: np.ndarray


def error_dynamics(
    robot: Robot, model: PredictionModel, arm_pose: tuple[float, float], track_orientation: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Continuous-time ``(A, B)`` of the terminal error ``z`` at arm pose (th1, th2) (rad)."""
    jac = kin.end_effector_jacobian_u(robot.L1, robot.L2, [0.0, 0.0, 0.0, *arm_pose])
    rows = 3 if track_orientation else 2
    jac = jac[:rows]
    if not isinstance(model, ThesisPrediction):
        return np.zeros((rows, rows)), jac
    d = model.dynamics
    inertia = d.inertia(arm_pose[1])
    nz = rows + 2
    A = np.zeros((nz, nz))
    B = np.zeros((nz, 4))
    A[:rows, rows] = jac[:, 0]  # edot from v
    A[:rows, rows + 1] = jac[:, 1]  # edot from w
    B[:rows, 2:] = jac[:, 2:]  # edot from the joint rates
    A[rows, rows] = -d.c1 / d.mass
    B[rows, :2] = 1.0 / d.mass
    A[rows + 1, rows + 1] = -d.c2 / inertia
    B[rows + 1, 0], B[rows + 1, 1] = -d.half_width / inertia, d.half_width / inertia
    return A, B


def design(
    robot: Robot, model: PredictionModel, config: OCPConfig, arm_pose: tuple[float, float]
) -> TerminalDesign:
    """The LQR terminal design for ``config``'s weights and interval at ``arm_pose`` (an
    error component of zero weight is left out: module docstring)."""
    # Imported here: python-control (with scipy.signal) takes most of a second to import,
    # which every command-line run would otherwise pay through the method registry.
    # ignore: python-control ships no type hints
    import control

    A, B = error_dynamics(robot, model, arm_pose, config.track_orientation)
    h, weights = float(config.interval_lengths()[-1]), config.weights
    try:
        return _designed(control, A, B, h, weights, model, config.track_orientation)
    except (np.linalg.LinAlgError, ValueError):
        if not isinstance(model, ThesisPrediction):
            raise  # the kinematic model's design always exists (module docstring)
        d = model.dynamics
        raise ParameterError(
            f"mpc: the force model cannot plan for this base: c1 = {d.c1:g} N s/m and c2 = "
            f"{d.c2:g} N m s/rad make its time constants m / c1 = {d.mass / d.c1:.3g} s and "
            f"I / c2 = {d.inertia(arm_pose[1]) / d.c2:.3g} s, which its intervals (the last "
            f"{h:.3g} s) cannot resolve (no finite terminal LQR); give the plant a damping "
            "nearer the thesis's (15 N s/m, 4 N m s/rad) or use model='kinematic'"
        ) from None


def _designed(
    control: Any,
    A: np.ndarray,
    B: np.ndarray,
    h: float,
    weights: Any,
    model: PredictionModel,
    track_orientation: bool,
) -> TerminalDesign:
    """:func:`design` once the continuous error dynamics ``(A, B)`` are known."""
    nz, nu = B.shape
    discrete = control.c2d(control.ss(A, B, np.eye(nz), np.zeros((nz, nu))), h)
    Ad, Bd = np.asarray(discrete.A), np.asarray(discrete.B)
    rows = 3 if track_orientation else 2  # the end-effector error; then (v, w)
    q = np.zeros(nz)
    q[:2] = weights.position
    if track_orientation:
        q[2] = weights.orientation
    Q = h * np.diag(q)
    R = h * np.diag(weights.input / np.asarray(model.u_scale, dtype=float) ** 2 + R_FLOOR)
    # unweighted error components are left out (module docstring): nothing depends on them
    floor = NEGLIGIBLE * max(float(np.max(Q)), float(np.max(np.diag(R))))
    keep = np.array([i for i in range(nz) if i >= rows or Q[i, i] > floor], dtype=int)
    P, K = np.zeros((nz, nz)), np.zeros((nu, nz))
    if np.any(np.diag(Q)[keep] > floor):
        part = np.ix_(keep, keep)
        K_kept, P_kept, _ = control.dlqr(Ad[part], Bd[keep], Q[part], R)
        P[part] = 0.5 * (P_kept + P_kept.T)
        K[:, keep] = K_kept
    poles = np.linalg.eigvals(Ad - Bd @ K)
    factor = np.linalg.cholesky(P + 1e-12 * np.eye(nz))
    return TerminalDesign(Ad, Bd, Q, R, P, np.asarray(K), np.asarray(poles), factor)
