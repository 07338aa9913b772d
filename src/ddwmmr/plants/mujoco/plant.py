"""The physics plant: the robot as a MuJoCo rigid-body model (:class:`MujocoPlant`).

Implements the :class:`~ddwmmr.plants.base.Plant` interface. Commands:

* **velocity** ``u = (v, w, th1dot, th2dot)``: limited like the kinematic plant (wheel
  speed, joint rate and joint position limits), then turned into wheel speed targets
  (docs/theory.md, "Wheels") and joint rate targets for the velocity servos of the model. The
  servos' torques are clipped at the robot's motor limits, the wheels grip the floor
  through friction: the base may lag, slip or saturate, and the controller sees it.
* **force** :class:`~ddwmmr.commands.WheelForces`: each wheel force F (N) is applied as
  the wheel torque ``F r`` (clipped at ``wheel_torque_limit``); the arm targets go through
  the thesis's synchronised position servo (thesis eq. 4.10, the
  :func:`~ddwmmr.plants.thesis.arm_step` law at ``joint_speed_limit``), whose joint rates
  drive the same joint velocity servos.

The engine advances at its own ``timestep``; the control step must be a whole multiple
of it. :meth:`observe` reports what the engine's state says: ``q = (x, y, phi, th1, th2)``
of the axle midpoint, its heading (continuous, not wrapped), the joint angles, and the
measured forward speed and yaw rate. Every step the floor's normal force on each support
is read (:mod:`ddwmmr.plants.mujoco.support`). Runs are deterministic.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

# mujoco ships no type hints (no py.typed): its objects are Any to mypy
import mujoco
import numpy as np

from ddwmmr.commands import VELOCITY, WheelForces
from ddwmmr.errors import ParameterError, check_range, float_values, shown
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import check_configuration, wrap_angle
from ddwmmr.plants.base import (
    Observation,
    PlantDivergedError,
    PlantNotResetError,
    Policy,
    check_step,
)
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.plants.mujoco.model import (
    ACTUATORS,
    BASE_CLEARANCE,
    DEFAULT_TIMESTEP,
    MAX_ENGINE_STEPS_PER_CONTROL_STEP,
    TIMESTEP_RANGE_S,
    TYRE_DAMPING_RATIO,
    EngineOptions,
    build_model,
    reflected_inertias,
    supports,
    tyre_stiffness,
)
from ddwmmr.plants.mujoco.support import SupportGeometry, centre_of_pressure
from ddwmmr.plants.thesis import arm_step, damped_base_envelope
from ddwmmr.registry import register_plant

if TYPE_CHECKING:
    import numpy.typing as npt

#: Time (s) the robot settles on its supports in :meth:`MujocoPlant.reset` before t = 0,
#: so that the first recorded contact forces carry the robot's weight (on its tyres: after
#: 0.2 s the floor still carried 0.1 % more than the weight as the base bounced on them,
#: after 0.5 s 1e-5).
SETTLE_TIME_S = 0.5
#: Share of a motor's torque limit counted as saturated (``torque_use``).
TORQUE_SATURATED = 0.999
#: Time constant (s) of the damping that holds the base still while it settles.
SETTLE_DAMPING_TIME_S = 0.01
#: An edge of the support polygon is unloaded when the supports off it carry less than
#: this fraction of the robot's weight.
UNLOADED_FRACTION = 1e-4
#: ``tipped``: the base pivots about an unloaded edge, tilting further, this long (s) ...
LIFT_TIME_S = 0.1
#: ... and by at least this much (rad) since it began (a flat, noisy tilt is not pivoting;
#: a base tipping at S = 0.98 gains 9e-4 rad in its first 0.1 s) ...
PIVOT_GROWTH_RAD = 1e-4
#: ... without slowing down: the tilt rate over the last sample is at least the mean rate
#: since the pivot began, less this share (rounding). Gravity pulls a base pivoting with
#: its centre of mass inside the edge back, so its tilt decelerates and it rocks back onto
#: its supports; one with the centre of mass beyond the edge, or pushed on harder than
#: gravity pulls back, keeps accelerating (docs/physics.md, "Tip-over from the contact
#: forces") ...
PIVOT_RATE_TOLERANCE = 1e-6
#: ... or the base tilted beyond this angle (rad; 5.7 deg, far beyond the contacts' own
#: compliance: a base at rest leans at most ~6e-4 rad into its contacts).
TIP_TILT_RAD = 0.1
_LOG = logging.getLogger(__name__)


def _log_engine_warning(message: str) -> None:
    # The plant reads MuJoCo's warning counters itself and raises with its own message; by
    # default MuJoCo would also print the warning and append it to MUJOCO_LOG.TXT in the
    # working directory, a file nobody asked for. Info, not warning: Python's last-resort
    # handler would print a warning beside the tools' one-line error.
    _LOG.info("MuJoCo: %s", message)


if mujoco.get_mju_user_warning() is None:  # leave a handler someone else installed
    mujoco.set_mju_user_warning(_log_engine_warning)

_WARNINGS = (
    mujoco.mjtWarning.mjWARN_BADQACC,
    mujoco.mjtWarning.mjWARN_BADQPOS,
    mujoco.mjtWarning.mjWARN_BADQVEL,
    mujoco.mjtWarning.mjWARN_BADCTRL,
)
#: A speed beyond this many times both the fastest the robot's motors drive that degree
#: of freedom and the fastest gravity moves it in a fall is a blown-up state
#: (:meth:`MujocoPlant._speed_bounds`): a robot within its limits stays near 1 times the
#: motors' (the default robot's tracking runs below 1.05) and a robot falling over within
#: 1 times the fall's on its base and a few times on the joints, which whip as it lands,
#: while a state blowing up passes both within a step or two, long before it turns
#: non-finite or the engine flags it (docs/physics.md, "The plant").
SPEED_BOUND_FACTOR = 10.0
#: What to do about a diverged state, for messages: a smaller engine step (the plant's
#: option: the API's, track's --plant-option), or heavier parts.
_SMALLER_STEP = (
    f"the engine step is too long for this robot's masses or stiffnesses, or a command "
    f"drove it beyond its limits; give it heavier parts, or a smaller timestep: "
    f"MujocoPlant(robot, timestep=...) or simulate(..., plant_options={{'timestep': ...}}) "
    f"in [{TIMESTEP_RANGE_S[0]:g}, {TIMESTEP_RANGE_S[1]:g}] s (track: --plant-option "
    f"timestep=...; the other tools run at the default {DEFAULT_TIMESTEP:g} s)"
)


@register_plant("mujoco", interfaces=("velocity", "force"))
class MujocoPlant:
    """The robot simulated by MuJoCo (rigid bodies, contacts, friction, motor limits).

    Args:
        robot: the robot; its MJCF model is generated from it (:mod:`.model`).
        timestep: engine step (s), default 0.002, in [1e-5, 0.01]
            (:data:`~ddwmmr.plants.mujoco.model.TIMESTEP_RANGE_S`; docs/physics.md,
            "Settings"); a control step is a whole multiple of it, at most 10,000 of them.
        friction: wheel-floor sliding friction coefficient, in [0.01, 5].
        servo_time_constant: response time of the velocity servos (s), in [1e-3, 1].
        cone: MuJoCo friction cone, ``"elliptic"`` (default, Coulomb's) or ``"pyramidal"``.
        contact_time_constant: stiffness of the contacts as a time constant (s), in
            [2e-5, 0.05] and at least 2 timesteps.
        tyre_stiffness: radial stiffness of each drive wheel's tyre (N/m, in [1e4, 1e8],
            or 0 for rigid wheels); default: 5e4 on the default robot, scaled to others
            (:func:`~ddwmmr.plants.mujoco.model.tyre_stiffness`).
        base_damping: ``(c_translation N s/m, c_yaw N m s/rad)`` viscous damping of the
            base's horizontal and yaw motion (the thesis plant's c1, c2: rolling resistance
            and drive friction as the thesis models them), each in [0, 1000]
            (:data:`BASE_DAMPING_MAX`); None (default): none, the engine's own friction
            only. Force-level controllers tuned on the thesis plant (its PD gains assume
            that damping) need it.

    The ranges are physical (:class:`~ddwmmr.plants.mujoco.model.EngineOptions`;
    docs/physics.md, "Settings").

    Raises:
        ParameterError: for a robot or option MuJoCo cannot build (one line).
    """

    #: Set by the register_plant decorator (declared here for the type checker).
    interfaces: tuple[str, ...]

    def __init__(
        self,
        robot: Robot,
        *,
        timestep: float | None = None,
        friction: float | None = None,
        servo_time_constant: float | None = None,
        cone: str | None = None,
        contact_time_constant: float | None = None,
        base_damping: tuple[float, float] | None = None,
        tyre_stiffness: float | None = None,
    ) -> None:
        self.base_damping = _check_damping(base_damping)
        # Any: the options as given, which EngineOptions checks
        given: dict[str, Any] = {
            "timestep": timestep,
            "friction": friction,
            "servo_time_constant": servo_time_constant,
            "cone": cone,
            "contact_time_constant": contact_time_constant,
            "tyre_stiffness": tyre_stiffness,
        }
        self.options = EngineOptions(**{k: v for k, v in given.items() if v is not None})
        self.robot = robot
        self.model = build_model(robot, self.options)
        self.data = mujoco.MjData(self.model)
        self.supports = supports(robot)
        self.geometry = SupportGeometry([s.point for s in self.supports])
        self.extra_columns = (
            "min_support_force_n",
            *(f"support_force_{s.name}_n" for s in self.supports),
            "min_edge_load_n",
            "physics_stability",
            "base_tilt_rad",
            "wheel_slip_m_s",
            "torque_use",
            "wheel_torque_use",
        )
        self.weight_n = float(np.sum(self.model.body_mass)) * -float(self.model.opt.gravity[2])
        self._limits = KinematicPlant(robot, "euler")
        self._ids = self._lookup_ids()
        self._geom_support = self._ids["geom_support"].tolist()
        self._kv = self.model.actuator_gainprm[:, 0].copy()
        self._wheel_mode = VELOCITY
        self._force_buffer = np.zeros(6)
        self._velocity_buffer = np.zeros(6)
        self._dt: float | None = None
        self._substeps = 0
        self._step_count = 0
        self._warnings = 0
        self._bad_controls = 0  # the engine's count of rejected controls, as last seen
        self._motor_bounds, self._fall_bounds, self._bound_names = self._speed_bounds()
        self._bounds = np.maximum(self._motor_bounds, self._fall_bounds)
        self._phi = 0.0
        self._cache: tuple[float, ...] | None = None
        self._contacts: tuple[list[int], list[float]] | None = None  # of the current state
        self._tip = TipDetector(self.weight_n, 0.0)
        self._unloaded_time = 0.0  # s: control steps that ended with an edge unloaded
        mass = float(np.sum(self.model.body_mass))
        inertia = mass * (robot.base_length**2 + robot.base_width**2) / 12.0 + robot.base_inertia
        # damping (N s/m, N m s/rad) for a SETTLE_DAMPING_TIME_S time constant of the base
        self._settle_damping = np.array([mass] * 3 + [inertia] * 3) / SETTLE_DAMPING_TIME_S

    # -- set-up -------------------------------------------------------------------------
    def _lookup_ids(self) -> dict[str, Any]:
        model = self.model

        def find(kind: mujoco.mjtObj, name: str) -> int:
            index: int = mujoco.mj_name2id(model, kind, name)
            return index

        geom_support = np.full(model.ngeom, -1, dtype=int)
        for i, support in enumerate(self.supports):
            geom_support[find(mujoco.mjtObj.mjOBJ_GEOM, support.name)] = i
        return {
            "base": find(mujoco.mjtObj.mjOBJ_BODY, "base"),
            "wheels": [find(mujoco.mjtObj.mjOBJ_BODY, n) for n in ("wheel_left", "wheel_right")],
            "geom_support": geom_support,
            "shoulder_qpos": model.jnt_qposadr[find(mujoco.mjtObj.mjOBJ_JOINT, "shoulder")],
            "elbow_qpos": model.jnt_qposadr[find(mujoco.mjtObj.mjOBJ_JOINT, "elbow")],
            "wheel_actuators": [ACTUATORS.index("wheel_left"), ACTUATORS.index("wheel_right")],
            "tyre_dofs": [
                int(model.jnt_dofadr[j])
                for j in (find(mujoco.mjtObj.mjOBJ_JOINT, n) for n in ("tyre_left", "tyre_right"))
                if j >= 0
            ],
        }

    @property
    def damping(self) -> tuple[float, float]:
        """The base's viscous damping ``(c1 N s/m, c2 N m s/rad)``: ``base_damping``, or
        ``(0, 0)`` without it (what a force-level model of this base should assume)."""
        return self.base_damping if self.base_damping is not None else (0.0, 0.0)

    @property
    def wheel_force_limit(self) -> float:
        """Largest traction force of each wheel (N): the motor's torque limit over the wheel
        radius, the robot's ``motor_force_limit`` (a force command beyond it is clipped)."""
        return self.robot.motor_force_limit

    @property
    def wheel_lever(self) -> float:
        """Lever arm of each wheel's force about the base centre (m): ``track_width / 2``."""
        return 0.5 * self.robot.track_width

    def velocity_envelope(self, fraction: float = 0.8) -> dict[str, Any] | None:
        """With ``base_damping``: what a velocity command can ask of the damped base
        (:func:`~ddwmmr.plants.thesis.damped_base_envelope` with the wheel force the motor
        torque limit allows, ``wheel_torque_limit / wheel_radius``), with the speed budget
        (the wheel servos saturate one by one: at a corner of the speed box the base
        would lose its yaw and drive in loops); None without damping, or with a zero
        damping on either axis (no drag there: no top speed to keep within; the wheel-speed
        and torque limits are the whole story)."""
        if self.base_damping is None or min(self.base_damping) == 0.0:
            return None
        robot = self.robot
        return damped_base_envelope(
            self.wheel_force_limit,
            self.base_damping[0],
            self.base_damping[1],
            float(np.sum(self.model.body_mass)),
            self.wheel_lever,
            robot.yaw_inertia.at(0.0),
            fraction,
            speed_budget=True,
        )

    @property
    def timestep(self) -> float:
        """Engine step (s): control steps must be whole multiples of it."""
        return self.options.timestep

    def control_step_choices(self, count: int = 3) -> str:
        """The first ``count`` allowed control steps (s), for messages."""
        h = self.options.timestep
        return ", ".join(f"{k * h:g}" for k in range(1, count + 1))

    def check_control_step(self, dt: float) -> int:
        """The engine steps in a control step of ``dt`` (s), which must be a whole multiple
        of the timestep, at most :data:`MAX_ENGINE_STEPS_PER_CONTROL_STEP` of them; else a
        one-line :class:`ParameterError` (what :meth:`reset` and :meth:`step` refuse, so a
        tool can refuse it before a run starts)."""
        h = self.options.timestep
        most = MAX_ENGINE_STEPS_PER_CONTROL_STEP
        try:
            if isinstance(dt, bool | str | bytes):
                raise TypeError  # not a number, even where float() reads it
            ratio = float(dt) / h
        except (TypeError, ValueError, OverflowError):  # OverflowError: an int like 10**400
            ratio = math.nan  # not a number: refused below, naming the allowed steps
        substeps = round(ratio) if math.isfinite(ratio) else 0
        if not 1 <= substeps <= most or abs(substeps * h - dt) > 1e-9 * max(1.0, abs(dt)):
            raise ParameterError(
                f"dt must be a whole multiple of the MuJoCo timestep {h:g} s in "
                f"[{h:g}, {most * h:g}] s ({self.control_step_choices()}, ...) "
                f"(got {shown(dt)})"
            )
        return substeps

    def reset(self, q0: np.ndarray, dt: float) -> None:
        """Place the robot at rest at ``q0`` on the floor for control step ``dt`` (s).

        The robot first settles on its supports for :data:`SETTLE_TIME_S` with the servos
        holding still; then x, y, heading and joints are put back exactly to ``q0``.
        Raises :class:`ParameterError` if dt is not a whole multiple of the engine timestep
        (at most :data:`~ddwmmr.plants.mujoco.model.MAX_ENGINE_STEPS_PER_CONTROL_STEP` of
        them) or q0 is not 5 finite numbers (m, rad) with the joints inside their limits
        (nothing changes then), and if the robot does not settle: its masses too light for
        the engine's timestep.
        """
        substeps = self.check_control_step(dt)
        q0 = np.array(check_configuration(q0))
        outside = self.robot.joints_outside(q0)
        if outside is not None:
            raise ParameterError(f"q0: {outside}")
        self._substeps, self._dt = substeps, float(dt)
        model, data = self.model, self.data
        mujoco.mj_resetData(model, data)
        self._set_wheel_mode(VELOCITY)
        self._place(q0, z=0.0)  # the base frame sits on the floor (model.py)
        mujoco.mj_forward(model, data)
        data.ctrl[:] = 0.0
        # Settle with the base's six degrees of freedom heavily damped, so that it sinks
        # into its contacts without bouncing or rocking (a pose close to S = 1 would
        # otherwise rock onto its edge and back).
        self._warnings = self._warning_count()
        self._bad_controls = int(data.warning[mujoco.mjtWarning.mjWARN_BADCTRL].number)
        model.dof_damping[0:6] = self._settle_damping
        tyres = self._ids["tyre_dofs"]
        running = model.dof_damping[tyres].copy()
        model.dof_damping[tyres] = running / TYRE_DAMPING_RATIO  # critically damped meanwhile
        mujoco.mj_step(model, data, max(1, round(SETTLE_TIME_S / model.opt.timestep)))
        model.dof_damping[tyres] = running
        model.dof_damping[0:6] = 0.0
        if self.base_damping is not None:
            # free joint: dofs 0-2 translate in the world frame, 3-5 rotate in the body's
            # (z is the yaw axis while the base stands); roll and pitch stay undamped.
            model.dof_damping[0] = model.dof_damping[1] = self.base_damping[0]
            model.dof_damping[5] = self.base_damping[1]
        try:
            self._check_state("while the robot settled at reset")
        except PlantDivergedError:
            raise ParameterError(self._unsettled()) from None
        self._step_count = 0
        self._place(q0, z=float(data.qpos[2]), keep_tilt=True)
        data.qvel[:] = 0.0
        data.time = 0.0
        mujoco.mj_forward(model, data)
        self._phi = float(q0[2])
        self._cache = self._contacts = None
        self._tip = TipDetector(self.weight_n, self._dt)
        self._unloaded_time = 0.0
        self._judge_tipping(0.0, 0.0)

    def _place(self, q: np.ndarray, z: float, keep_tilt: bool = False) -> None:
        """Set the base at (x, y, z) with heading q[2] (keeping roll/pitch if asked) and
        the joints at q[3:5]; the wheel angles stay as they are."""
        qpos = self.data.qpos
        yaw = np.array([math.cos(0.5 * q[2]), 0.0, 0.0, math.sin(0.5 * q[2])])
        if keep_tilt:
            # remove the settled quaternion's own yaw, keep its roll and pitch
            current = qpos[3:7].copy()
            unyaw = np.zeros(4)
            mujoco.mju_negQuat(unyaw, _yaw_quaternion(_heading(current)))
            tilt = np.zeros(4)
            mujoco.mju_mulQuat(tilt, unyaw, current)
            mujoco.mju_mulQuat(yaw, yaw.copy(), tilt)
        qpos[0:3] = (q[0], q[1], z)
        qpos[3:7] = yaw
        qpos[self._ids["shoulder_qpos"]] = q[3]
        qpos[self._ids["elbow_qpos"]] = q[4]

    def _set_wheel_mode(self, mode: str) -> None:
        """Wheel actuators as velocity servos (``"velocity"``) or torque motors (else)."""
        if mode == self._wheel_mode:
            return
        for i in self._ids["wheel_actuators"]:
            gain = self._kv[i] if mode == VELOCITY else 1.0
            self.model.actuator_gainprm[i, 0] = gain
            self.model.actuator_biasprm[i, 2] = -gain if mode == VELOCITY else 0.0
        self._wheel_mode = mode

    # -- the plant interface --------------------------------------------------------------
    def observe(self) -> Observation:
        """Measured ``q`` (world frame), forward speed v (m/s) and yaw rate w (rad/s).
        Before the first :meth:`reset` (the robot not yet on the floor) it is a
        :class:`PlantNotResetError`."""
        self._require_reset("observe")
        qpos, qvel = self.data.qpos, self.data.qvel
        phi = self._phi
        q = np.array(
            [qpos[0], qpos[1], phi, qpos[self._ids["shoulder_qpos"]], qpos[self._ids["elbow_qpos"]]]
        )
        v = float(qvel[0] * math.cos(phi) + qvel[1] * math.sin(phi))
        # qvel[3:6] is the base's angular velocity in its own frame: world z component
        rotation = self.data.xmat[self._ids["base"]]
        w = float(rotation[6] * qvel[3] + rotation[7] * qvel[4] + rotation[8] * qvel[5])
        return Observation(q=q, v=v, w=w)

    def limit(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:
        """``u`` after the kinematic plant's limits (wheel speed, joint rate and position),
        which are the servo targets; torque limits act later, in the engine."""
        return self._limits.saturate(np.asarray(q, dtype=float), np.asarray(u, dtype=float))

    def step(self, t: float, command: Any, dt: float, policy: Policy | None = None) -> None:
        """Hold ``command`` for ``dt`` (s) from time t (s): ``dt / timestep`` engine steps
        (``policy`` unused). ``command``: ``u = [v, w, th1dot, th2dot]`` (m/s, rad/s) or a
        :class:`~ddwmmr.commands.WheelForces` (N, rad), finite.

        Raises :class:`PlantNotResetError` before the first :meth:`reset`,
        :class:`PlantDivergedError` (naming the step) if the engine state becomes invalid,
        :class:`ParameterError` for a non-finite or misshapen argument
        (:func:`~ddwmmr.plants.base.check_step`) or if dt differs from the reset's control
        step and is not an allowed one (:meth:`check_control_step`).
        """
        self._require_reset("step")
        checked = check_step(t, command, dt, self.interfaces)
        substeps = self._substeps if dt == self._dt else self.check_control_step(dt)
        q = self.observe().q
        if isinstance(checked, WheelForces):
            self._force_controls(q, checked, dt)
        else:
            self._velocity_controls(q, np.array(checked))
        mujoco.mj_step(self.model, self.data, substeps)
        self._step_count += 1  # counted from 1, as the run's diverged_at_step
        where = f"in control step {self._step_count} (t = {t:.6g} to {t + dt:.6g} s)"
        self._check_state(where, checked)
        mujoco.mj_forward(self.model, self.data)
        self._phi += wrap_angle(_heading(self.data.qpos[3:7]) - self._phi)
        self._cache = self._contacts = None
        self._judge_tipping(t + dt, dt)

    @property
    def joint_time_constant(self) -> float:
        """Time constant (s) with which the joints follow their rate targets (the velocity
        servos' ``servo_time_constant``): what a controller may model of the arm."""
        return self.options.servo_time_constant

    @property
    def joint_acceleration_limit(self) -> tuple[float, float]:
        """Largest angular accelerations (rad/s^2) of the shoulder and the elbow: each
        motor's torque limit over the inertia it moves with the arm stretched
        (:func:`~ddwmmr.plants.mujoco.model.reflected_inertias`), what a controller may
        model of the torque-limited servos (12.8 and 33.3 rad/s^2 with 3 kg)."""
        _, shoulder, elbow = reflected_inertias(self.robot)
        torque = self.robot.joint_torque_limits
        return torque[0] / shoulder, torque[1] / elbow

    @property
    def tip_time(self) -> float | None:
        """Time (s) since the reset at which the robot tipped over by the contact forces
        (:class:`TipDetector`, judged after every control step), None if it has not (also
        before the first :meth:`reset`: a run not yet started has not tipped)."""
        return self._tip.tip_time

    @property
    def unloaded_time_s(self) -> float:
        """Time (s) since the reset with an edge of the support polygon unloaded: dt for
        every control step that ended so (a wheel chattering on a lightly loaded side
        counts); 0 before the first :meth:`reset`."""
        return self._unloaded_time

    def _require_reset(self, method: str) -> None:
        """:class:`PlantNotResetError` naming ``method`` before the first :meth:`reset`."""
        if self._dt is None:
            raise PlantNotResetError("mujoco", method)

    def _judge_tipping(self, t: float, dt: float) -> None:
        """Feed the tip criterion the state at t (s), which ends a step of dt (s; 0: the
        reset's state)."""
        edge_load = self._min_edge_load()  # with the tilt: all the criterion needs
        self._tip.update(t, edge_load, self.base_tilt())
        if self._tip.unloaded(edge_load):
            self._unloaded_time += dt

    def _velocity_controls(self, q: np.ndarray, u: np.ndarray) -> None:
        applied, _ = self.limit(q, u)
        self._set_wheel_mode(VELOCITY)
        v, w = float(applied[0]), float(applied[1])
        left, right = self.robot.wheel_speeds_from_u(v, w)
        lead_left, lead_right = self._damping_lead(v, w)
        self.data.ctrl[:] = (left + lead_left, right + lead_right, applied[2], applied[3])

    def _damping_lead(self, v: float, w: float) -> tuple[float, float]:
        """Wheel-speed targets' lead (rad/s) feeding the base damping forward: the wheel
        servos then hold ``(v, w)`` in steady state.

        With ``base_damping`` the base needs the wheel forces ``(c1 v -+ c2 w / (track/2)) /
        2`` to keep moving at ``(v, w)``; a proportional servo ``kv (target - rate)`` would
        fall short by ``torque / kv`` (measured: docs/physics.md, "The plant"). Raising the
        target by ``torque / kv`` makes the servo apply that torque at the target speed, as
        the thesis plant's velocity servo feeds the damping forward (docs/physics.md). Zero
        without damping."""
        c_t, c_yaw = self.damping
        robot = self.robot
        drive, turn = 0.5 * c_t * v, c_yaw * w / robot.track_width
        kv = self._kv[self._ids["wheel_actuators"][0]]
        scale = robot.wheel_radius / kv
        return (drive - turn) * scale, (drive + turn) * scale

    def _force_controls(self, q: np.ndarray, command: WheelForces, dt: float) -> None:
        self._set_wheel_mode("force")
        th1, th2 = float(q[3]), float(q[4])
        new1, new2 = arm_step(
            th1, th2, command.th1_target, command.th2_target, self.robot.joint_speed_limit, dt
        )
        r = self.robot.wheel_radius
        self.data.ctrl[:] = (
            command.left * r,
            command.right * r,
            (new1 - th1) / dt,
            (new2 - th2) / dt,
        )

    def _unsettled(self) -> str:
        """Why the robot could not settle at reset: the engine step is too long for its
        masses or for the stiffness of its tyres and contacts (one line, naming them and
        the timestep's range)."""
        r, options = self.robot, self.options
        links = ", ".join(f"{m:g}" for m in r.link_masses)
        low, high = TIMESTEP_RANGE_S
        return (
            f"MuJoCo cannot settle this robot at timestep {options.timestep:g} s (its "
            f"state diverged at reset): base_mass {r.base_mass:g} kg, wheel_mass "
            f"{r.wheel_mass:g} kg, link_masses [{links}] kg, payload {r.payload:g} kg on "
            f"tyre_stiffness {tyre_stiffness(r, options):g} N/m and contact_time_constant "
            f"{options.contact_time_constant:g} s (light parts on stiff springs need a "
            "shorter step); soften the tyres (lower tyre_stiffness, or 0 for rigid wheels) "
            "or the contacts (a longer contact_time_constant), give it heavier parts, or "
            f"a smaller MujocoPlant(robot, timestep=...) in [{low:g}, {high:g}] s (track: "
            "--plant-option)"
        )

    def _speed_bounds(self) -> tuple[np.ndarray, np.ndarray, list[tuple[str, str]]]:
        """Per degree of freedom (``MjData.qvel``), two bounds on a plausible speed and
        what it is (name, unit): :data:`SPEED_BOUND_FACTOR` times the fastest the robot's
        motors drive it (the base's velocity components: the wheels' rim speed
        ``wheel_speed_limit r``; its angular velocity components: that rim speed over half
        the track, the fastest yaw; the joints: ``joint_speed_limit``), and the same factor
        times the fastest a fall moves it (:meth:`_fall_scales`: the base's velocity its
        fall speed, its angular velocity and the joints' rates its tip-over rate), which
        is gravity's, not the motors' (a robot with slow motors still falls at full speed).
        A speed is plausible within the larger. The wheels' spin and the tyres' radial
        slides are unbounded: under force commands a wheel off the floor spins up freely
        (the model has no motor speed limit), and a blow-up of either moves the base."""
        robot, model = self.robot, self.model
        rim = robot.wheel_speed_limit * robot.wheel_radius
        fall_speed, fall_rate = self._fall_scales()
        motor = np.full(model.nv, np.inf)
        fall = np.full(model.nv, np.inf)
        names = [("tyre", "m/s")] * model.nv
        motor[0:3], fall[0:3] = rim, fall_speed
        names[0:3] = [("base speed", "m/s")] * 3
        motor[3:6], fall[3:6] = rim / (0.5 * robot.track_width), fall_rate
        names[3:6] = [("base rotation rate", "rad/s")] * 3
        for joint in ("shoulder", "elbow"):
            dof = int(model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)])
            motor[dof], fall[dof] = robot.joint_speed_limit, fall_rate
            names[dof] = (f"{joint} rate", "rad/s")
        return SPEED_BOUND_FACTOR * motor, SPEED_BOUND_FACTOR * fall, names

    def _fall_scales(self) -> tuple[float, float]:
        """The speed (m/s) and rotation rate (rad/s) a fall gives the robot, from gravity
        ``g`` alone: ``sqrt(2 g H)``, what a body falling from the robot's height ``H`` (the
        higher of its base's top and its arm's plane) reaches, and ``sqrt(2 g / h_c)``,
        the most a rigid body whose centre of mass stands ``h_c`` above the floor turns at
        tipping over an edge on the floor (its ``h_c`` in the model's rest pose; derived in
        docs/physics.md, "The plant")."""
        robot, model = self.robot, self.model
        g = -float(model.opt.gravity[2])
        height = max(BASE_CLEARANCE + robot.base_height, robot.arm_height)
        rest = mujoco.MjData(model)  # a scratch state: self.data stays untouched
        mujoco.mj_forward(model, rest)
        com_height = float(rest.subtree_com[0, 2])  # the world's subtree: the whole robot
        return math.sqrt(2.0 * g * height), math.sqrt(2.0 * g / com_height)

    def _warning_count(self) -> int:
        return sum(int(self.data.warning[w].number) for w in _WARNINGS)

    def _check_state(self, where: str, command: Any = None) -> None:
        """Raise :class:`PlantDivergedError` if the engine warned of a bad state (it then
        resets its data silently) or of a bad control (it then zeroes every control), or
        the state is not finite, or a speed is beyond its plausible bound
        (:meth:`_speed_bounds`: the state blew up in this step, and every number after it
        would be garbage)."""
        data = self.data
        count = self._warning_count()
        speeds_ok = bool(np.all(np.abs(data.qvel) <= self._bounds))  # NaN fails too
        if count == self._warnings and speeds_ok and np.all(np.isfinite(data.qpos)):
            return
        self._warnings = count
        controls = data.warning[mujoco.mjtWarning.mjWARN_BADCTRL]
        if controls.number > self._bad_controls:
            self._bad_controls = int(controls.number)
            raise PlantDivergedError(self._rejected(int(controls.lastinfo), where, command))
        excess = np.abs(data.qvel) > self._bounds
        if speeds_ok or not np.any(excess):
            cause = "non-finite or unstable accelerations"
        else:
            dof = int(np.argmax(excess))
            name, unit = self._bound_names[dof]
            cause = (
                f"{name} {abs(float(data.qvel[dof])):.3g} {unit}, beyond {SPEED_BOUND_FACTOR:g} "
                f"times the fastest the motors drive it ({self._motor_bounds[dof]:.3g} {unit}) "
                f"and a fall moves it ({self._fall_bounds[dof]:.3g} {unit})"
            )
        raise PlantDivergedError(f"MuJoCo state diverged {where}: {cause} ({_SMALLER_STEP})")

    def _rejected(self, actuator: int, where: str, command: Any) -> str:
        """The message for a control MuJoCo rejected (not finite or beyond ``mjMAXVAL``)."""
        name = ACTUATORS[actuator] if 0 <= actuator < len(ACTUATORS) else "an actuator"
        value = ""
        if isinstance(command, WheelForces) and name.startswith("wheel"):
            force = command.left if name == "wheel_left" else command.right
            value = f", the torque F r = {force * self.robot.wheel_radius:g} N m of its {force:g} N"
        return (
            f"MuJoCo rejected the control of {name} {where}{value}: beyond the engine's limit "
            f"{mujoco.mjMAXVAL:g} on any control, and zeroed every control (a wheel force "
            f"command is clipped at wheel_force_limit {self.wheel_force_limit:.3g} N only "
            "within that limit)"
        )

    # -- readout ------------------------------------------------------------------------
    def support_forces(self) -> tuple[np.ndarray, np.ndarray]:
        """Floor normal force on each support (N) and its contact point in the base frame
        (m), in the order of :attr:`supports` (an unloaded support: 0 N at its nominal
        point); before the first :meth:`reset` a :class:`PlantNotResetError`."""
        self._require_reset("support_forces")
        index, normal = self._support_contacts()
        forces = np.array(self._per_support(index, normal))
        ox, oy = self.data.xpos[self._ids["base"]][:2].tolist()
        c, s = math.cos(self._phi), math.sin(self._phi)
        moments = [[0.0, 0.0] for _ in self.supports]
        positions = self.data.contact.pos[: len(normal), :2].tolist()
        for support, force, (px, py) in zip(index, normal, positions):
            if support >= 0:
                dx, dy = px - ox, py - oy
                moments[support][0] += force * (c * dx + s * dy)
                moments[support][1] += force * (-s * dx + c * dy)
        points = self.geometry.points.copy()
        loaded = forces > 1e-12
        points[loaded] = np.array(moments)[loaded] / forces[loaded, None]
        return forces, points

    def _support_contacts(self) -> tuple[list[int], list[float]]:
        """For each active contact: the support it touches (-1: none) and its floor normal
        force (N). (Plain lists: a handful of contacts, read once per state: the tip
        criterion and the recorded columns share it.)"""
        if self._contacts is None:
            self._contacts = self._read_contacts()
        return self._contacts

    def _read_contacts(self) -> tuple[list[int], list[float]]:
        model, data = self.model, self.data
        count = data.ncon
        contacts = data.contact
        geom_support = self._geom_support
        pairs = zip(contacts.geom1[:count].tolist(), contacts.geom2[:count].tolist())
        index = [max(geom_support[a], geom_support[b]) for a, b in pairs]
        normal = []
        buffer = self._force_buffer
        for i in range(count):
            mujoco.mj_contactForce(model, data, i, buffer)
            normal.append(float(buffer[0]))
        return index, normal

    def _per_support(self, index: list[int], normal: list[float]) -> list[float]:
        """Contact normal forces (N) summed per support."""
        loads = [0.0] * len(self.supports)
        for support, force in zip(index, normal):
            if support >= 0:
                loads[support] += force
        return loads

    def _min_edge_load(self) -> float:
        """The smallest edge load (N) now, the one reading (with the tilt) the tip
        criterion needs after every step."""
        return self.geometry.min_edge_load(self._per_support(*self._support_contacts()))

    def base_tilt(self) -> float:
        """Angle (rad) between the base's z axis and the vertical (:class:`PlantNotResetError`
        before the first :meth:`reset`)."""
        self._require_reset("base_tilt")
        return float(math.acos(min(1.0, max(-1.0, self.data.xmat[self._ids["base"]][8]))))

    def wheel_slip(self) -> float:
        """Largest horizontal speed (m/s) of a wheel's contact point over the floor
        (:class:`PlantNotResetError` before the first :meth:`reset`)."""
        self._require_reset("wheel_slip")
        r = self.robot.wheel_radius
        worst = 0.0
        for body in self._ids["wheels"]:
            mujoco.mj_objectVelocity(
                self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, body, self._velocity_buffer, 0
            )
            wx, wy, _, vx, vy, _ = self._velocity_buffer
            # velocity of the wheel's lowest point: v + omega x (0, 0, -r)
            worst = max(worst, math.hypot(vx - r * wy, vy + r * wx))
        return worst

    def extra_values(self) -> tuple[float, ...]:
        """Values of :attr:`extra_columns` at the current state (:class:`PlantNotResetError`
        before the first :meth:`reset`)."""
        self._require_reset("extra_values")
        if self._cache is None:
            forces, points = self.support_forces()
            cop = centre_of_pressure(points, forces)
            stability = 0.0 if cop is None else self.geometry.stability(cop)
            self._cache = (
                float(np.min(forces)),
                *(float(f) for f in forces),
                float(np.min(self.geometry.edge_loads(forces))),
                stability,
                self.base_tilt(),
                self.wheel_slip(),
                self.torque_use(),
                self.torque_use(self._ids["wheel_actuators"]),
            )
        return self._cache

    def torque_use(self, actuators: Sequence[int] | None = None) -> float:
        """Largest share of its torque limit any motor uses now (1: saturated); only the
        motors of ``actuators`` (indices into the model's actuators), if given;
        :class:`PlantNotResetError` before the first :meth:`reset`."""
        self._require_reset("torque_use")
        index = slice(None) if actuators is None else list(actuators)
        limits = self.model.actuator_forcerange[index, 1]
        return float(np.max(np.abs(self.data.actuator_force[index]) / limits))

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        """Physics summary of a recorded run.

        Keys: ``tipped`` (see :func:`tip_time_s`), ``tip_time_s`` (when, None if never),
        ``support_lost`` (some polygon edge carried no load at some sample),
        ``unloaded_time_s`` (total time with an unloaded edge), ``min_support_force_n``,
        ``min_edge_load_n``, ``min_physics_stability``, ``max_base_tilt_rad``,
        ``max_wheel_slip_m_s``, ``actuator_saturated_time_s`` (time with a motor at its
        torque limit, the arm's included), ``wheel_saturated_time_s`` (time with a wheel
        motor at its torque limit) and ``mujoco_timestep_s``.
        """
        t = np.asarray(timeseries["t"], dtype=float)
        edge_load = np.asarray(timeseries["min_edge_load_n"], dtype=float)
        unloaded = edge_load < UNLOADED_FRACTION * self.weight_n
        interval = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
        tip_time = tip_time_s(
            t, edge_load, np.asarray(timeseries["base_tilt_rad"], dtype=float), self.weight_n
        )

        def saturated_time(column: str) -> float:
            return float(np.sum(np.asarray(timeseries[column]) >= TORQUE_SATURATED) * interval)

        return {
            "tipped": tip_time is not None,
            "tip_time_s": tip_time,
            "support_lost": bool(np.any(unloaded)),
            "unloaded_time_s": float(np.sum(unloaded) * interval),
            "min_support_force_n": float(np.min(timeseries["min_support_force_n"])),
            "min_edge_load_n": float(np.min(edge_load)),
            "min_physics_stability": float(np.min(timeseries["physics_stability"])),
            "max_base_tilt_rad": float(np.max(timeseries["base_tilt_rad"])),
            "max_wheel_slip_m_s": float(np.max(timeseries["wheel_slip_m_s"])),
            "actuator_saturated_time_s": saturated_time("torque_use"),
            "wheel_saturated_time_s": saturated_time("wheel_torque_use"),
            "mujoco_timestep_s": self.options.timestep,
        }


