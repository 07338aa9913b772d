"""Obstacle-avoidance behaviour (thesis 4.6.2, listing 4.5, Fig 4.11).

Obstacles are circular columns ``(x, y, radius)`` (m, world); the base is modelled by the
circle enclosing its footprint (``bubble``). An obstacle is *in range* when the centre
distance is below ``clearance + speed_factor |v| + bubble + radius`` (faster bases react
sooner) and *in the way* when the bearing to it differs from the bearing to the task point
by less than ``in_way_angle`` (pi/3). Then a temporary drive target is placed beside the
obstacle: in a frame aligned with the base->obstacle vector, ``(distance - radius -
clearance, +-offset_factor * radius)``, on the side of the task point; recomputed every
step, the base circles the obstacle until it is no longer in the way. The arm is frozen.
Returns None (off) when no obstacle is in range and in the way.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from ddwmmr.behaviours.base import DRIVE, Percept, Proposal
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import wrap_angle


def base_bubble(robot: Robot) -> float:
    """Radius of the circle enclosing the base footprint (m)."""
    return math.hypot(0.5 * robot.base_length, 0.5 * robot.base_width)


def bubble_gap(x: float, y: float, obstacle: tuple[float, float, float], bubble: float) -> float:
    """Gap (m) between the base's enclosing circle (centre ``(x, y)``, radius ``bubble``,
    m, world frame) and the circular ``obstacle`` ``(x, y, radius)``: negative where they
    overlap, which the scenario protocol counts as a collision. The sum of the radii is
    formed first, so ``gap < 0`` is exactly ``distance < radius + bubble``."""
    ox, oy, radius = obstacle
    return math.hypot(x - ox, y - oy) - (radius + bubble)


class ObstacleAvoidance:
    """Steer the base around circular obstacles with temporary waypoints (thesis 4.6.2)."""

    name = "obstacle"

    def __init__(
        self,
        robot: Robot,
        obstacles: Iterable[tuple[float, float, float]],
        clearance: float = 0.2,
        speed_factor: float = 0.7,
        offset_factor: float = 2.5,
        in_way_angle: float = math.pi / 3.0,
    ) -> None:
        self.obstacles = tuple((float(x), float(y), float(r)) for x, y, r in obstacles)
        self.bubble = base_bubble(robot)
        self.clearance = clearance
        self.speed_factor = speed_factor
        self.offset_factor = offset_factor
        self.in_way_angle = in_way_angle

    def threat(self, p: Percept) -> tuple[float, float, float, float] | None:
        """The nearest obstacle in range and in the way, with its distance (m), or None."""
        if p.target is None:
            return None
        best = None
        target_bearing = math.atan2(p.target[1] - p.y, p.target[0] - p.x)
        for ox, oy, radius in self.obstacles:
            distance = math.hypot(ox - p.x, oy - p.y)
            reach = self.clearance + self.speed_factor * abs(p.v) + self.bubble + radius
            if distance >= reach or (best is not None and distance >= best[3]):
                continue
            bearing = math.atan2(oy - p.y, ox - p.x)
            if abs(wrap_angle(bearing - target_bearing)) < self.in_way_angle:
                best = (ox, oy, radius, distance)
        return best

    def propose(self, p: Percept) -> Proposal | None:
        """A temporary waypoint beside the threatening obstacle, or None."""
        threat = self.threat(p)
        if threat is None:
            return None
        ox, oy, radius, distance = threat
        bearing = math.atan2(oy - p.y, ox - p.x)
        tx, ty = p.target  # type: ignore[misc]  # threat() ensured a target
        # Pass on the side of the task point (cross product sign), left when it is dead ahead.
        cross = (ox - p.x) * (ty - p.y) - (oy - p.y) * (tx - p.x)
        side = 1.0 if cross >= 0.0 else -1.0
        along = distance - radius - self.clearance
        lateral = side * self.offset_factor * radius
        c, s = math.cos(bearing), math.sin(bearing)
        bx = p.x + c * along - s * lateral
        by = p.y + s * along + c * lateral
        return Proposal(DRIVE, (p.th1, p.th2), bx, by)
