"""The nonlinear MPC controller, registered as method ``mpc`` (docs/mpc.md).

Every control step (one call per step; the command is held over it, ``zero_order_hold``):

1. the measured state (configuration, and the base velocities for the thesis model) pins
   node 0 of the OCP (:mod:`ddwmmr.mpc.ocp`);
2. the references of the nodes come from the trajectory's future poses (tracking), or the
   target ``pose_d`` is to be reached as early as possible (waypoint mode, free horizon;
   with a ``plan``, an offline minimum-time trajectory of the task, arriving there in the
   plan's state, ``plan_weight``);
3. the previous solution, shifted by the elapsed time, is the warm start; one Gauss-Newton
   iteration (the real-time iteration, default) or a full solve updates it;
4. the first input is applied: a velocity command (kinematic model) or wheel forces and
   one-step joint targets (thesis model); an exact check of S one step ahead scales the
   joint rates back if the linearisation was too optimistic (not a braking step's rates,
   which already slow the joints at their acceleration limit). On a lagged arm with a
   joint acceleration limit (a physics plant), a plan whose stability rows need more
   slack than ``brake_slack`` while the robot moves is replaced by the braking step
   (:mod:`ddwmmr.mpc.braking`).

In waypoint mode a plan that makes no progress, needs slack, or promises the same arrival
time for 0.5 s (``frozen_restart``, off where the braking step runs) is dropped and the
next step starts cold (:mod:`ddwmmr.mpc.stall`). The options are one frozen
:class:`~ddwmmr.mpc.options.MPCOptions`, resolved for the plant in one place; the OCPs are
shared between controllers (:mod:`ddwmmr.mpc.cache`).

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
``stability_violations`` (steps that ended with S < floor), ``mpc_fallbacks`` (steps that
used the ``qp`` fallback; both of the run's ``steps``:
:func:`~ddwmmr.controllers.base.step_results`,
:func:`~ddwmmr.controllers.base.commanded_steps`), ``mpc_brakes`` (braking steps),
``mpc_model``, ``mpc_solver``; the full list is in docs/mpc.md, "Options".
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import fields
from typing import Any, ClassVar, cast

import numpy as np

from ddwmmr.behaviours.obstacle import base_bubble
from ddwmmr.commands import FORCE, PlantTraits, WheelForces
from ddwmmr.controllers.base import (
    StepInfo,
    WaypointRun,
    check_known_options,
    commanded_steps,
    control_step,
    register_controller,
    step_results,
)
from ddwmmr.controllers.inputs import check_inputs, check_start
from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import check_angles
from ddwmmr.model.stability import GRAVITY_M_S2, warn_start_below_floor
from ddwmmr.mpc.braking import braked_velocity, braking_input, should_brake
from ddwmmr.mpc.fallback import fallback_input, make_fallback
from ddwmmr.mpc.min_time import Guess, PlanProblem, plan_path, plan_problem
from ddwmmr.mpc.models import PredictionModel, make_model
from ddwmmr.mpc.ocp import OCPConfig, check_integrable, longest_substep
from ddwmmr.mpc.options import (
    DEFAULT_DT,
    GRID_DEFAULTS,
    MODELS,
    BaseFacts,
    MPCOptions,
    options_signature,
)
from ddwmmr.mpc.problem import Problem
from ddwmmr.mpc.solvers import SolverFailure, installed_qp_solvers, installed_solvers
from ddwmmr.mpc.stall import StallWatch
from ddwmmr.qp.limits import run_clearance, safe_arm_scale
from ddwmmr.qp.limits.obstacles import Circle
from ddwmmr.resolution.kernels import length_unit
from ddwmmr.user_warnings import warn_user

#: Share of the planned wheel force (``mpc_wheel_force_limit_n``) at or above which a
#: wheel's measured force counts as held at it (``mpc_wheel_force_bound_time_s``): the
#: solver meets its bound to within its tolerance, as the MuJoCo plant's motors count as
#: saturated from 0.999 of their torque.
FORCE_BOUND_SHARE = 0.999


@register_controller("mpc", tasks=("tracking", "waypoints"), interfaces=("velocity", "force"))
class MPCController:
    """Nonlinear MPC: multiple shooting, hard exact S >= S_min, soft manipulability, preview.

    ``MPCController(robot, **options)``: the options are the fields of
    :class:`~ddwmmr.mpc.options.MPCOptions` (what each means, its default and range), given
    as keywords (``make_controller("mpc", robot, horizon=2.0)``) and kept in
    :attr:`options` as given; :attr:`resolved` holds them with every "None: chosen for the
    plant" filled in (:meth:`adopt_plant`), and the run's summary prints that whole
    (``mpc_options``).
    """

    #: Sampled-data controller: call once per control step, hold the command over it.
    zero_order_hold = True
    #: ~0.5 ms a step: ranked in the comparison, left out of its studies by default
    #: (``--study-methods mpc`` adds it).
    in_studies = False

    #: The registry name (:func:`register_controller` sets it).
    name: ClassVar[str]
    #: Options with a closed set of values, for front ends (the app shows a button cycling
    #: through them): option name -> function returning the values.
    option_choices: ClassVar[Mapping[str, Callable[[], list[Any]]]] = {
        "model": lambda: [None, *MODELS],  # None: chosen for the plant
        "solver": installed_solvers,
        "qp_solver": installed_qp_solvers,
    }

    def __init__(self, robot: Robot, **options: Any) -> None:
        check_known_options(self.name, options, [f.name for f in fields(MPCOptions)])
        self.options = MPCOptions(**options)
        self.robot = robot
        #: The robot's length unit (m), whatever the model: the unit of the defaults of
        #: ``obstacle_margin`` and ``reach_speed`` (docs/mpc.md, "Robot size").
        self.length_unit = length_unit(robot.L1)
        self.options.robot_reach_speed(self.length_unit)  # refuses one below the robot's least
        self._plan = _load_plan(self.options, robot.payload)
        self._configure(self.options.adopt_plant(None), None)
        self._loop_step: float | None = None
        self.dt = self.options.dt or DEFAULT_DT
        self._weights = {mode: self.options.weights(mode) for mode in GRID_DEFAULTS}
        self._fallback: Any = None
        self._trajectory: Any = None
        self.fallbacks = 0
        #: Message of the last solver failure (None before any).
        self.last_failure: str | None = None
        self.last = StepInfo()
        self._reset_memory()

    __init__.__signature__ = options_signature()  # type: ignore[attr-defined]

    # -- options ----------------------------------------------------------------------------
    @property
    def stability_min(self) -> float:
        """The floor S_min of the tip-over margin."""
        return self.options.stability_min

    @property
    def obstacles(self) -> list[Circle]:
        """The obstacles (circles) the base keeps clear of (the app draws them)."""
        return list(self.options.obstacles)

    @property
    def dynamic_stability(self) -> bool:
        """Whether the floor holds on the zero moment point too (resolved)."""
        return bool(self.resolved.dynamic_stability)

    @property
    def arm_time_constant(self) -> float | None:
        """The predicted joints' lag (s), None for none (resolved)."""
        return self.resolved.arm_time_constant or None

    @property
    def joint_acceleration_limit(self) -> tuple[float, float] | None:
        """The lagged joints' acceleration bounds (rad/s^2), None for none (resolved)."""
        return self.resolved.joint_acceleration_limit or None  # type: ignore[return-value]

    @property
    def brake_slack(self) -> float | None:
        """Stability slack (m) above which a moving robot brakes, None: off (resolved)."""
        return self.resolved.brake_slack or None

    def _configure(self, resolved: MPCOptions, plant: PlantTraits | None) -> None:
        """Set the prediction model for the ``resolved`` options on ``plant`` (problems are
        rebuilt on demand); ``_choice`` names the model (the shared OCPs' key)."""
        self.resolved = resolved
        self._choice = _model_choice(resolved, plant)
        model, _, lag, base, acceleration_limit = self._choice
        self.model_name = model
        self.dynamics = base.dynamics(self.robot) if model == "thesis" else None
        self.model: PredictionModel = make_model(
            model, self.robot, self.dynamics, lag, acceleration_limit
        )
        # the kinematic model plans in the robot's length unit (docs/mpc.md, "Robot size")
        self.unit = self.length_unit if model == "kinematic" else 1.0
        try:
            self._unit_robot = self.robot.in_length_unit(self.unit)
        except ParameterError as exc:
            raise ParameterError(
                f"mpc: the kinematic model measures lengths in the robot's length unit "
                f"(L1 / 0.35 m): {str(exc).removeprefix('robot: ')}"
            ) from None
        self._unit_model = (
            self.model
            if self.unit == 1.0
            else make_model(model, self._unit_robot, self.dynamics, lag, acceleration_limit)
        )
        self.interface = self.model.interface
        self.wants_base_velocity = model == "thesis"
        self._problems: dict[tuple[str, float], Problem] = {}
        if self._plan is not None and self._plan.states.shape[1] != self.model.nx:
            raise ParameterError(
                "plan needs the force model without a joint lag (model='thesis', "
                "arm_time_constant=0): its states are the thesis plant's"
            )

    def adopt_plant(self, plant: PlantTraits) -> None:
        """The loop's plant, described (:func:`ddwmmr.commands.traits_of`): options not
        given are chosen for it (:meth:`MPCOptions.adopt_plant`), before ``reset``."""
        resolved = self.options.adopt_plant(plant)
        if _model_choice(resolved, plant) == self._choice:
            self.resolved = resolved
            return
        self._configure(resolved, plant)
        self._reset_memory()  # sized and meant for the previous model
        self._fallback = None

    def _config(self, mode: str) -> OCPConfig:
        """The OCP of objective ``mode``: ``"tracking"``, ``"reach"`` (one target) or
        ``"reach2"`` (through the target to the next one, the reach grid twice)."""
        reach = mode != "tracking"
        base = "reach" if reach else mode
        options = self.options
        n, first, t = options.grid_at(base, self.dt)
        unit = self.unit  # lengths (m) and speeds (m/s) in the robot's unit
        huber = options.huber_scale(base, unit)
        circles = cast("tuple[Circle, ...]", options.obstacles)  # as_circles made them
        return OCPConfig(
            intervals=n,
            control_interval=self.dt,
            first_interval=first,
            horizon=t,
            reach=reach,
            second_leg_intervals=n if mode == "reach2" else 0,
            second_leg_weight=options.lookahead_weight,
            second_leg_horizon=options.lookahead_horizon,
            min_horizon=max(0.1, 2.0 * self.dt),
            reach_speed=options.robot_reach_speed(self.length_unit) / unit,
            arrival_weight=options.plan_weight if reach and self._plan is not None else 0.0,
            stability_min=options.stability_min,
            stability_margin=options.stability_margin,
            dynamic_stability=self.dynamic_stability,
            min_edge_load=options.min_edge_load,
            track_orientation=options.track_orientation and not reach,
            huber=None if huber is None else huber / unit,
            obstacles=tuple(_circle_in_unit(circle, unit) for circle in circles),
            base_radius=base_bubble(self._unit_robot),
            obstacle_margin=options.robot_obstacle_margin(self.length_unit) / unit,
            weights=self._weights[base],
        )

    def _problem(self, mode: str) -> Problem:
        key = (mode, self.dt)
        if key not in self._problems:
            options = self.options
            self._problems[key] = Problem(
                self._unit_robot,
                self._choice,
                self._unit_model,
                self._config(mode),
                options.solver,
                options.qp_solver,
                options.proximal,
                options.cold_iterations,
                self.unit,
            )
        return self._problems[key]

    # -- controller protocol ------------------------------------------------------------
    def _reset_memory(self) -> None:
        self._warm: np.ndarray | None = None
        self._warm_mode: str | None = None
        self._warm_time = 0.0
        self._target: tuple[float, float] | None = None
        self._route_index = 0  # where in ``route`` the current target was found
        self._following: tuple[float, float] | None = None  # the plan's second target
        self._single_target: tuple[float, float] | None = None  # lookahead dropped there
        self._u_prev = np.zeros(self.model.nu)
        self._predicted_velocity: tuple[float, float] = (0.0, 0.0)
        self._predicted_rates: tuple[float, float] = (0.0, 0.0)  # the lagged arm's
        self._stall = StallWatch(self.length_unit)  # progress in the robot's size
        self.restarts = 0
        self.brakes = 0  # steps that braked instead of following a plan that needed slack
        #: the least edge load (N) a plan predicted for its command (dynamic_stability)
        self.min_predicted_edge_load: float | None = None

    def adopt_control_step(self, dt: float) -> None:
        """The loop holds each command ``dt`` (s): plan with it (the first interval, the
        joint targets ``th + rate dt``), unless ``dt`` was given as an option."""
        self._loop_step = dt

    def reset(self, trajectory: Any, q0: np.ndarray | Sequence[float]) -> None:
        """Forget warm starts and counters; take the control step (:func:`control_step`).
        ``q0``: the start ``[x, y, phi, th1, th2]``, 5 finite numbers (m, rad)."""
        q0 = check_start(q0)
        warn_start_in_keep_out(self.robot, self.options, q0)
        warn_start_below_floor("mpc", self.robot, q0, self.stability_min)
        self.dt = control_step(self.options.dt, self._loop_step, trajectory, DEFAULT_DT)
        self._trajectory = trajectory
        self.fallbacks = 0
        self.last = StepInfo()
        self._reset_memory()
        self._check_integrable(trajectory is not None)
        if trajectory is not None:
            arm = (float(q0[3]), float(q0[4]))
            self._problem("tracking").design_terminal(arm)
        self._fallback = None  # rebuilt on the first failure with this run's dt

    def _check_integrable(self, tracking: bool) -> None:
        """Refuse a base the force model's RK4 cannot follow on the grids of this run's
        objectives at its control step (:func:`~ddwmmr.mpc.ocp.check_integrable`)."""
        if self.dynamics is None:
            return
        if tracking:
            modes = ["tracking"]
        else:
            modes = ["reach", "reach2"] if self.options.lookahead else ["reach"]
        substep = max(longest_substep(self._config(mode).interval_lengths()) for mode in modes)
        check_integrable(self.dynamics, self.robot.joint_limits[1], substep)

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
        t, *checked = check_inputs(t, q, pose_d, velocity_d)
        check_angles(checked[0])  # as every other method: angles whose sums overflow
        q, pose_d, velocity_d = (np.array(values) for values in checked)
        reach = self._trajectory is None and not np.any(velocity_d)
        target = (float(pose_d[0]), float(pose_d[1]))
        new_target = reach and self._target != target
        stuck = reach and self._stall.stuck(t, tuple(self.robot.fk(q)[:2]), new_target)
        # a frozen plan restarts cold in its own mode: unlike a stall short of the target,
        # it says nothing against planning through to the next one
        frozen = (
            reach and not stuck and self.resolved.frozen_restart and self._stall.horizon_frozen(t)
        )
        overdue = self._stall.arrival_overdue(t)
        if (stuck or overdue) and self._warm_mode == "reach2" and not new_target:
            # a plan through this target to the next stalled short of it: one target at a
            # time until it is reached
            self._single_target = target
            self.restarts += 1
        following = self._next_target(target) if reach and target != self._single_target else None
        mode = "tracking" if not reach else "reach" if following is None else "reach2"
        problem = self._problem(mode)
        if mode == "tracking" and problem.terminal_factor is None:
            problem.design_terminal((float(q[3]), float(q[4])))
        x0 = self._state(q, base_velocity)
        references = self._references(problem, t, pose_d, velocity_d, following)
        # ignore: the resolved options hold frozen_restart as a bool
        cold = self._cold_start(mode, new_target, restart=stuck or frozen)  # type: ignore[arg-type]
        warm, source, start, arrival = self._solve_starts(
            problem, x0, target, reach, new_target, cold
        )
        try:
            w, iterations = problem.solve(
                t, x0, references, self._u_prev, warm, self._warm_time, source, start, arrival
            )
        except SolverFailure as failure:
            return self._fallback_command(t, q, pose_d, velocity_d, x0, str(failure))
        self._warm, self._warm_mode, self._warm_time = w, mode, t
        self._target, self._following = target, following
        self._watch_plan(t, problem, w, mode, reach, new_target, cold)
        u = problem.first_input(w)
        braking = self._should_brake(problem, w, x0)
        if braking:
            self.brakes += 1
            u = self._braking_input(q, x0)
        return self._output(problem, q, x0, u, w, iterations, problem.max_slack(w), braking)

    # -- pieces ---------------------------------------------------------------------------
    def _cold_start(self, mode: str, new_target: bool, *, restart: bool) -> bool:
        """Whether this step's solve starts cold: no previous plan, another ``mode``, a
        ``new_target`` (the stall watch starts afresh), or a ``restart`` (stuck or frozen
        plan, counted in ``restarts``)."""
        cold = self._warm is None or self._warm_mode != mode or new_target
        if cold:
            self._stall.fresh_plan()
        elif restart:
            cold = True
            self.restarts += 1
        return cold

    def _solve_starts(
        self,
        problem: Problem,
        x0: np.ndarray,
        target: tuple[float, float],
        reach: bool,
        new_target: bool,
        cold: bool,
    ) -> tuple[Any, Any, tuple[np.ndarray, float] | None, np.ndarray | None]:
        """``(warm, source, start, arrival)`` of :meth:`Problem.solve`: the previous plan
        to shift (None when ``cold``, unless handed over), the two-target OCP handing its
        plan through the reached ``target`` (m, world) over to the next leg, and the
        offline plan's cold start from ``x0`` and arrival state on the leg ending at
        ``target`` (a plan's leg replaces the hand-over)."""
        # the plan that went through the reached target already plans the next leg
        handover = new_target and self._warm_mode == "reach2" and self._following == target
        source = self._problem("reach2").ocp if handover and self._warm is not None else None
        leg = self._plan_leg(target) if reach else None
        if leg is not None and cold:  # the offline plan's leg starts it, not the hand-over
            source = None
        warm = self._warm if not cold or source is not None else None
        # ignore: a plan's leg (leg not None) means a plan
        start = None if leg is None or not cold else problem.planned_start(x0, self._plan, leg)  # type: ignore[arg-type]
        arrival = None if leg is None else problem.planned_arrival(self._plan, leg)  # type: ignore[arg-type]
        return warm, source, start, arrival

    def _watch_plan(
        self,
        t: float,
        problem: Problem,
        w: np.ndarray,
        mode: str,
        reach: bool,
        new_target: bool,
        cold: bool,
    ) -> None:
        """The stall watch told of plan ``w`` solved at t (s): whether it arrives at the
        shortest horizon, its horizon (s) and whether that is free to shrink, its slack."""
        # "there at the shortest horizon" (within a millisecond: the QP's tolerance)
        shortest = problem.ocp.config.min_horizon + 1e-3
        horizon = problem.ocp.horizon_of(w)
        self._stall.plan_arrival(t, mode == "reach2" and horizon <= shortest, new_target)
        free = reach and shortest < horizon < problem.ocp.config.horizon - 1e-3
        self._stall.plan_horizon(t, horizon, free, cold)
        slack = problem.ocp.max_slack(w)
        self._stall.plan_slack(t, slack)

    def _should_brake(self, problem: Problem, w: np.ndarray, x0: np.ndarray) -> bool:
        """Whether to brake instead of sending plan ``w``'s first input: braking is on,
        the plan's stability rows need more slack than ``brake_slack`` (m) and the robot
        at ``x0`` moves (:func:`~ddwmmr.mpc.braking.should_brake`)."""
        return self.brake_slack is not None and should_brake(
            self.brake_slack,
            problem.max_stability_slack(w),
            (float(x0[5]), float(x0[6])),
            self._predicted_rates,
        )

    def _state(self, q: np.ndarray, base_velocity: tuple[float, float] | None) -> np.ndarray:
        if self.model_name == "kinematic":
            return q.copy()
        v, w = self._predicted_velocity if base_velocity is None else base_velocity
        # the lagged joints' rates: no sensor reports them, the controller carries them
        # forward from its own commands (why not from the measured joint motion:
        # docs/mpc.md, "Formulation")
        lagged = self._predicted_rates if self.arm_time_constant is not None else ()
        return np.concatenate([q, [float(v), float(w)], lagged])

    def _references(
        self,
        problem: Problem,
        t: float,
        pose_d: np.ndarray,
        velocity_d: np.ndarray,
        following: tuple[float, float] | None = None,
    ) -> np.ndarray:
        """Reference poses of nodes 1..N (N, 3); with a ``following`` target (x, y) the
        second leg's nodes aim at it."""
        ocp = problem.ocp
        times = ocp.node_times(ocp.config.horizon)[1:]
        if self._trajectory is not None:
            return np.array([self._trajectory.pose(t + tau) for tau in times])
        references: np.ndarray = pose_d[None, :] + times[:, None] * velocity_d[None, :]
        if following is not None:
            references[ocp.split :] = (following[0], following[1], 0.0)
        return references

    def _on_route(self, target: tuple[float, float]) -> int | None:
        """Index of ``target`` in ``route``, searched from the last one found (so a route
        may pass a point twice); None when it is not on the route."""
        route = self.options.route
        for index in range(self._route_index, len(route)):
            if math.dist(route[index], target) <= 1e-9:
                self._route_index = index
                return index
        return None

    def _next_target(self, target: tuple[float, float]) -> tuple[float, float] | None:
        """With ``lookahead``: the waypoint of ``route`` after ``target``, None at the
        route's end or when ``target`` is not on it."""
        route = self.options.route
        if not self.options.lookahead or not route:
            return None
        index = self._on_route(target)
        if index is None or index + 1 >= len(route):
            return None
        # ignore: MPCOptions holds the route's points as (x, y) pairs
        return tuple(route[index + 1])  # type: ignore[return-value]

    def _plan_leg(self, target: tuple[float, float]) -> int | None:
        """With a ``plan``: the index of its leg that ends at ``target`` (the route's),
        None without a plan or off the route."""
        return None if self._plan is None else self._on_route(target)

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

    def _output(
        self,
        problem: Problem,
        q: np.ndarray,
        x0: np.ndarray,
        u: np.ndarray,
        w: np.ndarray,
        iterations: int,
        slack: float,
        braking: bool = False,
    ) -> np.ndarray | WheelForces:
        """The command of plan ``w`` (its first input ``u``), the step's info with the
        plan's ``slack`` (m for the stability rows, m^2 for the obstacle rows,
        :meth:`Problem.max_slack`)."""
        k = self.robot.com_coefficients
        th1, th2 = float(q[3]), float(q[4])
        r1, r2 = float(u[2]), float(u[3])
        # a braking step's rates already slow the joints at their limit: cutting them
        # further would stop the arm at once, the jolt that tipped the robot on MuJoCo
        scale = 1.0 if braking else safe_arm_scale(k, th1, th2, r1, r2, self.dt, self.stability_min)
        r1, r2 = r1 * scale, r2 * scale
        ocp = problem.ocp
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
        if ocp.first_edge_loads is not None and not braking:
            # ignore: the solve of this step set last_parameters
            least = float(ocp.first_edge_loads(w, problem.last_parameters).full().min())  # type: ignore[arg-type]
            self.last.extra["min_predicted_edge_load_n"] = least
            if self.min_predicted_edge_load is None or least < self.min_predicted_edge_load:
                self.min_predicted_edge_load = least
        velocity = (0.0, 0.0)
        if braking:  # the plan's prediction is not what is sent: one Euler step instead
            assert self.dynamics is not None
            state = np.concatenate([q, x0[5:7]])
            velocity = braked_velocity(self.dynamics, state, u[:2], self.dt)
        elif self.dynamics is not None:
            xs, _ = ocp.trajectories(w)
            velocity = (float(xs[1][5]), float(xs[1][6]))
        return self._apply(float(u[0]), float(u[1]), r1, r2, q, velocity)

    def _apply(
        self,
        first: float,
        second: float,
        r1: float,
        r2: float,
        q: np.ndarray,
        velocity: tuple[float, float],
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

    def _fallback_command(
        self,
        t: float,
        q: np.ndarray,
        pose_d: np.ndarray,
        velocity_d: np.ndarray,
        x0: np.ndarray,
        reason: str,
    ) -> np.ndarray | WheelForces:
        """The ``qp`` command for this step (counted; :mod:`ddwmmr.mpc.fallback`); the
        next step starts cold."""
        self.fallbacks += 1
        self._warm = None
        if self._fallback is None:
            self._fallback = make_fallback(
                self.robot, self.options, self._trajectory, self.dt, self.dynamics
            )
        command, velocity = fallback_input(
            self._fallback, self.robot, self.dynamics, t, q, pose_d, velocity_d, x0
        )
        self.last = StepInfo(fallback=True, extra={"mpc_failure": 1.0})
        self.last_failure = reason
        return self._apply(*command, q, velocity)

    # -- reporting ----------------------------------------------------------------------
    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        """MPC metrics merged into the run summary (see the module docstring)."""
        stability = np.asarray(timeseries["stability"])
        if "fallback" in timeseries:
            fallbacks = int(np.sum(commanded_steps(timeseries["fallback"]) > 0))
        else:
            fallbacks = self.fallbacks
        # ignore: MPCOptions turns obstacles into Circles
        clearance = run_clearance(self.robot, self.options.obstacles, timeseries)  # type: ignore[arg-type]
        mode = "tracking" if self._trajectory is not None else "reach"
        solver = self.options.solver
        return {
            "stability_min": self.stability_min,
            "stability_violations": int(np.sum(step_results(stability) < self.stability_min)),
            "mpc_fallbacks": fallbacks,
            "mpc_restarts": self.restarts,
            "mpc_brakes": self.brakes,
            "mpc_brake_slack_m": self.brake_slack,
            "min_obstacle_clearance_m": clearance,
            "mpc_model": self.model_name,
            "mpc_dynamic_stability": self.dynamic_stability,
            "min_predicted_edge_load_n": self.min_predicted_edge_load,
            "min_edge_load_floor_n": (
                self.resolved.min_edge_load * self.robot.total_mass * GRAVITY_M_S2
                if self.dynamic_stability
                else None
            ),
            "mpc_arm_time_constant_s": self.arm_time_constant,
            "mpc_joint_acceleration_limit_rad_s2": self.joint_acceleration_limit,
            "mpc_wheel_force_limit_n": None if self.dynamics is None else self.dynamics.force_limit,
            "mpc_wheel_force_bound_time_s": self._force_bound_time(timeseries),
            "mpc_solver": solver if solver != "rti" else f"rti-{self.options.qp_solver}",
            "mpc_horizon_s": self.options.grid(mode)[2],
            "mpc_options": self.resolved.record(mode, self.dt, self.unit, self.length_unit),
        }

    def _force_bound_time(self, timeseries: dict[str, np.ndarray]) -> float | None:
        """Time (s) with a wheel's measured force at the force the model plans with
        (``mpc_wheel_force_limit_n``, to :data:`FORCE_BOUND_SHARE`), from the plant's wheel
        forces: the thesis plant's ``force_left_n``/``force_right_n`` (N), MuJoCo's
        ``wheel_torque_use`` (share of the motors' torque) x ``motor_force_limit`` (N). None
        without the force model or a plant recording wheel forces. The plant's own limit
        may be this bound too (the thesis plant's, by default)."""
        if self.dynamics is None:
            return None
        if "force_left_n" in timeseries and "force_right_n" in timeseries:
            left = np.abs(np.asarray(timeseries["force_left_n"], dtype=float))
            force = np.maximum(left, np.abs(np.asarray(timeseries["force_right_n"], dtype=float)))
        elif "wheel_torque_use" in timeseries:
            use = np.asarray(timeseries["wheel_torque_use"], dtype=float)
            force = use * self.robot.motor_force_limit
        else:
            return None
        t = np.asarray(timeseries["t"], dtype=float)
        interval = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
        at_bound = force >= FORCE_BOUND_SHARE * self.dynamics.force_limit
        return float(np.sum(at_bound) * interval)

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
        plant's traits (``adopt_plant``; why each is needed: docs/mpc.md, "The physics plant:
        tipping while moving").

        ``route`` is the scenario's waypoints with ``lookahead`` or a ``plan``; a ``plan``
        that is a folder (``python -m ddwmmr.bounds``'s output) becomes this scenario's
        best-known trajectory in it (:func:`ddwmmr.mpc.min_time.plan_path`); building the
        controller refuses a plan recorded for other waypoints or another payload."""
        config = run.config
        options: dict[str, Any] = {
            "model": "thesis" if FORCE in run.plant.interfaces else "kinematic",
            "stability_min": config.qp_stability_min,
            "track_orientation": False,
            "obstacles": [tuple(o) for o in run.scenario.obstacles],
            "dt": config.dt,
        }
        options.update(dict(config.controller_options))
        plan = options.get("plan")
        # a folder is a bounds run's: this scenario's plan in it
        if isinstance(plan, str | os.PathLike) and os.path.isdir(plan):
            options["plan"] = str(plan_path(plan, run.scenario.index + 1))
        if (options.get("lookahead") or plan is not None) and not options.get("route"):
            options["route"] = [tuple(w) for w in run.scenario.waypoints]
        return options


def warn_start_in_keep_out(
    robot: Robot, options: MPCOptions, q0: np.ndarray | Sequence[float]
) -> None:
    """Warn (:class:`UserWarning`, once) when the start ``q0`` (x, y m) puts the base inside
    the keep-out the OCP's obstacle rows hold: its enclosing circle
    (:func:`~ddwmmr.behaviours.obstacle.base_bubble`) less than the robot's
    ``obstacle_margin`` (m, :meth:`MPCOptions.robot_obstacle_margin`) from
    a circle of ``obstacles``. The run then starts in violation of those rows (their slack
    takes it). Warned, not refused, as the ``qp`` runs such a start too (its damper asks
    for the clearance to grow); a footprint overlapping a circle is refused by the tools
    (:func:`ddwmmr.sim.simulate.check_start`). The message names the circle with the least
    clearance."""
    bubble = base_bubble(robot)
    margin = options.robot_obstacle_margin(length_unit(robot.L1))
    inside = [
        (math.hypot(q0[0] - c.x, q0[1] - c.y) - c.radius - bubble, number, c)
        for number, c in enumerate(options.obstacles, start=1)
    ]
    inside = [entry for entry in inside if entry[0] < margin]
    if not inside:
        return
    clearance, number, circle = min(inside, key=lambda entry: entry[0])
    more = f" (and {len(inside) - 1} more)" if len(inside) > 1 else ""
    gap = (
        f"overlaps it by {-clearance:.3g} m" if clearance < 0.0 else f"is {clearance:.3g} m from it"
    )
    warn_user(
        f"obstacles: the start pose is inside the mpc's keep-out of obstacle {number} (x "
        f"{circle.x:g} m, y {circle.y:g} m, radius {circle.radius:g} m){more}: the base's "
        f"enclosing circle (radius {bubble:.3g} m) {gap}, within obstacle_margin {margin:g} "
        f"m; the run starts violating its obstacle constraint"
    )


#: How far (m) a waypoint may lie from the one a plan was recorded for: a JSON record
#: holds the waypoints exactly, so only rounding is allowed.
PLAN_WAYPOINT_TOLERANCE_M = 1e-9
#: The same for the payload (kg).
PLAN_PAYLOAD_TOLERANCE_KG = 1e-9


def _circle_in_unit(circle: Circle, unit: float) -> Circle:
    """``circle`` (m) with its centre and radius in the length ``unit`` (m)."""
    return Circle(circle.x / unit, circle.y / unit, circle.radius / unit)


def _load_plan(options: MPCOptions, payload: float) -> Guess | None:
    """The ``plan`` option's trajectory, with one leg per waypoint of ``route``, made for
    those waypoints and the robot's ``payload`` (kg) where its file records what it was
    made for (:func:`~ddwmmr.mpc.min_time.plan_problem`)."""
    if options.plan is None:
        return None
    plan = Guess.load(options.plan)
    if len(plan.arrivals) != len(options.route):
        raise ParameterError(
            f"plan {options.plan} has {len(plan.arrivals)} legs: route must list as many "
            f"waypoints (got {len(options.route)})"
        )
    problem = plan_problem(options.plan)
    if problem is not None:
        _check_plan_problem(options.plan, problem, options.route, payload)
    return plan


def _check_plan_problem(
    path: str, problem: PlanProblem, route: Sequence[Sequence[float]], payload: float
) -> None:
    """A one-line :class:`ParameterError` naming the plan, the file recording what it was
    made for and what differs, unless that is ``route`` (m; the scenario's waypoints in a
    scenario run) and ``payload`` (kg)."""
    advice = "a bounds run of the same seed and payload makes the matching plans"
    # "not within" rather than "beyond": a record holding NaN (damaged, edited) matches
    # no problem, and NaN compares False either way
    if not abs(problem.payload - payload) <= PLAN_PAYLOAD_TOLERANCE_KG:
        raise ParameterError(
            f"plan {path} was made for a payload of {problem.payload:g} kg "
            f"({problem.source}), the robot carries {payload:g} kg: {advice}"
        )
    waypoints, source = problem.waypoints, str(problem.source)
    if len(waypoints) != len(route):
        raise ParameterError(
            f"plan {path} was made for {len(waypoints)} waypoints ({source}), the route "
            f"(the scenario's) has {len(route)}: {advice}"
        )
    for number, (made, wanted) in enumerate(zip(waypoints, route, strict=True), start=1):
        if not math.dist(made, wanted) <= PLAN_WAYPOINT_TOLERANCE_M:
            raise ParameterError(
                f"plan {path} was made for other waypoints than the route's (the "
                f"scenario's): waypoint {number} is ({made[0]:.6g}, {made[1]:.6g}) m in "
                f"{source}, ({wanted[0]:.6g}, {wanted[1]:.6g}) m on the route: {advice}"
            )


def _model_choice(
    resolved: MPCOptions, plant: PlantTraits | None
) -> tuple[str, bool | None, float | None, BaseFacts, tuple[float, float] | None]:
    """``(model, dynamic_stability, arm_time_constant, base, joint_acceleration_limit)``:
    what the prediction model is made from (None for no lag, no bound)."""
    model = resolved.model
    base = BaseFacts.of(plant, resolved.wheel_force_limit) if model == "thesis" else BaseFacts()
    lag = resolved.arm_time_constant or None
    # ignore: resolved options hold the chosen model and the acceleration limit as a pair
    return model, resolved.dynamic_stability, lag, base, resolved.joint_acceleration_limit or None  # type: ignore[return-value]
