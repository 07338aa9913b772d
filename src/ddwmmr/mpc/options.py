"""The ``mpc``'s options: one frozen :class:`MPCOptions`, checked when made, resolved
against the plant's traits in one place (:meth:`MPCOptions.adopt_plant`).

Options documented as "None: chosen for the plant" are filled in by
:meth:`MPCOptions.adopt_plant`, once with no plant when the controller is built and again
with the loop's plant (``adopt_plant(traits)`` of the controller protocol); the result is
the options the controller runs with, every one of them a value, and the run's summary
prints it whole (``mpc_options``, :meth:`MPCOptions.record`). The grid's and the cost's
"None: per objective" options are filled in for the objective a run uses
(:meth:`MPCOptions.grid`, :meth:`MPCOptions.weights`).
"""

from __future__ import annotations

import copy
import inspect
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any

from ddwmmr.commands import FORCE, PlantTraits
from ddwmmr.errors import (
    LENGTH_RANGE_M,
    MAX_COST_WEIGHT,
    ParameterError,
    check_bool,
    check_finite,
    check_int_at_least,
    check_nonnegative,
    check_positive,
    check_range,
    check_weight,
    one_of,
    shown,
    texts_apart,
    xy_pairs,
)
from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.stability import (
    STABILITY_CAP,
    STABILITY_FLOOR,
    check_stability_floor,
    valid_stability_floor,
)
from ddwmmr.model.support_loads import DEFAULT_MIN_EDGE_LOAD, check_min_edge_load
from ddwmmr.model.thesis_base import (
    C1_DEFAULT,
    C2_DEFAULT,
    FORCE_LIMIT_DEFAULT,
    motors_share,
)
from ddwmmr.mpc.braking import BRAKE_SLACK
from ddwmmr.mpc.ocp import (
    MAX_HORIZON,
    MAX_INTERVALS,
    MIN_INTERVAL,
    Weights,
    check_step_in_horizon,
    shooting_grid,
)
from ddwmmr.mpc.problem import COLD_ITERATIONS
from ddwmmr.mpc.solvers import DEFAULT_QP_SOLVER, QP_BACKED_SOLVERS, QP_SOLVERS, SOLVERS
from ddwmmr.qp.limits import as_circles
from ddwmmr.qp.limits.obstacles import robot_margin

MODELS = ("kinematic", "thesis")
#: Control step (s) when neither ``dt`` nor the trajectory's resolution is known.
DEFAULT_DT = 0.02
#: ``stability_margin`` when it is not given: the OCP's floor on S above ``stability_min``.
DEFAULT_STABILITY_MARGIN = 0.01
#: Defaults per objective: (intervals, first interval s, horizon s). Chosen by the horizon
#: study in docs/mpc.md.
GRID_DEFAULTS = {"tracking": (10, 0.05, 1.0), "reach": (12, 0.05, 5.0)}
#: Default position weight per objective (1/(m^2 s); per the robot's length unit squared
#: on another robot, docs/mpc.md "Robot size").
POSITION_WEIGHTS = {"tracking": 100.0, "reach": 50.0}
#: Huber scale of the position error in waypoint mode when ``huber`` is not given, in the
#: robot's length unit (m for the default robot; docs/mpc.md, "Robot size").
REACH_HUBER = 0.01
#: ``reach_speed`` in waypoint mode when it is not given, in the robot's length unit per
#: second (m/s for the default robot; docs/mpc.md, "Robot size").
REACH_SPEED = 0.05


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
    def of(cls, plant: PlantTraits | None, force_limit: float | None) -> BaseFacts:
        """The facts ``plant`` states (none for an unknown plant) with the wheel force
        ``force_limit`` (N) the model plans with."""
        if plant is None:
            return cls(force_limit=force_limit)
        return cls(plant.base_damping, force_limit, plant.wheel_lever)

    def dynamics(self, robot: Robot) -> sym.ThesisDynamics:
        """The force-level model of ``robot`` on a base with these facts."""
        c1, c2 = self.damping if self.damping is not None else (C1_DEFAULT, C2_DEFAULT)
        force = self.force_limit if self.force_limit is not None else FORCE_LIMIT_DEFAULT
        return sym.ThesisDynamics.from_robot(robot, c1, c2, force, half_width=self.lever)