class TipDetector:
    """The tipped-over criterion of :func:`tip_time_s`, fed one sample at a time.

    Args:
        weight_n: the robot's weight (N).
        interval: the time (s) the first sample stands for (later samples: the time since
            the one before, so a run may change its step); 0 when there is only one sample
            (then only the tilt can say "tipped").

    :attr:`tip_time` is the time (s) of the first sample at which the criterion was met,
    None until then; it stays set.
    """

    def __init__(self, weight_n: float, interval: float) -> None:
        self._unloaded_below = UNLOADED_FRACTION * weight_n
        self._interval = interval
        self._t: float | None = None  # time of the previous sample (s)
        self._tilt = -math.inf  # tilt of the previous sample (rad; none before the first)
        self._pivot_time = 0.0  # s of consecutive samples pivoting on an unloaded edge
        self._pivot_start = 0.0  # tilt (rad) before the pivoting began
        self.tip_time: float | None = None

    def unloaded(self, edge_load: float) -> bool:
        """Whether an edge with this load (N) counts as unloaded."""
        return edge_load < self._unloaded_below

    def update(self, t: float, edge_load: float, tilt: float) -> float | None:
        """Take the sample at t (s): smallest edge load (N) and base tilt (rad); return
        :attr:`tip_time`."""
        if self.tip_time is not None:
            return self.tip_time
        step = self._interval if self._t is None else t - self._t
        pivoting = self.unloaded(edge_load) and tilt >= self._tilt
        if pivoting and self._pivot_time == 0.0:
            self._pivot_start = self._tilt if self._t is not None else tilt
        self._pivot_time = self._pivot_time + step if pivoting else 0.0
        rise = tilt - self._tilt if self._t is not None else 0.0  # over this sample (rad)
        self._t, self._tilt = t, tilt
        growth = tilt - self._pivot_start
        lifted = (
            self._interval > 0.0
            and self._pivot_time >= LIFT_TIME_S - 1e-9
            and growth >= PIVOT_GROWTH_RAD
            # not decelerating: this sample's rate at least the mean rate since it began
            and rise * self._pivot_time >= (1.0 - PIVOT_RATE_TOLERANCE) * growth * step
        )
        if tilt > TIP_TILT_RAD or lifted:
            self.tip_time = t
        return self.tip_time


