"""Manipulability behaviour (thesis 4.2.2, listing 4.3, Fig 4.4).

Manipulability ``eta = |sin th2|`` depends only on the elbow, so the base moves while the arm
keeps reaching for the task point (a *soft* threshold: the arm is not stopped). The
direction comes from the quadrant (+-45 deg around the base axes) holding the end
effector: an outstretched arm (``|th2| <= pi/2``) moves the base toward that quadrant's
axis, a folded one away from it. The drive target is ``adjust`` metres from the base along
that axis; it is recomputed every step, so the base keeps moving while the behaviour is
selected. Side quadrants use +-89 deg (as the thesis's listing does for one side) so the
low-level controller turns toward the end effector rather than sideways.
"""

from __future__ import annotations

import math

from ddwmmr.behaviours.base import DRIVE, Percept, Proposal, reach_toward
from ddwmmr.model import Robot

_QUARTER = 0.25 * math.pi
_SIDE = math.radians(89.0)


def quadrant_direction(bearing: float) -> float:
    """Base-frame axis direction (rad) of the quadrant containing ``bearing`` (rad)."""
    if abs(bearing) <= _QUARTER:
        return 0.0
    if abs(bearing) >= 3.0 * _QUARTER:
        return math.pi
    return math.copysign(_SIDE, bearing)


class Manipulability:
    """Reposition the base to restore manipulability (thesis 4.2.2)."""

    name = "manipulability"

    def __init__(self, robot: Robot, adjust: float = 0.5) -> None:
        self.robot = robot
        self.adjust = adjust

    def propose(self, p: Percept) -> Proposal:
        """Drive along the quadrant axis toward (outstretched) or away from (folded) the EE."""
        ex, ey = p.to_base(p.xe, p.ye)
        direction = quadrant_direction(math.atan2(ey, ex))
        sign = 1.0 if abs(p.th2) <= 0.5 * math.pi else -1.0
        heading = p.phi + direction
        bx = p.x + sign * self.adjust * math.cos(heading)
        by = p.y + sign * self.adjust * math.sin(heading)
        goal = p.target if p.target is not None else p.hold
        return Proposal(DRIVE, reach_toward(self.robot, p, *goal), bx, by)
