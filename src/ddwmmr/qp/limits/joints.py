"""Joint-speed limits and joint-position limits as velocity dampers (box bounds)."""

from __future__ import annotations

from ddwmmr.errors import check_nonnegative, check_positive
from ddwmmr.model import Robot
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import Limit


class JointLimit(Limit):
    """``|th_i dot| <= joint_speed_limit`` and, near a position limit,
    ``th_i dot <= gain (th_max - margin - th_i)`` (and the mirror image at th_min).

    The damper slows a joint exponentially as it nears its limit instead of letting it hit
    the stop at full speed; a joint already beyond ``margin`` is pushed back at no more than
    half the speed limit.
    """

    rows = 0
    name = "joints"

    def __init__(self, robot: Robot, gain: float = 5.0, margin: float = 0.02) -> None:
        self.limits = robot.joint_limits
        self.speed = robot.joint_speed_limit * (1.0 - 1e-6)
        self.gain = check_positive("joint limit gain", gain)
        self.margin = check_nonnegative("joint limit margin", margin)

    def compute(self, ctx: StepContext, G, lower, upper, lb, ub) -> None:
        """Tighten the box on th1dot (index 2) and th2dot (index 3)."""
        speed, gain, margin = self.speed, self.gain, self.margin
        for index, angle, (low, high) in (
            (2, ctx.th1, self.limits[0]),
            (3, ctx.th2, self.limits[1]),
        ):
            down = min(speed, gain * (angle - low - margin))  # allowed speed towards th_min
            up = min(speed, gain * (high - margin - angle))
            down = max(down, -0.5 * speed)  # beyond the margin: must move back, not too fast
            up = max(up, -0.5 * speed)
            lb[index] = max(lb[index], -down)
            ub[index] = min(ub[index], up)