def tip_time_s(
    t: np.ndarray, edge_load: np.ndarray, tilt: np.ndarray, weight_n: float
) -> float | None:
    """First time (s) a recorded run counts as tipped, or None.

    Tipped: the base pivots about an edge of the support polygon for at least
    :data:`LIFT_TIME_S` (consecutive samples, n samples spanning n sample intervals, at
    which the supports off the edge carry less than :data:`UNLOADED_FRACTION` of the weight
    ``weight_n``, N, and the tilt has not decreased since the sample before) and has
    tilted by :data:`PIVOT_GROWTH_RAD` since it began, or the base tilts beyond
    :data:`TIP_TILT_RAD`. A wheel that merely chatters on and off the floor,
    or a base that rocks onto an edge and back, lifts an edge without pivoting on: that is
    ``support_lost``, not tipped. The time returned is the sample where the criterion
    is first met. ``edge_load`` is the ``min_edge_load_n`` column, ``tilt`` the
    ``base_tilt_rad`` column. (:class:`TipDetector` is the criterion; the plant runs one
    during a run, :attr:`MujocoPlant.tip_time`.)
    """
    t = np.asarray(t, dtype=float)
    interval = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    detector = TipDetector(weight_n, interval)
    for time, load, angle in zip(
        t.tolist(), np.asarray(edge_load).tolist(), np.asarray(tilt).tolist()
    ):
        if detector.update(time, load, angle) is not None:
            break
    return detector.tip_time


