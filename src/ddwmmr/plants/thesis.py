"""The thesis plant: force-driven differential-drive base plus a rate-limited arm servo.

Base (thesis eqs 3.1-3.4; docs/thesis.md, "What is simulated"), along the base heading
(robot frame R) and about z::

    m xddot_R + c1 xdot_R = F,      F = F1 + F2                (N, m/s)
    I thddot  + c2 thdot  = T,      T = (F2 - F1) b            (N m, rad/s)

``F1``/``F2`` are the left/right wheel forces (N), each clipped to ``+-force_limit``; they
act at the wheels, ``b = track_width / 2`` either side of the base centre (the wheels'
lever; for the thesis robot ``track_width = base_width = 0.35`` m). ``m``
is the whole robot's mass (base + links + payload) and ``I`` its yaw inertia about the base
centre, which depends on the arm pose (links as uniform rods, payload as a point mass at
the end effector, thesis 3.4). The forces are held constant over a step (zero-order hold)
and the two linear first-order equations are integrated *exactly* over it, so the step
size only affects how often the controller acts, not the accuracy of the base motion.
The travelled distance is applied along the mean heading of the step (thesis eqs 3.5-3.7).

Arm: the thesis's pseudo-controller (4.4.2, eqs 4.10-4.11). Given joint targets, the joint
with the largest error moves at ``joint_speed`` (the robot's ``joint_speed_limit``, 2 rad/s
for the thesis robot) and every other joint at the
speed scaled by its error / the largest error, so all joints arrive together; a joint never
passes its target. Targets are clipped to the robot's ``joint_limits`` (the servo stops a
joint at its limit, as the kinematic plant does), and a start outside them is refused. The
plant knows nothing about controllers: it receives wheel forces and joint targets from a
simulation loop.

Constants: the arm servo's speed comes from the robot. The per-wheel force limit and the
damping c1, c2 are the thesis model's (:mod:`ddwmmr.model.thesis_base`: 10 N, 15 N s/m,
4 N m s/rad) for the thesis robot, and for any other robot derived from them in proportion
to its own motors' force, own mass and own yaw inertia (:func:`robot_constants`), unless
given; derived constants that differ from the thesis's get a one-line warning.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ddwmmr.commands import WheelForces
from ddwmmr.errors import (
    DURATION_RANGE_S,
    SPEED_RANGE_RAD_S,
    ParameterError,
    check_instance,
    check_positive,
    check_range,
)
from ddwmmr.gains import MAX_GAIN
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import check_configuration
from ddwmmr.model.robot import clamp_joints
from ddwmmr.model.thesis_base import (  # the base's constants (controllers' models use them)
    SCALES_WITH,
    THESIS_CONSTANTS,
    THESIS_FACTS,
    UNITS,
    drive_facts,
    robot_constants,
)
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
)
from ddwmmr.registry import register_plant
from ddwmmr.user_warnings import warn_user

#: Bandwidth (1/s) of the velocity servo that follows velocity commands.
VELOCITY_BANDWIDTH = 10.0
#: Allowed range ``(low, high, unit)`` of each constant :class:`ThesisPlant` takes (its
#: arguments, ``track --plant-option``), the same for every robot. The force limit and
#: the dampings hold what :func:`robot_constants` derives for every robot within
#: :class:`~ddwmmr.model.Robot`'s ranges (:mod:`ddwmmr.errors`: lengths 1e-6 to 1e3 m,
#: masses up to 1e5 kg, wheel torques 1e-6 to 1e6 N m): force limits of 4.9e-10 to
#: 4.9e11 N (the thesis's 10 of 20.5 N of motors giving 1e-9 to 1e12 N), c1 up to 3.75e5
#: N s/m (3e5 kg of base and links), c2 from 5e-9 (the least base inertia, 1e-9 kg m^2)
#: up to 1.3e12 N m s/rad (links of 1 km and 1e5 kg). A damping of 1e-20 leaves the thesis
#: robot's base undamped to 2e-11 over the longest run (1e9 s against ``m / c1`` = 1.3e21 s
#: and ``I / c2`` >= 5.9e19 s; 1e-16 tracks the ellipse as 1e-3 does,
#: tests/test_thesis_plant_damping.py): a smaller one is the same base. Within
#: these ranges every constant derived from them stays finite with room to square it, on
#: every robot: top speeds ``2 F / c1`` and ``2 F b / c2`` (at most 2e32 m/s and 1e35
#: rad/s), time constants ``m / c1`` and ``I / c2``, the servo's forces. The arm servo's
#: speed has the range of the robot's ``joint_speed_limit``; the velocity servo's
#: bandwidth ``k`` is a gain up to every controller's largest,
#: :data:`~ddwmmr.gains.MAX_GAIN` (as the servo's loop in
#: :func:`ddwmmr.sim.error_dynamics.velocity_loop`), from a time constant ``1 / k`` as long
#: as the longest duration.
CONSTANT_RANGES = {
    "force_limit": (1e-10, 1e12, "N"),
    "c1": (1e-20, 1e13, "N s/m"),
    "c2": (1e-20, 1e13, "N m s/rad"),
    "joint_speed": (*SPEED_RANGE_RAD_S, "rad/s"),
    "velocity_bandwidth": (1.0 / DURATION_RANGE_S[1], MAX_GAIN, "1/s"),
}


def check_constant(name: str, value: Any) -> float:
    """``value`` as a float if it is in the range of the plant's constant ``name`` (a key
    of :data:`CONSTANT_RANGES`), else a one-line :class:`ParameterError` naming it and
    the range."""
    return check_range(name, value, *CONSTANT_RANGES[name])


def warn_derived_constants(robot: Robot, derived: dict[str, float]) -> None:
    """Warn (a one-line :class:`UserWarning`, once per message under Python's default
    filter) when a constant in ``derived`` (name -> value, those :func:`robot_constants`
    chose because none was given) is not the thesis model's: no one measured it on
    ``robot``. The line names each such constant (a derived one equal to the thesis's is
    the thesis's own) with the thesis's value and what it scales with (``robot``'s and the
    thesis robot's), and how to set exactly those."""
    derived = {name: v for name, v in derived.items() if v != THESIS_CONSTANTS[name]}
    if not derived:
        return
    facts = drive_facts(robot)
    values = ", ".join(
        f"{name} = {value:.4g} {UNITS[name]} (the thesis's {THESIS_CONSTANTS[name]:g} "
        f"{UNITS[name]} scaled by {SCALES_WITH[name][0]}, {facts[name]:.4g} / "
        f"{THESIS_FACTS[name]:.4g} {SCALES_WITH[name][1]})"
        for name, value in derived.items()
    )
    keywords = ", ".join(f"{name}=..." for name in derived)
    options = " ".join(f"--plant-option {name}=..." for name in derived)
    them = "them" if len(derived) > 1 else "it"
    warn_user(
        f"thesis plant: {values} derived for this robot (ThesisPlant(robot, {keywords}) "
        f"sets {them}; track: {options})"
    )


@dataclass(slots=True)
class ThesisState:
    """Plant state: configuration ``q`` (world frame) and base velocities.

    Attributes:
        x, y: base centre (m, world); phi: heading (rad); th1, th2: joints (rad).
        v: forward speed along the heading (m/s); w: yaw rate (rad/s).
    """

    x: float = 0.0
    y: float = 0.0
    phi: float = 0.0
    th1: float = 0.0
    th2: float = 0.0
    v: float = 0.0
    w: float = 0.0

    @property
    def q(self) -> tuple[float, float, float, float, float]:
        """Configuration ``(x, y, phi, th1, th2)``."""
        return (self.x, self.y, self.phi, self.th1, self.th2)

    def copy(self) -> ThesisState:
        """An independent copy."""
        return ThesisState(self.x, self.y, self.phi, self.th1, self.th2, self.v, self.w)


#: Below this ``dt / tau`` :func:`first_order_step` takes the series (its docstring): at
#: the thesis's damping (m / c1 = 0.88 s for Robot(), 1 s with a 3 kg payload; I / c2 =
#: 0.15-0.52 s with the elbow) only a step below 1.5 us does.
SERIES_BELOW = 1e-5


def first_order_step(
    x0: float, u: float, gain: float, tau: float, dt: float
) -> tuple[float, float]:
    """Exact step of ``tau xdot + x = gain u`` with u held over dt.

    Returns ``(x(dt), integral of x over [0, dt])``; used for v (integral: distance) and w
    (integral: heading change). Where ``dt / tau`` is below :data:`SERIES_BELOW` (a
    damping c1 or c2 so small that ``tau = m / c`` is over 1e5 steps long), the
    closed form's ``1 - exp(-dt / tau)`` has lost its digits to rounding (its distance
    is off by ~1e-16 / (dt / tau)^2 of itself: a base driven off by hundreds of metres);
    its Taylor series takes over there, exact to rounding.
    """
    s = dt / tau
    if s < SERIES_BELOW:
        # x = x0 e^-s + (gain / tau) u dt phi1(s), integral = x0 dt phi1(s) + (gain / tau)
        # u dt^2 phi2(s), phi1 = (1 - e^-s) / s, phi2 = (s - 1 + e^-s) / s^2; the terms
        # dropped are below s^4 / 24 < 1e-21 of them
        phi1 = 1.0 - s / 2.0 + s * s / 6.0 - s**3 / 24.0
        phi2 = 0.5 - s / 6.0 + s * s / 24.0 - s**3 / 120.0
        push = gain / tau * u * dt  # what u adds to x over dt without the decay
        return x0 * math.exp(-s) + push * phi1, (x0 * phi1 + push * phi2) * dt
    x_ss = gain * u
    decay = math.exp(-s)
    return x_ss + (x0 - x_ss) * decay, x_ss * dt + (x0 - x_ss) * tau * (1.0 - decay)


def arm_step(
    th1: float, th2: float, target1: float, target2: float, speed: float, dt: float
) -> tuple[float, float]:
    """Joint angles after dt under the pseudo-controller of thesis eq. 4.10 (rad).

    Each joint moves by ``error_i * min(1, speed dt / max|error|)``: the largest error moves
    at ``speed`` and the joints stay synchronised; the target is never overshot.
    """
    e1, e2 = target1 - th1, target2 - th2
    largest = max(abs(e1), abs(e2))
    if largest == 0.0:
        return th1, th2
    fraction = min(1.0, speed * dt / largest)
    return th1 + e1 * fraction, th2 + e2 * fraction


def damped_base_envelope(
    force_limit: float,
    c1: float,
    c2: float,
    mass: float,
    half_width: float,
    stretched_inertia: float,
    fraction: float = 0.8,
    speed_budget: bool = False,
) -> dict[str, Any]:
    """What a velocity command can ask of a damped, force-limited base, as ``fraction`` of
    the physics.

    Top speeds where the full force balances damping (``2 F / c1`` m/s, ``2 F b / c2``
    rad/s) and accelerations from rest with the largest yaw inertia (arm stretched):
    ``2 F / m`` (m/s^2), ``2 F b / I`` (rad/s^2). ``force_limit`` F is per wheel (N),
    ``half_width`` b the wheels' lever about the base centre (m, ``track_width / 2``).
    Keys match the ``qp`` controller's options.

    ``speed_budget`` adds ``"speed_budget": (2 F / c1, 2 F b / c2)``, the full
    top speeds (no fraction): in steady state each wheel's force stays within F exactly
    when ``|v| / v_top + |w| / w_top <= 1`` (:class:`~ddwmmr.qp.limits.SpeedBudgetLimit`).
    """
    total = 2.0 * force_limit
    torque = total * half_width
    envelope: dict[str, Any] = {
        "max_base_speed": fraction * total / c1,
        "max_yaw_rate": fraction * torque / c2,
        "max_acceleration": fraction * total / mass,
        "max_yaw_acceleration": fraction * torque / stretched_inertia,
    }
    if speed_budget:
        envelope["speed_budget"] = (total / c1, torque / c2)
    return envelope


@register_plant("thesis", interfaces=("force", "velocity"))
class ThesisPlant:
    """Force-driven base dynamics with the arm pseudo-controller (thesis ch. 3 and 4.4.2).

    Args:
        robot: geometry and masses (``Robot().with_payload(3.0)`` in the benchmark).
        c1, c2, force_limit: translational damping (N s/m), rotational damping
            (N m s/rad) and per-wheel force limit (N); each None: the robot's own,
            :func:`robot_constants` (the thesis's 15, 4 and 10 for the thesis robot), with
            a one-line warning (:func:`warn_derived_constants`) where that is not the
            thesis's.
        joint_speed: maximum joint speed of the arm servo (rad/s); None: the robot's
            ``joint_speed_limit``.
        velocity_bandwidth: bandwidth of the velocity servo for velocity commands (1/s).

    A constant given outside its range (:data:`CONSTANT_RANGES`: c1 and c2 in [1e-20,
    1e13], force_limit in [1e-10, 1e12] N, joint_speed in [1e-6, 1e6] rad/s,
    velocity_bandwidth in [1e-9, 1e4] 1/s) is a one-line :class:`ParameterError` naming it
    and the range.

    Extra time-series columns: the wheel forces applied over the step that starts at the
    sample (N), ``force_left_n`` and ``force_right_n``.
    """

    #: Set by the register_plant decorator (declared here for the type checker).
    interfaces: tuple[str, ...]
    extra_columns = ("force_left_n", "force_right_n")

    def __init__(
        self,
        robot: Robot,
        c1: float | None = None,
        c2: float | None = None,
        force_limit: float | None = None,
        joint_speed: float | None = None,
        velocity_bandwidth: float = VELOCITY_BANDWIDTH,
    ) -> None:
        self.robot = check_instance("robot", robot, Robot)
        # Any: the arguments as given, which check_constant checks
        given: dict[str, Any] = {"force_limit": force_limit, "c1": c1, "c2": c2}
        derived = {
            name: value for name, value in robot_constants(robot).items() if given[name] is None
        }
        self.force_limit, self.c1, self.c2 = (
            check_positive(name, derived[name])
            if name in derived
            else check_constant(name, given[name])
            for name in THESIS_CONSTANTS
        )
        if derived:
            warn_derived_constants(robot, derived)
        if joint_speed is None:
            joint_speed = robot.joint_speed_limit
        self.joint_speed = check_constant("joint_speed", joint_speed)
        self.mass = robot.total_mass
        self._yaw_inertia = robot.yaw_inertia.at
        self._half_width = 0.5 * robot.track_width  # the wheels' lever b
        self._joint_limits = robot.joint_limits
        self.servo = VelocityServo(self, velocity_bandwidth)
        self._state = ThesisState()
        self._forces = (0.0, 0.0)
        self._started = False  # reset() gave a start state: step() may run

    @property
    def state(self) -> ThesisState:
        """The plant's state (configuration and base velocities), the object :meth:`step`
        advances in place; before the first :meth:`reset`, as :meth:`observe`, a
        :class:`PlantNotResetError` (the plant has no start state yet). Setting it (a
        :class:`ThesisState`, after a reset) moves the plant there."""
        if not self._started:
            raise PlantNotResetError("thesis", "state")
        return self._state

    @state.setter
    def state(self, value: ThesisState) -> None:
        if not self._started:
            raise PlantNotResetError("thesis", "state")
        self._state = check_instance("state", value, ThesisState)

    # -- Plant interface ------------------------------------------------------------------
    def reset(self, q0: np.ndarray, dt: float) -> None:
        """Start at rest at configuration ``q0`` (5 finite numbers ``[x, y, phi, th1,
        th2]``, m and rad, the joints within the robot's ``joint_limits``); the dynamics
        are exact for any control step dt > 0 (s, finite). Anything else is a one-line
        :class:`ParameterError` naming ``q0`` or ``dt`` (nothing changes then)."""
        state = check_configuration(q0)
        check_control_step(dt)
        outside = self.robot.joints_outside(state)
        if outside is not None:
            raise ParameterError(f"q0: {outside}")
        self._state = ThesisState(*state)
        self._forces = (0.0, 0.0)
        self._started = True

    def observe(self) -> Observation:
        """Configuration and base velocities, exactly; before the first :meth:`reset` a
        :class:`PlantNotResetError`."""
        if not self._started:
            raise PlantNotResetError("thesis", "observe")
        s = self._state
        return Observation(s.q, s.v, s.w)

    def limit(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:
        """The velocity command ``u = [v, w, th1dot, th2dot]`` as the plant applies it at
        configuration ``q``, and whether a limit clipped it: joint rates within the
        joint-speed limit, and 0 for a joint at a limit of ``joint_limits`` moving outward
        (as the kinematic plant reports it); (v, w) pass (the wheel forces saturate).
        A ``q`` that is not 5 finite numbers or a ``u`` that is not 4 (a NaN rate, which
        clipping would turn into the limit) is a :class:`ParameterError` naming it, as for
        the kinematic plant (:func:`check_limit`)."""
        th1, th2, (v, w, r1, r2) = check_limit(q, u)
        c1, c2 = self.joint_rates(th1, th2, r1, r2)
        if c1 == r1 and c2 == r2 and isinstance(u, np.ndarray):
            return u, False  # within the limits: the command as it is
        return np.array([v, w, c1, c2]), True

    def step(self, t: float, command: Any, dt: float, policy: Policy | None = None) -> None:
        """Advance by dt (s) from time t (s) under wheel forces (a
        :class:`~ddwmmr.commands.WheelForces`, N and rad) or a velocity command ``u = [v, w,
        th1dot, th2dot]`` (m/s, rad/s), held over the step; the arm's targets (the given
        ones, or ``th + rate dt`` with the rates of :meth:`joint_rates`) are clipped to the
        joint limits. Non-finite or misshapen arguments are a :class:`ParameterError`
        (:func:`check_step`), and so is a ``policy`` that is neither None nor callable
        (:func:`check_policy`; this plant holds the command and does not call it); before
        the first :meth:`reset` it is a :class:`PlantNotResetError`."""
        if not self._started:
            raise PlantNotResetError("thesis")
        checked = check_step(t, command, dt, self.interfaces)
        check_policy(policy)
        state = self._state
        inertia = self.inertia(state.th1, state.th2)  # once for the servo and the dynamics
        if isinstance(checked, WheelForces):
            f_left, f_right = checked.left, checked.right
            target = self.clip_targets(checked.th1_target, checked.th2_target)
        else:
            v, w, r1, r2 = checked
            f_left, f_right = self.servo.forces(state, v, w, inertia)
            r1, r2 = self.joint_rates(state.th1, state.th2, r1, r2)
            target = self.clip_targets(state.th1 + r1 * dt, state.th2 + r2 * dt)
        self._forces = self.advance(state, f_left, f_right, target, dt, inertia)
        # One sum tests all seven values: any inf or nan makes it non-finite.
        if not math.isfinite(
            state.x + state.y + state.phi + state.th1 + state.th2 + state.v + state.w
        ):
            raise PlantDivergedError(f"thesis plant: non-finite state at t = {t + dt:g} s")

    def extra_values(self) -> Sequence[float]:
        """Wheel forces (N) of the last step (0 after :meth:`reset`; before the first, a
        :class:`PlantNotResetError`)."""
        if not self._started:
            raise PlantNotResetError("thesis", "extra_values")
        return self._forces

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        """Peak wheel force (N) and the time (s) with a wheel at its force limit."""
        left = np.abs(timeseries.get("force_left_n", np.zeros(1)))
        right = np.abs(timeseries.get("force_right_n", np.zeros(1)))
        t = np.asarray(timeseries.get("t", np.zeros(1)))
        interval = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
        at_limit = np.maximum(left, right) >= self.force_limit * (1.0 - 1e-9)
        return {
            "max_wheel_force_n": float(max(np.max(left), np.max(right))),
            "actuator_saturated_time_s": float(np.sum(at_limit) * interval),
        }

    # -- the model --------------------------------------------------------------------------
    def inertia(self, th1: float, th2: float) -> float:
        """Yaw inertia of the whole robot about the base centre at arm pose (th1, th2) (kg m^2).

        Links are uniform rods (parallel-axis term at their midpoints), the payload a point
        mass at the end effector; the arm lies horizontally (docs/theory.md, "Tip-over
        stability"). The formula is :class:`ddwmmr.model.mass.YawInertia`'s.
        """
        return self._yaw_inertia(th2)

    @property
    def damping(self) -> tuple[float, float]:
        """The base's viscous damping ``(c1 N s/m, c2 N m s/rad)``."""
        return self.c1, self.c2

    @property
    def wheel_force_limit(self) -> float:
        """Largest traction force of each wheel (N): ``force_limit``."""
        return self.force_limit

    @property
    def wheel_lever(self) -> float:
        """Lever arm of each wheel's force about the base centre (m): ``track_width / 2``."""
        return self._half_width

    def velocity_envelope(self, fraction: float = 0.8) -> dict[str, Any]:
        """What a velocity command can ask of this base: :func:`damped_base_envelope`.

        Without the speed budget: this plant's velocity servo mixes with rotation
        priority, so a command at a corner of the speed box still turns (it gives up
        speed), and the budget would only slow the ``qp`` down (docs/thesis.md)."""
        return damped_base_envelope(
            self.force_limit,
            self.c1,
            self.c2,
            self.mass,
            self._half_width,
            self.inertia(0.0, 0.0),
            fraction,
        )

    def joint_rates(self, th1: float, th2: float, r1: float, r2: float) -> tuple[float, float]:
        """Joint rates (rad/s) the arm applies at joint angles (th1, th2) (rad) for the
        commanded rates (r1, r2): each within ``+-joint_speed_limit``, and 0 for a joint at
        (or beyond) a limit of ``joint_limits`` that would move further out."""
        return arm_rates(th1, th2, r1, r2, self.robot.joint_speed_limit, self._joint_limits)

    def clip_targets(self, target1: float, target2: float) -> tuple[float, float]:
        """Joint targets (rad) clipped to the robot's ``joint_limits``: the servo stops a
        joint at its limit (:func:`~ddwmmr.model.robot.clamp_joints`)."""
        return clamp_joints(target1, target2, self._joint_limits)

    def clip_force(self, force: float) -> float:
        """A wheel force limited to ``+-force_limit`` (N)."""
        return min(self.force_limit, max(-self.force_limit, force))

    def advance(
        self,
        state: ThesisState,
        f_left: float,
        f_right: float,
        arm_target: tuple[float, float],
        dt: float,
        inertia: float | None = None,
    ) -> tuple[float, float]:
        """Advance ``state`` in place by dt (s) under wheel forces (N) and joint targets (rad).

        The model without the joint limits (:class:`~ddwmmr.model.symbolic.ThesisDynamics`'s
        equations; :meth:`step` clips the targets to them first). The inertia is evaluated
        at the arm pose at the start of the step (``inertia``, if given, is that value:
        :meth:`inertia` at ``state``'s arm pose). Returns the wheel forces applied, after
        the force limit (N).
        """
        f1 = self.clip_force(f_left)
        f2 = self.clip_force(f_right)
        if inertia is None:
            inertia = self.inertia(state.th1, state.th2)
        v, distance = first_order_step(state.v, f1 + f2, 1.0 / self.c1, self.mass / self.c1, dt)
        torque = (f2 - f1) * self._half_width
        w, turn = first_order_step(state.w, torque, 1.0 / self.c2, inertia / self.c2, dt)
        heading = state.phi + 0.5 * turn  # mean heading over the step (thesis eq. 3.5)
        state.x += distance * math.cos(heading)
        state.y += distance * math.sin(heading)
        state.phi += turn
        state.v, state.w = v, w
        state.th1, state.th2 = arm_step(
            state.th1, state.th2, arm_target[0], arm_target[1], self.joint_speed, dt
        )
        return f1, f2


class VelocityServo:
    """Wheel forces (N) tracking a commanded (v, w) on the thesis plant.

    ``F = c1 v_d + k m (v_d - v)`` and ``T = c2 w_d + k I (w_d - w)`` (the damping
    feed-forward makes steady-state tracking exact; ``k`` is the loop bandwidth in 1/s),
    ``F_r = T / b`` (``b = track_width / 2``, the wheels' lever), mixed into wheel forces
    with rotation priority.
    """

    def __init__(self, plant: ThesisPlant, bandwidth: float = VELOCITY_BANDWIDTH) -> None:
        self.plant = plant
        self.bandwidth = check_constant("velocity_bandwidth", bandwidth)
        self._half_width = plant.wheel_lever
        self._total = 2.0 * plant.force_limit

    def forces(
        self, state: ThesisState, v_d: float, w_d: float, inertia: float | None = None
    ) -> tuple[float, float]:
        """Left/right wheel forces (N) for the desired speed (m/s) and yaw rate (rad/s);
        ``inertia``, if given, is the plant's yaw inertia at ``state`` (kg m^2)."""
        p = self.plant
        k = self.bandwidth
        if inertia is None:
            inertia = p.inertia(state.th1, state.th2)
        f_t = p.c1 * v_d + k * p.mass * (v_d - state.v)
        torque = p.c2 * w_d + k * inertia * (w_d - state.w)
        f_r = min(self._total, max(-self._total, torque / self._half_width))
        room = self._total - abs(f_r)
        f_t = min(room, max(-room, f_t))
        return 0.5 * f_t - 0.5 * f_r, 0.5 * f_t + 0.5 * f_r
