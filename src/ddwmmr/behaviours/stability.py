"""Stability behaviour (thesis 4.2.3, listing 4.4, Fig 4.5).

A *hard* threshold: the task stops and the end effector is held at the point where it was
when the state was entered (``Percept.hold``) while the base moves under it:

* lateral risk (``S_lat <= S_lon``, the centre of mass is off to the side): turn the base in
  place to face the end effector, forwards or backwards whichever is nearer (the
  support polygon is longer than wide on the default robot, so this raises the counter
  moment);
* longitudinal risk: drive ``adjust`` metres toward the end effector along the heading
  (forward if the centre of mass is in front, else backward), shortening the lever arm.
"""

from __future__ import annotations

import math

from ddwmmr.behaviours.base import DRIVE, TURN, Percept, Proposal, reach_toward
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import wrap_angle


class Stability:
    """Move the base under a held end effector to restore tip-over stability."""

    name = "stability"

    def __init__(self, robot: Robot, adjust: float = 0.5) -> None:
        self.robot = robot
        self.adjust = adjust

    def propose(self, p: Percept) -> Proposal:
        """Turn toward the end effector (lateral risk) or drive toward it (longitudinal)."""
        arm = reach_toward(self.robot, p, *p.hold)
        if p.s_lat <= p.s_lon:
            facing = math.atan2(p.hold[1] - p.y, p.hold[0] - p.x)
            if abs(wrap_angle(facing - p.phi)) > 0.5 * math.pi:
                facing += math.pi  # reversing is as good as driving forward (thesis 4.2.3)
            return Proposal(TURN, arm, heading=p.phi + wrap_angle(facing - p.phi))
        sign = 1.0 if p.x_com >= 0.0 else -1.0
        bx = p.x + sign * self.adjust * math.cos(p.phi)
        by = p.y + sign * self.adjust * math.sin(p.phi)
        return Proposal(DRIVE, arm, bx, by)
