"""Heading: turn the base towards a far-away target so it can drive there forwards."""

from __future__ import annotations

import math

from ddwmmr.errors import check_nonnegative, check_positive
from ddwmmr.gains import check_gain
from ddwmmr.model.kinematics import wrap_angle
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.tasks.avoidance import Detour
from ddwmmr.qp.tasks.base import YawRowTask


class HeadingTask(YawRowTask):
    """``w = gain * wrap_angle(bearing - phi)`` while the target is farther than ``distance`` (m).

    ``bearing`` is the direction from the base to the desired end-effector position. Near
    the target the row fades out (scaled by ``(d - distance) / fade``, clipped to [0, 1]),
    leaving the arm to finish the job. The fade matters: a row that switched off at once
    made the command jump as the base crossed ``distance``, and the base chattered there.
    Without it a differential drive asked to move sideways can end up parked broadside,
    its arm stretched, making no progress. ``fade`` is in the robot's length unit ``unit``
    (m: 0.3 m on the default robot), ``distance`` in m.
    """

    rows = 1
    name = "heading"

    def __init__(
        self,
        weight: float = 1.0,
        gain: float = 2.0,
        distance: float = 0.8,
        fade: float = 0.3,
        unit: float = 1.0,
    ) -> None:
        super().__init__(weight)
        self.unit: float = check_positive("unit", unit)
        self.gain = check_gain("heading gain", gain)
        self.distance = check_nonnegative("heading distance", distance)
        self.fade = check_positive("heading fade", fade)
        #: Optional :class:`~ddwmmr.qp.tasks.avoidance.Detour` for the bearing.
        self.detour: Detour | None = None

    def values(self, ctx: StepContext) -> tuple[float, float]:
        """``(J[0, 1], e[0])``: the fade factor and the yaw-rate target (rad/s)."""
        dx, dy = ctx.pose_d[0] - ctx.x, ctx.pose_d[1] - ctx.y
        factor = min(1.0, (math.hypot(dx, dy) - self.distance) / (self.fade * self.unit))
        if factor <= 0.0:
            return 0.0, 0.0
        if self.detour is not None:
            ax, ay = self.detour.aim(ctx.x, ctx.y, ctx.pose_d[0], ctx.pose_d[1])
            dx, dy = ax - ctx.x, ay - ctx.y
        return factor, factor * self.gain * wrap_angle(math.atan2(dy, dx) - ctx.phi)
