"""Prediction models of the MPC: what it integrates over the horizon and what it may command.

Three models, one interface (:class:`PredictionModel`):

* :class:`KinematicPrediction` (``model="kinematic"``): state ``q`` (5), inputs
  ``u = (v, w, th1dot, th2dot)``; the velocity command is applied as it is (the kinematic
  plant). Bounds: wheel speeds (rows), joint speeds (box).
* :class:`ThesisPrediction` (``model="thesis"``): state ``[q, v, w]`` (7), inputs the wheel
  forces and the joint rates ``(F_left, F_right, th1dot, th2dot)`` (N, N, rad/s, rad/s);
  the thesis plant's force-level dynamics (:class:`ddwmmr.model.symbolic.ThesisDynamics`).
  Bounds: the force limit per wheel, joint speeds (box), wheel speeds of the predicted
  base velocity (rows).
* :class:`LaggedArmPrediction` (``model="thesis"`` with ``arm_time_constant``): the same
  base, and joints that follow the commanded rates through a first-order lag (state
  ``[q, v, w, th1dot, th2dot]``, 9): the arm's accelerations, which move the centre of
  pressure, are then part of the prediction (a velocity servo with that time constant, as
  the physics plant's). With ``acceleration_limit`` the lag's accelerations are bounded
  (rows) by what the joints' motors give, as the physics plant's torque-limited servos,
  and ``stopping_configuration`` is the pose where the joints come to rest braked at that
  limit (the OCP holds its centre of mass in the stability box at the last node), and
  ``stopped_arm_motion`` the base's motion once the arm rests there (the yaw the arm's
  angular momentum leaves it with; the OCP keeps every edge loaded under it).

Joint-position limits are state bounds of the models; the OCP holds them as bounds of the
nodes where the joints stop at once (``joints_stop_at_once``) and as slackened rows for the
lagged arm (:mod:`ddwmmr.mpc.ocp`).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any

import casadi as ca
import numpy as np

from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym

INF = math.inf


class PredictionModel(ABC):
    """Interface: sizes, the symbolic right-hand side, bounds, rows, scaling.

    Attributes:
        name: ``"kinematic"`` or ``"thesis"``.
        nx, nu: state and input sizes.
        interface: command interface of the controller using it (``"velocity"``/``"force"``).
        u_lower, u_upper: input box (nu,); x_lower, x_upper: state box (nx,).
        u_scale: typical input magnitudes (nu,) used to normalise the input cost.
        joints_stop_at_once: the joint rates are inputs, so the joints can halt within any
            interval and a node inside the joint box can always keep the next inside it.
    """

    name = "model"
    nx = 0
    nu = 0
    interface = "velocity"
    joints_stop_at_once = True
    # set by each model's __init__ (declared here for the solver code that reads them)
    u_lower: np.ndarray
    u_upper: np.ndarray
    u_scale: np.ndarray

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        lo1, hi1 = robot.joint_limits[0]
        lo2, hi2 = robot.joint_limits[1]
        x_lower = np.full(self.nx, -INF)
        x_upper = np.full(self.nx, INF)
        x_lower[3:5], x_upper[3:5] = (lo1, lo2), (hi1, hi2)
        self.x_lower, self.x_upper = x_lower, x_upper
        self.wheel_limit = robot.wheel_speed_limit * (1.0 - 1e-6)

    @abstractmethod
    def rhs(self, x: Any, u: Any) -> Any:
        """State rate (symbolic)."""

    @abstractmethod
    def wheel_rows(self, x: Any, u: Any | None) -> Any | None:
        """Wheel speeds (rad/s) implied at a node, or None when they are not decided there."""

    def acceleration_rows(self, x: Any, u: Any) -> tuple[Any, tuple[float, float]] | None:
        """The joints' angular accelerations (rad/s^2) at the start of an interval from
        state ``x`` under input ``u``, with their bounds, or None when not bounded."""
        return None

    def configuration(self, x: Any) -> Any:
        """The configuration part ``q`` of a state."""
        return x[:5]

    def stopping_configuration(self, x: Any) -> Any | None:
        """Where the joints come to rest from state ``x`` when braked as hard as they may,
        or None when the model's joints stop at once (rates are inputs)."""
        return None

    def stopped_arm_motion(self, x: Any) -> tuple[Any, Any, Any] | None:
        """``(q, v, w)`` when the joints have come to rest from state ``x``, or None when
        the model's joints stop at once (rates are inputs) or have no braking bound."""
        return None

    def integrate(self, x: Any, u: Any, h: Any, substeps: int) -> Any:
        """The state after h (s) under u held: RK4 in ``substeps`` equal sub-steps."""
        for _ in range(substeps):
            x = sym.rk4_step(self.rhs, x, u, h / substeps)
        return x

    def base_motion(self, x: Any, u: Any) -> tuple[Any, Any, Any, Any] | None:
        """``(v, w, vdot, wdot)`` of the base at state x under input u (symbolic), None
        when the model has no base dynamics (then no dynamic tip-over margin)."""
        return None

    def joint_motion(self, x: Any, u: Any) -> tuple[Any, Any] | None:
        """Joint rates (rad/s) and accelerations (rad/s^2) at state x under u, or None
        when the model holds the rates constant over an interval (the commanded ones, with
        steps between intervals)."""
        return None

    def joint_rates(self, u: Any) -> Any:
        """The joint rates (rad/s) an input commands."""
        return u[2:4]


