"""The QP task-priority controller, registered as method ``qp`` (docs/qp.md).

Every control step solves one small QP over ``u = (v, w, th1dot, th2dot)`` plus the
tracking slack (see :mod:`ddwmmr.qp.problem`):

* hard limits: tip-over stability ``S >= S_min`` (velocity damper, exact gradient),
  wheel speeds, joint speeds, joint positions (dampers), a margin from the shoulder
  singularity ``cos th1 = 0``, base-footprint clearance from circular obstacles;
* tasks, by priority: end-effector tracking (feed-forward + feedback, slack weighted
  ``tracking_weight``), then manipulability, posture and regularisation (low weights),
  plus a heading task for far-away targets when the orientation is not tracked.

After the solve, the exact stability one step ``dt`` ahead is checked and the joint rates
are scaled back if the linearisation was too optimistic (the exact look-ahead runs only
when a bound cannot prove the full step safe). If the QP fails, a safe command is used
(base stopped, arm still or moving to raise S, every limit kept) and counted as a
fallback. Task targets are bounded at 10x what the robot can do (:func:`demand_limits`), so
absurd demands cannot swamp the solver's tolerances: every limit holds for every finite
state (tests/test_qp_limits_extreme.py).

Built by name::

    make_controller("qp", Robot().with_payload(3.0), stability_min=1.25,
                    obstacles=load_obstacles("trajectories/obstacles/ellipse_post.toml"))

``summarize`` adds to the run summary: ``stability_min`` (the floor), ``stability_violations``
(steps that ended with S < floor), ``qp_fallbacks`` (steps that used the safe command; both
of the run's ``steps``: :func:`~ddwmmr.controllers.base.step_results`,
:func:`~ddwmmr.controllers.base.commanded_steps`), ``min_obstacle_clearance_m`` (base
footprint vs circles; None without obstacles), ``qp_mode``, ``qp_solver`` and
``min_predicted_edge_load_n`` (the least edge load, N, the edge-load limit predicted for a
command sent; None where that limit is off) and ``min_edge_load_floor_n`` (its floor, N;
None where off), ``edge_load_relaxed_steps`` (steps whose edge rows conflicted with the
other limits and were dropped for that step's solve; the QP fallback runs only if that
solve fails too).

The QP works in the robot's own length unit (:func:`~ddwmmr.resolution.kernels.length_unit`,
exactly 1.0 m for the default robot): its ``v`` is ``v / unit``, its linear rows and
targets are divided by the unit, and the length constants of its pieces are in it, so a
robot scaled by a power of two solves the default robot's QP to the last bit (docs/qp.md,
"Robot size"). Options in m or m/s stay in m or m/s.

Its benchmark twin, :class:`ddwmmr.qp.naive.NaiveQPController`, is deliberately not a
registered method: it is a baseline for ``python -m ddwmmr.bench``, not a method to compare.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar, cast

import numpy as np

from ddwmmr.behaviours.obstacle import base_bubble
from ddwmmr.commands import PlantTraits
from ddwmmr.controllers.base import (
    StepInfo,
    WaypointRun,
    commanded_steps,
    control_step,
    register_controller,
    step_results,
)
from ddwmmr.controllers.inputs import check_inputs, check_start
from ddwmmr.errors import ParameterError, check_bool, check_range, iterable, shown
from ddwmmr.gains import MIN_TAU
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import whole_turns
from ddwmmr.model.stability import STABILITY_FLOOR, warn_start_below_floor
from ddwmmr.model.support_loads import DEFAULT_MIN_EDGE_LOAD, check_min_edge_load
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits import (
    INF,
    BaseMotionLimit,
    Circle,
    JointLimit,
    Limit,
    ObstacleLimit,
    ShoulderSingularityLimit,
    SpeedBudgetLimit,
    StabilityLimit,
    WheelSpeedLimit,
    as_circles,
    full_step_is_safe,
    run_clearance,
    safe_arm_scale,
)
from ddwmmr.qp.limits.edge_loads import EdgeLoadLimit
from ddwmmr.qp.limits.obstacles import check_margin_in_influence, robot_margin
from ddwmmr.qp.limits.stability import ascent_direction, stability_rows
from ddwmmr.qp.problem import QPProblem
from ddwmmr.qp.solve import (
    MODES,
    Backend,
    check_mode,
    installed_solvers,
    make_backend,
    solve,
)
from ddwmmr.qp.tasks import (
    Detour,
    EndEffectorTask,
    HeadingTask,
    ManipulabilityTask,
    ObstacleSteeringTask,
    PostureTask,
    RegularizationTask,
    Task,
)
from ddwmmr.resolution.kernels import length_unit

#: Look-ahead step (s) when neither ``dt`` nor the trajectory's resolution is known.
DEFAULT_DT = 0.02
#: Allowed range (s) of the ``dt`` option, the control step the qp plans each command for:
#: the range of the ``mpc``'s step, which its fallback qp takes ([MIN_INTERVAL,
#: MAX_HORIZON] of :mod:`ddwmmr.mpc.ocp`, not imported here: that imports CasADi). Below
#: it no gain of the library (at most 1/:data:`~ddwmmr.gains.MIN_TAU`) acts within a step
#: and the acceleration limits hold every command still; above it a step outlasts any
#: horizon a plan looks ahead.
DT_RANGE_S = (MIN_TAU, 100.0)

#: Default solver: the fastest measured (docs/qp.md, "Solvers").
DEFAULT_SOLVER = "daqp"


#: Factor between the demand bounds and what the robot's inputs can produce (see
#: :func:`demand_limits`): large, so the bounds act on absurd demands only.
DEMAND_FACTOR = 10.0


def demand_limits(robot: Robot) -> tuple[float, float]:
    """Bounds on the built-in tasks' target rates: ``DEMAND_FACTOR`` times the fastest
    end-effector speed (m/s) and rate (rad/s) the robot's input limits allow.

    ``|d(xE, yE)/dt| <= v_max + (L1 + L2)(w_max + th_dot_max) + L2 th_dot_max`` and
    ``|d phiE/dt| <= w_max + 2 th_dot_max`` (wheel speed limit for v_max and w_max).
    """
    v_max = robot.wheel_radius * robot.wheel_speed_limit
    w_max = 2.0 * v_max / robot.track_width
    speed = robot.joint_speed_limit
    linear = v_max + robot.reach * (w_max + speed) + robot.L2 * speed
    return DEMAND_FACTOR * linear, DEMAND_FACTOR * (w_max + 2.0 * speed)


@register_controller("qp", tasks=("tracking", "waypoints"))
class QPController:
    """QP task priorities: hard stability/limits, tracking with slack, soft manipulability.

    Args:
        robot: the robot (payload included).
        stability_min: floor S_min of the tip-over margin (hard).
        manipulability_weight: weight of the manipulability task (soft, >= 0).
        obstacles: circles (``Circle`` or (x, y, radius) triples, m) or a TOML file path.
        solver: a qpsolvers backend name; ``"daqp"`` (default) is called directly.
        mode: ``"weighted"`` (one QP) or ``"hierarchical"`` (strict lexicographic levels).
        tau: tracking time constant(s) (s), one or three (xE, yE, phiE).
        track_orientation: False tracks the end-effector position only.
        max_speed: clip of the feedback end-effector velocity (m/s), None for no clip.
        tracking_weight: slack penalty of the tracking rows (per (m/s)^2).
        posture_weight: weight of the posture task (shoulder towards the heading).
        regularization_weight: weight of the input-norm task.
        heading_weight: weight of the far-target heading task; default 1 when the
            orientation is not tracked, else 0 (off).
        stability_gain: damper gain of the stability limit (1/s).
        obstacle_margin: clearance kept from every obstacle (m), in [0, 0.6 unit): below
            the obstacle influence (:data:`~ddwmmr.qp.limits.obstacles.INFLUENCE_M` of the
            robot's length unit); None (default): the robot's own,
            :data:`~ddwmmr.qp.limits.obstacles.MARGIN` of its length unit (0.05 m on the
            default robot).
        max_base_speed, max_yaw_rate: caps on v (m/s) and w (rad/s), e.g. a force-limited
            base's top speeds; None (default) leaves only the wheel-speed limit.
        max_acceleration, max_yaw_acceleration: slew limits on v (m/s^2) and w (rad/s^2)
            around the previous command (one call per control step assumed); None: off.
        speed_budget: ``(v_top, w_top)`` (m/s, rad/s): v and w share the wheels' force
            budget, ``|v|/v_top + |w|/w_top <= 1`` (:class:`SpeedBudgetLimit`; a damped,
            force-limited base whose wheel servos saturate one by one); None: off.
        singularity_margin: angle (rad) kept between link 1 and the base heading's normal
            (shoulder singularity, ``cos th1 = 0``); None switches the limit off.
        min_edge_load: least load every edge of the support polygon keeps, as a share of
            the weight in [0, 0.5) (default 0.1: 14.7 N with 3 kg, the static floor S 1.25's
            own side-edge load), predicted from the command through the servos' lag
            (:class:`~ddwmmr.qp.limits.edge_loads.EdgeLoadLimit`); on a plant that judges
            tipping by its physics and reports its joints' lag (MuJoCo), where the inertial
            loads it predicts are real; None: off.
        dt: look-ahead step of the exact stability check and the acceleration limits' step
            (s), in :data:`DT_RANGE_S` (1e-4 to 100 s); default the step the loop
            holds each command (``adopt_control_step``), else the trajectory's
            ``duration / samples`` at reset, else 0.02 s
            (:func:`~ddwmmr.controllers.base.control_step`).
        warm_start: pass the previous solution to the solver (default: on for the
            qpsolvers path, off for direct DAQP where it does not pay off).
        tasks, limits: extra user-defined :class:`Task`/:class:`Limit` objects.
    """

    #: Options with a closed set of values, for front ends (the app shows a button cycling
    #: through them): option name -> function returning the values.
    option_choices: ClassVar[Mapping[str, Callable[[], list[str]]]] = {
        "solver": installed_solvers,
        "mode": lambda: list(MODES),
    }

    def __init__(
        self,
        robot: Robot,
        stability_min: float = STABILITY_FLOOR,
        manipulability_weight: float = 0.5,
        obstacles: Sequence[Circle | Sequence[float]] | str = (),
        solver: str = DEFAULT_SOLVER,
        mode: str = "weighted",
        tau: float | Sequence[float] = 0.5,
        track_orientation: bool = True,
        max_speed: float | None = None,
        tracking_weight: float = 1e4,
        posture_weight: float = 0.1,
        regularization_weight: float = 1e-3,
        heading_weight: float | None = None,
        stability_gain: float = 5.0,
        obstacle_margin: float | None = None,
        singularity_margin: float | None = 0.25,
        max_base_speed: float | None = None,
        max_yaw_rate: float | None = None,
        max_acceleration: float | None = None,
        max_yaw_acceleration: float | None = None,
        speed_budget: tuple[float, float] | None = None,
        min_edge_load: float | None = DEFAULT_MIN_EDGE_LOAD,
        dt: float | None = None,
        warm_start: bool | None = None,
        tasks: Sequence[Task] = (),
        limits: Sequence[Limit] = (),
    ) -> None:
        self.robot = robot
        #: The robot's length unit (m) the QP measures lengths in (docs/qp.md, "Robot size").
        self.unit = unit = length_unit(robot.L1)
        self._com = robot.com_coefficients
        self.mode = check_mode(mode)
        self.solver = solver
        if warm_start is not None:
            check_bool("warm_start", warm_start)
        check_bool("track_orientation", track_orientation)
        self.backend = self._make_backend(solver, warm_start)
        self.obstacles = as_circles(obstacles)
        # checked without obstacles too: a bad margin is a mistake whatever the scene
        obstacle_margin = check_margin_in_influence(robot_margin(obstacle_margin, unit), unit)
        if heading_weight is None:
            heading_weight = 0.0 if track_orientation else 1.0
        heading = self._build_tasks(
            tracking=(tracking_weight, tau, track_orientation, max_speed),
            manipulability_weight=manipulability_weight,
            posture_weight=posture_weight,
            regularization_weight=regularization_weight,
            heading_weight=heading_weight,
        )
        self.tasks.extend(_pieces("tasks", tasks, Task))
        self._build_limits(
            stability=(stability_min, stability_gain),
            motion=(max_base_speed, max_yaw_rate, max_acceleration, max_yaw_acceleration),
            speed_budget=speed_budget,
            singularity_margin=singularity_margin,
        )
        if self.obstacles:
            self._avoid_obstacles(obstacle_margin, heading)
        self.limits.extend(_pieces("limits", limits, Limit))
        self.min_edge_load = None if min_edge_load is None else check_min_edge_load(min_edge_load)
        self.edge_loads: EdgeLoadLimit | None = None  # set by adopt_plant
        self.min_predicted_edge_load: float | None = None
        self.edge_relaxed_steps = 0  # steps whose edge rows gave way to the other limits
        self.problem = QPProblem(self.tasks, self.limits, unit=unit)
        self._dt_option = None if dt is None else check_range("dt", dt, *DT_RANGE_S, "s")
        self._loop_step: float | None = None
        self.ctx = StepContext(robot, self._dt_option or DEFAULT_DT)
        self.fallbacks = 0
        self.last = StepInfo()

    def _build_tasks(
        self,
        *,
        tracking: tuple[float, float | Sequence[float], bool, float | None],
        manipulability_weight: float,
        posture_weight: float,
        regularization_weight: float,
        heading_weight: float,
    ) -> HeadingTask:
        """``self.tracking`` and ``self.tasks`` in priority order: end-effector tracking
        (``tracking`` = weight per (m/s)^2, tau s, track_orientation, max_speed m/s or
        None), manipulability, posture, regularisation, then the heading task if its
        weight is positive. Returns the heading task (an obstacle detour is set on it)."""
        robot, unit = self.robot, self.unit
        tracking_weight, tau, track_orientation, max_speed = tracking
        linear, angular = demand_limits(robot)
        self.tracking = EndEffectorTask(
            tracking_weight,
            tau,
            track_orientation,
            max_speed,
            demand_limit=(linear, angular),
            unit=unit,
        )
        self.tasks: list[Task] = [
            self.tracking,
            ManipulabilityTask(manipulability_weight, arm_row=not track_orientation, unit=unit),
            PostureTask(posture_weight, rate_limit=angular),
            RegularizationTask(regularization_weight, unit=unit),
        ]
        heading = HeadingTask(heading_weight, distance=0.8 * robot.reach, unit=unit)
        if heading_weight > 0.0:
            self.tasks.append(heading)
        return heading

    def _build_limits(
        self,
        *,
        stability: tuple[float, float],
        motion: tuple[float | None, float | None, float | None, float | None],
        speed_budget: tuple[float, float] | None,
        singularity_margin: float | None,
    ) -> None:
        """``self.limits`` in order: stability (``stability`` = floor S_min, damper gain
        1/s), wheel speeds, joints, then the base-motion caps if any of ``motion`` =
        (v m/s, w rad/s, v slew m/s^2, w slew rad/s^2) is set, the speed budget, the
        shoulder singularity margin (rad) unless None."""
        robot, unit = self.robot, self.unit
        stability_min, stability_gain = stability
        self.stability = StabilityLimit(
            robot.com_coefficients,
            stability_min,
            stability_gain,
            joint_speed=robot.joint_speed_limit,
        )
        self.stability_min = self.stability.stability_min
        self.joints = JointLimit(robot)
        self.limits: list[Limit] = [self.stability, WheelSpeedLimit(robot, unit=unit), self.joints]
        max_base_speed, max_yaw_rate, max_acceleration, max_yaw_acceleration = motion
        self.base_motion: BaseMotionLimit | None = None
        if any(value is not None for value in motion):
            self.base_motion = BaseMotionLimit(
                max_base_speed if max_base_speed is not None else INF,
                max_yaw_rate if max_yaw_rate is not None else INF,
                max_acceleration,
                max_yaw_acceleration,
                unit=unit,
            )
            self.limits.append(self.base_motion)
        if speed_budget is not None:
            self.limits.append(SpeedBudgetLimit(speed_budget, unit=unit))
        self.singularity: ShoulderSingularityLimit | None = None
        if singularity_margin is not None:
            self.singularity = ShoulderSingularityLimit(
                singularity_margin, joint_speed=robot.joint_speed_limit
            )
            self.limits.append(self.singularity)

    def _avoid_obstacles(self, margin: float, heading: HeadingTask) -> None:
        """``self.obstacles`` kept ``margin`` (m) from the base footprint (a limit), steered
        round (a task after the others so far) and detoured by tracking and ``heading``."""
        robot, unit = self.robot, self.unit
        self.limits.append(ObstacleLimit(robot, self.obstacles, margin=margin, unit=unit))
        self.tasks.append(
            ObstacleSteeringTask(
                self.obstacles,
                0.5 * robot.base_length,
                0.5 * robot.base_width,
                # Steering must be able to bend tracking round a post: scale with it.
                weight=3e-3 * self.tracking.weight,
                unit=unit,
            )
        )
        half_diagonal = 0.5 * math.hypot(robot.base_length, robot.base_width)
        detour = Detour(self.obstacles, half_diagonal + 2.0 * margin)
        self.tracking.detour = heading.detour = detour

    def _make_backend(self, solver: str, warm_start: bool | None) -> Backend:
        """The solver backend (overridden by the naive benchmark variant)."""
        return make_backend(solver, warm_start)

    # -- controller protocol ------------------------------------------------------------
    @property
    def wants_base_velocity(self) -> bool:
        """The edge-load limit needs the measured ``(v, w)`` (``base_velocity``)."""
        return self.edge_loads is not None

    def adopt_plant(self, plant: PlantTraits) -> None:
        """The loop's plant, described: the edge-load limit is on where the plant judges
        tipping by its physics and its joints lag (``min_edge_load`` not None)."""
        physics = plant.judges_tipping and plant.joint_time_constant
        wanted = self.min_edge_load is not None and bool(physics)
        if self.edge_loads is not None:
            self.limits.remove(self.edge_loads)
            self.edge_loads = None
        if wanted:
            # ignore: wanted holds only with min_edge_load and joint_time_constant set
            self.edge_loads = EdgeLoadLimit(
                self.robot,
                self.min_edge_load,  # type: ignore[arg-type]
                plant.joint_time_constant,  # type: ignore[arg-type]
                plant.joint_acceleration_limit,
                unit=self.unit,
            )
            self.limits.append(self.edge_loads)
        self.problem = QPProblem(self.tasks, self.limits, unit=self.unit)

    def adopt_control_step(self, dt: float) -> None:
        """The loop holds each command ``dt`` (s): the look-ahead step, unless ``dt`` was
        given as an option."""
        self._loop_step = dt

    @property
    def feedback_gains(self) -> tuple[float, float, float]:
        """The tracking task's gains (1/s) of its ``e' = -K e`` loops (x, y, phi; phi's 0
        when the orientation is not tracked): what the simulation checks against the
        control step (:func:`ddwmmr.gains.gain_step_warning`)."""
        task = self.tracking
        return task.kx, task.ky, (task.kphi if task.track_orientation else 0.0)

    def reset(self, trajectory: Any, q0: np.ndarray, *, warn_start: bool = True) -> None:
        """Forget warm starts and counters; take the look-ahead step (:func:`control_step`).

        ``q0``: the start configuration, 5 finite numbers ``[x, y, phi, th1, th2]`` (m,
        rad), else :class:`ParameterError` naming ``q0``. ``warn_start``: warn of a start
        below ``stability_min`` (:func:`~ddwmmr.model.stability.warn_start_below_floor`);
        False where ``q0`` is no run's start (the ``mpc``'s backup qp)."""
        start = check_start(q0)
        if warn_start:
            warn_start_below_floor("qp", self.robot, start, self.stability_min)
        self.ctx.dt = control_step(self._dt_option, self._loop_step, trajectory, DEFAULT_DT)
        self.backend.reset()
        self.ctx.previous_command = None
        # cast: start holds 5 numbers (check_start), so [2:5] three (mypy counts no generator)
        self.ctx.start_turns = cast(
            "tuple[float, float, float]", tuple(whole_turns(angle) for angle in start[2:5])
        )
        self.fallbacks = 0
        self.last = StepInfo()
        self.min_predicted_edge_load = None
        self.edge_relaxed_steps = 0
        if self.edge_loads is not None:
            self.edge_loads.reset()

    def command(
        self,
        t: float,
        q: np.ndarray,
        pose_d: np.ndarray,
        velocity_d: np.ndarray,
        base_velocity: Sequence[float] | None = None,
    ) -> np.ndarray:
        """Input ``u = (v, w, th1dot, th2dot)`` (m/s, rad/s, rad/s, rad/s) for this step;
        ``base_velocity``: the measured ``(v, w)`` (the edge-load limit's; else the
        previous command's)."""
        ctx = self.ctx
        ctx.update_floats(*check_inputs(t, q, pose_d, velocity_d))
        if self.edge_loads is not None:
            measured = base_velocity if base_velocity is not None else ctx.previous_command
            self.edge_loads.observe(*(measured or (0.0, 0.0)))
        x = self._solve(ctx)
        relaxed = x is None and self.edge_loads is not None
        if relaxed:  # the edge rows conflict with the other limits: they give way
            # ignore: relaxed holds only with an edge-load limit
            self.edge_loads.active = False  # type: ignore[union-attr]
            try:
                x = self._solve(ctx)
            finally:
                self.edge_loads.active = True  # type: ignore[union-attr]
            self.edge_relaxed_steps += 1
        if x is None:
            return self._edge_prediction(ctx, self._fallback(ctx), relaxed)
        v, w, r1, r2, *slack = x
        v *= self.problem.unit
        scale = self.arm_scale(ctx, r1, r2)
        self.last = StepInfo(extra={"slack": self._slack_size(slack), "arm_scale": scale})
        ctx.previous_command = (v, w)
        return self._edge_prediction(ctx, np.array([v, w, r1 * scale, r2 * scale]), relaxed)

    def _slack_size(self, slack: list[float]) -> float:
        """The largest slack of an answer, the tracking rows' in m/s and rad/s (their
        position rows are in the tracking task's unit), 0 without slack."""
        if not slack:
            return 0.0
        unit = self.tracking.unit
        return max(abs(slack[0]) * unit, abs(slack[1]) * unit, *map(abs, slack[2:]))

    def _edge_prediction(self, ctx: StepContext, command: np.ndarray, relaxed: bool) -> np.ndarray:
        """With the edge-load limit: the least predicted edge load of ``command`` and
        whether the rows gave way (``relaxed``) into the step's info
        (``min_predicted_edge_load_n``, ``edge_load_relaxed``) and the run's minimum, and
        the joints' rate estimate moved on; ``command`` unchanged."""
        limit = self.edge_loads
        if limit is None:
            return command
        values = command.tolist()
        least = min(limit.predict(values))
        self.last.extra["min_predicted_edge_load_n"] = least
        self.last.extra["edge_load_relaxed"] = float(relaxed)
        if self.min_predicted_edge_load is None or least < self.min_predicted_edge_load:
            self.min_predicted_edge_load = least
        limit.advance(values, ctx.dt)
        return command

    def arm_scale(self, ctx: StepContext, rate1: float, rate2: float) -> float:
        """Scale of the joint rates that keeps the exact S one step ahead above the floor
        (:func:`safe_arm_scale`); the exact look-ahead runs only when the linearised
        margin is tight (:func:`full_step_is_safe` cannot prove scale 1)."""
        com = self._com
        trig = (ctx.sin_th1, ctx.cos_th1, ctx.sin_th12, ctx.cos_th12)
        th1, th2, dt, floor = ctx.th1, ctx.th2, ctx.dt, self.stability_min
        if full_step_is_safe(com, trig, th1, th2, rate1, rate2, dt, floor):
            return 1.0
        return safe_arm_scale(com, th1, th2, rate1, rate2, dt, floor)

    def _solve(self, ctx: StepContext) -> list[float] | None:
        """Build and solve this step's QP: the decision vector as floats, None on failure
        (inconsistent box, solver failure, non-finite answer)."""
        problem = self.problem
        problem.build(ctx)
        if self.mode != "weighted":
            x = solve(problem, self.backend, self.mode).x
            return None if x is None else x.tolist()
        if not problem.box_ok:
            return None
        x = self.backend(problem)
        if x is None:
            return None
        values = x.tolist()
        return values if all(map(math.isfinite, values)) else None

    def _fallback(self, ctx: StepContext) -> np.ndarray:
        """Safe command when the QP fails; it keeps every built-in limit:

        * arm: at half the speed limit along a direction raising every stability term
          below the floor (every edge of a support polygon; :meth:`_stability_ascent`;
          else still), never further past a joint limit or deeper into the
          shoulder-singularity margin, then scaled by the exact one-step stability check
          (:func:`safe_arm_scale`: S never drops below ``min(S_min, S_now)``);
        * base: stopped, or, with a slew limit, as close to stopped as its envelope
          allows (a force-limited base cannot stop within one step).
        """
        self.fallbacks += 1
        rates = list(self._stability_ascent(ctx))
        for joint, angle in enumerate((ctx.th1, ctx.th2)):
            low, up = self.joints.joint_bounds(angle, joint)  # 0 is always allowed
            rates[joint] = min(max(rates[joint], min(low, 0.0)), max(up, 0.0))
        r1, r2 = rates
        if self.singularity is not None:
            slope, bound = self.singularity.values(ctx)
            if bound > 0.0 and slope * r1 < 0.0:  # inside the margin: never deeper
                r1 = 0.0
        scale = safe_arm_scale(self._com, ctx.th1, ctx.th2, r1, r2, ctx.dt, self.stability_min)
        v = w = 0.0
        if self.base_motion is not None and ctx.previous_command is not None:
            low_v, high_v, low_w, high_w = self.base_motion.envelope(ctx)
            v, w = min(max(0.0, low_v), high_v), min(max(0.0, low_w), high_w)
        shortfall = self.tracking_shortfall(ctx, (v, w, r1, r2))
        self.last = StepInfo(fallback=True, extra={"slack": shortfall, "arm_scale": scale})
        ctx.previous_command = (v, w)
        return np.array([v, w, r1 * scale, r2 * scale])

    def tracking_shortfall(self, ctx: StepContext, u: Sequence[float]) -> float:
        """The slack the tracking rows need for the velocity command ``u = (v, w, th1dot,
        th2dot)`` (m/s, rad/s, rad/s, rad/s) at this step: the largest ``|J_E u - target|``
        (m/s on the xE, yE rows, rad/s on the phiE row; 0 on a row the task does not
        track). A QP answer's ``slack`` is this for its ``u``; a fallback step, which has
        no answer, reports it for the fallback's command (before the arm scale, as the
        QP's is), so ``last.extra["slack"]`` is a finite number on every step."""
        jac, target = np.zeros((3, 4)), np.zeros(3)
        tracking = self.tracking
        tracking.compute(ctx, jac, target)  # position rows in the task's unit
        v, w, r1, r2 = map(float, u)
        residual = jac @ np.array([v / tracking.unit, w, r1, r2]) - target
        residual[:2] *= tracking.unit
        return float(np.max(np.abs(residual)))

    def _stability_ascent(self, ctx: StepContext) -> tuple[float, float]:
        """Joint rates (rad/s) at half the speed limit along a direction that raises every
        stability row's term below the damper's target (:func:`ascent_direction`: on a
        polygon every edge, so a ridge between two edges is climbed, not crossed); zero
        when none is below it or no direction raises them all."""
        target = self.stability_min + self.stability.margin
        r1, r2 = ascent_direction(stability_rows(self._com, ctx.th1, ctx.th2), target)
        norm = math.hypot(r1, r2)
        if norm == 0.0:
            return 0.0, 0.0
        speed = 0.5 * self.robot.joint_speed_limit
        return speed * r1 / norm, speed * r2 / norm

    # -- reporting ----------------------------------------------------------------------
    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        """QP metrics merged into the run summary (see the module docstring)."""
        stability = np.asarray(timeseries["stability"])
        clearance = run_clearance(self.robot, self.obstacles, timeseries)
        return {
            "stability_min": self.stability_min,
            "stability_violations": int(np.sum(step_results(stability) < self.stability_min)),
            "qp_fallbacks": int(np.sum(commanded_steps(timeseries["fallback"]) > 0)),
            "min_obstacle_clearance_m": clearance,
            "qp_mode": self.mode,
            "qp_solver": self.solver,
            "min_predicted_edge_load_n": self.min_predicted_edge_load,
            "min_edge_load_floor_n": None if self.edge_loads is None else self.edge_loads.floor_n,
            "edge_load_relaxed_steps": self.edge_relaxed_steps,
        }

    # -- the scenario protocol's waypoint task -------------------------------------------
    @classmethod
    def waypoint_options(cls, run: WaypointRun) -> dict[str, Any]:
        """The options of a waypoint-task run: the protocol's stability floor and
        end-effector speed, position only, the scenario's obstacles as the protocol judges
        them, its control step; the plant's velocity envelope (what a force-limited base
        can follow), then the run's own ``controller_options`` over all of these.

        The protocol judges a collision by the base's enclosing circle (radius
        :func:`~ddwmmr.behaviours.obstacle.base_bubble`) while the qp keeps its footprint
        rectangle clear: each circle is grown by ``base_bubble - min(base_length,
        base_width) / 2`` (0.110 m for the protocol's robot), the least growth with which a
        footprint clear of the grown circle keeps the enclosing circle clear of the real
        one (level with the middle of a long side; with more room elsewhere), so the qp's
        ``obstacle_margin`` is the enclosing circle's clearance there."""
        config, robot = run.config, run.robot
        grow = base_bubble(robot) - 0.5 * min(robot.base_length, robot.base_width)
        return {
            "stability_min": config.qp_stability_min,
            "track_orientation": False,
            "max_speed": config.qp_max_speed,
            "obstacles": [(x, y, radius + grow) for x, y, radius in run.scenario.obstacles],
            "dt": config.dt,
            **(run.velocity_envelope or {}),
            **dict(config.controller_options),
        }


def _pieces(name: str, pieces: Any, kind: type) -> list[Any]:
    """The user's extra tasks or limits as a list (None: none); each must be a ``kind``."""
    items = list(pieces) if pieces is not None and iterable(pieces) else None
    if items is None and pieces is not None:
        raise ParameterError(
            f"{name} must be a list of {kind.__name__} objects (got {shown(pieces)})"
        )
    for item in items or []:
        if not isinstance(item, kind):
            raise ParameterError(f"{name} must be {kind.__name__} objects (got {shown(item)})")
    return items or []
