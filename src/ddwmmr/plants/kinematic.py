"""The kinematic plant: integrates inputs u, so the nonholonomic constraint holds exactly.

State: configuration ``q = [x, y, phi, th1, th2]``. Inputs ``u = [v, w, th1dot, th2dot]``
are saturated at the robot's limits before use:

* wheel speeds above ``wheel_speed_limit`` scale ``(v, w)`` down together (the path
  curvature is kept);
* each joint rate is clipped to ``+-joint_speed_limit``;
* a joint at a position limit cannot be driven further out.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot

INTEGRATORS = ("euler", "rk4")
#: A control policy: time (s) and configuration -> input u.
Policy = Callable[[float, np.ndarray], np.ndarray]


class KinematicPlant:
    """Kinematic model of the differential-drive mobile manipulator."""

    def __init__(self, robot: Robot, integrator: str = "rk4") -> None:
        if integrator not in INTEGRATORS:
            raise ParameterError(
                f"integrator must be one of {', '.join(INTEGRATORS)} (got {integrator!r})"
            )
        self.robot = robot
        self.integrator = integrator

    def saturate(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:
        """The input the robot can actually apply at q, and whether any limit was hit."""
        robot = self.robot
        v, w, t1, t2 = u.tolist()
        if not all(math.isfinite(a) for a in (v, w, t1, t2)):
            raise FloatingPointError(f"non-finite command u = {u}")
        saturated = False
        left, right = robot.wheel_speeds_from_u(v, w)
        peak = max(abs(left), abs(right))
        if peak > robot.wheel_speed_limit:
            scale = robot.wheel_speed_limit / peak
            v, w = v * scale, w * scale
            saturated = True
        rates = []
        for rate, angle, (low, high) in zip((t1, t2), q[3:5].tolist(), robot.joint_limits):
            limited = min(max(rate, -robot.joint_speed_limit), robot.joint_speed_limit)
            if (angle >= high and limited > 0) or (angle <= low and limited < 0):
                limited = 0.0
            saturated |= limited != rate
            rates.append(limited)
        return np.array([v, w, rates[0], rates[1]]), saturated

    @staticmethod
    def derivative(q: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Configuration rate ``qdot = B(phi) u``."""
        phi = q[2]
        return np.array([u[0] * math.cos(phi), u[0] * math.sin(phi), u[1], u[2], u[3]])

    def _clamp(self, q: np.ndarray) -> np.ndarray:
        for i, (low, high) in zip((3, 4), self.robot.joint_limits):
            q[i] = min(max(q[i], low), high)
        return q

    def step(
        self,
        t: float,
        q: np.ndarray,
        dt: float,
        policy: Policy | None,
        first_command: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray, bool]:
        """Advance q by dt under ``policy``.

        Returns ``(q_next, u0, saturated0)``: the new configuration and the (saturated)
        input applied at the start of the step. ``euler`` calls the policy once per step;
        ``rk4`` evaluates the closed-loop vector field at its four stages (the control law
        treated as continuous in time, as in an ODE solver). ``first_command``, if given, is
        used instead of calling the policy at (t, q); with ``euler`` the policy may then be
        None (a zero-order hold of ``first_command``).
        """
        if policy is None and (first_command is None or self.integrator != "euler"):
            raise ValueError("a policy is needed unless euler steps a given first_command")
        command = policy(t, q) if first_command is None else first_command
        u0, saturated0 = self.saturate(q, command)
        k1 = self.derivative(q, u0)
        if self.integrator == "euler":
            return self._clamp(q + dt * k1), u0, saturated0
        half = 0.5 * dt
        q2 = q + half * k1
        k2 = self.derivative(q2, self.saturate(q2, policy(t + half, q2))[0])
        q3 = q + half * k2
        k3 = self.derivative(q3, self.saturate(q3, policy(t + half, q3))[0])
        q4 = q + dt * k3
        k4 = self.derivative(q4, self.saturate(q4, policy(t + dt, q4))[0])
        return self._clamp(q + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)), u0, saturated0
