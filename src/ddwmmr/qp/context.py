"""Per-step quantities shared by every task and limit of the QP controller.

One :class:`StepContext` is refreshed at the start of each control step from the measured
configuration and the desired end-effector motion; tasks and limits read from it instead of
recomputing trigonometry. Frames: world frame for poses and end-effector velocities, base
frame for the centre of mass. Units: metres, radians, seconds.
"""

from __future__ import annotations

import math

import numpy as np

from ddwmmr.model import Robot

#: Number of inputs u = (v, w, th1dot, th2dot) (m/s, rad/s, rad/s, rad/s).
NU = 4


class StepContext:
    """Measured state, desired motion and the end-effector Jacobian of one control step.

    Attributes (after :meth:`update`):
        t: time (s); q: configuration as floats ``(x, y, phi, th1, th2)``.
        x, y, phi, th1, th2: the same, unpacked (m, m, rad, rad, rad).
        cos_phi, sin_phi: heading trigonometry.
        pose_e: end-effector pose ``(xE, yE, phiE)`` (world frame, m, rad).
        pose_d, velocity_d: desired pose and velocity (world frame), as float tuples.
        jac_e: (3, 4) array, end-effector rates per input, ``d(xE, yE, phiE)/du``.
        dt: control step (s) used for one-step look-ahead checks.
        previous_command: ``(v, w)`` of the controller's previous command, None after a
            reset (kept by the controller, read by slew limits).
    """

    def __init__(self, robot: Robot, dt: float) -> None:
        self.robot = robot
        self.L1, self.L2 = robot.L1, robot.L2
        self.dt = dt
        self.jac_e = np.zeros((3, NU))
        self.jac_e[2, 1:] = 1.0  # phiE = phi + th1 + th2, constant rows
        self.t = 0.0
        self.q = (0.0, 0.0, 0.0, 0.0, 0.0)
        self.previous_command: tuple[float, float] | None = None

    def update(self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray) -> None:
        """Refresh every shared quantity for time t (s) and configuration q."""
        self.t = t
        x, y, phi, th1, th2 = np.asarray(q, dtype=float).tolist()
        self.q = (x, y, phi, th1, th2)
        self.x, self.y, self.phi, self.th1, self.th2 = x, y, phi, th1, th2
        L1, L2 = self.L1, self.L2
        c, s = math.cos(phi), math.sin(phi)
        a1 = phi + th1
        a12 = a1 + th2
        c1, s1 = math.cos(a1), math.sin(a1)
        c12, s12 = math.cos(a12), math.sin(a12)
        self.cos_phi, self.sin_phi = c, s
        self.pose_e = (x + L1 * c1 + L2 * c12, y + L1 * s1 + L2 * s12, a12)
        self.pose_d = tuple(np.asarray(pose_d, dtype=float).tolist())
        self.velocity_d = tuple(np.asarray(velocity_d, dtype=float).tolist())
        dx = -L1 * s1 - L2 * s12
        dy = L1 * c1 + L2 * c12
        jac = self.jac_e
        jac[0, 0], jac[0, 1], jac[0, 2], jac[0, 3] = c, dx, dx, -L2 * s12
        jac[1, 0], jac[1, 1], jac[1, 2], jac[1, 3] = s, dy, dy, L2 * c12