def _heading(quaternion: npt.NDArray[np.float64]) -> float:
    """Heading (rad) of a body's x axis projected on the floor, from its quaternion."""
    w, x, y, z = (float(v) for v in quaternion)
    return math.atan2(2.0 * (x * y + w * z), 1.0 - 2.0 * (y * y + z * z))


def _yaw_quaternion(angle: float) -> np.ndarray:
    return np.array([math.cos(0.5 * angle), 0.0, 0.0, math.sin(0.5 * angle)])


#: Largest ``base_damping`` ``(N s/m, N m s/rad)``: at 1000 N s/m the motors' full force
#: (41 N on the default robot) drives the base at 4 cm/s, and at 1000 N m s/rad their
#: full moment (7 N m) turns it at 0.007 rad/s: a base stuck in mud, 70 and 250 times the
#: thesis's c1 = 15 and c2 = 4 (docs/physics.md, "The plant").
BASE_DAMPING_MAX = (1e3, 1e3)


def _check_damping(value: tuple[float, float] | None) -> tuple[float, float] | None:
    """Validate the ``base_damping`` option: None or two numbers ``(c1, c2)`` in [0,
    :data:`BASE_DAMPING_MAX`] (N s/m, N m s/rad); text and booleans are no numbers."""
    if value is None:
        return None
    high_t, high_yaw = BASE_DAMPING_MAX
    values = float_values(value, 2)
    if values is None:
        raise ParameterError(
            f"base_damping must be two numbers, translation in [0, {high_t:g}] N s/m and "
            f"yaw in [0, {high_yaw:g}] N m s/rad (got {shown(value)})"
        )
    c_t, c_yaw = values
    check_range("base_damping[1]", c_t, 0.0, high_t, "N s/m")
    check_range("base_damping[2]", c_yaw, 0.0, high_yaw, "N m s/rad")
    return c_t, c_yaw
