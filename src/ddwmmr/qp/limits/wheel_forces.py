"""Wheel-force limit: the velocity command must be reachable within the force limit.

For a force-driven base (the thesis plant, docs/thesis.md, "What is simulated") tracked by
the velocity loop ``F = c1 v_d + k m (v_d - v)``, ``T = c2 w_d + k I (w_d - w)``
(``F_r = T / (width/2)``),
the wheel forces ``F_l = (F - F_r)/2`` and ``F_r' = (F + F_r)/2`` are affine in the
command ``(v_d, w_d)``. Keeping both within ``+-force_limit`` is the plant's real envelope,
a polytope that couples translation and rotation, instead of separate boxes on speed and
acceleration (``BaseMotionLimit``)::

    -F_max <= 0.5 a_v v_d -+ 0.5 a_w w_d + (0.5 b_v -+ 0.5 b_w) <= F_max

with ``a_v = c1 + k m``, ``b_v = -k m v``, ``a_w = (c2 + k I)/(width/2)``,
``b_w = -k I w / (width/2)``. The base velocity ``(v, w)`` is the controller's previous
command (``StepContext.previous_command``; the loop tracks it); the rows are off on the
first step after a reset. ``I`` is evaluated at the current arm pose.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ddwmmr.errors import check_positive
from ddwmmr.model.symbolic import ThesisDynamics
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import INF, Limit

if TYPE_CHECKING:
    import numpy as np


class WheelForceLimit(Limit):
    """Two rows: left and right wheel force of the velocity loop within the force limit.

    Args:
        dynamics: the base's force-level model (mass, damping, inertia, force limit).
        bandwidth: the velocity loop's bandwidth k (1/s).
        fraction: share of the force limit the command may use (headroom for the loop).
    """

    rows = 2
    name = "wheel forces"

    def __init__(
        self, dynamics: ThesisDynamics, bandwidth: float = 10.0, fraction: float = 0.95
    ) -> None:
        self.dynamics = dynamics
        self.bandwidth = check_positive("bandwidth", bandwidth)
        self.fraction = check_positive("fraction", fraction)

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Rows ``[0.5 a_v, -+0.5 a_w, 0, 0]`` with the force bounds shifted by the offsets."""
        d, k = self.dynamics, self.bandwidth
        inertia = d.inertia(float(ctx.th2))
        a_v = d.c1 + k * d.mass
        a_w = (d.c2 + k * inertia) / d.half_width
        for row, sign in enumerate((-1.0, 1.0)):
            G[row, 0], G[row, 1], G[row, 2], G[row, 3] = 0.5 * a_v, sign * 0.5 * a_w, 0.0, 0.0
            if ctx.previous_command is None:
                lower[row], upper[row] = -INF, INF
                continue
            v, w = ctx.previous_command
            offset = 0.5 * (-k * d.mass * v) + sign * 0.5 * (-k * inertia * w / d.half_width)
            limit = self.fraction * d.force_limit
            lower[row], upper[row] = -limit - offset, limit - offset