class KinematicPrediction(PredictionModel):
    """``qdot = G(q) u``: the velocity command integrates into the configuration."""

    name = "kinematic"
    nx = sym.NQ
    nu = sym.NU
    interface = "velocity"

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        r, lw, limit = robot.wheel_radius, robot.track_width, robot.wheel_speed_limit
        v_max, w_max = r * limit, 2.0 * r * limit / lw
        rate = robot.joint_speed_limit * (1.0 - 1e-6)
        self.u_lower = np.array([-v_max, -w_max, -rate, -rate])
        self.u_upper = -self.u_lower
        self.u_scale = np.array([1.0, 1.0, robot.joint_speed_limit, robot.joint_speed_limit])

    def rhs(self, x: Any, u: Any) -> Any:
        return sym.kinematic_rhs(x, u)

    def wheel_rows(self, x: Any, u: Any | None) -> Any | None:
        """Wheel speeds of the command ``u`` (none at the last node)."""
        return None if u is None else sym.wheel_speeds(self.robot, u[0], u[1])


class ThesisPrediction(PredictionModel):
    """The thesis plant: wheel forces drive a damped base, the arm follows joint rates."""

    name = "thesis"
    nx = sym.NX_FORCE
    nu = sym.NU_FORCE
    interface = "force"

    def __init__(self, robot: Robot, dynamics: sym.ThesisDynamics) -> None:
        super().__init__(robot)
        self.dynamics = dynamics
        force = dynamics.force_limit
        rate = min(dynamics.joint_speed, robot.joint_speed_limit) * (1.0 - 1e-6)
        self.u_lower = np.array([-force, -force, -rate, -rate])
        self.u_upper = -self.u_lower
        self.u_scale = np.array([force, force, rate, rate])

    def rhs(self, x: Any, u: Any) -> Any:
        return self.dynamics.rhs(x, u)

    def wheel_rows(self, x: Any, u: Any | None) -> Any | None:
        """Wheel speeds of the predicted base velocity (the forces do not enter)."""
        return sym.wheel_speeds(self.robot, x[5], x[6])

    def base_motion(self, x: Any, u: Any) -> tuple[Any, Any, Any, Any]:
        """Measured-state velocities and the accelerations the wheel forces give."""
        rate = self.rhs(x, u)
        return x[5], x[6], rate[5], rate[6]


