"""Per-step quantities shared by every task and limit of the QP controller.

One :class:`StepContext` is refreshed at the start of each control step from the measured
configuration and the desired end-effector motion; tasks and limits read from it instead of
recomputing trigonometry. Frames: world frame for poses and end-effector velocities, base
frame for the centre of mass. Units: metres, radians, seconds.
"""

from __future__ import annotations

import math

import numpy as np

from ddwmmr.errors import FLOAT64
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import angles_in_range, refuse_angles

#: Number of inputs u = (v, w, th1dot, th2dot) (m/s, rad/s, rad/s, rad/s).
NU = 4


def _floats(values: np.ndarray) -> list[float]:
    """``values`` as a list of Python floats (fast for a float64 array, the usual case)."""
    if type(values) is np.ndarray and values.dtype is FLOAT64:
        floats: list[float] = values.tolist()
        return floats
    converted: list[float] = np.asarray(values, dtype=float).tolist()
    return converted


class StepContext:
    """Measured state, desired motion and the end-effector Jacobian of one control step.

    Attributes (after :meth:`update`):
        t: time (s); q: configuration as floats ``(x, y, phi, th1, th2)``.
        x, y, phi, th1, th2: the same, unpacked (m, m, rad, rad, rad).
        cos_phi, sin_phi: heading trigonometry.
        cos_th1, sin_th1, cos_th12, sin_th12: arm trigonometry in the base frame
            (``th12 = th1 + th2``), as the stability limit and its look-ahead use it.
        pose_e: end-effector pose ``(xE, yE, phiE)`` (world frame, m, rad).
        pose_d, velocity_d: desired pose and velocity (world frame), as float tuples.
        jac_e_rows: the varying entries of the end-effector Jacobian as floats,
            ``(dxE/dv, dxE/dw, dxE/dth2dot, dyE/dv, dyE/dw, dyE/dth2dot)`` (``dxE/dth1dot``
            equals ``dxE/dw``; the phiE row is the constant ``(0, 1, 1, 1)``).
        jac_e: (3, 4) array, end-effector rates per input, ``d(xE, yE, phiE)/du`` (filled
            from ``jac_e_rows`` on first access after each update).
        dt: control step (s) used for one-step look-ahead checks.
        previous_command: ``(v, w)`` of the controller's previous command, None after a
            reset (kept by the controller, read by slew limits).
        start_turns: whole turns (rad) of the start's ``(phi, th1, th2)``
            (:func:`~ddwmmr.model.kinematics.whole_turns`, set at reset): potentials count
            the angles from the start's own turn, so a start whole turns apart is the same
            run. ``(0.0, 0.0, 0.0)`` for a start within (-pi, pi].
    """

    def __init__(self, robot: Robot, dt: float) -> None:
        self.robot = robot
        self.L1, self.L2 = robot.L1, robot.L2
        self.dt = dt
        self._jac_e = np.zeros((3, NU))
        self._jac_e[2, 1:] = 1.0  # phiE = phi + th1 + th2, constant rows
        self._jac_fresh = True
        self.jac_e_rows = (0.0,) * 6
        self.t = 0.0
        self.q = (0.0, 0.0, 0.0, 0.0, 0.0)
        self.x = self.y = self.phi = self.th1 = self.th2 = 0.0
        self.previous_command: tuple[float, float] | None = None
        self.start_turns = (0.0, 0.0, 0.0)

    @property
    def jac_e(self) -> np.ndarray:
        """``d(xE, yE, phiE)/du`` (3 x 4), world frame."""
        if not self._jac_fresh:
            jac = self._jac_e
            dx_v, dx_w, dx_2, dy_v, dy_w, dy_2 = self.jac_e_rows
            jac[0, 0], jac[0, 1], jac[0, 2], jac[0, 3] = dx_v, dx_w, dx_w, dx_2
            jac[1, 0], jac[1, 1], jac[1, 2], jac[1, 3] = dy_v, dy_w, dy_w, dy_2
            self._jac_fresh = True
        return self._jac_e

    def update(self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray) -> None:
        """Refresh every shared quantity for time t (s) and configuration q."""
        self.update_floats(t, _floats(q), _floats(pose_d), _floats(velocity_d))

    def update_floats(
        self, t: float, q: list[float], pose_d: list[float], velocity_d: list[float]
    ) -> None:
        """:meth:`update` from lists of floats (as :func:`check_inputs` returns them).

        Angles beyond +-``MAX_CONFIGURATION_ANGLE_RAD`` (``ddwmmr.model.kinematics``) are a
        :class:`~ddwmmr.errors.ParameterError` naming q: the link headings formed here
        would overflow."""
        self.t = t
        x, y, phi, th1, th2 = q
        if not angles_in_range(phi, th1, th2):  # the sums below would overflow
            refuse_angles(phi, th1, th2)
        self.q = (x, y, phi, th1, th2)
        self.x, self.y, self.phi, self.th1, self.th2 = x, y, phi, th1, th2
        L1, L2 = self.L1, self.L2
        c, s = math.cos(phi), math.sin(phi)
        a1 = phi + th1
        a12 = a1 + th2
        c1, s1 = math.cos(a1), math.sin(a1)
        c12, s12 = math.cos(a12), math.sin(a12)
        self.cos_phi, self.sin_phi = c, s
        th12 = th1 + th2
        self.cos_th1, self.sin_th1 = math.cos(th1), math.sin(th1)
        self.cos_th12, self.sin_th12 = math.cos(th12), math.sin(th12)
        self.pose_e = (x + L1 * c1 + L2 * c12, y + L1 * s1 + L2 * s12, a12)
        self.pose_d = tuple(pose_d)
        self.velocity_d = tuple(velocity_d)
        dx = -L1 * s1 - L2 * s12
        dy = L1 * c1 + L2 * c12
        self.jac_e_rows = (c, dx, -L2 * s12, s, dy, L2 * c12)
        self._jac_fresh = False
