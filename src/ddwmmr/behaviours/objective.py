"""Objective behaviour (thesis 4.2.1, listing 4.2): reach the task point with the end effector.

If the target is farther from the base centre than ``reach_fraction`` of the arm reach
(80 %, thesis 4.3), drive the base toward it with the arm in the default pose (label
``"base"``). Otherwise solve the two-link IK in the base frame; on success brake the base
and move the arm (label ``"arm"``); on failure (target inside the arm's inner radius) back
the base away from it with the arm in the default pose.
"""

from __future__ import annotations

import math

from ddwmmr.behaviours.base import BRAKE, DRIVE, Percept, Proposal, elbow_of
from ddwmmr.model import Robot

#: Thesis 4.3: the target is in range below 80 % of the maximum arm reach.
REACH_FRACTION = 0.8


def default_pose(robot: Robot) -> tuple[float, float]:
    """The thesis's default arm pose: best manipulability, end effector straight ahead (rad).

    ``th2 = pi/2`` maximises ``eta = |sin th2|``; ``th1 = -atan2(L2, L1)`` puts the end
    effector on the base x axis at ``sqrt(L1^2 + L2^2)`` in front of the centre. (The
    library's ``Robot.home_pose`` has eta = 0.56, below the 0.75 manipulability threshold,
    so it cannot be the pose the thesis holds while driving.)
    """
    return -math.atan2(robot.L2, robot.L1), 0.5 * math.pi


class Objective:
    """Drive the base into range, then move the arm onto the target (thesis 4.2.1)."""

    name = "objective"

    def __init__(
        self,
        robot: Robot,
        reach_fraction: float = REACH_FRACTION,
        pose: tuple[float, float] | None = None,
    ) -> None:
        self.robot = robot
        self.range = reach_fraction * robot.reach
        self.pose = pose if pose is not None else default_pose(robot)
        self._inner = abs(robot.L1 - robot.L2)

    def propose(self, p: Percept) -> Proposal:
        """Drive (label "base") or brake and reach (label "arm") for the target."""
        if p.target is None:
            return Proposal(BRAKE, (p.th1, p.th2), label="arm")
        tx, ty = p.target
        distance = math.hypot(tx - p.x, ty - p.y)
        if distance > self.range:
            return Proposal(DRIVE, self.pose, tx, ty, label="base")
        dx, dy = p.to_base(tx, ty)
        solution = self.robot.arm_ik(dx, dy, elbow_of(p.th2))
        if solution is None or distance < self._inner:
            # Too close for the arm: back off to the middle of the reachable annulus.
            if distance > 1e-9:
                ux, uy = (p.x - tx) / distance, (p.y - ty) / distance
            else:
                ux, uy = -math.cos(p.phi), -math.sin(p.phi)
            middle = 0.5 * (self._inner + self.range)
            return Proposal(DRIVE, self.pose, tx + middle * ux, ty + middle * uy, label="base")
        return Proposal(BRAKE, solution, label="arm")
