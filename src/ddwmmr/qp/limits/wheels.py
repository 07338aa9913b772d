"""Wheel-speed limits: ``|phidot_l|, |phidot_r| <= wheel_speed_limit``.

The wheel map: docs/theory.md, "Wheels".
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from ddwmmr.errors import check_positive
from ddwmmr.model import Robot
from ddwmmr.qp.blocks import CONSTANT, LimitBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import Limit

if TYPE_CHECKING:
    import numpy as np


class WheelSpeedLimit(Limit):
    """Rows ``phidot_l = (2v - Lw w)/(2r)`` and ``phidot_r = (2v + Lw w)/(2r)`` in +-limit
    (rad/s), with ``v`` taken as ``v / unit`` (``unit``: m, :attr:`Limit.unit`)."""

    rows = 2
    name = "wheels"

    def __init__(self, robot: Robot, scale: float = 1.0, unit: float = 1.0) -> None:
        self.unit: float = check_positive("unit", unit)
        r, lw = robot.wheel_radius, robot.track_width
        self.rows_lr = ((unit / r, -lw / (2.0 * r)), (unit / r, lw / (2.0 * r)))
        # A hair inside the plant's limit so the plant never has to rescale our command.
        self.limit = robot.wheel_speed_limit * scale * (1.0 - 1e-6)

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Constant rows; written every step because the arrays are shared views."""
        for row, (a_v, a_w) in enumerate(self.rows_lr):
            G[row, 0], G[row, 1], G[row, 2], G[row, 3] = a_v, a_w, 0.0, 0.0
            lower[row], upper[row] = -self.limit, self.limit

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Everything is constant: written once."""
        if overrides(self, WheelSpeedLimit):
            return None
        block.write_constant_rows([(a_v, a_w, 0.0, 0.0) for a_v, a_w in self.rows_lr])
        block.write_constant_bounds((-self.limit,) * 2, (self.limit,) * 2)
        return CONSTANT