def planned_force(plant: PlantTraits | None) -> float:
    """The wheel force (N) the force model plans with by default on ``plant``: the plant's
    own limit where the model is the plant's (the thesis plant); on a plant that judges
    tipping by its physics, the thesis model's share of the plant's motors
    (:func:`~ddwmmr.model.thesis_base.motors_share` of ``wheel_force_limit``: the force
    limit the thesis plant derives for the same robot, 10 N of the thesis robot's 20.5 N,
    always within the motors); the thesis's 10 N on a plant that does not say, or before
    the plant is known. Why not the motors' full force there: docs/mpc.md, "The physics
    plant: tipping while moving"."""
    motors = None if plant is None else plant.wheel_force_limit
    if motors is None:
        return FORCE_LIMIT_DEFAULT
    return motors_share(motors) if plant.judges_tipping else motors  # type: ignore[union-attr]


@dataclass(frozen=True)
class MPCOptions:
    """Options of the nonlinear MPC (method ``mpc``), each checked when the object is made.

    Attributes:
        model: ``"kinematic"`` (velocity commands, the kinematic plant) or ``"thesis"``
            (wheel forces, the thesis plant's force-level dynamics; needs the measured base
            velocities, ``base_velocity=(v, w)``); None (default): chosen for the plant
            (:meth:`adopt_plant`: ``"thesis"`` on a plant that takes wheel forces and
            judges tipping by its physics, or when ``dynamic_stability``,
            ``arm_time_constant``, ``joint_acceleration_limit`` or ``wheel_force_limit``
            asks for it, else ``"kinematic"``).
        stability_min: floor S_min of the tip-over margin (hard, exact at every node).
        manipulability_weight: weight of ``cos^2 th2`` (soft).
        obstacles: circles (``Circle`` or (x, y, radius) triples, m) or a TOML file path,
            kept as a tuple of circles; the base's enclosing circle keeps
            ``obstacle_margin`` (m) from each.
        track_orientation: cost on the end-effector orientation (tracking).
        horizon, intervals, first_interval: the grid (s, count, s); None: per objective,
            :data:`GRID_DEFAULTS` (:meth:`grid`). ``intervals`` in [2, 200]: the control
            step dt, then ``intervals - 1`` growing geometrically from ``first_interval``
            to fill the horizon (with 2, one interval spanning the rest of it); the
            horizon must be at least ``dt + (intervals - 1) x first_interval``.
        solver: ``"rti"`` (one Gauss-Newton iteration per step, default), ``"sqp"``
            (iterated Gauss-Newton), ``"ipopt"``, ``"sqpmethod"`` or ``"fatrop"``.
        qp_solver: QP backend of ``rti``/``sqp`` (``"hpipm"`` default); another with a
            solver that takes none (``"ipopt"``, ``"sqpmethod"``, ``"fatrop"``) is refused:
            it would have no effect, yet the run's record would show it.
        cold_iterations: Gauss-Newton iterations (one QP each) of a cold start with
            ``solver="rti"`` (the first step, a new waypoint, after a fallback or a stall),
            in [1, 20]; the later steps refine the plan one iteration each, so fewer bound
            the slowest step at the cost of a rougher first plan (docs/mpc.md, "Where an
            MPC step's time goes").
        position_weight, orientation_weight, input_weight: cost weights (see
            :class:`ddwmmr.mpc.ocp.Weights`; position None: per objective,
            :data:`POSITION_WEIGHTS`); huber: Huber scale (m) of position errors (None:
            :data:`REACH_HUBER` in waypoint mode, none when tracking).
        reach_speed: waypoint mode: m/s converting the distance left at the end of the
            horizon into seconds; None (default): the robot's own, :data:`REACH_SPEED` of
            its length unit per second (:meth:`robot_reach_speed`; 0.05 m/s on the default
            robot).
        lookahead: waypoint mode: plan through the current target to the next one of
            ``route`` (two legs of free duration, each at most ``horizon``), so that the
            robot arrives moving the way the next leg wants; off (default): one target at
            a time (docs/mpc.md, "Planning through the next waypoint").
        lookahead_weight: the second leg's time and reach cost against the first's, in
            [0, 1] (default 0.5; 1: the plan minimises the time of both legs, but where the
            second leg cannot reach its target that ties with giving up the first).
        lookahead_horizon: the second leg's longest duration (s), with as many intervals
            as the first leg.
        route: the task's waypoints ``(x, y)`` in order (m, world; a list, not a set)
            that ``lookahead`` and ``plan`` look along; the scenario protocol fills it in
            with either.
        plan: waypoint mode: a minimum-time trajectory of the whole task, one leg per
            waypoint of ``route`` (a ``.npz`` as ``python -m ddwmmr.bounds`` stores its
            best-known ones, :meth:`ddwmmr.mpc.min_time.Guess.load`; in the scenario tool
            also that tool's output folder, each scenario's own file taken from it). Every
            cold start (a new target, a restart) starts from the plan's leg to the target
            (and the next leg with ``lookahead``) instead of a standing guess, so the plan
            the controller settles in has the offline plan's structure (direction of
            travel, elbow branch, turns); None (default): no plan (docs/mpc.md,
            "Following an offline plan's structure").
        plan_weight: with a ``plan``: the weight ``Wa`` of the cost ``0.5 Wa |e|^2`` (s)
            on the state the controller's plan arrives at the target in, ``e`` its
            difference from the plan's state there (heading as a chord, joint angles in
            rad, base velocities in m/s and rad/s), so that it arrives as the plan of the
            whole task does; off on the plan's last leg; 0: the plan only starts the cold
            starts (default 2; docs/mpc.md, "Arriving as the plan does").
        proximal: damping of the input steps between two solves (see
            :class:`ddwmmr.mpc.solvers.GaussNewtonSQP`).
        stability_margin: the OCP keeps ``S >= stability_min + stability_margin``; >= 0,
            and the sum below S's cap (:data:`~ddwmmr.model.stability.STABILITY_CAP`),
            which a floor at or above it could never meet.
        dynamic_stability: keep every edge of the support polygon loaded while moving (at
            least ``min_edge_load``; the edge loads of the force model with the inertial
            forces of turning, accelerating and the arm's motion, ``model="thesis"`` only;
            docs/mpc.md), besides the static floor on the centre of mass; None (default):
            on exactly when the force model runs on a physics plant.
        min_edge_load: with ``dynamic_stability``, the least load every edge keeps, as a
            share of the weight in [0, 0.5) (default 0.1: 14.7 N with 3 kg, the static
            floor S 1.25's own side-edge load).
        arm_time_constant: the joints follow the commanded rates with this first-order lag
            (s) in the prediction (``model="thesis"`` only; the physics plant's joint
            servos have one); None (default): that plant's lag when the force model runs on
            a physics plant, else none; 0: none (the joints move at the commanded rates at
            once).
        joint_acceleration_limit: bound (rad/s^2) on the lagged joints' accelerations, one
            number for both or (shoulder, elbow), kept as the pair (with the lagged arm
            only: the physics plant's servos are torque-limited); None (default): that
            plant's (``PlantTraits.joint_acceleration_limit``) when the lagged arm runs on
            a physics plant, else none; 0 (kept as ``()``): none.
        wheel_force_limit: per-wheel traction force (N) the force model plans with
            (``model="thesis"`` only), at most the plant's motors
            (``PlantTraits.wheel_force_limit``; more is refused when the loop hands over the
            plant's traits); None (default): :func:`planned_force`, the thesis plant's own
            limit there, the thesis's 10 N on a physics plant.
        brake_slack: when the plan needs more slack in its stability rows than this (m,
            in the box on the centre of mass and the zero moment point; 0 or in [1e-4, 1])
            while the robot moves, the step brakes instead
            (:func:`ddwmmr.mpc.braking.braking_input`: base and arm slowed within the force
            and acceleration limits), counted in ``mpc_brakes``; only with the lagged arm
            and a joint acceleration limit; None (default): :data:`BRAKE_SLACK` (5 mm)
            there, else off; 0: off.
        frozen_restart: in waypoint mode, start cold when every plan for 0.5 s promised
            the same arrival time (:mod:`ddwmmr.mpc.stall`); None (default): on, except
            where the braking step is on (the lagged arm on a physics plant: there a cold
            start is when the plans are most violent, and a frozen plan's cold start tipped
            scenario 99 of seed 1; docs/mpc.md, "Seed 1's re-search finished, and a frozen
            plan").
        obstacle_margin: clearance (m, >= 0) of the base's enclosing circle from each
            obstacle; None (default): the robot's own,
            :data:`~ddwmmr.qp.limits.obstacles.MARGIN` of its length unit
            (:meth:`robot_obstacle_margin`; 0.05 m on the default robot). No upper bound:
            the OCP holds every circle at every node, near or far.
        dt: control step (s); None (default): the loop's control step
            (``adopt_control_step``), else the trajectory's ``duration / samples`` at
            reset, else :data:`DEFAULT_DT`.
        fallback_options: options of the ``qp`` fallback controller, a dict by name
            (merged over the defaults derived from these options; None: none).
    """

    model: str | None = None
    stability_min: float = STABILITY_FLOOR
    manipulability_weight: float = 0.5
    obstacles: Sequence[Any] | str = ()
    track_orientation: bool = True
    horizon: float | None = None
    intervals: int | None = None
    first_interval: float | None = None
    solver: str = "rti"
    qp_solver: str = DEFAULT_QP_SOLVER
    cold_iterations: int = COLD_ITERATIONS
    position_weight: float | None = None
    orientation_weight: float = 10.0
    input_weight: float = 0.01
    huber: float | None = None
    reach_speed: float | None = None
    lookahead: bool = False
    lookahead_weight: float = 0.5
    lookahead_horizon: float = 12.0
    route: Sequence[Sequence[float]] = ()
    plan: str | None = None
    plan_weight: float = 2.0
    proximal: float = 0.01
    stability_margin: float = DEFAULT_STABILITY_MARGIN
    dynamic_stability: bool | None = None
    min_edge_load: float = DEFAULT_MIN_EDGE_LOAD
    arm_time_constant: float | None = None
    joint_acceleration_limit: float | Sequence[float] | None = None
    wheel_force_limit: float | None = None
    brake_slack: float | None = None
    frozen_restart: bool | None = None
    obstacle_margin: float | None = None
    dt: float | None = None
    fallback_options: dict[str, Any] | None = None

    def __post_init__(self) -> None:
        model, solver, qp_solver = self.model, self.solver, self.qp_solver
        if model is not None and not one_of(model, MODELS):
            raise ParameterError(f"model must be one of {', '.join(MODELS)} (got {shown(model)})")
        if not one_of(solver, SOLVERS):
            raise ParameterError(
                f"solver must be one of {', '.join(SOLVERS)} (got {shown(solver)})"
            )
        if not one_of(qp_solver, QP_SOLVERS):
            raise ParameterError(
                f"qp_solver must be one of {', '.join(QP_SOLVERS)} (got {shown(qp_solver)})"
            )
        if solver not in QP_BACKED_SOLVERS and qp_solver != DEFAULT_QP_SOLVER:
            raise ParameterError(
                f"qp_solver needs solver {' or '.join(QP_BACKED_SOLVERS)}: solver "
                f"{shown(solver)} uses no QP backend (got qp_solver {shown(qp_solver)})"
            )
        self._set(
            "cold_iterations", check_int_at_least("cold_iterations", self.cold_iterations, 1, 20)
        )
        lag = self.arm_time_constant
        if lag is not None and lag != 0.0:
            check_range("arm_time_constant", lag, 1e-3, 1.0, "s")
        self._set("arm_time_constant", None if lag is None else float(lag))
        self._set("joint_acceleration_limit", _acceleration_option(self.joint_acceleration_limit))
        if self.wheel_force_limit is not None:
            force = check_range("wheel_force_limit", self.wheel_force_limit, 1e-6, 1e7, "N")
            self._set("wheel_force_limit", force)
            if model == "kinematic":
                raise ParameterError("wheel_force_limit needs model='thesis'")
        if self.brake_slack is not None:
            brake = check_finite(
                "brake_slack", self.brake_slack, "equal to 0 (off) or in [0.0001, 1] m"
            )
            if brake != 0.0 and not 1e-4 <= brake <= 1.0:
                raise ParameterError(
                    f"brake_slack must be 0 (off) or in [0.0001, 1] m (got {self.brake_slack:g})"
                )
            self._set("brake_slack", brake)
        if self.dynamic_stability is not None:
            self._set("dynamic_stability", check_bool("dynamic_stability", self.dynamic_stability))
        if self.frozen_restart is not None:
            self._set("frozen_restart", check_bool("frozen_restart", self.frozen_restart))
        self._set("min_edge_load", check_min_edge_load(self.min_edge_load))
        self.adopt_plant(None)  # the combinations that need the force model, plant aside
        self._set("stability_min", check_stability_floor(self.stability_min))
        self._set("obstacles", tuple(as_circles(self.obstacles)))
        self._set("track_orientation", check_bool("track_orientation", self.track_orientation))
        self._set("lookahead", check_bool("lookahead", self.lookahead))
        self._set(
            "lookahead_weight", check_range("lookahead_weight", self.lookahead_weight, 0.0, 1.0)
        )
        self._set("route", _route_option(self.route))
        if self.plan is not None:
            if not isinstance(self.plan, str | os.PathLike) or not str(self.plan):
                raise ParameterError(f"plan must be a file path (got {shown(self.plan)})")
            self._set("plan", str(self.plan))
        self._set(
            "lookahead_horizon",
            check_range("lookahead_horizon", self.lookahead_horizon, 0.5, MAX_HORIZON, "s"),
        )
        if self.dt is not None:
            self._set("dt", check_positive("dt", self.dt))
        for mode in GRID_DEFAULTS:
            self.grid(mode)
            self.weights(mode)
        if self.huber is not None:  # None: per objective (huber_scale)
            self._set("huber", _check_huber("huber", self.huber))
        for name, check in (  # None is no value of these: refused as any non-number
            ("proximal", check_nonnegative),
            ("stability_margin", check_nonnegative),
            ("plan_weight", check_weight),
        ):
            self._set(name, check(name, getattr(self, name)))
        if self.reach_speed is not None:  # None: the robot's own (robot_reach_speed)
            self._set("reach_speed", check_positive("reach_speed", self.reach_speed))
        if self.obstacle_margin is not None:  # None: the robot's own (robot_obstacle_margin)
            self._set("obstacle_margin", robot_margin(self.obstacle_margin, 1.0))
        self._check_stability_target()
        self._set("fallback_options", _fallback_option(self.fallback_options))

    def _set(self, name: str, value: Any) -> None:
        object.__setattr__(self, name, value)

    def _check_stability_target(self) -> None:
        """Refuse a ``stability_margin`` that puts the OCP's floor ``stability_min +
        stability_margin`` at or above S's cap (a floor no S can meet,
        :func:`~ddwmmr.model.stability.valid_stability_floor`), naming the margin's range
        for this ``stability_min``."""
        floor, margin = self.stability_min, self.stability_margin
        if valid_stability_floor(floor + margin):
            return
        if margin == DEFAULT_STABILITY_MARGIN:  # the floor the user set is what lifts it
            got, (top,) = texts_apart(floor, STABILITY_CAP - margin)
            raise ParameterError(
                f"stability_min must be in (0, {top}) with stability_margin {margin:g}: the "
                f"OCP keeps S >= stability_min + stability_margin, and S is capped at "
                f"{STABILITY_CAP:g} (got {got})"
            )
        got, (room,) = texts_apart(margin, STABILITY_CAP - floor)
        raise ParameterError(
            f"stability_margin must be in [0, {room}) with stability_min {floor:g}: the OCP "
            f"keeps S >= stability_min + stability_margin, and S is capped at "
            f"{STABILITY_CAP:g} (got {got})"
        )

    # -- resolution ---------------------------------------------------------------------
    def adopt_plant(self, plant: PlantTraits | None) -> MPCOptions:
        """These options with every "None: chosen for the plant" filled in for ``plant``
        (None: not known yet; combinations that need the plant are then let pass).

        On a plant that takes wheel forces and judges tipping by its physics: the
        force-level model, the floor on the dynamic margin and the plant's joint lag (docs/mpc.md,
        "The physics plant: tipping while moving"; likewise for ``model="thesis"`` given
        there); elsewhere the kinematic model (the force model
        when any force-model option is given: ``dynamic_stability``, a lag, a joint
        acceleration bound or a wheel force), static floor, no lag. The force model's wheel
        force is the one asked for (within the plant's motors), else
        :func:`planned_force`. The lagged joints' accelerations are bounded as asked, else
        by the physics plant's motors; the braking step is on (``brake_slack``) where the
        lagged arm has that bound, and a frozen plan's cold start (``frozen_restart``)
        everywhere else.

        In the result ``arm_time_constant`` 0, ``joint_acceleration_limit`` ``()`` and
        ``brake_slack`` 0 mean none, and ``wheel_force_limit`` is None for the kinematic
        model (which has no wheel forces).
        """
        physics = plant is not None and plant.judges_tipping and FORCE in plant.interfaces
        wants_force = (
            bool(self.dynamic_stability)
            or bool(self.arm_time_constant)
            or bool(self.joint_acceleration_limit)
            or self.wheel_force_limit is not None
        )
        model = self.model or ("thesis" if physics or wants_force else "kinematic")
        suited = physics and model == "thesis"  # the force model on a physics plant
        dynamic = self.dynamic_stability if self.dynamic_stability is not None else suited
        lag = self.arm_time_constant
        if lag is None:
            lag = plant.joint_time_constant if suited else None  # type: ignore[union-attr]
        accel = self.joint_acceleration_limit
        if accel is None and suited:
            accel = plant.joint_acceleration_limit  # type: ignore[union-attr]
        if accel and not lag:
            if plant is not None and self.joint_acceleration_limit:
                raise ParameterError(
                    "joint_acceleration_limit needs the lagged arm (arm_time_constant, or a "
                    "physics plant's joint lag)"
                )
            accel = None  # the plant is not known yet (or has no lag): nothing to bound
        if lag and model != "thesis":
            raise ParameterError("arm_time_constant needs model='thesis'")
        if dynamic and model != "thesis":
            raise ParameterError(
                "dynamic_stability needs model='thesis' (the kinematic model has no base "
                "accelerations)"
            )
        force = self._planned_force(plant) if model == "thesis" else None
        brakeable = bool(lag) and bool(accel)  # the braking step needs both
        if self.brake_slack and not brakeable and plant is not None:
            raise ParameterError(
                "brake_slack needs the lagged arm with a joint acceleration limit (a physics "
                "plant, or arm_time_constant and joint_acceleration_limit)"
            )
        braked = brakeable and self.brake_slack != 0.0
        resolved = copy.copy(self)  # values taken from the plant are not options to check
        for name, value in (
            ("model", model),
            ("dynamic_stability", dynamic),
            ("arm_time_constant", lag or 0.0),
            ("joint_acceleration_limit", accel or ()),
            ("wheel_force_limit", force),
            ("brake_slack", (self.brake_slack or BRAKE_SLACK) if braked else 0.0),
            ("frozen_restart", not braked if self.frozen_restart is None else self.frozen_restart),
        ):
            resolved._set(name, value)
        return resolved

    def _planned_force(self, plant: PlantTraits | None) -> float:
        """The wheel force (N) asked for, refused above the plant's motors, else
        :func:`planned_force`."""
        force = self.wheel_force_limit
        if force is None:
            return planned_force(plant)
        motors = None if plant is None else plant.wheel_force_limit
        if motors is not None and force > motors:
            raise ParameterError(
                f"wheel_force_limit must be <= the plant's motors, {motors:.4g} N per wheel "
                f"(got {force:g})"
            )
        return force

    def grid(self, mode: str) -> tuple[int, float, float]:
        """``(intervals, first interval s, horizon s)`` of objective ``mode``
        (``"tracking"`` or ``"reach"``), the options given else :data:`GRID_DEFAULTS`; a
        short horizon with the default first interval gets uniform intervals. Checked as
        the OCP checks its grid (:func:`ddwmmr.mpc.ocp.shooting_grid`: ``intervals`` in
        [2, 200], ``horizon > dt`` and ``horizon >= dt + (intervals - 1) x
        first_interval``) at the control step ``dt`` (else :data:`DEFAULT_DT`), so a grid
        these options accept is one the OCP builds. A step too long for the horizon names
        the horizon when it was given, else ``dt``
        (:func:`~ddwmmr.mpc.ocp.check_step_in_horizon`, which also refuses a loop's step
        too long for the grid when the controller adopts it)."""
        dt = self.dt or DEFAULT_DT
        n0, h0, t0 = GRID_DEFAULTS[mode]
        intervals, horizon = self.intervals, self.horizon
        n = check_int_at_least(
            "intervals", n0 if intervals is None else intervals, 2, MAX_INTERVALS
        )
        t = check_range(
            "horizon", t0 if horizon is None else horizon, MIN_INTERVAL, MAX_HORIZON, "s"
        )
        if horizon is not None and not t > dt:
            raise ParameterError(f"horizon must be > the control step dt = {dt:g} s (got {t:g})")
        if self.first_interval is None:
            h = min(h0, max((t - dt) / (n - 1), MIN_INTERVAL))
        else:
            h = self.first_interval
        shooting_grid(n, dt, h, t)  # the OCP's own check (one-line errors)
        return int(n), float(h), float(t)

    def grid_at(self, mode: str, dt: float) -> tuple[int, float, float]:
        """``(intervals, first interval s, horizon s)`` of objective ``mode`` as a run at
        control step ``dt`` (s) builds it: :meth:`grid` with the first interval shortened
        to the horizon's rest, ``(horizon - dt) / (intervals - 1)``, when that is shorter;
        a ``dt`` with no room left is refused naming ``dt``
        (:func:`~ddwmmr.mpc.ocp.check_step_in_horizon`)."""
        n, h, t = self.grid(mode)
        dt = check_step_in_horizon(dt, t, n)
        return n, min(h, (t - dt) / (n - 1)), t

    def weights(self, mode: str) -> Weights:
        """The cost weights of objective ``mode`` (the terminal cost only when tracking)."""
        position = self.position_weight
        return Weights(  # which checks them
            position=POSITION_WEIGHTS[mode] if position is None else position,
            orientation=self.orientation_weight,
            manipulability=self.manipulability_weight,
            input=self.input_weight,
            terminal=1.0 if mode == "tracking" else 0.0,
        )

    def huber_scale(self, mode: str, unit: float = 1.0) -> float | None:
        """Huber scale (m) of objective ``mode``: ``huber``, else :data:`REACH_HUBER` of
        the robot's length ``unit`` (m) in waypoint mode and none when tracking."""
        if self.huber is not None:
            return self.huber
        return REACH_HUBER * unit if mode == "reach" else None

    def robot_obstacle_margin(self, length: float) -> float:
        """The clearance (m) kept from every obstacle by a robot of length unit ``length``
        (m, :func:`~ddwmmr.resolution.kernels.length_unit`, whatever the model):
        ``obstacle_margin``, else the robot's own
        (:func:`~ddwmmr.qp.limits.obstacles.robot_margin`, as the qp's)."""
        return robot_margin(self.obstacle_margin, length)

    def robot_reach_speed(self, length: float) -> float:
        """The waypoint mode's ``reach_speed`` (m/s) for a robot of length unit ``length``
        (m, whatever the model): ``reach_speed``, else :data:`REACH_SPEED` of the unit per
        second. A ``reach_speed`` below the robot's least, ``length /``
        :data:`~ddwmmr.errors.MAX_COST_WEIGHT` (1e-6 of the unit per second, 1e-6 m/s on
        ``Robot()``), is a one-line :class:`ParameterError` naming that range: its
        reciprocal is the reach cost's weight, seconds per unit of distance left at the
        horizon's end, capped as every cost weight. At the cap a unit left costs 1e6 s,
        1e4 times the longest horizon (:data:`~ddwmmr.mpc.ocp.MAX_HORIZON`), so a lower
        speed changes nothing a plan weighs (reaching outweighs time either way) but the
        solver's conditioning."""
        if self.reach_speed is None:
            return REACH_SPEED * length
        least = length / MAX_COST_WEIGHT
        if self.reach_speed < least * (1.0 - 1e-12):  # the unit's own rounding passes
            got, (low,) = texts_apart(self.reach_speed, least)
            raise ParameterError(
                f"reach_speed must be >= {low} m/s for this robot, {1.0 / MAX_COST_WEIGHT:g} "
                f"of its length unit ({length:g} m) per second: its reciprocal weighs the "
                f"distance left, at most {MAX_COST_WEIGHT:g} s per unit as every cost weight "
                f"(got {got})"
            )
        return self.reach_speed

    # -- reporting ----------------------------------------------------------------------
    def record(
        self, mode: str, dt: float, unit: float = 1.0, length: float = 1.0
    ) -> dict[str, Any]:
        """Every option with the value a run of objective ``mode`` at control step ``dt``
        (s) uses: the grid, the position weight and the Huber scale of that objective (the
        default Huber scale in the OCP's length ``unit``, m), ``obstacle_margin`` and
        ``reach_speed`` of a robot of length unit ``length`` (m), in plain types for the
        run's summary."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        intervals, first, horizon = self.grid_at(mode, dt)
        values.update(
            intervals=intervals,
            # the interval after dt as the controller builds it (with 2, the horizon's rest)
            first_interval=float(shooting_grid(intervals, dt, first, horizon)[1]),
            horizon=horizon,
            position_weight=self.weights(mode).position,
            huber=self.huber_scale(mode, unit),
            obstacle_margin=self.robot_obstacle_margin(length),
            reach_speed=self.robot_reach_speed(length),
            dt=dt,
            obstacles=[(c.x, c.y, c.radius) for c in self.obstacles],  # type: ignore[union-attr]
            joint_acceleration_limit=list(self.joint_acceleration_limit or ()),  # type: ignore[arg-type]
        )
        return values


def _fallback_option(value: Any) -> dict[str, Any]:
    """The ``fallback_options`` option: the ``qp``'s options by name (None: none), kept as
    a dict."""
    if value is None:
        return {}
    if not isinstance(value, Mapping) or not all(isinstance(key, str) for key in value):
        raise ParameterError(
            f"fallback_options must be a dict of qp options by name (got {shown(value)})"
        )
    return dict(value)


def _route_option(value: Any) -> tuple[tuple[float, float], ...]:
    """The ``route`` option: points ``(x, y)`` (m), kept as a tuple of float pairs
    (:func:`~ddwmmr.errors.xy_pairs`, possibly empty)."""
    return xy_pairs("route", value, empty=True)


def _acceleration_option(value: Any) -> tuple[float, float] | tuple[()] | None:
    """The ``joint_acceleration_limit`` option: None (not given), ``()`` (0: none) or
    ``(shoulder, elbow)`` rad/s^2."""
    if value is None or (isinstance(value, tuple) and not value):
        return value
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


def options_signature() -> inspect.Signature:
    """The signature ``(self, robot, *, <every option with its default>)`` of the
    controller's constructor: what :func:`ddwmmr.controllers.base.method_options` and the
    app read (each option's default and annotation, as :class:`MPCOptions` has them)."""
    keyword = inspect.Parameter.KEYWORD_ONLY
    positional = inspect.Parameter.POSITIONAL_OR_KEYWORD
    parameters = [
        inspect.Parameter("self", positional),
        inspect.Parameter("robot", positional, annotation="Robot"),
    ]
    parameters += [
        inspect.Parameter(f.name, keyword, default=f.default, annotation=f.type)
        for f in fields(MPCOptions)
    ]
    return inspect.Signature(parameters)


def _check_huber(name: str, value: float) -> float:
    """A Huber scale (m): a length (:data:`~ddwmmr.errors.LENGTH_RANGE_M`); it is squared
    in the cost, so 1e300 overflowed."""
    return check_range(name, value, *LENGTH_RANGE_M, "m")
