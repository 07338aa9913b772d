"""The nonlinear MPC controller, registered as method ``mpc`` (docs/mpc.md).

Every control step (one call per step; the command is held over it, ``zero_order_hold``):

1. the measured state (configuration, and the base velocities for the thesis model) pins
   node 0 of the OCP (:mod:`ddwmmr.mpc.ocp`);
2. the references of the nodes come from the trajectory's future poses (tracking), or the
   target ``pose_d`` is to be reached as early as possible (waypoint mode, free horizon);
3. the previous solution, shifted by the elapsed time, is the warm start; one Gauss-Newton
   iteration (the real-time iteration, default) or a full solve updates it;
4. the first input is applied: a velocity command (kinematic model) or wheel forces and
   one-step joint targets (thesis model); an exact check of S one step ahead scales the
   joint rates back if the linearisation was too optimistic (not a braking step's rates,
   which already slow the joints at their acceleration limit). On a lagged arm with a
   joint acceleration limit (a physics plant), a plan whose stability rows need more
   slack than ``brake_slack`` while the robot moves is replaced by the braking step
   (:mod:`ddwmmr.mpc.braking`).

A failed solve (infeasible QP, solver error, non-finite numbers) falls back to the ``qp``
controller's command for that step, counted in ``mpc_fallbacks``; the next step starts cold.

Built by name::

    make_controller("mpc", Robot())    # kinematic model (run on MuJoCo: the force model)
    make_controller("mpc", Robot().with_payload(3.0), model="thesis",
                    track_orientation=False)                          # wheel forces

With ``model="thesis"`` the controller declares ``interface = "force"`` and
``wants_base_velocity = True``: ``command(t, q, pose_d, velocity_d, base_velocity=(v, w))``
returns :class:`ddwmmr.commands.WheelForces`.

``summarize`` adds to the run summary, among others, ``stability_min``,
``stability_violations`` (recorded steps with S < floor), ``mpc_fallbacks`` (steps that
used the ``qp`` fallback), ``mpc_brakes`` (braking steps), ``mpc_model``, ``mpc_solver``;
the full list is in docs/mpc.md, "Options".
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ddwmmr.commands import FORCE, PlantTraits, WheelForces
from ddwmmr.controllers.base import StepInfo, WaypointRun, control_step, register_controller
from ddwmmr.errors import (
    ParameterError,
    check_bool,
    check_finite,
    check_int_at_least,
    check_nonnegative,
    check_positive,
    check_range,
)
from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.thesis_base import C1_DEFAULT, C2_DEFAULT, FORCE_LIMIT_DEFAULT
from ddwmmr.mpc import terminal
from ddwmmr.mpc.braking import braking_input
from ddwmmr.mpc.models import PredictionModel, make_model
from ddwmmr.mpc.ocp import (
    MAX_HORIZON,
    MAX_INTERVALS,
    MIN_INTERVAL,
    OCPConfig,
    ShootingOCP,
    Weights,
    grid_intervals,
)
from ddwmmr.mpc.solvers import (
    QP_SOLVERS,
    SOLVERS,
    SolverFailure,
    installed_qp_solvers,
    installed_solvers,
    make_solver,
)
from ddwmmr.qp.limits import as_circles, run_clearance, safe_arm_scale

MODELS = ("kinematic", "thesis")
#: Control step (s) when neither ``dt`` nor the trajectory's resolution is known.
DEFAULT_DT = 0.02
#: Gauss-Newton iterations of a cold start (first step, new target, after a fallback).
COLD_ITERATIONS = 5
#: Waypoint mode: when the end effector has not moved 1 mm (net) for this long (s) short of
#: the target, the plan is dropped and the next step starts cold. One real-time iteration
#: per step follows the optimum it is near; from a poor warm start that can be a
#: stationary point far from the best plan (2 of 100 scenarios stalled before this rule).
STALL_TIME = 0.5
STALL_PROGRESS = 1e-3
#: ... and likewise when every plan for this long needed the constraints' slack (largest
#: slack above this, in the rows' units, m for the stability box; the joint box's slack
#: left out, ``ShootingOCP.max_slack``): a plan that cannot meet
#: its hard constraints is stuck (on the physics plant: spinning on the spot with the arm
#: stretched at the dynamic floor for 35 s, 4 of 100 scenarios, before this rule).
STALL_SLACK = 1e-3
#: Default ``brake_slack`` (m) where the lagged arm has a joint acceleration limit (a
#: physics plant): a plan whose stability rows' largest slack (m,
#: ``ShootingOCP.max_stability_slack``) exceeds it is replaced by the braking step.
BRAKE_SLACK = 5e-3
#: Below this speed (m/s, rad/s: base speed, yaw rate, joint rates) the robot is at rest
#: and the braking step is not taken.
AT_REST = 0.05
#: Defaults per objective: (intervals, first interval s, horizon s). Chosen by the horizon
#: study in docs/mpc.md.
GRID_DEFAULTS = {"tracking": (10, 0.05, 1.0), "reach": (12, 0.05, 5.0)}


@dataclass(frozen=True)
class BaseFacts:
    """What the force-level model takes from its plant's traits (None: the thesis plant's
    value, ``ddwmmr.plants.thesis``).

    Attributes:
        damping: ``(c1 N s/m, c2 N m s/rad)``.
        force_limit: each wheel's largest traction force (N).
        lever: each wheel force's lever about the base centre (m).
    """

    damping: tuple[float, float] | None = None
    force_limit: float | None = None
    lever: float | None = None

    @classmethod
    def of(cls, plant: PlantTraits | None, force_limit: float | None = None) -> BaseFacts:
        """The facts ``plant`` states (none for an unknown plant), with the wheel force
        ``force_limit`` (N) asked for (refused above the plant's motors), else
        :func:`planned_force` (at most the motors')."""
        if plant is None:
            return cls(force_limit=force_limit)
        motors = plant.wheel_force_limit
        if force_limit is not None and motors is not None and force_limit > motors:
            raise ParameterError(
                f"wheel_force_limit must be <= the plant's motors, {motors:.4g} N per wheel "
                f"(got {force_limit:g})"
            )
        force = planned_force(plant) if force_limit is None else force_limit
        return cls(plant.base_damping, force, plant.wheel_lever)

    def dynamics(self, robot: Robot) -> sym.ThesisDynamics:
        """The force-level model of ``robot`` on a base with these facts."""
        c1, c2 = self.damping if self.damping is not None else (C1_DEFAULT, C2_DEFAULT)
        force = self.force_limit if self.force_limit is not None else FORCE_LIMIT_DEFAULT
        return sym.ThesisDynamics.from_robot(robot, c1, c2, force, half_width=self.lever)


def _acceleration_option(value: Any) -> tuple[float, float] | None:
    """The ``joint_acceleration_limit`` option: None (not given), ``()`` (0: none) or
    ``(shoulder, elbow)`` rad/s^2."""
    if value is None:
        return None
    pair = value if isinstance(value, list | tuple) else (value, value)
    if len(pair) != 2:
        raise ParameterError(
            f"joint_acceleration_limit must be one number or two (shoulder, elbow) in rad/s^2 "
            f"(got {len(pair)} values)"
        )
    limits = tuple(float(check_nonnegative("joint_acceleration_limit", v)) for v in pair)
    if limits == (0.0, 0.0):
        return ()
    for v in limits:
        check_range("joint_acceleration_limit", v, 0.1, 1e4, "rad/s^2")
    return limits  # type: ignore[return-value]


def _can_brake(lag: float | None, acceleration_limit: tuple[float, float] | None) -> bool:
    """The braking step needs the lagged arm (only the force model has one) and its joint
    acceleration limit."""
    return lag is not None and acceleration_limit is not None


def planned_force(plant: PlantTraits) -> float:
    """The wheel force (N) the force model plans with by default on ``plant``: the plant's
    own limit where the model is the plant's (the thesis plant), the thesis's 10 N, within
    the motors, on a plant that judges tipping by its physics (and 10 N on a plant that
    does not say). On MuJoCo the motors' full 20.5 N tipped the robot in 26 of 100
    scenarios (the wheels lift and spin where the model has them rolling; docs/mpc.md),
    against 3 with 10 N, both before the brakeable last node and the braking step (with
    them 10 N tips none)."""
    motors = plant.wheel_force_limit
    if motors is None:
        return FORCE_LIMIT_DEFAULT
    return min(FORCE_LIMIT_DEFAULT, motors) if plant.judges_tipping else motors


@register_controller("mpc", tasks=("tracking", "waypoints"), interfaces=("velocity", "force"))
class MPCController:
    """Nonlinear MPC: multiple shooting, hard exact S >= S_min, soft manipulability, preview.

    Args:
        robot: the robot (payload included).
        model: ``"kinematic"`` (velocity commands, the kinematic plant) or ``"thesis"``
            (wheel forces, the thesis plant's force-level dynamics; needs the measured base
            velocities, ``base_velocity=(v, w)``); None (default): chosen for the plant the
            loop runs it on (:meth:`adopt_plant`: ``"thesis"`` on a plant that takes wheel
            forces and judges tipping by its physics, or when ``dynamic_stability``,
            ``arm_time_constant``, ``joint_acceleration_limit`` or ``wheel_force_limit``
            asks for it, else ``"kinematic"``).
        stability_min: floor S_min of the tip-over margin (hard, exact at every node).
        manipulability_weight: weight of ``cos^2 th2`` (soft).
        obstacles: circles (``Circle`` or (x, y, radius) triples, m) or a TOML file path;
            the base's enclosing circle keeps ``obstacle_margin`` (m) from each.
        track_orientation: cost on the end-effector orientation (tracking).
        horizon, intervals, first_interval: the grid (s, count, s); defaults per objective
            in :data:`GRID_DEFAULTS`.
        solver: ``"rti"`` (one Gauss-Newton iteration per step, default), ``"sqp"``
            (iterated Gauss-Newton), ``"ipopt"``, ``"sqpmethod"`` or ``"fatrop"``.
        qp_solver: QP backend of ``rti``/``sqp`` (``"hpipm"`` default).
        position_weight, orientation_weight, input_weight: cost weights (see
            :class:`ddwmmr.mpc.ocp.Weights`); huber: Huber scale (m) of position errors.
        reach_speed: waypoint mode: m/s converting the distance left at the end of the
            horizon into seconds.
        proximal: damping of the input steps between two solves (see
            :class:`ddwmmr.mpc.solvers.GaussNewtonSQP`).
        stability_margin: the OCP keeps ``S >= stability_min + stability_margin``.
        dynamic_stability: hold the floor on the zero moment point too, the centre of
            pressure with the inertial forces of turning and accelerating
            (``model="thesis"`` only; docs/mpc.md), besides the static centre of mass; None
            (default): on exactly when the force model runs on a physics plant.
        arm_time_constant: the joints follow the commanded rates with this first-order lag
            (s) in the prediction (``model="thesis"`` only; the physics plant's joint
            servos have one); None (default): that plant's lag when the force model runs on
            a physics plant, else none; 0: none (the joints move at the commanded rates at
            once).
        joint_acceleration_limit: bound (rad/s^2) on the lagged joints' accelerations, one
            number for both or (shoulder, elbow) (with the lagged arm only: the physics
            plant's servos are torque-limited); None (default): that plant's
            (``PlantTraits.joint_acceleration_limit``) when the lagged arm runs on a
            physics plant, else none; 0: none.
        wheel_force_limit: per-wheel traction force (N) the force model plans with
            (``model="thesis"`` only), at most the plant's motors
            (``PlantTraits.wheel_force_limit``; more is refused when the loop hands over the
            plant's traits); None (default): :func:`planned_force`,
            the thesis plant's own limit there, the thesis's 10 N on a physics plant.
        brake_slack: when the plan needs more slack in its stability rows than this (m,
            in the box on the centre of mass and the zero moment point; 0 or in [1e-4, 1])
            while the robot moves, the step brakes instead
            (:func:`ddwmmr.mpc.braking.braking_input`: base and arm slowed within the force
            and acceleration limits), counted in ``mpc_brakes``; only with the lagged arm
            and a joint acceleration limit; None (default): :data:`BRAKE_SLACK` (5 mm)
            there, else off; 0: off.
        dt: control step (s); default the loop's control step (:meth:`adopt_control_step`),
            else the trajectory's ``duration / samples`` at reset, else 0.02 s.
        fallback_options: options of the ``qp`` fallback controller (merged over the
            defaults derived from these options).
    """

    #: Sampled-data controller: call once per control step, hold the command over it.
    zero_order_hold = True
    #: ~0.5 ms a step: ranked in the comparison, left out of its studies by default
    #: (``--study-methods mpc`` adds it).
    in_studies = False

    #: Options with a closed set of values, for front ends (the app shows a button cycling
    #: through them): option name -> function returning the values.
    option_choices: ClassVar[Mapping[str, Callable[[], list[Any]]]] = {
        "model": lambda: [None, *MODELS],  # None: chosen for the plant
        "solver": installed_solvers,
        "qp_solver": installed_qp_solvers,
    }

    def __init__(
        self,
        robot: Robot,
        model: str | None = None,
        stability_min: float = 1.25,
        manipulability_weight: float = 0.5,
        obstacles: Sequence[Any] | str = (),
        track_orientation: bool = True,
        horizon: float | None = None,
        intervals: int | None = None,
        first_interval: float | None = None,
        solver: str = "rti",
        qp_solver: str = "hpipm",
        position_weight: float | None = None,
        orientation_weight: float = 10.0,
        input_weight: float = 0.01,
        huber: float | None = None,
        reach_speed: float = 0.05,
        proximal: float = 0.01,
        stability_margin: float = 0.01,
        dynamic_stability: bool | None = None,
        arm_time_constant: float | None = None,
        joint_acceleration_limit: float | Sequence[float] | None = None,
        wheel_force_limit: float | None = None,
        brake_slack: float | None = None,
        obstacle_margin: float = 0.05,
        dt: float | None = None,
        fallback_options: dict[str, Any] | None = None,
    ) -> None:
        if model is not None and model not in MODELS:
            raise ParameterError(f"model must be one of {', '.join(MODELS)} (got {model!r})")
        if solver not in SOLVERS:
            raise ParameterError(f"solver must be one of {', '.join(SOLVERS)} (got {solver!r})")
        if qp_solver not in QP_SOLVERS:
            raise ParameterError(
                f"qp_solver must be one of {', '.join(QP_SOLVERS)} (got {qp_solver!r})"
            )
        self.robot = robot
        self._model_option = model
        self._lag_option = None  # not given; 0.0: given as "no lag"
        if arm_time_constant is not None and arm_time_constant != 0.0:
            check_range("arm_time_constant", arm_time_constant, 1e-3, 1.0, "s")
        if arm_time_constant is not None:
            self._lag_option = float(arm_time_constant)
        self._accel_option = _acceleration_option(joint_acceleration_limit)
        self._force_option = None
        if wheel_force_limit is not None:
            self._force_option = check_range("wheel_force_limit", wheel_force_limit, 0.1, 1e4, "N")
            if model == "kinematic":
                raise ParameterError("wheel_force_limit needs model='thesis'")
        self._brake_option = None
        if brake_slack is not None:
            self._brake_option = check_finite("brake_slack", brake_slack)
            if self._brake_option != 0.0 and not 1e-4 <= self._brake_option <= 1.0:
                raise ParameterError(
                    f"brake_slack must be 0 (off) or in [0.0001, 1] m (got {brake_slack:g})"
                )
        self._dynamic_option = None
        if dynamic_stability is not None:
            self._dynamic_option = check_bool("dynamic_stability", dynamic_stability)
        self._configure(*self._resolve(None))
        self.stability_min = check_positive("stability_min", stability_min)
        if self.stability_min >= 10.0:
            raise ParameterError(f"stability_min must be in (0, 10) (got {stability_min:g})")
        self.obstacles = as_circles(obstacles)
        self.track_orientation = check_bool("track_orientation", track_orientation)
        self.solver_name, self.qp_solver = solver, qp_solver
        self._dt_option = None if dt is None else check_positive("dt", dt)
        self._loop_step: float | None = None
        self.dt = self._dt_option or DEFAULT_DT
        self._grid = {
            mode: self._grid_option(mode, horizon, intervals, first_interval, self.dt)
            for mode in GRID_DEFAULTS
        }
        self._weights = {
            mode: Weights(
                position=check_nonnegative(
                    "position_weight",
                    (100.0 if mode == "tracking" else 50.0)
                    if position_weight is None
                    else position_weight,
                ),
                orientation=orientation_weight,
                manipulability=manipulability_weight,
                input=input_weight,
                terminal=1.0 if mode == "tracking" else 0.0,
            )
            for mode in GRID_DEFAULTS
        }
        self.huber = None if huber is None else check_positive("huber", huber)
        self.reach_speed = check_positive("reach_speed", reach_speed)
        self.proximal = check_nonnegative("proximal", proximal)
        self.stability_margin = check_nonnegative("stability_margin", stability_margin)
        self.obstacle_margin = check_nonnegative("obstacle_margin", obstacle_margin)
        self._fallback_options = dict(fallback_options or {})
        self._fallback: Any = None
        self._trajectory: Any = None
        self.fallbacks = 0
        #: Message of the last solver failure (None before any).
        self.last_failure: str | None = None
        self.last = StepInfo()
        self._reset_memory()

    # -- options ----------------------------------------------------------------------------
    def _resolve(
        self, plant: PlantTraits | None
    ) -> tuple[str, bool, float | None, BaseFacts, tuple[float, float] | None]:
        """``(model, dynamic_stability, arm_time_constant, base, joint_acceleration_limit)``:
        the options given, else what suits ``plant`` (None: not known yet).

        On a plant that takes wheel forces and judges tipping by its physics: the
        force-level model, the floor on the dynamic margin and the plant's joint lag (the
        static floor alone tipped 94 of 100 scenarios there, docs/mpc.md; likewise for
        ``model="thesis"`` given there); elsewhere the kinematic model (the force model when
        any force-model option is given: ``dynamic_stability``, a lag, a joint acceleration
        bound or a wheel force), static floor, no lag. The force
        model's base (damping, wheel force limit, wheel lever: :class:`BaseFacts`) is the
        plant's where it says, else the thesis plant's; its wheel force is the one asked
        for (within the plant's motors), else :func:`planned_force`. The lagged joints'
        accelerations are bounded as asked, else by the physics plant's motors.
        """
        physics = plant is not None and plant.judges_tipping and FORCE in plant.interfaces
        wants_force = (
            bool(self._dynamic_option)
            or bool(self._lag_option)
            or bool(self._accel_option)
            or self._force_option is not None
        )
        model = self._model_option or ("thesis" if physics or wants_force else "kinematic")
        suited = physics and model == "thesis"  # the force model on a physics plant
        dynamic = self._dynamic_option if self._dynamic_option is not None else suited
        lag = self._lag_option
        if lag is None:
            lag = plant.joint_time_constant if suited else None  # type: ignore[union-attr]
        base = BaseFacts.of(plant, self._force_option) if model == "thesis" else BaseFacts()
        accel = self._accel_option
        if accel is None and suited:
            accel = plant.joint_acceleration_limit  # type: ignore[union-attr]
        if accel and not lag:
            if plant is not None and self._accel_option:
                raise ParameterError(
                    "joint_acceleration_limit needs the lagged arm (arm_time_constant, or a "
                    "physics plant's joint lag)"
                )
            accel = None  # the plant is not known yet (or has no lag): nothing to bound
        return model, dynamic, (lag or None), base, (accel or None)

    def _configure(
        self,
        model: str,
        dynamic_stability: bool,
        lag: float | None,
        base: BaseFacts,
        acceleration_limit: tuple[float, float] | None,
    ) -> None:
        """Set the prediction model and its options (problems are rebuilt on demand):
        the choice :meth:`_resolve` made, kept as ``_choice``."""
        if lag is not None and model != "thesis":
            raise ParameterError("arm_time_constant needs model='thesis'")
        if dynamic_stability and model != "thesis":
            raise ParameterError(
                "dynamic_stability needs model='thesis' (the kinematic model has no base "
                "accelerations)"
            )
        self._choice = (model, dynamic_stability, lag, base, acceleration_limit)
        self.model_name = model
        self.dynamics = None
        if model == "thesis":
            self.dynamics = base.dynamics(self.robot)
        self.arm_time_constant = lag
        self.joint_acceleration_limit = acceleration_limit
        self.dynamic_stability = dynamic_stability
        braked = _can_brake(lag, acceleration_limit) and self._brake_option != 0.0
        self.brake_slack = (self._brake_option or BRAKE_SLACK) if braked else None
        self.model: PredictionModel = make_model(
            model, self.robot, self.dynamics, lag, acceleration_limit
        )
        self.interface = self.model.interface
        self.wants_base_velocity = model == "thesis"
        self._problems: dict[tuple[str, float], _Problem] = {}

    def adopt_plant(self, plant: PlantTraits) -> None:
        """The loop's plant, described (:func:`ddwmmr.commands.traits_of`): options not
        given are chosen for it (:meth:`_resolve`), before ``reset``."""
        choice = self._resolve(plant)
        _, _, lag, _, acceleration_limit = choice
        if self._brake_option and not _can_brake(lag, acceleration_limit):
            raise ParameterError(
                "brake_slack needs the lagged arm with a joint acceleration limit (a physics "
                "plant, or arm_time_constant and joint_acceleration_limit)"
            )
        if choice != self._choice:
            self._configure(*choice)
            self._reset_memory()  # sized and meant for the previous model
            self._fallback = None

    @staticmethod
    def _grid_option(mode, horizon, intervals, first_interval, dt) -> tuple[int, float, float]:
        n0, h0, t0 = GRID_DEFAULTS[mode]
        n = check_int_at_least(
            "intervals", n0 if intervals is None else intervals, 2, MAX_INTERVALS
        )
        t = check_range(
            "horizon", t0 if horizon is None else horizon, MIN_INTERVAL, MAX_HORIZON, "s"
        )
        if first_interval is None:
            # A short horizon with the default first interval: uniform intervals.
            h = min(h0, max(t - dt, 1e-3) / max(int(n) - 1, 1))
        else:
            h = first_interval
        if not t > dt:
            raise ParameterError(f"horizon must be > the control step dt = {dt:g} s (got {t:g})")
        grid_intervals(n, h, t)  # validates the count and the lengths (one-line errors)
        return int(n), float(h), float(t)

    def _config(self, mode: str) -> OCPConfig:
        n, h, t = self._grid[mode]
        reach = mode == "reach"
        return OCPConfig(
            intervals=n,
            control_interval=self.dt,
            first_interval=min(h, (t - self.dt) / (n - 1)),
            horizon=t,
            reach=reach,
            min_horizon=max(0.1, 2.0 * self.dt),
            reach_speed=self.reach_speed,
            stability_min=self.stability_min,
            stability_margin=self.stability_margin,
            dynamic_stability=self.dynamic_stability,
            track_orientation=self.track_orientation and not reach,
            huber=self.huber if self.huber is not None else (0.01 if reach else None),
            obstacles=tuple(self.obstacles),
            base_radius=0.5 * math.hypot(self.robot.base_length, self.robot.base_width),
            obstacle_margin=self.obstacle_margin,
            weights=self._weights[mode],
        )

    def _problem(self, mode: str) -> _Problem:
        key = (mode, self.dt)
        if key not in self._problems:
            self._problems[key] = _Problem(self, self._config(mode))
        return self._problems[key]

    # -- controller protocol ------------------------------------------------------------
    def _reset_memory(self) -> None:
        self._warm: np.ndarray | None = None
        self._warm_mode: str | None = None
        self._warm_time = 0.0
        self._target: tuple[float, float] | None = None
        self._u_prev = np.zeros(self.model.nu)
        self._predicted_velocity: tuple[float, float] = (0.0, 0.0)
        self._predicted_rates: tuple[float, float] = (0.0, 0.0)  # the lagged arm's
        self._infeasible_since: float | None = None  # first of the plans that needed slack
        self._anchor: tuple[float, float] | None = None
        self._anchor_time = 0.0
        self.restarts = 0
        self.brakes = 0  # steps that braked instead of following a plan that needed slack

    def adopt_control_step(self, dt: float) -> None:
        """The loop holds each command ``dt`` (s): plan with it (the first interval, the
        joint targets ``th + rate dt``), unless ``dt`` was given as an option."""
        self._loop_step = dt

    def reset(self, trajectory: Any, q0: np.ndarray) -> None:
        """Forget warm starts and counters; take the control step (:func:`control_step`)."""
        self.dt = control_step(self._dt_option, self._loop_step, trajectory, DEFAULT_DT)
        self._trajectory = trajectory
        self.fallbacks = 0
        self.last = StepInfo()
        self._reset_memory()
        if trajectory is not None:
            arm = (float(q0[3]), float(q0[4]))
            self._problem("tracking").design_terminal(arm)
        self._fallback = None  # rebuilt on the first failure with this run's dt

    def command(
        self,
        t: float,
        q: np.ndarray,
        pose_d: np.ndarray,
        velocity_d: np.ndarray,
        *,
        base_velocity: tuple[float, float] | None = None,
    ) -> np.ndarray | WheelForces:
        """The command for time t (s) at configuration q: ``u = (v, w, th1dot, th2dot)``
        (kinematic model) or :class:`WheelForces` (thesis model).

        ``base_velocity = (v, w)`` (m/s, rad/s) is the measured base velocity the thesis
        model needs; without it the previous plan's prediction is used.
        """
        q = np.asarray(q, dtype=float)
        pose_d = np.asarray(pose_d, dtype=float)
        velocity_d = np.asarray(velocity_d, dtype=float)
        reach = self._trajectory is None and not np.any(velocity_d)
        mode = "reach" if reach else "tracking"
        problem = self._problem(mode)
        if mode == "tracking" and problem.terminal_factor is None:
            problem.design_terminal((float(q[3]), float(q[4])))
        x0 = self._state(q, base_velocity)
        references = self._references(problem, t, pose_d, velocity_d)
        target = (float(pose_d[0]), float(pose_d[1]))
        new_target = reach and self._target != target
        cold = self._warm is None or self._warm_mode != mode or new_target
        stuck = reach and (self._stalled(t, q, new_target) or self._infeasible_too_long(t))
        if cold:
            self._infeasible_since = None  # a fresh plan gets its own 0.5 s
        elif stuck:
            cold = True
            self.restarts += 1
        try:
            w, iterations = problem.solve(
                t, x0, references, self._u_prev, None if cold else self._warm, self._warm_time
            )
        except SolverFailure as failure:
            return self._fallback_command(t, q, pose_d, velocity_d, x0, str(failure))
        self._warm, self._warm_mode, self._warm_time = w, mode, t
        self._target = target
        if problem.ocp.max_slack(w) <= STALL_SLACK:
            self._infeasible_since = None
        elif self._infeasible_since is None:
            self._infeasible_since = t
        u = problem.ocp.first_input(w)
        braking = (
            self.brake_slack is not None
            and problem.ocp.max_stability_slack(w) > self.brake_slack
            and self._moving(x0)
        )
        if braking:
            self.brakes += 1
            u = self._braking_input(q, x0)
        return self._output(problem, q, x0, u, w, iterations, braking)

    # -- pieces ---------------------------------------------------------------------------
    def _stalled(self, t: float, q: np.ndarray, new: bool) -> bool:
        """True (once per STALL_TIME) when the end effector has stopped short of the target."""
        xe, ye, _ = self.robot.fk(q)
        anchor = self._anchor
        if new or anchor is None or math.hypot(xe - anchor[0], ye - anchor[1]) > STALL_PROGRESS:
            self._anchor, self._anchor_time = (xe, ye), t
            return False
        if t - self._anchor_time > STALL_TIME:
            self._anchor_time = t
            return True
        return False

    def _infeasible_too_long(self, t: float) -> bool:
        """True (once per STALL_TIME) when every plan since STALL_TIME needed slack."""
        since = self._infeasible_since
        if since is None or t - since <= STALL_TIME:
            return False
        self._infeasible_since = t
        return True

    def _state(self, q: np.ndarray, base_velocity: tuple[float, float] | None) -> np.ndarray:
        if self.model_name == "kinematic":
            return q.copy()
        v, w = self._predicted_velocity if base_velocity is None else base_velocity
        # the lagged joints' rates: no sensor reports them, the controller carries them
        # forward from its own commands (estimating them from the measured joint motion
        # tipped 25 of 100 scenarios on the physics plant against 6, both measured with the
        # lagged arm alone, docs/mpc.md)
        lagged = self._predicted_rates if self.arm_time_constant is not None else ()
        return np.concatenate([q, [float(v), float(w)], lagged])

    def _references(self, problem: _Problem, t: float, pose_d, velocity_d) -> np.ndarray:
        """Reference poses of nodes 1..N (N, 3)."""
        times = problem.ocp.node_times(problem.ocp.config.horizon)[1:]
        if self._trajectory is not None:
            return np.array([self._trajectory.pose(t + tau) for tau in times])
        return pose_d[None, :] + times[:, None] * velocity_d[None, :]

    def _moving(self, x0: np.ndarray) -> bool:
        """True when base or arm moves faster than :data:`AT_REST` (m/s, rad/s): at rest
        there is nothing to brake, and a plan that needs slack there (a pose at the floor)
        must be let move the arm back."""
        rates = self._predicted_rates
        speed = max(abs(float(x0[5])), abs(float(x0[6])), abs(rates[0]), abs(rates[1]))
        return speed > AT_REST

    def _braking_input(self, q: np.ndarray, x0: np.ndarray) -> np.ndarray:
        """The braking step at the measured state (force model with the lagged arm)."""
        assert self.dynamics is not None and self.joint_acceleration_limit is not None
        assert self.arm_time_constant is not None
        return braking_input(
            self.dynamics,
            float(q[4]),
            (float(x0[5]), float(x0[6])),
            self._predicted_rates,
            self.joint_acceleration_limit,
            self.arm_time_constant,
        )

    def _braked_velocity(self, q: np.ndarray, x0: np.ndarray, u: np.ndarray) -> tuple:
        """``(v, w)`` (m/s, rad/s) one control step after the braking forces ``u[:2]``
        (Euler on the force model; used only when no measured velocity is given)."""
        assert self.dynamics is not None
        state = np.concatenate([q, x0[5:7]])
        rate = np.asarray(self.dynamics.rhs(state, np.r_[u[:2], 0.0, 0.0]), dtype=float).ravel()
        return float(x0[5] + self.dt * rate[5]), float(x0[6] + self.dt * rate[6])

    def _output(
        self, problem, q, x0, u, w, iterations, braking: bool = False
    ) -> np.ndarray | WheelForces:
        k = self.robot.com_coefficients
        th1, th2 = float(q[3]), float(q[4])
        r1, r2 = float(u[2]), float(u[3])
        # a braking step's rates already slow the joints at their limit: cutting them
        # further would stop the arm at once, the jolt that tipped the robot on MuJoCo
        scale = 1.0 if braking else safe_arm_scale(k, th1, th2, r1, r2, self.dt, self.stability_min)
        r1, r2 = r1 * scale, r2 * scale
        ocp = problem.ocp
        slack = ocp.max_slack(w)
        self.last = StepInfo(
            extra={
                "mpc_iterations": float(iterations),
                "mpc_horizon_s": ocp.horizon_of(w),
                "mpc_slack": slack,
                "mpc_joint_slack": ocp.max_joint_slack(w),
                "arm_scale": scale,
                "mpc_braking": float(braking),
            }
        )
        velocity = (0.0, 0.0)
        if braking:  # the plan's prediction is not what is sent: one Euler step instead
            velocity = self._braked_velocity(q, x0, u)
        elif self.dynamics is not None:
            xs, _ = ocp.trajectories(w)
            velocity = (float(xs[1][5]), float(xs[1][6]))
        return self._apply(float(u[0]), float(u[1]), r1, r2, q, velocity)

    def _apply(
        self, first: float, second: float, r1: float, r2: float, q, velocity: tuple[float, float]
    ) -> np.ndarray | WheelForces:
        """The command ``(first, second, r1, r2)`` as sent (``u``, or wheel forces with
        one-step joint targets from ``q``), remembered for the next step: the input-change
        cost starts from it, and the force model predicts from ``velocity`` (m/s, rad/s)
        and the lagged joint rates (exact for the first-order lag; no sensor reports them)."""
        self._u_prev = np.array([first, second, r1, r2])
        if self.dynamics is None:
            return self._u_prev.copy()
        self._predicted_velocity = velocity
        if self.arm_time_constant is not None:
            keep = math.exp(-self.dt / self.arm_time_constant)
            old1, old2 = self._predicted_rates
            self._predicted_rates = r1 + (old1 - r1) * keep, r2 + (old2 - r2) * keep
        return WheelForces(first, second, float(q[3]) + r1 * self.dt, float(q[4]) + r2 * self.dt)

    def _fallback_command(self, t, q, pose_d, velocity_d, x0, reason: str):
        """The ``qp`` command for this step (counted); the next step starts cold."""
        self.fallbacks += 1
        self._warm = None
        if self._fallback is None:
            self._fallback = self._make_fallback()
        qp = self._fallback
        if self.dynamics is not None:
            qp.ctx.previous_command = (float(x0[5]), float(x0[6]))
        u = np.asarray(qp.command(t, q, pose_d, velocity_d), dtype=float)
        if not np.all(np.isfinite(u)):  # pragma: no cover - the qp has its own safe command
            u = np.zeros(4)
        self.last = StepInfo(fallback=True, extra={"mpc_failure": 1.0})
        self.last_failure = reason
        if self.dynamics is None:
            return self._apply(*map(float, u), q, (0.0, 0.0))
        v, w = float(x0[5]), float(x0[6])
        f_left, f_right = self.dynamics.velocity_tracking_forces(v, w, u[0], u[1], float(q[4]))
        limit = min(self.dynamics.joint_speed, self.robot.joint_speed_limit)
        r1 = min(limit, max(-limit, float(u[2])))
        r2 = min(limit, max(-limit, float(u[3])))
        return self._apply(float(f_left), float(f_right), r1, r2, q, (v, w))

    def _make_fallback(self) -> Any:
        from ddwmmr.controllers.base import make_controller

        options: dict[str, Any] = {
            "stability_min": self.stability_min,
            "track_orientation": self.track_orientation and self._trajectory is not None,
            "obstacles": list(self.obstacles),
            "dt": self.dt,
        }
        if self._trajectory is None:
            options["max_speed"] = 1.0
        if self.dynamics is not None:
            options.update(self.dynamics.velocity_envelope())
        options.update(self._fallback_options)
        qp = make_controller("qp", self.robot, **options)
        qp.reset(self._trajectory, np.zeros(5))
        return qp

    # -- reporting ----------------------------------------------------------------------
    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        """MPC metrics merged into the run summary (see the module docstring)."""
        stability = np.asarray(timeseries["stability"])
        if "fallback" in timeseries:
            fallbacks = int(np.sum(np.asarray(timeseries["fallback"]) > 0))
        else:
            fallbacks = self.fallbacks
        clearance = run_clearance(self.robot, self.obstacles, timeseries)
        mode = "tracking" if self._trajectory is not None else "reach"
        return {
            "stability_min": self.stability_min,
            "stability_violations": int(np.sum(stability < self.stability_min)),
            "mpc_fallbacks": fallbacks,
            "mpc_restarts": self.restarts,
            "mpc_brakes": self.brakes,
            "mpc_brake_slack_m": self.brake_slack,
            "min_obstacle_clearance_m": clearance,
            "mpc_model": self.model_name,
            "mpc_dynamic_stability": self.dynamic_stability,
            "mpc_arm_time_constant_s": self.arm_time_constant,
            "mpc_joint_acceleration_limit_rad_s2": self.joint_acceleration_limit,
            "mpc_wheel_force_limit_n": None if self.dynamics is None else self.dynamics.force_limit,
            "mpc_solver": self.solver_name
            if self.solver_name != "rti"
            else f"rti-{self.qp_solver}",
            "mpc_horizon_s": self._grid[mode][2],
        }

    # -- the scenario protocol's waypoint task -------------------------------------------
    @classmethod
    def waypoint_options(cls, run: WaypointRun) -> dict[str, Any]:
        """The options of a waypoint-task run: it predicts with the thesis base's
        force-level model (wheel forces as decisions) on a plant that takes forces (the
        thesis plant, the physics plant with the thesis damping), with the kinematic model
        on the kinematic plant. Its stability floor is the qp's (``qp_stability_min``).

        On a plant that judges tipping by its physics (``tip_time``) the mpc itself holds
        the floor on the dynamic margin too (``dynamic_stability``: the centre of pressure
        of a robot that turns and accelerates), with the joints lagging as that plant's
        servos do (``arm_time_constant`` = ``plant.joint_time_constant``) and accelerating
        no faster than its motors allow (``joint_acceleration_limit``), braking instead of
        following a plan that needs slack (``brake_slack``), when the loop hands it the
        plant's traits (``adopt_plant``): the static floor alone tipped the robot over in
        94 of 100 scenarios, all of it in none of 400 (docs/mpc.md)."""
        config = run.config
        options: dict[str, Any] = {
            "model": "thesis" if FORCE in run.plant.interfaces else "kinematic",
            "stability_min": config.qp_stability_min,
            "track_orientation": False,
            "obstacles": [tuple(o) for o in run.scenario.obstacles],
            "dt": config.dt,
        }
        options.update(dict(config.controller_options))
        return options


#: Most OCPs kept for reuse by :func:`_shared_ocp` (a run uses one or two; a benchmark
#: worker's scenarios share them).
SHARED_OCPS = 8
_OCPS: OrderedDict[tuple, ShootingOCP] = OrderedDict()
_OCPS_LOCK = threading.Lock()


def _shared_ocp(
    robot: Robot, choice: tuple, model: PredictionModel, config: OCPConfig
) -> ShootingOCP:
    """The OCP of ``robot``, the model ``choice`` (:meth:`MPCController._resolve`,
    which ``model`` was made from) and ``config``: built once and shared by every
    controller that asks for the same one. Building it and its solvers' QP functions took
    0.5 s per benchmark scenario on the thesis plant and 1.5 s on the physics plant (9
    states; both measured on the 2-core machine under load), now 0.02-0.04 s after the
    first; the OCP is symbolic and keeps no state of a run. Shared within a thread only:
    a solver reads its QP's statistics after the call, which another thread's call on the
    same function could replace."""
    key = (threading.get_ident(), robot, choice, config)
    try:
        hash(key)
    except TypeError:  # an unhashable option from somewhere: build it, do not share
        return ShootingOCP(robot, model, config)
    with _OCPS_LOCK:
        ocp = _OCPS.get(key)
        if ocp is not None:
            _OCPS.move_to_end(key)
            return ocp
    ocp = ShootingOCP(robot, model, config)  # outside the lock: it takes a while
    with _OCPS_LOCK:
        _OCPS[key] = ocp
        if len(_OCPS) > SHARED_OCPS:
            _OCPS.popitem(last=False)
    return ocp


class _Problem:
    """One OCP with its solvers, terminal design and warm-start shifting."""

    def __init__(self, owner: MPCController, config: OCPConfig) -> None:
        self.owner = owner
        self.ocp = _shared_ocp(owner.robot, owner._choice, owner.model, config)
        name = owner.solver_name
        self.solver = make_solver(name, self.ocp, owner.qp_solver, proximal=owner.proximal)
        self.cold = (
            make_solver("sqp", self.ocp, owner.qp_solver, iterations=COLD_ITERATIONS)
            if name == "rti"
            else self.solver
        )
        self.terminal_factor: np.ndarray | None = None

    def design_terminal(self, arm_pose: tuple[float, float]) -> None:
        """LQR terminal cost at the arm pose (tracking only)."""
        if self.ocp.config.reach:
            return
        design = terminal.design(self.owner.robot, self.owner.model, self.ocp.config, arm_pose)
        self.terminal_factor = design.factor

    def _initial(self, x0: np.ndarray) -> np.ndarray:
        ocp = self.ocp
        node = np.concatenate([x0, [ocp.config.horizon]])[: ocp.nx]
        return ocp.pack(np.tile(node, (ocp.N + 1, 1)), np.zeros((ocp.N, ocp.nu)))

    def _shifted(self, warm: np.ndarray, elapsed: float, x0: np.ndarray) -> tuple:
        """The previous solution moved ``elapsed`` s forward (linear interpolation)."""
        ocp = self.ocp
        xs, us = ocp.trajectories(warm)
        old_horizon = ocp.horizon_of(warm)
        horizon = old_horizon
        if ocp.config.reach:
            horizon = min(max(old_horizon - elapsed, ocp.config.min_horizon), ocp.config.horizon)
        old_t = ocp.node_times(old_horizon)
        new_t = ocp.node_times(horizon) + elapsed
        xs = _interpolate_rows(old_t, xs, new_t)
        us = _interpolate_rows(old_t[:-1], us, new_t[:-1])
        if ocp.config.reach:
            xs[:, -1] = horizon
        xs[0, : ocp.nxm] = x0
        return ocp.pack(xs, us), horizon

    def solve(self, t, x0, references, u_prev, warm, warm_time) -> tuple[np.ndarray, int]:
        """Solve from the shifted warm start (or cold); returns (w, iterations)."""
        ocp = self.ocp
        if warm is None:
            guess, horizon, solver = self._initial(x0), ocp.config.horizon, self.cold
        else:
            guess, horizon = self._shifted(warm, max(0.0, t - warm_time), x0)
            solver = self.solver
        p = ocp.parameters(references, u_prev, self.terminal_factor, horizon_prev=horizon)
        lbw, ubw = ocp.bounds(x0)
        w = solver.solve(guess, p, lbw, ubw, ocp.lbg, ocp.ubg)
        return w, solver.last_iterations


def _interpolate_rows(times: np.ndarray, rows: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Rows (one per time, increasing) linearly interpolated at ``at``, held beyond the ends
    (``np.interp`` on every column at once)."""
    at = np.clip(at, times[0], times[-1])
    upper = np.clip(np.searchsorted(times, at, side="right"), 1, len(times) - 1)
    lower = upper - 1
    span = times[upper] - times[lower]
    weight = np.where(span > 0.0, (at - times[lower]) / np.where(span > 0.0, span, 1.0), 0.0)
    return rows[lower] + weight[:, None] * (rows[upper] - rows[lower])
