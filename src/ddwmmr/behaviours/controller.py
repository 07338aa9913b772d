"""The thesis's hierarchical behaviour-based controller (thesis ch. 4), assembled.

High level: behaviours (objective, manipulability, stability, optional obstacle avoidance)
all see the same :class:`~ddwmmr.behaviours.base.Percept` and return the same
:class:`~ddwmmr.behaviours.base.Proposal`; an arbiter picks one. Low level: the PD base
mover turns the proposal into wheel forces, the arm mover into joint targets.

The controller sees only sensor values (configuration and base velocities) and outputs
actuator commands (wheel forces in N, joint targets in rad); which plant consumes them is
up to the simulation loop. It speaks the force interface of :mod:`ddwmmr.commands`:
:meth:`ThesisController.command` is the loop's entry point (the same call as every other
controller, with the measured base velocity), :meth:`ThesisController.act` the plain form.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ddwmmr.arbiters.base import Arbiter
from ddwmmr.arbiters.state_machine import StateMachineArbiter
from ddwmmr.behaviours.base import Behaviour, Percept, sense
from ddwmmr.behaviours.lowlevel import ArmMover, BaseMover, PDGains
from ddwmmr.behaviours.manipulability import Manipulability
from ddwmmr.behaviours.objective import Objective
from ddwmmr.behaviours.obstacle import ObstacleAvoidance
from ddwmmr.behaviours.stability import Stability
from ddwmmr.commands import FORCE, WheelForces
from ddwmmr.model import Robot

#: Actuator command: (left wheel force N, right wheel force N, th1 target rad, th2 target rad).
Actuation = tuple[float, float, float, float]


class ThesisController:
    """Behaviours + arbiter + low-level controllers (thesis Fig 4.1).

    Args:
        robot: the robot (geometry for IK and metrics).
        arbiter: any :class:`~ddwmmr.arbiters.Arbiter`; default the thesis's
            :class:`StateMachineArbiter` with its thresholds.
        obstacles: ``(x, y, radius)`` circles (m); adds the obstacle-avoidance behaviour.
        gains: PD gains (thesis Table 4.2).
        adjust: base displacement target of the manipulability/stability behaviours (m).
    """

    name = "thesis"
    #: Loop contract: wheel forces out, measured (v, w) in, one call per control step.
    interface = FORCE
    wants_base_velocity = True
    zero_order_hold = True

    def __init__(
        self,
        robot: Robot,
        arbiter: Arbiter | None = None,
        obstacles: Iterable[tuple[float, float, float]] = (),
        gains: PDGains | None = None,
        adjust: float = 0.5,
    ) -> None:
        self.robot = robot
        self.arbiter: Arbiter = arbiter if arbiter is not None else StateMachineArbiter()
        self.behaviours: dict[str, Behaviour] = {
            "objective": Objective(robot),
            "manipulability": Manipulability(robot, adjust),
            "stability": Stability(robot, adjust),
        }
        obstacles = tuple(obstacles)
        if obstacles:
            self.behaviours["obstacle"] = ObstacleAvoidance(robot, obstacles)
        self.base = BaseMover(gains)
        self.arm = ArmMover(robot)
        self.target: tuple[float, float] | None = None
        self.state = self.arbiter.state
        self._hold: tuple[float, float] | None = None
        self.last_percept: Percept | None = None

    @property
    def default_pose(self) -> tuple[float, float]:
        """Arm pose held while driving (rad); scenarios start in it."""
        return self.behaviours["objective"].pose  # type: ignore[attr-defined]

    def reset(self, target: tuple[float, float] | None = None, q0: object = None) -> None:
        """Start a new run toward ``target`` (m, world); ``q0`` is not needed.

        The loop calls ``reset(None, q0)`` like for every controller; the target then
        arrives with each :meth:`command`.
        """
        self.arbiter.reset()
        self.state = self.arbiter.state
        self.target = target
        self._hold = None

    def set_target(self, target: tuple[float, float] | None) -> None:
        """Change the task point (the next waypoint), or None when the task is done."""
        self.target = target

    def command(
        self,
        t: float,
        q: np.ndarray,
        pose_d: np.ndarray,
        velocity_d: np.ndarray,
        *,
        base_velocity: tuple[float, float] = (0.0, 0.0),
    ) -> WheelForces:
        """Wheel forces and joint targets for the task point ``pose_d[:2]`` (m, world).

        ``base_velocity`` is the measured ``(v, w)`` (m/s, rad/s); ``velocity_d`` is unused
        (the behaviours work on points, not trajectories).
        """
        self.target = (float(pose_d[0]), float(pose_d[1]))
        v, w = base_velocity
        q = tuple(q.tolist()) if isinstance(q, np.ndarray) else tuple(float(a) for a in q)
        f_left, f_right, a1, a2 = self.act(t, q, v, w)
        return WheelForces(f_left, f_right, a1, a2)

    def act(
        self, t: float, q: tuple[float, float, float, float, float], v: float, w: float
    ) -> Actuation:
        """Actuator command for time t (s), configuration q, speed v (m/s), yaw rate w (rad/s)."""
        p = sense(self.robot, t, q, v, w, self.target, self._hold)
        selection = self.arbiter.select(p, self.behaviours)
        proposal = selection.proposal
        if selection.state != self.state or self._hold is None:
            # Latch the end effector where it is as the new state starts, and let the
            # chosen behaviour see the fresh hold point on this very step.
            self._hold = (p.xe, p.ye)
            p = p.with_hold(self._hold)
            fresh = self.behaviours[selection.behaviour].propose(p)
            proposal = fresh if fresh is not None else proposal
        self.state = selection.state
        self.last_percept = p
        f_left, f_right = self.base.wheel_forces(p, proposal)
        a1, a2 = self.arm.targets(proposal)
        return f_left, f_right, a1, a2
