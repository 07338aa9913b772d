"""The scenario protocol (thesis 5.1): run one scenario, judge it, measure it.

Success: every waypoint reached by the end effector within ``tolerance`` (0.01 m) in order
within the time limit (60 s, 120 s with obstacles), with ``S > 1`` at every step and (with
obstacles) the base's enclosing circle never touching an obstacle. On a plant that judges
tipping by its own physics (the MuJoCo plant's contact forces, ``Plant.tip_time``) the
robot must also never tip over there (reason ``"tipped (physics)"``; ``"tipped"`` is
``S <= 1``). The run stops at the first failure.

A scenario is a :class:`WaypointTask` run by the library's one simulation loop
(:func:`ddwmmr.sim.loop.run_loop`), which connects any controller to any plant through
the plant interface (controllers never import plants and plants never import controllers).
The registry decides which take part (:mod:`ddwmmr.registry`): every controller registered
for the ``"waypoints"`` task (:func:`scenario_controllers`), on every registered plant that
accepts a command interface it sends (:func:`plants_for`); any other pair is refused with
one line. docs/thesis.md, "What is simulated", describes the pairs and why some are left
out.

Metrics (seconds unless noted): ``time_s`` (time to the last waypoint, or to the failure),
``speed_m_s`` (straight-line length start -> waypoints / ``time_s``; NaN for a scenario
that did not finish), ``time_base_s`` and
``time_arm_s`` (thesis controller: time in the moving-base / moving-arm states; other
controllers, which have no states: time with the base moving, |v| > 1 mm/s or |w| > 1 mrad/s,
and with an arm joint moving, > 1 mrad/s), time in and transitions into each fix state
(NaN for controllers without states), ``min_stability``, ``min_manipulability``,
``unloaded_time_s`` (physics plants, NaN elsewhere: time with an edge of the support
polygon unloaded, ``Plant.unloaded_time_s``; a wheel chattering on a lightly loaded side
counts), ``sim_steps`` and ``fallback_steps`` (steps whose command was the controller's safe
fallback after a failed solve, ``StepInfo.fallback``; NaN for the thesis controller).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import astuple, dataclass, replace
from typing import Any

import numpy as np

from ddwmmr import provenance
from ddwmmr.arbiters.checked import checked_arbiter
from ddwmmr.arbiters.factory import check_arbiter, check_arbiter_options
from ddwmmr.arbiters.state_machine import (
    MANIPULABILITY,
    MOVE_ARM,
    MOVE_BASE,
    OBSTACLE,
    STABILITY,
    STATES,
    THESIS_MANIPULABILITY,
    THESIS_STABILITY,
)
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.behaviours.obstacle import base_bubble, bubble_gap
from ddwmmr.commands import FORCE, VELOCITY, WheelForces, traits_of
from ddwmmr.controllers.base import (
    WaypointRun,
    available_controllers,
    controller_class,
    controller_traits,
    make_controller,
)
from ddwmmr.errors import (
    MASS_RANGE_KG,
    ParameterError,
    PluginError,
    check_finite,
    check_int_at_least,
    check_positive,
    check_range,
    check_step_count,
    float_values,
    one_of,
    raise_plugin_error,
    real_number,
    shown,
    texts_apart,
    xy_pairs,
)
from ddwmmr.model import Robot
from ddwmmr.model.stability import (
    STABILITY_CAP,
    STABILITY_FLOOR,
    max_payload,
    stability_terms,
    valid_stability_floor,
)
from ddwmmr.model.thesis_base import C1_DEFAULT, C2_DEFAULT
from ddwmmr.plants import available_plants, make_plant
from ddwmmr.plants.base import Observation, Plant, PlantDivergedError
from ddwmmr.registry import BUILTIN_MODULES, CONTROLLERS, PLANTS, unknown_hint
from ddwmmr.scenarios.generator import Scenario
from ddwmmr.sim.loop import run_loop

#: What each command interface sends, for the messages.
SENDS = {FORCE: "wheel forces", VELOCITY: "velocity commands"}
#: Motion detection thresholds for controllers without states (m/s, rad/s).
MOVING_SPEED, MOVING_RATE = 1e-3, 1e-3
#: Time limit (s) of a scenario when ``RunConfig.time_limit`` is None, and of one with
#: obstacles (thesis 5.1).
TIME_LIMIT_S, OBSTACLE_TIME_LIMIT_S = 60.0, 120.0
#: Longest control step (s): the thesis controller's gains are tuned per 0.01 s sample.
MAX_DT = 0.1
#: Largest threshold of each fix state: S is capped at STABILITY_CAP, eta = |sin th2| at 1.
THRESHOLD_RANGES = {"stability": STABILITY_CAP, "manipulability": 1.0}
#: Upper bound of ``qp_max_speed`` (m/s): far above what the robot can do (base 1.5 m/s).
MAX_QP_SPEED = 10.0
#: The ``qp_*`` options: a test of an allowed value and the allowed range as text.
QP_RANGES = {
    "qp_stability_min": (valid_stability_floor, f"(0, {STABILITY_CAP:g})"),
    "qp_max_speed": (lambda v: 0.0 < v <= MAX_QP_SPEED, f"(0, {MAX_QP_SPEED:g}] m/s"),
}
#: Trace sampling interval for recorded scenarios (s).
TRACE_INTERVAL = 0.05
#: Within this distance (m) of its waypoint the end effector is traced at every step.
FINE_TRACE_DISTANCE = 0.1
#: Columns of the per-scenario metrics, in CSV order.
METRICS = (
    "scenario",
    "success",
    "reason",
    "waypoints_reached",
    "time_s",
    "path_length_m",
    "speed_m_s",
    "time_base_s",
    "time_arm_s",
    "time_manipulability_s",
    "transitions_manipulability",
    "time_stability_s",
    "transitions_stability",
    "time_obstacle_s",
    "transitions_obstacle",
    "min_stability",
    "min_manipulability",
    "unloaded_time_s",
    "sim_steps",
    # Steps whose command was a safe fallback (a failed solve: the qp's stop, the mpc's
    # qp command); NaN for the thesis controller, which has none.
    "fallback_steps",
)
#: The metrics a run's outcome holds as NaN where they do not apply: the fix
#: states' times and transitions for a controller without states, the unloaded time off a
#: physics plant, the fallback steps for the thesis controller.
NOT_APPLICABLE_AS_NAN = (
    "time_manipulability_s",
    "transitions_manipulability",
    "time_stability_s",
    "transitions_stability",
    "time_obstacle_s",
    "transitions_obstacle",
    "unloaded_time_s",
    "fallback_steps",
)


@dataclass(frozen=True)
class RunConfig:
    """How to run scenarios (picklable: it travels to worker processes).

    Attributes:
        controller: a registered controller of the waypoint task
            (:func:`scenario_controllers`); plant: a registered plant it can command
            (:func:`plants_for`).
        payload: end-effector payload (kg); 3.0 by default (see docs/thesis.md); in
            [0, 1e5] kg and light enough that the start pose stands, S > 1
            (:func:`check_payload`; at most 9.338 kg for the default robot).
        stability, manipulability: (enter, exit) thresholds, enter <= exit, both in
            (0, 10] and (0, 1] (:data:`THRESHOLD_RANGES`, :func:`check_thresholds`);
            exit == enter: no hysteresis.
        dt: control and integration step (s), in (0, :data:`MAX_DT`] (:func:`check_dt`),
            at most the time limit and with at most :data:`ddwmmr.errors.MAX_STEPS` steps
            per run, as :func:`ddwmmr.simulate` (with ``time_limit`` None: dt >= 6e-5 s,
            checked here, and >= 1.2e-4 s for a scenario with obstacles, checked when it
            is run).
        time_limit: s, > 0 and finite (:func:`check_time_limit`); None: 60 s, or 120 s
            when the scenario has obstacles.
        tolerance: waypoint tolerance (m).
        qp_stability_min, qp_max_speed: options of the ``qp`` controller (the stability
            floor is also ``mpc``'s), in :data:`QP_RANGES` (:func:`check_qp_option`).
        controller_options: further ``(name, value)`` options of the controller (e.g.
            ``(("horizon", 3.0),)`` for the ``mpc``), over the protocol's own: a tuple (or
            list) of pairs, each name a str given once (:func:`check_controller_options`).
        record: keep a trace (every ``TRACE_INTERVAL``) for plots.
        arbiter: thesis controller's arbiter, a registered name
            (``ddwmmr.arbiters.available_arbiters()``: ``"state-machine"``, ``"competitive"``;
            thresholds above) or an arbiter instance (``ddwmmr.arbiters.make_arbiter``).
        arbiter_seed: noise seed of the competitive arbiter, an integer >= 0.
        arbiter_options: further ``(name, value)`` options of the arbiter named by
            ``arbiter`` (a plug-in's constructor parameters but the thresholds and seed,
            :func:`ddwmmr.arbiters.factory.arbiter_option_specs`; the built-in arbiters
            have none), pairs as ``controller_options`` takes them.

    Each field is checked on construction; a bad one raises a one-line
    :class:`~ddwmmr.errors.ParameterError` worded as ``python -m ddwmmr.scenarios``
    words it (which builds its configuration here, so both refuse the same values).
    """

    controller: str = "thesis"
    plant: str = "thesis"
    payload: float = 3.0
    stability: tuple[float, float] = astuple(THESIS_STABILITY)
    manipulability: tuple[float, float] = astuple(THESIS_MANIPULABILITY)
    dt: float = 0.01
    time_limit: float | None = None
    tolerance: float = 0.01
    qp_stability_min: float = STABILITY_FLOOR
    qp_max_speed: float = 1.0
    controller_options: tuple[tuple[str, Any], ...] = ()
    record: bool = False
    arbiter: Any = "state-machine"
    arbiter_seed: int = 0
    arbiter_options: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        controllers = scenario_controllers()
        if not one_of(self.controller, controllers):
            known = CONTROLLERS.names()
            raise ParameterError(
                f"controller must be one of {', '.join(controllers)} (got {shown(self.controller)})"
                + (
                    ""
                    if one_of(self.controller, known)
                    else unknown_hint(self.controller, controllers)
                )
            )
        PLANTS.entry(self.plant)  # an unknown name: one line naming the known ones
        accepted = plants_for(self.controller)
        if self.plant not in accepted:
            sends = " or ".join(
                SENDS.get(i, i) for i in controller_traits(self.controller)["interfaces"]
            )
            raise ParameterError(
                f"plant: the {self.controller} controller outputs {sends} and needs a plant "
                f"that takes them ({' or '.join(accepted)})"
            )
        check_thresholds("stability", self.stability)
        check_thresholds("manipulability", self.manipulability)
        check_arbiter(self.arbiter, self.controller)
        check_int_at_least("arbiter_seed", self.arbiter_seed, 0)  # any size: a seed
        # In the command line's order (python -m ddwmmr.scenarios), so that a bad value
        # gets its words there: dt's own range before the step count it makes.
        check_dt(self.dt)
        if self.time_limit is not None:
            check_time_limit(self.time_limit)
        for name in QP_RANGES:
            check_qp_option(name, getattr(self, name))
        check_payload(self.payload)
        check_positive("tolerance", self.tolerance)
        # stored as a tuple of tuples: a frozen configuration stays hashable
        object.__setattr__(
            self, "controller_options", check_controller_options(self.controller_options)
        )
        arbiter_options = check_controller_options(self.arbiter_options, "arbiter_options")
        check_arbiter_options(arbiter_options, self.arbiter, self.controller)
        object.__setattr__(self, "arbiter_options", arbiter_options)
        # Checked here rather than when a worker reaches a scenario halfway through a
        # batch. Without a time_limit, the shorter default: dt above it would run no step
        # at all; whether 120 s (obstacles) stays within the cap depends on the scenario,
        # which steps_for checks when the run starts.
        step_count(TIME_LIMIT_S if self.time_limit is None else self.time_limit, self.dt)

    def limit_for(self, scenario: Scenario) -> float:
        """Time limit (s) for a scenario."""
        if self.time_limit is not None:
            return self.time_limit
        return OBSTACLE_TIME_LIMIT_S if scenario.obstacles else TIME_LIMIT_S

    def steps_for(self, scenario: Scenario) -> int:
        """Most steps of a run of ``scenario``: its time limit / ``dt``, rounded (>= 1)."""
        return step_count(self.limit_for(scenario), self.dt)


def step_count(limit: float, dt: float) -> int:
    """:func:`ddwmmr.errors.check_step_count` of a run whose duration is its time limit,
    the messages naming ``time_limit``."""
    try:
        return check_step_count(limit, dt)
    except ParameterError as exc:
        raise ParameterError(str(exc).replace("duration", "time_limit")) from None


def check_dt(dt: Any) -> float:
    """``dt`` as a float if it is a control step in (0, :data:`MAX_DT`] s, else a one-line
    :class:`ParameterError` (also for what is no number: text, a boolean, None)."""
    value = real_number(dt)
    if value is None:
        raise ParameterError(f"dt must be in (0, {MAX_DT:g}] s (got {shown(dt)})")
    if not (math.isfinite(value) and 0.0 < value <= MAX_DT):
        got, (high,) = texts_apart(value, MAX_DT)
        raise ParameterError(f"dt must be in (0, {high}] s (got {got})")
    return value


def check_time_limit(limit: Any) -> float:
    """``limit`` as a float if it is a scenario's time limit, > 0 s and finite, else a
    one-line :class:`ParameterError` naming ``time_limit``."""
    value = real_number(limit)
    if value is None or not (math.isfinite(value) and value > 0.0):
        got = shown(limit) if value is None else f"{value:g}"
        raise ParameterError(f"time_limit must be > 0 s and finite (got {got})")
    return value


def check_payload(payload: Any) -> float:
    """``payload`` (kg) as a float if it is in :data:`ddwmmr.errors.MASS_RANGE_KG` and the
    default robot carrying it stands in the scenarios' start pose (:func:`check_start_pose`),
    else a one-line :class:`ParameterError`."""
    value = check_range("payload", payload, *MASS_RANGE_KG, "kg")
    check_start_pose(value)
    return value


def config_robot(config: RunConfig) -> Robot:
    """The robot a configuration simulates: the default robot with ``config.payload``."""
    return Robot().with_payload(config.payload)


def check_start_pose(payload: float) -> None:
    """Refuse a payload (kg) that already tips the default robot over in the scenarios'
    start pose (S <= 1): every scenario would fail at t = 0. The message names the
    heaviest payload the pose holds (:func:`max_start_payload`)."""
    robot = Robot().with_payload(payload)
    th1, th2 = default_pose(robot)
    s = robot.stability((0.0, 0.0, 0.0, th1, th2))[2]
    if s <= 1.0:
        raise ParameterError(
            f"payload: {payload:g} kg tips the robot over in the start pose (S = {s:.3g} <= 1); "
            f"the start pose holds at most {max_start_payload():.10g} kg"
        )


def max_start_payload() -> float:
    """The heaviest payload (kg, rounded down to the gram) with S > 1 in the scenarios'
    start pose (:func:`~ddwmmr.model.stability.max_payload` of the default robot)."""
    robot = Robot()
    return max_payload(robot, *default_pose(robot))


def check_controller_options(
    options: Any, field: str = "controller_options"
) -> tuple[tuple[str, Any], ...]:
    """``options`` as a tuple if it is ``RunConfig.controller_options`` (or the ``field``
    of the same form, ``arbiter_options``): a tuple (or list) of ``(name, value)`` pairs,
    each name a str given once, else a one-line :class:`ParameterError` (text or a dict
    would otherwise fail in the controller's ``dict()`` of them, and a name given twice
    would silently keep its last value)."""
    wanted = 'a tuple of (name, value) pairs with distinct names, e.g. (("horizon", 3.0),)'
    if not isinstance(options, (tuple, list)):
        raise ParameterError(f"{field} must be {wanted} (got {shown(options)})")
    seen: set[str] = set()
    for pair in options:
        if not (isinstance(pair, (tuple, list)) and len(pair) == 2 and isinstance(pair[0], str)):
            raise ParameterError(f"{field} must be {wanted} (got {shown(pair)})")
        if pair[0] in seen:
            raise ParameterError(f"{field}: {pair[0]!r} is given twice; each name once ({wanted})")
        seen.add(pair[0])
    return tuple((name, value) for name, value in options)


def check_qp_option(name: str, value: float) -> float:
    """``value`` if it is allowed for the ``qp_*`` option ``name`` (:data:`QP_RANGES`),
    else a one-line :class:`ParameterError`."""
    allowed, text = QP_RANGES[name]
    value = check_finite(name, value, f"in {text}")
    if not allowed(value):
        raise ParameterError(f"{name} must be in {text} (got {value:g})")
    return value


def check_thresholds(name: str, thresholds: Sequence[float]) -> tuple[float, float]:
    """``(enter, exit)`` of fix state ``name`` (``"stability"`` or ``"manipulability"``)
    if both are in (0, :data:`THRESHOLD_RANGES` [name]] with enter <= exit, else a
    one-line :class:`ParameterError`."""
    high = THRESHOLD_RANGES[name]
    values = float_values(thresholds, 2)
    if values is None:
        raise ParameterError(
            f"{name} thresholds must be two numbers (ENTER, EXIT) in (0, {high:g}] "
            f"(got {shown(thresholds)})"
        )
    enter, exit_ = values
    if not all(math.isfinite(v) and 0.0 < v <= high for v in values):
        raise ParameterError(
            f"{name} thresholds must be in (0, {high:g}] (got {enter:g}, {exit_:g})"
        )
    if not enter <= exit_:
        raise ParameterError(
            f"{name} thresholds: ENTER must be <= EXIT, both in (0, {high:g}] "
            f"(got {enter:g}, {exit_:g})"
        )
    return enter, exit_


@dataclass
class Outcome:
    """Result of one scenario: metrics (keys of :data:`METRICS`) and an optional trace.

    The trace (recorded runs only) has lists ``t`` (s), ``x``, ``y``, ``phi`` (base),
    ``xe``, ``ye`` (end effector), ``state`` (index into ``STATES``), ``s``, ``eta`` and
    ``distance`` (end effector to the current waypoint, m).
    """

    metrics: dict[str, Any]
    trace: dict[str, list[float]] | None = None
    #: Median wall-clock time of one controller call (us): a timing, so not a metric (the
    #: metrics, and scenarios.csv, are deterministic).
    median_step_us: float | None = None


class _Tally:
    """Per-step bookkeeping shared by the loops: waypoints, metrics, failure, trace."""

    def __init__(self, robot: Robot, scenario: Scenario, config: RunConfig) -> None:
        self.robot = robot
        self.scenario = scenario
        self.config = config
        self.index = 0
        self.steps_in = dict.fromkeys(STATES, 0)  # step counts: exact times at the end
        self.entries = dict.fromkeys(STATES, 0)
        self.previous: str | None = None
        self.steps_base = self.steps_arm = 0
        self.fallback_steps = 0
        self.min_s = math.inf
        self.min_eta = math.inf
        #: Physics plants: the plant, which judges tipping itself (``tip_time``).
        self.physics: Any = None
        self.reason = "timeout"
        self.step_ns: list[int] = []  # wall-clock time of each controller call
        self.clearance = base_bubble(robot)
        self.trace: dict[str, list[float]] | None = None
        if config.record:
            keys = ("t", "x", "y", "phi", "xe", "ye", "state", "s", "eta", "distance")
            self.trace = {k: [] for k in keys}
        self._every = max(1, round(TRACE_INTERVAL / config.dt))
        self.steps = config.steps_for(scenario)
        self._tolerance = config.tolerance
        self._com = robot.com_coefficients
        #: Current waypoint (m, world), None when all are reached (kept with ``index``).
        self.target: tuple[float, float] | None = self._waypoint(0)

    def _waypoint(self, index: int) -> tuple[float, float] | None:
        w = self.scenario.waypoints
        return w[index] if index < len(w) else None

    def advance(self, xe: float, ye: float) -> bool:
        """Mark reached waypoints; True when the last one is reached."""
        goal = self.target
        while goal is not None and math.hypot(xe - goal[0], ye - goal[1]) <= self._tolerance:
            self.index += 1
            goal = self.target = self._waypoint(self.index)
        if goal is None:
            self.reason = "ok"
            return True
        return False

    def count(self, state: str) -> None:
        """One step in, and entries into, arbiter states."""
        self.steps_in[state] += 1
        if state != self.previous:
            self.entries[state] += 1
            self.previous = state

    def check(self, q: Sequence[float]) -> bool:
        """Stability and collision after a step; True when the run has failed."""
        s = stability_terms(self._com, q[3], q[4])[2]
        self.min_s = min(self.min_s, s)
        self.min_eta = min(self.min_eta, abs(math.sin(q[4])))
        if s <= 1.0:
            self.reason = "tipped"
            return True
        for obstacle in self.scenario.obstacles:
            if bubble_gap(q[0], q[1], obstacle, self.clearance) < 0.0:
                self.reason = "collision"
                return True
        return False

    def record(
        self,
        k: int,
        t: float,
        q: tuple[float, ...],
        state: str,
        goal: tuple[float, float] | None = None,
    ) -> None:
        """Append a trace sample every ``TRACE_INTERVAL``, and at every step while the end
        effector is within ``FINE_TRACE_DISTANCE`` of its waypoint (so the trace resolves
        the approach to the 0.01 m tolerance). ``goal`` overrides the current waypoint
        (the sample of the step that reached it)."""
        if self.trace is None:
            return
        x, y, phi, th1, th2 = q
        r = self.robot
        xe = x + r.L1 * math.cos(phi + th1) + r.L2 * math.cos(phi + th1 + th2)
        ye = y + r.L1 * math.sin(phi + th1) + r.L2 * math.sin(phi + th1 + th2)
        goal = goal if goal is not None else self.target
        distance = math.hypot(xe - goal[0], ye - goal[1]) if goal else 0.0
        if k % self._every and distance >= FINE_TRACE_DISTANCE:
            return
        tr = self.trace
        tr["t"].append(t)
        tr["x"].append(x)
        tr["y"].append(y)
        tr["phi"].append(phi)
        tr["xe"].append(xe)
        tr["ye"].append(ye)
        tr["distance"].append(distance)
        tr["state"].append(float(STATES.index(state)))
        tr["s"].append(r.stability(q)[2])
        tr["eta"].append(abs(math.sin(th2)))

    def outcome(self, t: float, steps: int, has_states: bool) -> Outcome:
        """Collect the metrics at the end of a run at time t (s)."""
        length = self.scenario.path_length()
        nan = math.nan
        dt = self.config.dt
        metrics: dict[str, Any] = {
            "scenario": self.scenario.index + 1,
            "success": self.reason == "ok",
            "reason": self.reason,
            "waypoints_reached": self.index,
            "time_s": t,
            "path_length_m": length,
            # thesis Table 5.2: the route over the time to its last waypoint; a run that
            # stopped early covered only part of the route, so it has no such speed
            "speed_m_s": length / t if t > 0 and self.reason == "ok" else nan,
            "min_stability": self.min_s,
            "min_manipulability": self.min_eta,
            "unloaded_time_s": nan if self.physics is None else self.physics.unloaded_time_s,
            "sim_steps": steps,
            "fallback_steps": nan if has_states else self.fallback_steps,
        }
        if has_states:
            metrics["time_base_s"] = self.steps_in[MOVE_BASE] * dt
            metrics["time_arm_s"] = self.steps_in[MOVE_ARM] * dt
            for key, state in (
                ("manipulability", MANIPULABILITY),
                ("stability", STABILITY),
                ("obstacle", OBSTACLE),
            ):
                metrics[f"time_{key}_s"] = self.steps_in[state] * dt
                metrics[f"transitions_{key}"] = self.entries[state]
        else:
            metrics["time_base_s"] = self.steps_base * dt
            metrics["time_arm_s"] = self.steps_arm * dt
            for key in ("manipulability", "stability", "obstacle"):
                metrics[f"time_{key}_s"] = nan
                metrics[f"transitions_{key}"] = nan
        median = float(np.median(self.step_ns)) / 1000.0 if self.step_ns else None
        return Outcome({k: metrics[k] for k in METRICS}, self.trace, median)


class WaypointTask:
    """The thesis protocol as a loop task: reference = current waypoint, judged by a tally.

    ``has_states``: the controller is the thesis state machine (its states are counted);
    otherwise base and arm motion are detected from the measured state and the command.
    ``plant``: the run's plant; one with ``tip_time`` (physics) also judges tipping.
    """

    trajectory = None

    def __init__(
        self, tally: _Tally, controller: Any, has_states: bool, plant: Plant | None = None
    ) -> None:
        self.tally = tally
        self.controller = controller
        self.has_states = has_states
        tally.physics = plant if plant is not None and traits_of(plant).judges_tipping else None
        self._velocity_d = np.zeros(3)
        self._goal: tuple[float, float] | None = None
        self._pose_d = np.zeros(3)
        self._L1, self._L2 = tally.robot.L1, tally.robot.L2

    def start(self, obs: Observation) -> bool:
        """A payload too heavy for the start pose fails at once."""
        return self.tally.check(obs.values)

    def finished(self, k: int, t: float, obs: Observation) -> bool:
        """Every waypoint reached, or the time limit (checked before commanding)."""
        x, y, phi, th1, th2 = obs.values
        a1 = phi + th1
        a12 = a1 + th2
        xe = x + self._L1 * math.cos(a1) + self._L2 * math.cos(a12)
        ye = y + self._L1 * math.sin(a1) + self._L2 * math.sin(a12)
        tally = self.tally
        goal, index = tally.target, tally.index
        done = tally.advance(xe, ye)
        if tally.index != index and tally.trace is not None:  # trace the reaching sample
            state = self.controller.state if self.has_states else MOVE_ARM
            tally.record(k, t, (x, y, phi, th1, th2), state, goal=goal)
        return done or k == tally.steps

    def reference(self, t: float, obs: Observation | None) -> tuple[np.ndarray, np.ndarray]:
        """The current waypoint as a pose (orientation 0, not tracked) at rest (the arrays
        are shared between steps: read-only)."""
        goal = self.tally.target
        if goal is not self._goal:
            assert goal is not None
            self._goal, self._pose_d = goal, np.array([goal[0], goal[1], 0.0])
        return self._pose_d, self._velocity_d

    def record(
        self,
        k: int,
        t: float,
        obs: Observation,
        command: Any,
        applied: Any,
        saturated: bool,
        info: Any,
        step_ns: int,
    ) -> None:
        """Count the controller's state (state machines) and trace the state at t.

        Controllers without states are traced as moving the base when the measured base
        velocity says so (|v| > 1 mm/s or |w| > 1 mrad/s).
        """
        self.tally.step_ns.append(step_ns)
        if self.has_states:
            state = self.controller.state
            self.tally.count(state)
        else:
            moving = abs(obs.v) > MOVING_SPEED or abs(obs.w) > MOVING_RATE
            state = MOVE_BASE if moving else MOVE_ARM
            self.tally.steps_arm += int(self._arm_rate(obs, applied) > MOVING_RATE)
            self.tally.fallback_steps += int(getattr(info, "fallback", False))
        if self.tally.trace is not None:
            self.tally.record(k, t, obs.values, state)

    def after_step(self, k: int, t: float, obs: Observation, applied: Any) -> bool:
        """Motion tallies (stateless controllers), then stability and collision."""
        if not self.has_states:
            base_moving = abs(obs.v) > MOVING_SPEED or abs(obs.w) > MOVING_RATE
            self.tally.steps_base += int(base_moving)
        failed = self.tally.check(obs.values)
        if failed or self.tally.physics is None:
            return failed
        return self._tipped_physically()

    def _tipped_physically(self) -> bool:
        """Physics plants: True (a failure) once the plant says the robot tipped over."""
        if self.tally.physics.tip_time is None:
            return False
        self.tally.reason = "tipped (physics)"
        return True

    def _arm_rate(self, obs: Observation, applied: Any) -> float:
        """Largest commanded joint rate (rad/s): from u, or from the joint targets of a
        force command over one step."""
        if isinstance(applied, WheelForces):
            _, _, _, th1, th2 = obs.values
            dt = self.tally.config.dt
            return max(abs(applied.th1_target - th1), abs(applied.th2_target - th2)) / dt
        rate: float = max(abs(applied[2]), abs(applied[3]))
        return rate

    def controller_error(self, k: int, error: Exception) -> bool:
        """A controller failure ends the scenario with the error as its reason."""
        self.tally.reason = f"controller error: {type(error).__name__}: {error}".splitlines()[0]
        return True

    def diverged(self, k: int, error: PlantDivergedError) -> None:
        """The plant blew up: the scenario fails."""
        self.tally.reason = "diverged"


def scenario_controllers() -> list[str]:
    """The registered controllers that do the waypoint task (``RunConfig.controller``,
    ``--controller``), in listing order."""
    return available_controllers("waypoints")


def plants_for(controller: str) -> list[str]:
    """The registered plants that take a command interface ``controller`` can send."""
    interfaces = controller_traits(controller)["interfaces"]
    return [p for p in available_plants() if set(interfaces) & set(PLANTS.traits(p)["interfaces"])]


def run_scenario(scenario: Scenario, config: RunConfig) -> Outcome:
    """Run one scenario under ``config`` and return its outcome.

    A ``scenario`` that is no :class:`Scenario` or a ``config`` that is no
    :class:`RunConfig` is refused with a one-line :class:`ParameterError`."""
    if not isinstance(scenario, Scenario):
        raise ParameterError(
            f"scenario must be a Scenario (ddwmmr.scenarios.generate) (got {shown(scenario)})"
        )
    if not isinstance(config, RunConfig):
        raise ParameterError(
            f"config must be a RunConfig (ddwmmr.scenarios.RunConfig) (got {shown(config)})"
        )
    scenario = check_scenario(scenario)
    robot = config_robot(config)
    plant = make_scenario_plant(robot, config)
    controller = make_scenario_controller(robot, scenario, config, plant)
    # Start at the origin heading +x in the thesis's default pose (the pose it drives in).
    q0 = np.array([0.0, 0.0, 0.0, *default_pose(robot)])
    # A controller with an arbiter reports the arbiter's state; the others have none.
    has_states = controller_traits(config.controller)["arbiter"]
    tally = _Tally(robot, scenario, config)
    task = WaypointTask(tally, controller, has_states, plant)
    end = run_loop(plant, controller, task, q0, config.dt, tally.steps)
    return tally.outcome(end.samples * config.dt, end.samples, has_states=has_states)


def check_scenario(scenario: Scenario) -> Scenario:
    """``scenario`` with its ``waypoints`` as a tuple of float pairs, if it is a
    :class:`Scenario` (built by hand, say) whose ``index`` is an integer >= 0, whose
    ``waypoints`` are a non-empty list of (x, y) pairs in m
    (:func:`~ddwmmr.errors.xy_pairs`: finite, within
    +-:data:`~ddwmmr.errors.MAX_COORDINATE_M` m; not a set, whose order is undefined), and
    whose ``obstacles`` are (x, y, radius) circles (m) as the ``qp``'s option takes them
    (:func:`ddwmmr.qp.limits.obstacles.as_circles`; its refusal prefixed with ``scenario
    obstacles``); else a one-line :class:`ParameterError` naming the field."""
    from ddwmmr.qp.limits.obstacles import as_circles

    check_int_at_least("scenario index", scenario.index, 0)
    waypoints = xy_pairs("scenario waypoints", scenario.waypoints)
    try:
        as_circles(scenario.obstacles)
    except ParameterError as exc:
        message = str(exc)
        field = "" if message.startswith("obstacles") else "obstacles: "
        raise ParameterError(f"scenario {field}{message}") from None
    # the checked list: an iterator is spent by the check, a numpy array's rows are arrays
    return replace(scenario, waypoints=waypoints)


def make_scenario_plant(robot: Robot, config: RunConfig) -> Plant:
    """The plant of ``config``: thesis dynamics, the kinematic model (Euler), or MuJoCo.

    The MuJoCo plant carries the thesis plant's base damping (c1, c2): the benchmark then
    differs between the thesis and the physics plant only by what physics adds (contacts,
    tipping, wheel slip, motor torque limits, arm inertia), and the thesis controller's PD
    gains meet the damped base they were designed for.
    """
    if config.plant == "kinematic":
        return make_plant("kinematic", robot, integrator="euler")
    if config.plant == "mujoco":
        return make_plant("mujoco", robot, base_damping=(C1_DEFAULT, C2_DEFAULT))
    return make_plant(config.plant, robot)


def make_scenario_controller(
    robot: Robot, scenario: Scenario, config: RunConfig, plant: Plant
) -> Any:
    """The registered controller ``config.controller`` built for a waypoint-task run of
    ``scenario`` on ``plant``, with the options its ``waypoint_options`` asks for (it sees
    the plant's traits and velocity envelope, never the plant)."""
    run = WaypointRun(scenario, config, traits_of(plant), robot, _envelope(plant))
    options = waypoint_options(config.controller, run)
    arbiter = options.get("arbiter")
    if arbiter is not None and controller_traits(config.controller)["arbiter"]:
        # A plug-in arbiter's decisions are checked as it makes them (the tally counts
        # its states), whichever controller takes it; the library's own run unwrapped.
        origin = f"controller {config.controller}: waypoint_options"
        options["arbiter"] = checked_arbiter(arbiter, origin)
    return make_controller(config.controller, robot, **options)


def waypoint_options(controller: str, run: WaypointRun) -> dict[str, Any]:
    """The options registered controller ``controller`` asks for on ``run`` (its
    ``waypoint_options(run)``, a copy). A plug-in declaring the waypoint task without that
    method, one whose method raises or returns no mapping, is refused with a one-line
    :class:`PluginError` naming it; a ParameterError it raises (bad input) passes as it
    is, and so does anything a built-in controller raises (a bug of ours keeps its
    traceback)."""
    hook = getattr(controller_class(controller), "waypoint_options", None)
    if not callable(hook):
        raise PluginError(
            f"controller {controller}: declares the waypoints task but has no "
            "waypoint_options(run) classmethod (ddwmmr.controllers.base.WaypointRun -> dict "
            "of options)"
        )
    built_in = CONTROLLERS.entry(controller).module in BUILTIN_MODULES
    try:
        options = hook(run)
    except Exception as error:
        if built_in:
            raise
        raise_plugin_error(f"controller {controller}: waypoint_options(run)", error)
    if not isinstance(options, Mapping):
        raise PluginError(
            f"controller {controller}: waypoint_options(run) must return a dict of options "
            f"(got {shown(options)})"
        )
    return dict(options)


def controller_options_record(config: RunConfig, scenario: Scenario) -> dict[str, Any]:
    """Every option of ``config.controller`` with the value the runs of ``config`` use, as
    a batch's ``summary.json["controller_options"]`` records it (JSON-ready,
    :func:`ddwmmr.provenance.encode`), taken on ``scenario`` without its obstacles (each
    scenario's own).

    A controller that resolves its options for the plant (the ``mpc``: its ``resolved``
    options, after ``adopt_plant``) records them as resolved, in the waypoint task's
    objective (``"reach"``); any other records its ``waypoint_options`` over the defaults
    of its constructor (:func:`ddwmmr.provenance.options_record`, where the defaults are
    read, not restated). An option holding an object JSON has no form for (the thesis
    controller's arbiter) is recorded as its class, ``module.Class``: a repr would carry a
    memory address and differ from run to run. Building the controller checks the options
    as a run would (a bad one: its one-line :class:`ParameterError`)."""
    robot = config_robot(config)
    plant = make_scenario_plant(robot, config)
    controller = make_scenario_controller(robot, scenario, config, plant)
    adopt = getattr(controller, "adopt_plant", None)
    if callable(adopt):  # as the loop does before the first step
        adopt(traits_of(plant))
    resolved = getattr(controller, "resolved", None)
    if callable(getattr(resolved, "record", None)):
        # ignore: a callable resolved.record above rules None out
        options = dict(resolved.record("reach", config.dt))  # type: ignore[union-attr]
    else:
        run = WaypointRun(scenario, config, traits_of(plant), robot, _envelope(plant))
        options = waypoint_options(config.controller, run)
        options = {**provenance.options_record(config.controller, {}), **options}
    options.pop("obstacles", None)
    return {name: _recorded(value) for name, value in options.items()}


def _recorded(value: Any) -> Any:
    """``value`` JSON-ready (:func:`ddwmmr.provenance.encode`), or the class of an object
    it has no form for (``"ddwmmr.arbiters.state_machine.StateMachineArbiter"``)."""
    encoded = provenance.encode(value)
    if isinstance(encoded, dict) and set(encoded) == {"repr"}:
        return f"{type(value).__module__}.{type(value).__qualname__}"
    return encoded


def _envelope(plant: Plant) -> dict[str, Any] | None:
    """What a velocity command can ask of a force-limited base (None: no limit)."""
    envelope = getattr(plant, "velocity_envelope", None)
    return envelope() if envelope is not None else None


__all__ = [
    "MAX_DT",
    "METRICS",
    "THRESHOLD_RANGES",
    "Outcome",
    "RunConfig",
    "WaypointTask",
    "check_controller_options",
    "check_dt",
    "check_payload",
    "check_qp_option",
    "check_start_pose",
    "check_thresholds",
    "check_time_limit",
    "config_robot",
    "controller_options_record",
    "make_scenario_controller",
    "make_scenario_plant",
    "max_start_payload",
    "plants_for",
    "run_scenario",
    "scenario_controllers",
    "step_count",
    "waypoint_options",
]
