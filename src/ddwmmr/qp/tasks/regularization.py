"""Regularisation: small input norm, so the problem is strictly convex and commands calm."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ddwmmr.errors import check_positive
from ddwmmr.qp.blocks import CONSTANT, TaskBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.tasks.base import Task


class RegularizationTask(Task):
    """``u = 0`` with weights ``weight * (1, length^2, length^2, length^2)``.

    ``length`` (in ``unit``, :attr:`Task.unit`: m by default) converts rates (rad/s) into
    end-effector speeds (units per second), so a base speed and a joint rate moving the
    end effector equally fast cost the same. Given its robot's unit, the task costs a
    robot scaled by s as the default one: the ``v`` row takes ``v / unit``.
    """

    rows = 4
    name = "regularization"

    def __init__(self, weight: float = 1e-3, length: float = 0.5, unit: float = 1.0) -> None:
        super().__init__(weight)
        self.length = check_positive("regularization length", length)
        self.unit: float = check_positive("unit", unit)

    def row_weights(self) -> np.ndarray:
        """Per-input weights (cost per (unit/s)^2 and per (rad/s)^2)."""
        l2 = self.length**2
        return self.weight * np.array([1.0, l2, l2, l2])

    def compute(self, ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
        """Identity rows, zero targets (constant: written every step for simplicity)."""
        jac[:] = 0.0
        jac[0, 0] = jac[1, 1] = jac[2, 2] = jac[3, 3] = 1.0
        error[:] = 0.0

    def compile(self, block: TaskBlock) -> Callable[[StepContext], None] | None:
        """Everything is constant: written once."""
        if overrides(self, RegularizationTask):
            return None
        block.write_constant_rows(np.eye(4).tolist())
        block.write_constant_targets([0.0] * 4)
        return CONSTANT