class LaggedArmPrediction(ThesisPrediction):
    """The thesis base with joints that follow the commanded rates with a lag ``tau``,
    ``d(th_dot)/dt = (th_dot_cmd - th_dot) / tau``, as a physical arm does: with its
    reaction on the base's yaw (:meth:`ThesisDynamics.arm_yaw_reaction`)."""

    nx = sym.NX_FORCE + 2
    #: a joint moving towards its limit needs its braking distance to stop
    joints_stop_at_once = False

    def __init__(
        self,
        robot: Robot,
        dynamics: sym.ThesisDynamics,
        tau: float,
        acceleration_limit: tuple[float, float] | None = None,
    ) -> None:
        super().__init__(robot, dynamics)
        self.tau = tau
        self.acceleration_limit = acceleration_limit
        rate = min(dynamics.joint_speed, robot.joint_speed_limit)
        self.x_lower[7:9], self.x_upper[7:9] = -rate, rate

    def acceleration_rows(self, x: Any, u: Any) -> tuple[Any, tuple[float, float]] | None:
        """``(u_rates - rates) / tau``, the lag's largest acceleration over the interval
        (at its start: it decays from there), bounded by ``acceleration_limit``."""
        if self.acceleration_limit is None:
            return None
        return self.joint_motion(x, u)[1], self.acceleration_limit

    def stopping_configuration(self, x: Any) -> Any | None:
        """``q`` with each joint moved on by its braking distance ``rate |rate| / (2 a)``
        at the acceleration limit ``a``: the distance when the command leads the rate down
        at that deceleration throughout. It is optimistic for the controller's braking
        step (:func:`ddwmmr.mpc.braking.braking_input`), whose command is held over each
        control step, so that the lag decelerates at ``a`` only at the step's start (0.79 a
        on average for a 10 ms step and a 20 ms lag; the arm then travels up to 1.6 times
        as far, tested). The braking step's own distance was tried in the row and did worse
        on the scenarios (docs/mpc.md): the row is a heuristic for a plan's last node, not
        a guarantee. ``|rate|`` is smoothed by 1e-3 rad/s so the row stays differentiable
        at rest."""
        if self.acceleration_limit is None:
            return None
        rates = x[7:9]
        limits = ca.DM(self.acceleration_limit)
        distance = rates * ca.sqrt(rates**2 + 1e-6) / (2.0 * limits)
        return ca.vertcat(x[:3], x[3:5] + distance)

    def stopped_arm_motion(self, x: Any) -> tuple[Any, Any, Any] | None:
        """``(q, v, w)`` once the joints have braked to rest from state ``x``: ``q`` the
        stopping pose (:meth:`stopping_configuration`), ``v`` the base's speed now (m/s)
        and ``w`` the yaw rate (rad/s) the arm's angular momentum leaves the base with.
        Braking the arm moves its momentum ``H`` into the base (the total ``I(th2) w + H``
        about the base centre changes only by the wheels' torque and the damping,
        :meth:`ThesisDynamics.arm_yaw_reaction`), so ``w = (I(th2) w + H) / I(th2_stop)``:
        a shoulder swinging at 2 rad/s with the payload out turns the base at about
        1 rad/s once it stops, which the wheels' few N m take most of a second to shed.
        The wheels' torque and the damping while the arm brakes (about 0.15 s) are left
        out, and so is the change of v: the state the arm's braking leaves the base in
        (why: docs/mpc.md, "The last node with the arm braked to rest")."""
        stop = self.stopping_configuration(x)
        if stop is None:
            return None
        d = self.dynamics
        momentum = d.inertia(x[4]) * x[6] + d.arm_momentum(x[4], x[7:9])
        return stop, x[5], momentum / d.inertia(stop[4])

    def rhs(self, x: Any, u: Any) -> Any:
        rates, accelerations = self.joint_motion(x, u)
        base = self._base_rate(x[:7], u, rates, accelerations)
        return ca.vertcat(base, accelerations)

    def _base_rate(self, x7: Any, u: Any, rates: Any, accelerations: Any) -> Any:
        """Rate of ``[q, v, w]`` with the joints moving at ``rates``."""
        d = self.dynamics
        rate = d.rhs(x7, ca.vertcat(u[0], u[1], rates))
        reaction = d.arm_yaw_reaction(x7[4], x7[6], rates, accelerations)
        return ca.vertcat(rate[:6], rate[6] + reaction)

    def joint_motion(self, x: Any, u: Any) -> tuple[Any, Any]:
        return x[7:9], (u[2:4] - x[7:9]) / self.tau

    def integrate(self, x: Any, u: Any, h: Any, substeps: int) -> Any:
        """The state after h (s): the joints exactly (the lag is linear, and stiff for
        RK4 at the coarse intervals: tau = 0.02 s against sub-steps up to 0.2 s), the
        base by RK4 in ``substeps`` with the joints' exact path inside. The yaw is carried
        as the total angular momentum ``L = I(th2) w + H`` (wheels and damping change it
        smoothly; the arm's reaction, a short pulse when the joints' rates change, only
        moves momentum between the arm and the base)."""
        tau, start, command = self.tau, x[7:9], u[2:4]
        d = self.dynamics

        def arm(t: Any) -> tuple[Any, Any]:
            decay = ca.exp(-t / tau)
            angles = x[3:5] + command * t + (start - command) * tau * (1.0 - decay)
            return angles, command + (start - command) * decay

        def yaw_rate(angles: Any, rates: Any, momentum: Any) -> Any:
            return (momentum - d.arm_momentum(angles[1], rates)) / d.inertia(angles[1])

        def base_rate(t: Any, b: Any) -> Any:
            angles, rates = arm(t)
            w = yaw_rate(angles, rates, b[4])
            full = ca.vertcat(b[0], b[1], b[2], angles, b[3], w)
            rate = d.rhs(full, ca.vertcat(u[0], u[1], rates))
            torque = rate[6] * d.inertia(angles[1])  # (wheels - damping), N m
            return ca.vertcat(rate[0], rate[1], rate[2], rate[5], torque)

        momentum = d.inertia(x[4]) * x[6] + d.arm_momentum(x[4], start)
        b = ca.vertcat(x[0], x[1], x[2], x[5], momentum)
        step = h / substeps
        for i in range(substeps):
            t = i * step
            k1 = base_rate(t, b)
            k2 = base_rate(t + 0.5 * step, b + 0.5 * step * k1)
            k3 = base_rate(t + 0.5 * step, b + 0.5 * step * k2)
            k4 = base_rate(t + step, b + step * k3)
            b = b + step / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        angles, rates = arm(h)
        w = yaw_rate(angles, rates, b[4])
        return ca.vertcat(b[0], b[1], b[2], angles, b[3], w, rates)


def make_model(
    name: str,
    robot: Robot,
    dynamics: sym.ThesisDynamics | None,
    arm_time_constant: float | None = None,
    acceleration_limit: tuple[float, float] | None = None,
) -> PredictionModel:
    """The prediction model called ``name`` (validated by the controller); a
    ``arm_time_constant`` (s) makes the thesis model's joints lag, ``acceleration_limit``
    (rad/s^2, shoulder and elbow) bounds the lag's accelerations."""
    if name == "thesis":
        assert dynamics is not None
        if arm_time_constant is not None:
            return LaggedArmPrediction(robot, dynamics, arm_time_constant, acceleration_limit)
        return ThesisPrediction(robot, dynamics)
    return KinematicPrediction(robot)
