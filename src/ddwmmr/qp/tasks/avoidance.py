"""Obstacle steering: turn the base to pass an obstacle ahead instead of stopping at it.

The obstacle limit only stops the base short of a circle; a differential drive blocked
head-on would wait there forever. This soft task turns the heading towards the tangent of
the nearest circle ahead (the thesis's temporary tangent waypoint, as a rate): with the
circle centre at bearing ``b`` in the base frame, ``w = gain * (b - sign(b) pi/2)``,
passing on the side the base already leans to (or the target's side when head-on).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ddwmmr.errors import check_positive
from ddwmmr.gains import check_gain
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.obstacles import INFLUENCE_M, Circle, clearance_and_rate
from ddwmmr.qp.tasks.base import YawRowTask


class ObstacleSteeringTask(YawRowTask):
    """One row on w, active while a circle ahead is within ``influence`` of the base
    (in the robot's length unit ``unit``, m: 0.6 m on the default robot)."""

    rows = 1
    primary = True  # in hierarchical mode it may trade tracking, like the thesis behaviour
    name = "obstacle steering"

    def __init__(
        self,
        circles: Sequence[Circle],
        half_length: float,
        half_width: float,
        weight: float = 3.0,
        influence: float = INFLUENCE_M,
        gain: float = 2.0,
        unit: float = 1.0,
    ) -> None:
        super().__init__(weight)
        self.unit: float = check_positive("unit", unit)
        self.circles = list(circles)
        self.half_length, self.half_width = half_length, half_width
        self.influence = check_positive("obstacle influence", influence)
        self.gain = check_gain("obstacle steering gain", gain)

    def values(self, ctx: StepContext) -> tuple[float, float]:
        """``(J[0, 1], e[0])``: 1 and the yaw-rate target (rad/s) while a circle ahead is
        near, else zeros."""
        nearest, bearing = self.influence * self.unit, None
        c, s = ctx.cos_phi, ctx.sin_phi
        for circle in self.circles:
            d, _, _ = clearance_and_rate(
                self.half_length, self.half_width, ctx.x, ctx.y, ctx.phi, circle
            )
            dx, dy = circle.x - ctx.x, circle.y - ctx.y
            px, py = c * dx + s * dy, -s * dx + c * dy
            if d < nearest and px > 0.0:
                nearest, bearing = d, math.atan2(py, px)
        if bearing is None:
            return 0.0, 0.0
        side = math.copysign(1.0, bearing) if bearing else self._target_side(ctx)
        return 1.0, self.gain * (bearing - side * 0.5 * math.pi)

    @staticmethod
    def _target_side(ctx: StepContext) -> float:
        """+1 when the desired end effector is left of the heading (pass the circle right)."""
        dx, dy = ctx.pose_d[0] - ctx.x, ctx.pose_d[1] - ctx.y
        return -1.0 if -ctx.sin_phi * dx + ctx.cos_phi * dy > 0.0 else 1.0


class Detour:
    """Temporary tangent waypoint around circles blocking the way (thesis obstacle
    behaviour, as a steering aid for far targets).

    If the straight segment from the base to the target passes through a circle inflated
    by ``inflate`` (m: the footprint's half-diagonal plus a margin), the aim becomes the
    point on the tangent ray to the nearest such circle (on the side away from its centre),
    as far out as the target, so that the end effector, ahead of the base, still points
    along the ray; the aim slides round the circle as the base moves. Otherwise the aim is
    the target itself.
    """

    def __init__(self, circles: Sequence[Circle], inflate: float) -> None:
        self.circles = list(circles)
        self.inflate = check_positive("detour inflate", inflate)

    def aim(self, bx: float, by: float, tx: float, ty: float) -> tuple[float, float]:
        """Aim point (world frame, m) for a base at (bx, by) heading for (tx, ty)."""
        dx, dy = tx - bx, ty - by
        length2 = dx * dx + dy * dy
        if length2 == 0.0:
            return tx, ty
        best, blocker = 1.0, None
        for circle in self.circles:
            radius = circle.radius + self.inflate
            cx, cy = circle.x - bx, circle.y - by
            along = (cx * dx + cy * dy) / length2  # projection of the centre on the segment
            if not 0.0 < along < best:
                continue
            if abs(dx * cy - dy * cx) / math.sqrt(length2) < radius:  # segment hits it
                best, blocker = along, (circle, radius)
        if blocker is None:
            return tx, ty
        circle, radius = blocker
        cx, cy = circle.x - bx, circle.y - by
        dist = math.hypot(cx, cy)
        side = -1.0 if dx * cy - dy * cx > 0.0 else 1.0  # centre left of the way: pass right
        bearing = math.atan2(cy, cx)
        far = math.sqrt(length2)
        if dist <= radius:  # inside the inflated circle: go along its tangent
            heading = bearing + side * 0.5 * math.pi
        else:
            heading = bearing + side * math.asin(radius / dist)
        return bx + far * math.cos(heading), by + far * math.sin(heading)
