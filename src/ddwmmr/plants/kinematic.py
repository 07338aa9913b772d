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
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ddwmmr.errors import ParameterError, check_instance, one_of, shown
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import base_motion, check_configuration, qdot_from_u
from ddwmmr.model.robot import clamp_joints
from ddwmmr.plants.base import (
    Observation,
    PlantDivergedError,
    PlantNotResetError,
    Policy,
    arm_rates,
    check_control_step,
    check_limit,
    check_policy,
    check_step,
    command_refusal,
)
from ddwmmr.registry import register_plant

if TYPE_CHECKING:
    import numpy.typing as npt

INTEGRATORS = ("euler", "rk4")


@register_plant("kinematic", interfaces=("velocity",))
class KinematicPlant:
    """Kinematic model of the differential-drive mobile manipulator (velocity interface)."""

    #: Set by the register_plant decorator (declared here for the type checker).
    interfaces: tuple[str, ...]
    extra_columns: tuple[str, ...] = ()

    def __init__(self, robot: Robot, integrator: str = "rk4") -> None:
        if not one_of(integrator, INTEGRATORS):
            raise ParameterError(
                f"integrator must be one of {', '.join(INTEGRATORS)} (got {shown(integrator)})"
            )
        self.robot = check_instance("robot", robot, Robot)
        self.integrator = integrator
        # Constants of the saturation, read once (it runs at every integrator stage).
        self._wheel = (1.0 / robot.wheel_radius, 0.5 * robot.track_width / robot.wheel_radius)
        self._wheel_limit = robot.wheel_speed_limit
        self._joint_speed = robot.joint_speed_limit
        self._joint_limits = robot.joint_limits
        self._state = [0.0] * 5  # configuration as floats (a new list every step)
        self._v = self._w = 0.0
        self._started = False  # reset() gave a start state: step() may run
        self._limited: np.ndarray | None = None

    # -- Plant interface ------------------------------------------------------------------
    def reset(self, q0: np.ndarray, dt: float) -> None:
        """Start at configuration ``q0`` (5 finite numbers ``[x, y, phi, th1, th2]``, m and
        rad) at rest; any control step dt > 0 (s, finite) suits this plant. Anything else
        is a :class:`ParameterError` naming ``q0`` or ``dt``."""
        state = check_configuration(q0)
        check_control_step(dt)
        self._state = state
        self._v = self._w = 0.0
        self._started = True

    def observe(self) -> Observation:
        """The exact state; ``v``, ``w`` are those of the last applied input (0 at rest).
        Before the first :meth:`reset` it is a :class:`PlantNotResetError`."""
        if not self._started:
            raise PlantNotResetError("kinematic", "observe")
        return Observation(tuple(self._state), self._v, self._w)

    def limit(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:
        """Same as :meth:`saturate` (its arguments checked the same way)."""
        applied, saturated = self.saturate(q, u)
        self._limited = applied  # step() need not saturate this exact command again
        return applied, saturated

    def step(self, t: float, command: Any, dt: float, policy: Policy | None = None) -> None:
        """Advance by dt (s) from time t (s) under velocity ``command``, 4 finite numbers
        ``u = [v, w, th1dot, th2dot]`` (m/s, rad/s, rad/s, rad/s), see :meth:`integrate`;
        other arguments are a :class:`ParameterError` (:func:`check_step`), and so is a
        ``policy`` that is neither None nor callable (:func:`check_policy`); before the
        first :meth:`reset` it is a :class:`PlantNotResetError`."""
        if not self._started:
            raise PlantNotResetError("kinematic")
        # cast: on the velocity interface alone check_step returns the list of 4 floats
        values = cast("list[float]", check_step(t, command, dt, self.interfaces))
        check_policy(policy)
        state = self._state
        if command is self._limited:  # limit() saturated this very command
            u0 = tuple(values)
        else:
            u0, _ = self._saturate(state[3], state[4], tuple(values))
        x, y, phi, th1, th2 = new = self._advance(t, state, dt, policy, u0)
        isfinite = math.isfinite
        if not (isfinite(x) and isfinite(y) and isfinite(phi) and isfinite(th1 + th2)):
            raise PlantDivergedError(f"kinematic plant: non-finite state at t = {t + dt:g} s")
        self._state = new
        self._v, self._w = u0[0], u0[1]

    def extra_values(self) -> Sequence[float]:
        """No plant-specific columns (:class:`PlantNotResetError` before the first
        :meth:`reset`, as every plant's)."""
        if not self._started:
            raise PlantNotResetError("kinematic", "extra_values")
        return ()

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        """No plant-specific summary keys."""
        return {}

    # -- the model --------------------------------------------------------------------------
    def saturate(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:
        """The input the robot can actually apply at configuration ``q`` (5 finite numbers,
        m and rad) for the velocity command ``u`` (4 finite numbers, m/s and rad/s), and
        whether any limit was hit; other arguments are a :class:`ParameterError` naming
        ``q`` or ``u`` (:func:`check_limit`)."""
        th1, th2, values = check_limit(q, u)
        (v, w, t1, t2), saturated = self._saturate(th1, th2, values, checked=True)
        return np.array([v, w, t1, t2]), saturated

    def _saturate(
        self,
        th1: float,
        th2: float,
        u: Sequence[float] | npt.NDArray[np.float64],
        checked: bool = False,
    ) -> tuple[tuple[float, ...], bool]:
        """:meth:`saturate` on floats (joint angles th1, th2 in rad; ``u`` a tuple of
        floats, an array or any sequence of 4 numbers; a non-finite one, as from a policy
        of :meth:`integrate`, is a :class:`ParameterError` naming ``u``). ``checked``: ``u``
        is 4 finite floats already (:func:`check_limit`'s list)."""
        if type(u) is tuple or checked:
            v, w, t1, t2 = u
        elif isinstance(u, np.ndarray):
            v, w, t1, t2 = u.tolist()
        else:
            v, w, t1, t2 = (float(a) for a in u)
        isfinite = math.isfinite
        if not (checked or (isfinite(v) and isfinite(w) and isfinite(t1) and isfinite(t2))):
            raise ParameterError(command_refusal("u", u))
        saturated = False
        # Wheel speeds (docs/theory.md, "Wheels"):
        # (2v -+ Lw w) / (2r) = v / r -+ (Lw / 2r) w; the faster
        # wheel's |a| + |b| is max(|a - b|, |a + b|) to the last bit (one is a sum of the
        # magnitudes either way).
        per_v, per_w = self._wheel
        peak = abs(v * per_v) + abs(w * per_w)
        limit = self._wheel_limit
        if peak > limit:
            scale = limit / peak
            v, w = v * scale, w * scale
            saturated = True
        r1, r2 = arm_rates(th1, th2, t1, t2, self._joint_speed, self._joint_limits)
        return (v, w, r1, r2), saturated or r1 != t1 or r2 != t2

    @staticmethod
    def derivative(q: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Configuration rate ``qdot = B(phi) u`` (:func:`~ddwmmr.model.kinematics.qdot_from_u`
        at the heading ``q[2]``)."""
        return qdot_from_u(float(q[2]), u)

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
        state = q.tolist()
        th1, th2 = state[3], state[4]
        # cast: policy is not None when first_command is (refused above)
        command = cast("Policy", policy)(t, state) if first_command is None else first_command
        if saturated and first_command is not None:
            u0, saturated0 = tuple(first_command.tolist()), False
        else:
            u0, saturated0 = self._saturate(th1, th2, command)
        return np.array(self._advance(t, state, dt, policy, u0)), np.array(u0), saturated0

    def _advance(
        self,
        t: float,
        state: list[float],
        dt: float,
        policy: Policy | None,
        u0: tuple[float, ...],
    ) -> list[float]:
        """``state`` after dt under the integrator, ``u0`` applied first; joints clamped."""
        if self.integrator == "euler":
            x, y, phi, th1, th2 = state
            dx, dy, dphi, d1, d2 = base_motion(phi, *u0)
            new = [x + dt * dx, y + dt * dy, phi + dt * dphi, th1 + dt * d1, th2 + dt * d2]
        else:
            new = self._rk4(t, state, dt, policy, u0)
        new[3], new[4] = clamp_joints(new[3], new[4], self._joint_limits)
        return new

    def _rk4(
        self,
        t: float,
        state: list[float],
        dt: float,
        policy: Policy | None,
        u0: tuple[float, ...],
    ) -> list[float]:
        """One RK4 step of ``qdot = B(phi) u`` from ``state`` with ``u0`` at the start: the
        policy's saturated input at every later stage, or ``u0`` held (zero-order hold).

        The stage rates ``k1..k4`` are summed as ``k1 + 2 k2 + 2 k3 + k4`` while the stages
        run (the same operations in the same order as the sum written out)."""
        x, y, phi, th1, th2 = state
        v, w, r1, r2 = u0
        cx, cy, sp, s1, s2 = base_motion(phi, v, w, r1, r2)  # k1
        sx, sy = cx, cy  # with sp, s1, s2: the weighted sum of the stage rates
        for h, weight in ((0.5 * dt, 2.0), (0.5 * dt, 2.0), (dt, 1.0)):
            # the next stage at state + h k (k: the stage before)
            p, t1, t2 = phi + h * w, th1 + h * r1, th2 + h * r2
            if policy is None:
                v, w, r1, r2 = u0
            else:
                stage = [x + h * cx, y + h * cy, p, t1, t2]
                (v, w, r1, r2), _ = self._saturate(t1, t2, policy(t + h, stage))
            cx, cy, cp, c1, c2 = base_motion(p, v, w, r1, r2)
            sx += weight * cx
            sy += weight * cy
            sp += weight * cp
            s1 += weight * c1
            s2 += weight * c2
        sixth = dt / 6.0
        return [
            x + sixth * sx,
            y + sixth * sy,
            phi + sixth * sp,
            th1 + sixth * s1,
            th2 + sixth * s2,
        ]
