"""The kinematic plant: integrates inputs u, so the nonholonomic constraint holds exactly.

State: configuration ``q = [x, y, phi, th1, th2]``. Inputs ``u = [v, w, th1dot, th2dot]``
are saturated at the robot's limits before use:

* wheel speeds above ``wheel_speed_limit`` scale ``(v, w)`` down together (the path
  curvature is kept);
* each joint rate is clipped to ``+-joint_speed_limit``;
* a joint at a position limit cannot be driven further out.

Two integrators: ``euler`` (one command per step, held) and ``rk4``. With a policy (a
continuous-time control law), ``rk4`` evaluates the closed-loop vector field at its four
stages, as an ODE solver would; without one (a sampled-data controller, zero-order hold)
it integrates the held command exactly to fourth order.

The plant implements :class:`ddwmmr.plants.base.Plant`; :meth:`KinematicPlant.integrate` is
the same step as a pure function of ``q`` (no plant state) for code that drives the model
directly.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ddwmmr.commands import VELOCITY
from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.plants.base import Observation, PlantDivergedError, Policy

INTEGRATORS = ("euler", "rk4")


class KinematicPlant:
    """Kinematic model of the differential-drive mobile manipulator (velocity interface)."""

    name = "kinematic"
    interfaces = (VELOCITY,)
    extra_columns: tuple[str, ...] = ()

    def __init__(self, robot: Robot, integrator: str = "rk4") -> None:
        if integrator not in INTEGRATORS:
            raise ParameterError(
                f"integrator must be one of {', '.join(INTEGRATORS)} (got {integrator!r})"
            )
        self.robot = robot
        self.integrator = integrator
        self._q = np.zeros(5)
        self._v = self._w = 0.0

    # -- Plant interface ------------------------------------------------------------------
    def reset(self, q0: np.ndarray, dt: float) -> None:
        """Start at configuration ``q0`` at rest; any control step dt > 0 suits this plant."""
        q = np.array(q0, dtype=float)
        if q.shape != (5,) or not np.all(np.isfinite(q)):
            raise ParameterError("q0 must be 5 finite numbers [x, y, phi, th1, th2]")
        self._q = q
        self._v = self._w = 0.0

    def observe(self) -> Observation:
        """The exact state; ``v``, ``w`` are those of the last applied input (0 at rest)."""
        return Observation(self._q.copy(), self._v, self._w)

    def limit(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:
        """Same as :meth:`saturate`."""
        return self.saturate(q, u)

    def step(self, t: float, command: Any, dt: float, policy: Policy | None = None) -> None:
        """Advance by dt under velocity ``command`` (see :meth:`integrate`)."""
        q_next, u0, _ = self.integrate(t, self._q, dt, policy, first_command=command)
        if not all(math.isfinite(v) for v in q_next.tolist()):
            raise PlantDivergedError(f"kinematic plant: non-finite state at t = {t + dt:g} s")
        self._q = q_next
        self._v, self._w = float(u0[0]), float(u0[1])

    def extra_values(self) -> Sequence[float]:
        """No plant-specific columns."""
        return ()

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        """No plant-specific summary keys."""
        return {}

    # -- the model --------------------------------------------------------------------------
    def saturate(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:
        """The input the robot can actually apply at q, and whether any limit was hit."""
        robot = self.robot
        v, w, t1, t2 = np.asarray(u, dtype=float).tolist()
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

    def integrate(
        self,
        t: float,
        q: np.ndarray,
        dt: float,
        policy: Policy | None,
        first_command: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray, bool]:
        """Advance configuration q by dt: ``(q_next, u0, saturated0)``, no plant state.

        ``u0`` is the (saturated) input applied at the start of the step. ``euler`` calls
        the policy once per step; ``rk4`` with a policy evaluates the closed-loop vector
        field at its four stages, and without one holds ``first_command`` over the step.
        ``first_command``, if given, is used instead of calling the policy at (t, q).
        """
        if first_command is None and policy is None:
            raise ValueError("a policy or a first_command is needed")
        command = policy(t, q) if first_command is None else first_command
        u0, saturated0 = self.saturate(q, command)
        k1 = self.derivative(q, u0)
        if self.integrator == "euler":
            return self._clamp(q + dt * k1), u0, saturated0
        half = 0.5 * dt
        q2 = q + half * k1
        if policy is None:  # zero-order hold: the same input at every stage
            k2 = self.derivative(q2, u0)
            q3 = q + half * k2
            k3 = self.derivative(q3, u0)
            q4 = q + dt * k3
            k4 = self.derivative(q4, u0)
        else:
            k2 = self.derivative(q2, self.saturate(q2, policy(t + half, q2))[0])
            q3 = q + half * k2
            k3 = self.derivative(q3, self.saturate(q3, policy(t + half, q3))[0])
            q4 = q + dt * k3
            k4 = self.derivative(q4, self.saturate(q4, policy(t + dt, q4))[0])
        return self._clamp(q + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)), u0, saturated0
