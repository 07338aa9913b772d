"""The thesis's hierarchical behaviour-based controller (thesis ch. 4), assembled.

High level: behaviours (objective, manipulability, stability, optional obstacle avoidance)
all see the same :class:`~ddwmmr.behaviours.base.Percept` and return the same
:class:`~ddwmmr.behaviours.base.Proposal`; an arbiter picks one. Low level: the PD base
mover turns the proposal into wheel forces, the arm mover into joint targets.

Arbiters that blend (they have ``weigh(percept, behaviours) -> Blend``, e.g. the
competitive-dynamics arbiter) take the blending path of :meth:`ThesisController.act`:

* every behaviour with a share is turned into wheel forces by the base mover on its own
  (drive, turn or brake, each saturated by the mixer) and into the one-step joint motion the
  arm servo would make toward its joint targets (thesis eq. 4.10: synchronised, the larger
  error at the joint speed limit). Forces and motions are summed with the shares; the joint
  target sent is the current pose plus the blended motion. A convex combination of
  admissible wheel forces is admissible, so the blend needs no second saturation; blending
  motions rather than targets makes a share scale the arm's speed (the servo runs at full
  speed toward any target: a 5 % share of a target 2 rad away would otherwise move the arm
  at full speed); a behaviour with share 1 acts exactly as under the state machine.
* the share left when the shares add up to less than 1 brakes the base and holds the arm
  (the paper's eq. 1: commands scale with the weights; no behaviour, no motion).
* hold points are per behaviour: latched where the end effector is when the behaviour's
  share rises to ``ENGAGE``, released when it falls below ``RELEASE`` (until then the hold is
  the current end-effector position). A latched hold moves with the arm motion the *other*
  behaviours command: stability alone keeps the end effector in place while the base turns
  under it (the thesis's stability state); blended with the objective, the end effector goes
  on toward the waypoint at the objective's share while the base turns to face it.
  Proposals the arbiter evaluated itself (it computes advantages from them) are used as
  they are.

The controller sees only sensor values (configuration and base velocities) and outputs
actuator commands (wheel forces in N, joint targets in rad); which plant consumes them is
up to the simulation loop. It speaks the force interface of :mod:`ddwmmr.commands`:
:meth:`ThesisController.command` is the loop's entry point (the same call as every other
controller, with the measured base velocity), :meth:`ThesisController.act` the plain form.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ddwmmr.arbiters.base import Arbiter
from ddwmmr.arbiters.checked import checked_arbiter, refuse_unproposed
from ddwmmr.arbiters.factory import make_arbiter
from ddwmmr.arbiters.state_machine import StateMachineArbiter
from ddwmmr.behaviours.base import BRAKE, Behaviour, Percept, Proposal, sense
from ddwmmr.behaviours.lowlevel import ArmMover, BaseMover, PDGains
from ddwmmr.behaviours.manipulability import Manipulability
from ddwmmr.behaviours.objective import Objective
from ddwmmr.behaviours.obstacle import ObstacleAvoidance
from ddwmmr.behaviours.stability import Stability
from ddwmmr.commands import WheelForces
from ddwmmr.controllers.base import WaypointRun, register_controller
from ddwmmr.controllers.inputs import check_time
from ddwmmr.errors import check_range, name_of
from ddwmmr.model import Robot

if TYPE_CHECKING:
    from collections.abc import Mapping

#: Actuator command: (left wheel force N, right wheel force N, th1 target rad, th2 target rad).
Actuation = tuple[float, float, float, float]
#: Blending path: a behaviour's hold point is latched at this share and released below RELEASE.
ENGAGE, RELEASE = 0.1, 0.05
#: Allowed range (m) of ``adjust``, how far ahead of or behind the base the manipulability
#: and stability behaviours put their drive target (the thesis: 0.5 m). 0 would stop
#: the behaviours and a negative value reverse them (away from the end effector); below
#: 1 cm (the scenarios' waypoint tolerance) the base hardly moves, and beyond 5 m (more
#: than the scenarios' arena half-width, 4 m) it drives off across the arena.
ADJUST_RANGE_M = (0.01, 5.0)


@register_controller("thesis", tasks=("waypoints",), interfaces=("force",), arbiter=True)
class ThesisController:
    """Thesis behaviour-based control: behaviours + arbiter + low-level controllers (Fig 4.1).

    Args:
        robot: the robot (geometry for IK and metrics).
        arbiter: any :class:`~ddwmmr.arbiters.Arbiter`; default the thesis's
            :class:`StateMachineArbiter` with its thresholds. One from outside the library
            has its decisions checked (:func:`~ddwmmr.arbiters.checked.checked_arbiter`):
            a bad one stops the run with a one-line PluginError naming it.
        obstacles: ``(x, y, radius)`` circles (m); adds the obstacle-avoidance behaviour.
        gains: PD gains (thesis Table 4.2).
        adjust: base displacement target of the manipulability/stability behaviours (m),
            in :data:`ADJUST_RANGE_M` (0.01 to 5 m).
    """

    #: Loop contract: wheel forces out (its registered interfaces), measured (v, w) in, one
    #: call per control step.
    wants_base_velocity = True
    zero_order_hold = True
    float_state = True

    def __init__(
        self,
        robot: Robot,
        arbiter: Arbiter | None = None,
        obstacles: Iterable[tuple[float, float, float]] = (),
        gains: PDGains | None = None,
        adjust: float = 0.5,
    ) -> None:
        self.robot = robot
        adjust = check_range("adjust", adjust, *ADJUST_RANGE_M, "m")
        # A plug-in's decisions are checked as it makes them; the library's run unwrapped.
        self.arbiter: Arbiter = (
            StateMachineArbiter() if arbiter is None else checked_arbiter(arbiter)
        )
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
        self._holds: dict[str, tuple[float, float]] = {}
        self._t: float | None = None
        self.last_percept: Percept | None = None
        self.last_shares: dict[str, float] = {}
        #: An arbiter with ``weigh()`` blends the behaviours (competitive dynamics).
        self._blending = callable(getattr(self.arbiter, "weigh", None))

    @classmethod
    def waypoint_options(cls, run: WaypointRun) -> dict[str, Any]:
        """The options of a waypoint-task run: the arbiter the run configuration asks for
        (state machine or competitive dynamics, :func:`ddwmmr.arbiters.make_arbiter`) and
        the scenario's obstacles, then the run's own ``controller_options``."""
        return {
            "arbiter": make_arbiter(run.config),
            "obstacles": run.scenario.obstacles,
            **dict(run.config.controller_options),
        }

    @property
    def default_pose(self) -> tuple[float, float]:
        """Arm pose ``(th1, th2)`` (rad) held while driving; scenarios start in it.

        The thesis's pose (:func:`~ddwmmr.behaviours.objective.default_pose`: best
        manipulability, end effector straight ahead) as the arm mover sends it, clipped
        to the robot's ``joint_limits``: the pose the arm holds, and a start every plant
        accepts (the thesis's own robot: the thesis's pose unchanged)."""
        pose = self.behaviours["objective"].pose  # type: ignore[attr-defined]
        return self.arm.targets(Proposal(BRAKE, pose))

    def reset(self, target: tuple[float, float] | None = None, q0: object = None) -> None:
        """Start a new run toward ``target`` (m, world); ``q0`` is not needed.

        The loop calls ``reset(None, q0)`` like for every controller; the target then
        arrives with each :meth:`command`.
        """
        self.arbiter.reset()
        self.state = self.arbiter.state
        self.target = target
        self._hold = None
        self._holds = {}
        self._t = None
        self.last_shares = {}

    def set_target(self, target: tuple[float, float] | None) -> None:
        """Change the task point (the next waypoint), or None when the task is done."""
        self.target = target

    def command(
        self,
        t: float,
        q: np.ndarray | tuple[float, float, float, float, float],
        pose_d: np.ndarray,
        velocity_d: np.ndarray,
        *,
        base_velocity: tuple[float, float] = (0.0, 0.0),
    ) -> WheelForces:
        """Wheel forces and joint targets for the task point ``pose_d[:2]`` (m, world).

        ``t`` (s) is a finite time, taken as a float (:func:`~ddwmmr.controllers.inputs.
        check_time`); ``base_velocity`` is the measured ``(v, w)`` (m/s, rad/s);
        ``velocity_d`` is unused (the behaviours work on points, not trajectories).
        """
        t = check_time(t)
        x, y, _ = pose_d.tolist() if isinstance(pose_d, np.ndarray) else pose_d
        self.target = (float(x), float(y))
        v, w = base_velocity
        if type(q) is not tuple:  # the loop passes a tuple of floats (float_state)
            # ignore: q holds the five numbers of a configuration (mypy sees a tuple of any length)
            q = cast(
                "tuple[float, float, float, float, float]",
                tuple(q.tolist()) if isinstance(q, np.ndarray) else tuple(float(a) for a in q),
            )
        f_left, f_right, a1, a2 = self.act(t, q, v, w)
        return WheelForces(f_left, f_right, a1, a2)

    def act(
        self, t: float, q: tuple[float, float, float, float, float], v: float, w: float
    ) -> Actuation:
        """Actuator command for time t (s), configuration q, speed v (m/s), yaw rate w (rad/s)."""
        if self._blending:
            return self._act_blended(sense(self.robot, t, q, v, w, self.target))
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

    def _act_blended(self, p: Percept) -> Actuation:
        """Blending path: wheel forces and joint targets averaged with the arbiter's shares."""
        blend = self.arbiter.weigh(p, self.behaviours)  # type: ignore[attr-defined]
        h = self.base.gains.sample_time if self._t is None else max(0.0, p.t - self._t)
        self._t = p.t
        reach = self.robot.joint_speed_limit * h  # the servo's largest joint step (rad)
        # The share no behaviour claims (weights all small) brakes and holds the arm.
        rest = max(0.0, 1.0 - sum(blend.shares.values()))
        f_left, f_right = self.base.mix(*self.base.brake_forces(p))
        f_left, f_right = rest * f_left, rest * f_right
        d1 = d2 = 0.0
        own: dict[str, tuple[float, float]] = {}
        for name, share in blend.shares.items():
            proposal = self._proposal(name, share, p, blend.proposals)
            left, right = self.base.wheel_forces(p, proposal)
            s1, s2 = servo_step(p.th1, p.th2, *self.arm.targets(proposal), reach)
            f_left += share * left
            f_right += share * right
            d1 += share * s1
            d2 += share * s2
            own[name] = (share * s1, share * s2)
        a1, a2 = self.arm.targets(Proposal(BRAKE, (p.th1 + d1, p.th2 + d2)))
        self._carry_holds(p, d1, d2, own)
        for name in list(self._holds):
            if name not in blend.shares:
                del self._holds[name]
        self.state = blend.state
        self.last_percept = p
        self.last_shares = dict(blend.shares)
        return f_left, f_right, a1, a2

    def _carry_holds(
        self, p: Percept, d1: float, d2: float, own: dict[str, tuple[float, float]]
    ) -> None:
        """Move each latched hold point with the arm motion the *other* behaviours command.

        A behaviour holds the end effector against its own and the base's motion, not
        against the arm motion of the behaviours it is blended with: with share 1 its hold
        stays put (the thesis's stability state), with a smaller share the end effector
        goes on toward the others' targets and the hold goes with it (first order: the
        world-frame arm Jacobian times the others' joint motion).
        """
        if not self._holds:
            return
        r = self.robot
        a1 = p.phi + p.th1
        a12 = a1 + p.th2
        s1, c1 = r.L1 * math.sin(a1), r.L1 * math.cos(a1)
        s12, c12 = r.L2 * math.sin(a12), r.L2 * math.cos(a12)
        for name, (hx, hy) in self._holds.items():
            m1, m2 = own.get(name, (0.0, 0.0))
            o1, o2 = d1 - m1, d2 - m2
            self._holds[name] = (hx - (s1 + s12) * o1 - s12 * o2, hy + (c1 + c12) * o1 + c12 * o2)

    def _proposal(
        self, name: str, share: float, p: Percept, evaluated: Mapping[str, Proposal]
    ) -> Proposal:
        """Behaviour ``name``'s proposal; its own hold point is latched while it is engaged.

        Proposals the arbiter evaluated (it derives advantages from them) are used as they
        are, so the weights and the commands come from the same proposals. A share for a
        behaviour that proposes nothing (and no proposal for it) is a one-line PluginError
        naming the arbiter (:func:`~ddwmmr.arbiters.checked.refuse_unproposed`).
        """
        if name in evaluated:
            return evaluated[name]
        hold = self._holds.get(name)
        if hold is None and share >= ENGAGE:
            hold = self._holds[name] = (p.xe, p.ye)
        elif hold is not None and share < RELEASE:
            hold = None
            del self._holds[name]
        proposal = self.behaviours[name].propose(p if hold is None else p.with_hold(hold))
        if proposal is None:  # a share for a behaviour with nothing to propose
            refuse_unproposed(name_of(self.arbiter), name, share, p.t)
        return proposal


def servo_step(
    th1: float, th2: float, target1: float, target2: float, reach: float
) -> tuple[float, float]:
    """Joint motion (rad) of the arm servo toward a target in one step (thesis eq. 4.10).

    The joint with the larger error moves by at most ``reach`` (joint speed x step), the
    other in proportion, so both arrive together; a target within reach is met exactly.
    """
    e1, e2 = target1 - th1, target2 - th2
    largest = max(abs(e1), abs(e2))
    if largest <= reach:
        return e1, e2
    scale = reach / largest
    return e1 * scale, e2 * scale
