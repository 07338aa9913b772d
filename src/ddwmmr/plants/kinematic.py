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
        # Constants of the saturation, read once (it runs at every integrator stage).
        self._wheel = (1.0 / robot.wheel_radius, 0.5 * robot.track_width / robot.wheel_radius)
        self._wheel_limit = robot.wheel_speed_limit
        self._joint_speed = robot.joint_speed_limit
        self._joint_limits = robot.joint_limits
        self._q = np.zeros(5)
        self._v = self._w = 0.0
        self._limited: np.ndarray | None = None

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
        applied, saturated = self.saturate(q, u)
        self._limited = applied  # step() need not saturate this exact command again
        return applied, saturated

    def step(self, t: float, command: Any, dt: float, policy: Policy | None = None) -> None:
        """Advance by dt under velocity ``command`` (see :meth:`integrate`)."""
        trusted = command is self._limited
        q_next, u0, _ = self.integrate(
            t, self._q, dt, policy, first_command=command, saturated=trusted
        )
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
        (v, w, t1, t2), saturated = self._saturate(q[3], q[4], u)
        return np.array([v, w, t1, t2]), saturated

    def _saturate(self, th1: float, th2: float, u) -> tuple[tuple[float, ...], bool]:
        """:meth:`saturate` on floats (joint angles th1, th2 in rad)."""
        v, w, t1, t2 = u.tolist() if isinstance(u, np.ndarray) else (float(a) for a in u)
        if not (math.isfinite(v) and math.isfinite(w) and math.isfinite(t1) and math.isfinite(t2)):
            raise FloatingPointError(f"non-finite command u = {u}")
        saturated = False
        # Wheel speeds (SPEC §1): (2v -+ Lw w) / (2r) = v / r -+ (Lw / 2r) w.
        per_v, per_w = self._wheel
        peak = max(abs(v * per_v - w * per_w), abs(v * per_v + w * per_w))
        limit = self._wheel_limit
        if peak > limit:
            scale = limit / peak
            v, w = v * scale, w * scale
            saturated = True
        speed = self._joint_speed
        (low1, high1), (low2, high2) = self._joint_limits
        r1 = min(max(t1, -speed), speed)
        if (th1 >= high1 and r1 > 0) or (th1 <= low1 and r1 < 0):
            r1 = 0.0
        r2 = min(max(t2, -speed), speed)
        if (th2 >= high2 and r2 > 0) or (th2 <= low2 and r2 < 0):
            r2 = 0.0
        return (v, w, r1, r2), saturated or r1 != t1 or r2 != t2

    @staticmethod
    def derivative(q: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Configuration rate ``qdot = B(phi) u``."""
        return np.array(_rate(float(q[2]), *(float(a) for a in u)))

    def integrate(
        self,
        t: float,
        q: np.ndarray,
        dt: float,
        policy: Policy | None,
        first_command: np.ndarray | None = None,
        saturated: bool = False,
    ) -> tuple[np.ndarray, np.ndarray, bool]:
        """Advance configuration q by dt: ``(q_next, u0, saturated0)``, no plant state.

        ``u0`` is the (saturated) input applied at the start of the step. ``euler`` calls
        the policy once per step; ``rk4`` with a policy evaluates the closed-loop vector
        field at its four stages, and without one holds ``first_command`` over the step.
        ``first_command``, if given, is used instead of calling the policy at (t, q).
        ``saturated=True`` says ``first_command`` already is :meth:`saturate`'s output at q
        (it is used as is; ``saturated0`` is then False). Joint angles are clamped to their
        limits after the step.
        """
        if first_command is None and policy is None:
            raise ValueError("a policy or a first_command is needed")
        command = policy(t, q) if first_command is None else first_command
        x, y, phi, th1, th2 = q.tolist()
        if saturated and first_command is not None:
            u0, saturated0 = tuple(first_command.tolist()), False
        else:
            u0, saturated0 = self._saturate(th1, th2, command)
        k1 = _rate(phi, *u0)
        state = (x, y, phi, th1, th2)
        if self.integrator == "euler":
            new = [a + dt * b for a, b in zip(state, k1)]
        else:
            half = 0.5 * dt
            k2 = self._stage(t + half, state, k1, half, policy, u0)
            k3 = self._stage(t + half, state, k2, half, policy, u0)
            k4 = self._stage(t + dt, state, k3, dt, policy, u0)
            sixth = dt / 6.0
            new = [
                a + sixth * (b1 + 2.0 * b2 + 2.0 * b3 + b4)
                for a, b1, b2, b3, b4 in zip(state, k1, k2, k3, k4)
            ]
        (low1, high1), (low2, high2) = self.robot.joint_limits
        new[3] = min(max(new[3], low1), high1)
        new[4] = min(max(new[4], low2), high2)
        return np.array(new), np.array(u0), saturated0

    def _stage(
        self,
        t: float,
        state: tuple[float, ...],
        slope: tuple[float, ...],
        h: float,
        policy: Policy | None,
        held: tuple[float, ...],
    ) -> tuple[float, ...]:
        """RK4 stage derivative at ``state + h slope``: the policy's (saturated) input there,
        or the held input ``held`` (zero-order hold)."""
        stage = [a + h * b for a, b in zip(state, slope)]
        if policy is None:
            u = held
        else:
            u, _ = self._saturate(stage[3], stage[4], policy(t, np.array(stage)))
        return _rate(stage[2], *u)


def _rate(phi: float, v: float, w: float, r1: float, r2: float) -> tuple[float, ...]:
    """``qdot = B(phi) u`` on floats: (x', y', phi', th1', th2')."""
    return (v * math.cos(phi), v * math.sin(phi), w, r1, r2)
