"""The naive baseline of the method table: the textbook pseudoinverse step, a fresh SVD
every call."""

from __future__ import annotations

import numpy as np

from ddwmmr.controllers.base import StepInfo
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import u_from_qdot

#: Label of the naive pseudoinverse baseline row.
NAIVE_LABEL = "naive-pinv"


class NaivePseudoinverseController:
    """Naive baseline: ``qdot = pinv(J(q)) [Xd_dot; 0]`` with a fresh SVD every step.

    ``J`` is the 4x5 Jacobian from :meth:`Robot.jacobian`; the result is projected on the
    inputs ``u = (v, w, th1dot, th2dot)`` and the sideways base speed (m/s) is reported.
    No damping: this is the textbook formula the closed-form kernels replace.
    """

    name = NAIVE_LABEL

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.last = StepInfo()

    def reset(self, trajectory: object, q0: np.ndarray) -> None:
        """Nothing to prepare (memoryless)."""
        self.last = StepInfo()

    def command(
        self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray
    ) -> np.ndarray:
        """Input for the desired end-effector velocity (m/s, m/s, rad/s), world frame."""
        task_rate = np.append(velocity_d, 0.0)
        qdot = np.linalg.pinv(self.robot.jacobian(q)) @ task_rate
        u, residual = u_from_qdot(float(q[2]), qdot)
        self.last = StepInfo(nonholonomic_residual=residual)
        return u
