"""Posture / artificial potential ``V = K1 th1^2 + K2 th2^2 + K3 phi^2``.

The potential of the ``ap`` method (docs/theory.md, "Methods").
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ddwmmr.errors import check_positive
from ddwmmr.gains import check_gain
from ddwmmr.qp.blocks import TaskBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.tasks.base import Task, bounded

#: The rows on (w, th1dot, th2dot).
IDENTITY_ROWS = ((0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0))


class PostureTask(Task):
    """Descend V: rows ``w = -gain phi``, ``th1dot = -gain th1``, ``th2dot = -gain th2``.

    Row weights are ``weight * (K3, K1, K2)``, so the unconstrained optimum is the
    K-weighted gradient descent of V. The QP default keeps only K1 (shoulder towards the
    heading): K2 would fight the manipulability reward, and K3 pins the base heading to 0,
    which a closed path around the origin cannot respect.
    """

    rows = 3
    name = "posture"
    unit = None  # rows on rates only: any problem's length unit

    def __init__(
        self,
        weight: float = 0.1,
        K1: float = 1.0,
        K2: float = 0.0,
        K3: float = 0.0,
        gain: float = 1.0,
        rate_limit: float | None = None,
    ) -> None:
        super().__init__(weight)
        #: Bound (rad/s) of each row's target, None for none (see EndEffectorTask).
        self.rate_limit = None if rate_limit is None else check_positive("rate_limit", rate_limit)
        self.K1 = check_gain("K1", K1, zero=True)
        self.K2 = check_gain("K2", K2, zero=True)
        self.K3 = check_gain("K3", K3, zero=True)
        self.gain = check_gain("posture gain", gain)

    def row_weights(self) -> np.ndarray:
        """``weight * (K3, K1, K2)`` for the rows (w, th1dot, th2dot)."""
        return self.weight * np.array([self.K3, self.K1, self.K2])

    def compute(self, ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
        """Identity rows on (w, th1dot, th2dot), targets ``-gain * (phi, th1, th2)``."""
        jac[:] = 0.0
        jac[0, 1] = jac[1, 2] = jac[2, 3] = 1.0
        error[0], error[1], error[2] = self.targets(ctx)

    def targets(self, ctx: StepContext) -> tuple[float, float, float]:
        """``-gain * (phi, th1, th2)`` (rad/s), each bounded by ``rate_limit``; the angles
        count from the start's own turn (``ctx.start_turns``)."""
        gain, limit = self.gain, self.rate_limit
        turns_phi, turns_1, turns_2 = ctx.start_turns
        e0 = -gain * (ctx.phi - turns_phi)
        e1 = -gain * (ctx.th1 - turns_1)
        e2 = -gain * (ctx.th2 - turns_2)
        if limit is None:
            return e0, e1, e2
        return bounded(e0, limit), bounded(e1, limit), bounded(e2, limit)

    def compile(self, block: TaskBlock) -> Callable[[StepContext], None] | None:
        """Constant rows, written once; the writer fills the three weighted targets."""
        if overrides(self, PostureTask) or overrides(self, PostureTask, "targets"):
            return None
        block.write_constant_rows(IDENTITY_ROWS)
        (target,) = block.target_views
        t0, t1, t2 = block.targets
        w0, w1, w2 = block.scales
        targets = self.targets

        def write(ctx: StepContext) -> None:
            e0, e1, e2 = targets(ctx)
            target[t0] = e0 * w0
            target[t1] = e1 * w1
            target[t2] = e2 * w2

        return write
