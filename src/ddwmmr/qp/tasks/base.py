"""The task interface: one soft objective of the QP controller.

A task asks for ``J u = e``: ``J`` (rows x 4) maps the inputs ``u = (v, w, th1dot, th2dot)``
(m/s, rad/s, rad/s, rad/s) to some task rate, ``e`` is the rate it wants. The solver adds
``weight * ||J u - e||^2`` to the cost, or, for a task with ``slack = True``, turns the rows
into equality constraints ``J u - s = e`` whose slack ``s`` is penalised by ``weight``.
A task's rows may measure lengths in a robot's own length unit (:attr:`Task.unit`): its
rows then take ``v`` in units per second (docs/qp.md, "Robot size").
A new objective is one subclass implementing :meth:`Task.compute`; the built-in tasks also
implement the optional fast path :meth:`Task.compile` (see :mod:`ddwmmr.qp.blocks`).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable

import numpy as np

from ddwmmr.errors import check_weight
from ddwmmr.qp.blocks import TaskBlock, overrides
from ddwmmr.qp.context import StepContext


def bounded(value: float, limit: float) -> float:
    """``value`` clipped to ``[-limit, limit]``; a non-finite value (an overflow of huge
    but finite inputs) becomes its sign times ``limit`` (+-inf) or 0 (nan)."""
    if -limit <= value <= limit:
        return value
    if math.isnan(value):
        return 0.0
    return math.copysign(limit, value)


def bounded_pair(a: float, b: float, limit: float) -> tuple[float, float]:
    """``(a, b)`` scaled to a norm of at most ``limit``, direction kept; infinite entries
    (overflow) give the limiting direction, nan entries count as 0."""
    norm = math.hypot(a, b)
    if norm <= limit:
        return a, b
    if not math.isfinite(norm):
        a, b = (0.0 if math.isnan(v) else v for v in (a, b))
        if math.isinf(a) or math.isinf(b):  # the direction of the infinite part
            a, b = (math.copysign(1.0, v) if math.isinf(v) else 0.0 for v in (a, b))
        norm = math.hypot(a, b)
        if norm <= limit:
            return a, b
    scale = limit / norm
    return a * scale, b * scale


class Task(ABC):
    """A soft objective ``weight * ||J u - e||^2`` over the inputs u.

    Class attributes:
        rows: number of task rows.
        slack: True puts the rows into equality constraints with penalised slack (the
            primary, tracking level); False adds them to the cost directly.
        primary: a cost task solved at the primary level in hierarchical mode (next to
            the slack tasks) instead of in the secondary level.
        unit: the length (m, finite and > 0) in which the rows measure lengths: ``J``
            takes ``v`` as ``v / unit`` and a linear target is in units per second.
            1.0: SI (m/s), the default, whatever the robot's size; a built-in task is
            given its robot's unit (:func:`~ddwmmr.resolution.kernels.length_unit`) by
            the controller that builds it. The problem converts a task's ``v`` column to
            its own unit (:class:`~ddwmmr.qp.problem.QPProblem`). None: no ``v`` column
            (``jac[:, 0]`` stays zero; a user's task that writes there is refused). Any
            other value is refused when the problem is built
            (docs/qp.md, "A piece's length unit").
    """

    rows: int = 1
    slack: bool = False
    primary: bool = False
    name: str = "task"
    unit: float | None = 1.0

    def __init__(self, weight: float) -> None:
        self.weight = check_weight(f"{self.name.replace(' ', '_')}_weight", weight)

    def row_weights(self) -> np.ndarray:
        """Weight of each row (cost per squared task-rate unit); default: ``weight``."""
        return np.full(self.rows, self.weight)

    @abstractmethod
    def compute(self, ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
        """Fill ``jac`` (rows x 4) and ``error`` (rows,) in place for this step.

        Both arrays are views into the stacked problem: write every entry, every step.
        """

    def compile(self, block: TaskBlock) -> Callable[[StepContext], None] | None:
        """Optional fast path: a writer filling ``block`` each step (see
        :mod:`ddwmmr.qp.blocks`). The default, None, has :meth:`compute` called instead."""
        return None


class YawRowTask(Task):
    """A one-row task on the yaw rate w: ``values(ctx) -> (factor, rate)`` gives the row
    ``factor * w = rate`` (both already faded by the factor); :meth:`compute` and the fast
    path (:meth:`compile`) write it."""

    rows = 1

    @abstractmethod
    def values(self, ctx: StepContext) -> tuple[float, float]:
        """``(factor, rate)`` of this step's row ``factor * w = rate`` (rad/s)."""

    def compute(self, ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
        """One row on w."""
        jac[0, 0] = jac[0, 2] = jac[0, 3] = 0.0
        jac[0, 1], error[0] = self.values(ctx)

    def compile(self, block: TaskBlock) -> Callable[[StepContext], None] | None:
        """Writer for the weighted entry on w and the target (None: a subclass changed
        ``compute`` or ``values`` in a way the fast path does not know)."""
        owner = _yaw_row_owner(type(self))
        if overrides(self, owner) or overrides(self, owner, "values"):
            return None
        block.write_constant_rows([[0.0] * 4])
        jac, (target,) = block.jac, block.target_views
        entry, (row,), (scale,) = block.rows[0] + 1, block.targets, block.scales
        values = self.values

        def write(ctx: StepContext) -> None:
            factor, rate = values(ctx)
            jac[entry] = factor * scale
            target[row] = rate * scale

        return write


def _yaw_row_owner(cls: type) -> type:
    """The library class (first direct subclass of :class:`YawRowTask` in the MRO) whose
    ``values`` the fast path was written for."""
    for klass in cls.__mro__:
        if YawRowTask in klass.__bases__:
            return klass
    return cls
