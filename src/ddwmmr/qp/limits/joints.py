"""Joint-speed limits and joint-position limits as velocity dampers (box bounds)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from ddwmmr.errors import check_nonnegative
from ddwmmr.gains import check_gain
from ddwmmr.model import Robot
from ddwmmr.qp.blocks import LimitBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import Limit

if TYPE_CHECKING:
    import numpy as np


class JointLimit(Limit):
    """``|th_i dot| <= joint_speed_limit`` and, near a position limit,
    ``th_i dot <= gain (th_max - margin - th_i)`` (and the mirror image at th_min).

    The damper slows a joint exponentially as it nears its limit instead of letting it hit
    the stop at full speed; a joint already beyond ``margin`` is pushed back at no more than
    half the speed limit.
    """

    rows = 0
    name = "joints"
    unit = None  # rows on rates only: any problem's length unit

    def __init__(self, robot: Robot, gain: float = 5.0, margin: float = 0.02) -> None:
        self.limits = robot.joint_limits
        self.speed = robot.joint_speed_limit * (1.0 - 1e-6)
        self.gain = check_gain("joint limit gain", gain)
        self.margin = check_nonnegative("joint limit margin", margin)

    def joint_bounds(self, angle: float, joint: int) -> tuple[float, float]:
        """``(lowest, highest)`` allowed rate (rad/s) of joint ``joint`` (0 or 1) at
        ``angle`` (rad): the speed limit and the position dampers.

        Written with comparisons, not ``min``/``max`` (the same results, NaN included;
        it runs twice in every qp step)."""
        speed, gain, margin = self.speed, self.gain, self.margin
        low, high = self.limits[joint]
        down = gain * (angle - low - margin)  # allowed speed towards th_min
        up = gain * (high - margin - angle)
        down = down if down < speed else speed
        up = up if up < speed else speed
        back = -0.5 * speed  # beyond the margin: must move back, not too fast
        down = back if back > down else down
        up = back if back > up else up
        return -down, up

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Tighten the box on th1dot (index 2) and th2dot (index 3)."""
        for index, angle in ((2, ctx.th1), (3, ctx.th2)):
            low, up = self.joint_bounds(angle, index - 2)
            lb[index] = max(lb[index], low)
            ub[index] = min(ub[index], up)

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Writer tightening the Python box (no rows) with :meth:`joint_bounds`."""
        if overrides(self, JointLimit) or overrides(self, JointLimit, "joint_bounds"):
            return None
        box, bounds = block.box, self.joint_bounds

        def write(ctx: StepContext) -> None:
            low, up = bounds(ctx.th1, 0)
            if low > box[2]:
                box[2] = low
            if up < box[6]:
                box[6] = up
            low, up = bounds(ctx.th2, 1)
            if low > box[3]:
                box[3] = low
            if up < box[7]:
                box[7] = up

        return write
