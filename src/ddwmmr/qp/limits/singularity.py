"""Shoulder singularity: keep the first link away from perpendicular to the heading.

With the arm mounted on the base's rotation centre, the inputs reach the end-effector pose
through ``(v, w + th1dot, th2dot)``, a 3x3 map with determinant ``-L1 cos th1``
(docs/theory.md, "Singularities and damping": the augmented Jacobians' singularity). Near
``th1 = +-pi/2`` a tracked end effector can no longer be moved along the heading's normal
without huge rates: the QP would let tracking fail there. The limit keeps
``h = cos^2 th1 - cos^2(pi/2 - margin) >= 0`` with the damper

    dh/dt = -sin(2 th1) th1dot >= -gain h.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from ddwmmr.errors import ParameterError, check_positive
from ddwmmr.gains import check_gain
from ddwmmr.qp.blocks import LimitBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import INF, Limit

if TYPE_CHECKING:
    import numpy as np


class ShoulderSingularityLimit(Limit):
    """One row ``[0, 0, -sin(2 th1), 0] u >= -gain (cos^2 th1 - sin^2 margin)``.

    Args:
        margin: smallest angle (rad) kept between link 1 and the heading's normal.
        gain: damper gain (1/s).
        joint_speed: the joint-speed limit (rad/s), used to keep the row feasible.
    """

    rows = 1
    name = "shoulder singularity"
    unit = None  # rows on rates only: any problem's length unit

    def __init__(self, margin: float = 0.25, gain: float = 5.0, joint_speed: float = 2.0) -> None:
        self.margin = check_positive("singularity_margin", margin)
        if self.margin >= 0.5 * math.pi:
            raise ParameterError(f"singularity_margin must be in (0, pi/2) rad (got {margin:g})")
        self.floor = math.sin(self.margin) ** 2
        self.gain = check_gain("singularity gain", gain)
        self.joint_speed = check_positive("joint speed", joint_speed)

    def values(self, ctx: StepContext) -> tuple[float, float]:
        """``(G[0, 2], lower[0])``: the row's slope on th1dot and its damper bound."""
        slope = -math.sin(2.0 * ctx.th1)
        achievable = 0.5 * self.joint_speed * abs(slope)
        return slope, min(-self.gain * (ctx.cos_th1**2 - self.floor), achievable)

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """The damper row on th1dot."""
        G[0, 0] = G[0, 1] = G[0, 3] = 0.0
        G[0, 2], lower[0] = self.values(ctx)
        upper[0] = INF

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Writer for the slope and the bound; the rest is constant."""
        if overrides(self, ShoulderSingularityLimit) or overrides(
            self, ShoulderSingularityLimit, "values"
        ):
            return None
        block.write_constant_rows([[0.0] * 4])
        block.write_constant_bounds((-INF,), (INF,))
        G, lower = block.matrix, block.lower
        entry, (bound,) = block.rows[0] + 2, block.bounds
        values = self.values

        def write(ctx: StepContext) -> None:
            G[entry], lower[bound] = values(ctx)

        return write
