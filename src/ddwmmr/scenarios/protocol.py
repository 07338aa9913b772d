"""The scenario protocol (thesis 5.1, SPEC §5): run one scenario, judge it, measure it.

Success: every waypoint reached by the end effector within ``tolerance`` (0.01 m) in order
within the time limit (60 s, 120 s with obstacles), with ``S > 1`` at every step and (with
obstacles) the base's enclosing circle never touching an obstacle. The run stops at the
first failure.

Simulation loops here connect controllers to plants; controllers never import plants and
plants never import controllers:

* thesis controller on the thesis plant: wheel forces and joint targets straight through.
  It is a force-level controller and has no kinematic-plant run: the kinematic plant is
  the thesis plant's massless limit (``v = F / c1``), where its brake (P 100 > c1 = 15)
  becomes an unstable algebraic loop;
* ``qp`` controller (input ``u = (v, w, th1dot, th2dot)``) on the thesis plant through a
  model-based velocity-tracking loop (feed-forward of the damping plus a proportional
  term, bandwidth ``VELOCITY_BANDWIDTH``) and joint-rate commands turned into one-step joint
  targets; or on the kinematic plant directly (Euler, one controller call per step).

Metrics (seconds unless noted): ``time_s`` (time to the last waypoint, or to the failure),
``speed_m_s`` (straight-line length start -> waypoints / ``time_s``), ``time_base_s`` and
``time_arm_s`` (thesis controller: time in the moving-base / moving-arm states; other
controllers, which have no states: time with the base moving, |v| > 1 mm/s or |w| > 1 mrad/s,
and with an arm joint moving, > 1 mrad/s), time in and transitions into each fix state
(NaN for controllers without states), ``min_stability``, ``min_manipulability``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ddwmmr.arbiters.factory import check_arbiter, make_arbiter
from ddwmmr.arbiters.state_machine import (
    MANIPULABILITY,
    MOVE_ARM,
    MOVE_BASE,
    OBSTACLE,
    STABILITY,
    STATES,
    Hysteresis,
)
from ddwmmr.behaviours.controller import ThesisController
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.behaviours.obstacle import base_bubble
from ddwmmr.errors import ParameterError, check_nonnegative, check_positive
from ddwmmr.model import Robot
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.plants.thesis import ThesisPlant, ThesisState
from ddwmmr.scenarios.generator import Scenario

CONTROLLERS = ("thesis", "qp")
PLANTS = ("thesis", "kinematic")
#: Velocity-loop bandwidth (1/s) of the qp-on-thesis-plant adapter.
VELOCITY_BANDWIDTH = 10.0
#: Motion detection thresholds for controllers without states (m/s, rad/s).
MOVING_SPEED, MOVING_RATE = 1e-3, 1e-3
#: Trace sampling interval for recorded scenarios (s).
TRACE_INTERVAL = 0.05
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
    "sim_steps",
)


@dataclass(frozen=True)
class RunConfig:
    """How to run scenarios (picklable: it travels to worker processes).

    Attributes:
        controller: ``"thesis"`` or ``"qp"``; plant: ``"thesis"`` or ``"kinematic"``.
        payload: end-effector payload (kg); 3.0 by default (see docs/thesis.md).
        stability, manipulability: (enter, exit) thresholds; exit == enter: no hysteresis.
        dt: control and integration step (s).
        time_limit: s; None: 60 s, or 120 s when the scenario has obstacles.
        tolerance: waypoint tolerance (m).
        qp_stability_min, qp_max_speed: options of the ``qp`` controller.
        record: keep a trace (every ``TRACE_INTERVAL``) for plots.
        arbiter: thesis controller's arbiter, ``"state-machine"`` or ``"competitive"``
            (thresholds above) or an arbiter instance (``ddwmmr.arbiters.make_arbiter``).
        arbiter_seed: noise seed of the competitive arbiter.
    """

    controller: str = "thesis"
    plant: str = "thesis"
    payload: float = 3.0
    stability: tuple[float, float] = (1.25, 1.60)
    manipulability: tuple[float, float] = (0.75, 0.90)
    dt: float = 0.01
    time_limit: float | None = None
    tolerance: float = 0.01
    qp_stability_min: float = 1.25
    qp_max_speed: float = 1.0
    record: bool = False
    arbiter: Any = "state-machine"
    arbiter_seed: int = 0

    def __post_init__(self) -> None:
        if self.controller not in CONTROLLERS:
            raise ParameterError(
                f"controller must be one of {', '.join(CONTROLLERS)} (got {self.controller!r})"
            )
        if self.plant not in PLANTS:
            raise ParameterError(f"plant must be one of {', '.join(PLANTS)} (got {self.plant!r})")
        if self.controller == "thesis" and self.plant != "thesis":
            raise ParameterError(
                "plant: the thesis controller outputs wheel forces and needs --plant thesis"
            )
        Hysteresis(*self.stability)
        Hysteresis(*self.manipulability)
        check_arbiter(self.arbiter, self.controller)
        check_nonnegative("payload", self.payload)
        for name in ("dt", "tolerance", "qp_stability_min", "qp_max_speed"):
            check_positive(name, getattr(self, name))
        if self.time_limit is not None:
            check_positive("time_limit", self.time_limit)

    def limit_for(self, scenario: Scenario) -> float:
        """Time limit (s) for a scenario."""
        if self.time_limit is not None:
            return self.time_limit
        return 120.0 if scenario.obstacles else 60.0


@dataclass
class Outcome:
    """Result of one scenario: metrics (keys of :data:`METRICS`) and an optional trace.

    The trace (recorded runs only) has lists ``t`` (s), ``x``, ``y``, ``phi`` (base),
    ``xe``, ``ye`` (end effector), ``state`` (index into ``STATES``), ``s``, ``eta`` and
    ``distance`` (end effector to the current waypoint, m).
    """

    metrics: dict[str, Any]
    trace: dict[str, list[float]] | None = None


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
        self.min_s = math.inf
        self.min_eta = math.inf
        self.reason = "timeout"
        self.clearance = base_bubble(robot)
        self.trace: dict[str, list[float]] | None = None
        if config.record:
            keys = ("t", "x", "y", "phi", "xe", "ye", "state", "s", "eta", "distance")
            self.trace = {k: [] for k in keys}
        self._every = max(1, round(TRACE_INTERVAL / config.dt))

    @property
    def target(self) -> tuple[float, float] | None:
        """Current waypoint, None when all are reached."""
        w = self.scenario.waypoints
        return w[self.index] if self.index < len(w) else None

    def advance(self, xe: float, ye: float) -> bool:
        """Mark reached waypoints; True when the last one is reached."""
        tol = self.config.tolerance
        while (goal := self.target) is not None and math.hypot(xe - goal[0], ye - goal[1]) <= tol:
            self.index += 1
        if self.target is None:
            self.reason = "ok"
            return True
        return False

    def count(self, state: str) -> None:
        """One step in, and entries into, arbiter states."""
        self.steps_in[state] += 1
        if state != self.previous:
            self.entries[state] += 1
            self.previous = state

    def check(self, q: tuple[float, ...]) -> bool:
        """Stability and collision after a step; True when the run has failed."""
        s = self.robot.stability(q)[2]
        self.min_s = min(self.min_s, s)
        self.min_eta = min(self.min_eta, abs(math.sin(q[4])))
        if s <= 1.0:
            self.reason = "tipped"
            return True
        for ox, oy, radius in self.scenario.obstacles:
            if math.hypot(q[0] - ox, q[1] - oy) < radius + self.clearance:
                self.reason = "collision"
                return True
        return False

    def record(self, k: int, t: float, q: tuple[float, ...], state: str) -> None:
        """Append a trace sample every ``TRACE_INTERVAL``."""
        if self.trace is None or k % self._every:
            return
        x, y, phi, th1, th2 = q
        r = self.robot
        tr = self.trace
        tr["t"].append(t)
        tr["x"].append(x)
        tr["y"].append(y)
        tr["phi"].append(phi)
        xe = x + r.L1 * math.cos(phi + th1) + r.L2 * math.cos(phi + th1 + th2)
        ye = y + r.L1 * math.sin(phi + th1) + r.L2 * math.sin(phi + th1 + th2)
        tr["xe"].append(xe)
        tr["ye"].append(ye)
        goal = self.target
        tr["distance"].append(math.hypot(xe - goal[0], ye - goal[1]) if goal else 0.0)
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
            "speed_m_s": length / t if t > 0 else nan,
            "min_stability": self.min_s,
            "min_manipulability": self.min_eta,
            "sim_steps": steps,
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
        return Outcome({k: metrics[k] for k in METRICS}, self.trace)


def run_scenario(scenario: Scenario, config: RunConfig) -> Outcome:
    """Run one scenario under ``config`` and return its outcome."""
    robot = Robot().with_payload(config.payload)
    if config.controller == "thesis":
        return _run_thesis(robot, scenario, config)
    return _run_qp(robot, scenario, config)


def _run_thesis(robot: Robot, scenario: Scenario, config: RunConfig) -> Outcome:
    dt = config.dt
    plant = ThesisPlant(robot)
    arbiter = make_arbiter(config)
    controller = ThesisController(robot, arbiter, obstacles=scenario.obstacles)
    state = ThesisState(0.0, 0.0, 0.0, *controller.default_pose)
    tally = _Tally(robot, scenario, config)
    controller.reset(tally.target)
    steps = round(config.limit_for(scenario) / dt)
    r = robot
    if tally.check(state.q):  # a payload too heavy for the start pose
        return tally.outcome(0.0, 0, has_states=True)
    k = 0
    for k in range(steps + 1):
        t = k * dt
        a1 = state.phi + state.th1
        a12 = a1 + state.th2
        xe = state.x + r.L1 * math.cos(a1) + r.L2 * math.cos(a12)
        ye = state.y + r.L1 * math.sin(a1) + r.L2 * math.sin(a12)
        if tally.advance(xe, ye) or k == steps:
            break
        controller.set_target(tally.target)
        f_left, f_right, th1_t, th2_t = controller.act(t, state.q, state.v, state.w)
        tally.count(controller.state)
        tally.record(k, t, state.q, controller.state)
        plant.step(state, f_left, f_right, (th1_t, th2_t), dt)
        if tally.check(state.q):
            k += 1
            break
    return tally.outcome(k * dt, k, has_states=True)


class VelocityLoop:
    """Wheel forces (N) tracking a commanded (v, w) on the thesis plant.

    ``F = c1 v_d + k m (v_d - v)`` and ``T = c2 w_d + k I (w_d - w)`` (the damping
    feed-forward makes steady-state tracking exact; ``k`` is the loop bandwidth in 1/s),
    ``F_r = T / (width/2)``, mixed into wheel forces with rotation priority.
    """

    def __init__(self, plant: ThesisPlant, bandwidth: float = VELOCITY_BANDWIDTH) -> None:
        self.plant = plant
        self.bandwidth = bandwidth
        self._half_width = 0.5 * plant.robot.base_width
        limit = plant.force_limit
        self._total = 2.0 * limit

    def forces(self, state: ThesisState, v_d: float, w_d: float) -> tuple[float, float]:
        """Left/right wheel forces (N) for the desired speed (m/s) and yaw rate (rad/s)."""
        p = self.plant
        k = self.bandwidth
        f_t = p.c1 * v_d + k * p.mass * (v_d - state.v)
        torque = p.c2 * w_d + k * p.inertia(state.th1, state.th2) * (w_d - state.w)
        f_r = min(self._total, max(-self._total, torque / self._half_width))
        room = self._total - abs(f_r)
        f_t = min(room, max(-room, f_t))
        return 0.5 * f_t - 0.5 * f_r, 0.5 * f_t + 0.5 * f_r


def make_qp(
    robot: Robot, scenario: Scenario, config: RunConfig, envelope: dict[str, float] | None = None
) -> Any:
    """The registry's ``qp`` controller configured for waypoint tasks.

    ``envelope`` (the plant's :meth:`ThesisPlant.velocity_envelope`) keeps the commanded
    (v, w) within what a force-limited base can follow.
    """
    from ddwmmr.controllers import available_methods, make_controller

    if "qp" not in available_methods():
        raise ParameterError("controller: the qp controller is not available in this install")
    return make_controller(
        "qp",
        robot,
        stability_min=config.qp_stability_min,
        track_orientation=False,
        max_speed=config.qp_max_speed,
        obstacles=[tuple(o) for o in scenario.obstacles],
        dt=config.dt,
        **(envelope or {}),
    )


def _run_qp(robot: Robot, scenario: Scenario, config: RunConfig) -> Outcome:
    envelope = ThesisPlant(robot).velocity_envelope() if config.plant == "thesis" else None
    controller = make_qp(robot, scenario, config, envelope)
    pose0 = default_pose(robot)
    q = np.array([0.0, 0.0, 0.0, pose0[0], pose0[1]])
    tally = _Tally(robot, scenario, config)
    if hasattr(controller, "reset"):
        controller.reset(None, q.copy())
    dt = config.dt
    steps = round(config.limit_for(scenario) / dt)
    kinematic = KinematicPlant(robot, "euler") if config.plant == "kinematic" else None
    plant = ThesisPlant(robot) if kinematic is None else None
    state = ThesisState(*q.tolist()) if plant is not None else None
    loop = VelocityLoop(plant) if plant is not None else None
    velocity_d = np.zeros(3)
    if tally.check(tuple(q.tolist())):
        return tally.outcome(0.0, 0, has_states=False)
    k = 0
    for k in range(steps + 1):
        t = k * dt
        xe, ye, _ = robot.fk(q)
        if tally.advance(float(xe), float(ye)) or k == steps:
            break
        goal = tally.target
        assert goal is not None
        try:
            u = np.asarray(
                controller.command(t, q, np.array([goal[0], goal[1], 0.0]), velocity_d),
                dtype=float,
            )
        except Exception as exc:  # report a controller failure as the scenario's reason
            tally.reason = f"controller error: {type(exc).__name__}: {exc}".splitlines()[0]
            break
        if kinematic is not None:
            u, _ = kinematic.saturate(q, u)
            q = kinematic.step(t, q, dt, None, first_command=u)[0]
            base_moving = abs(u[0]) > MOVING_SPEED or abs(u[1]) > MOVING_RATE
        else:
            assert state is not None and loop is not None and plant is not None
            f_left, f_right = loop.forces(state, float(u[0]), float(u[1]))
            limit = robot.joint_speed_limit
            r1 = min(limit, max(-limit, float(u[2])))
            r2 = min(limit, max(-limit, float(u[3])))
            plant.step(state, f_left, f_right, (state.th1 + r1 * dt, state.th2 + r2 * dt), dt)
            q = np.array(state.q)
            base_moving = abs(state.v) > MOVING_SPEED or abs(state.w) > MOVING_RATE
        tally.steps_base += int(base_moving)
        tally.steps_arm += int(max(abs(u[2]), abs(u[3])) > MOVING_RATE)
        tally.record(k, t, tuple(q.tolist()), MOVE_BASE if base_moving else MOVE_ARM)
        if tally.check(tuple(q.tolist())):
            k += 1
            break
    return tally.outcome(k * dt, k, has_states=False)
