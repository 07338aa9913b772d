"""The limit interface: one hard constraint block of the QP controller.

A limit restricts the inputs ``u = (v, w, th1dot, th2dot)`` (m/s, rad/s, rad/s, rad/s)
either through general rows ``lower <= G u <= upper`` (``rows`` of them) or by tightening
the box ``lb <= u <= ub``. A limit's rows may take ``v`` in a robot's own length unit
per second (:attr:`Limit.unit`; docs/qp.md, "Robot size"). A new constraint is one
subclass implementing :meth:`Limit.compute`. Use :data:`INF` for a missing side. The
built-in limits also implement the optional fast path :meth:`Limit.compile` (see
:mod:`ddwmmr.qp.blocks`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable

import numpy as np

from ddwmmr.qp.blocks import LimitBlock
from ddwmmr.qp.context import StepContext

#: "No bound": DAQP's infinity; other backends drop rows and bounds at this magnitude.
INF = 1e30


class Limit(ABC):
    """A hard constraint on the inputs (rows ``lower <= G u <= upper`` and/or the box).

    ``unit``: the length (m, finite and > 0) in which the rows and the box take ``v``
    (``v / unit``, units per second); 1.0: SI (m/s), the default, unless a built-in limit
    is given its robot's unit (see :attr:`ddwmmr.qp.tasks.base.Task.unit`). None: no
    ``v`` column and no bound on ``v`` (``G[:, 0]`` stays zero, ``lb[0]``, ``ub[0]``
    untouched; a user's limit that writes there is refused).
    """

    rows: int = 0
    name: str = "limit"
    unit: float | None = 1.0

    @abstractmethod
    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Fill ``G`` (rows x 4), ``lower``, ``upper`` (rows,) and tighten ``lb``/``ub`` (4,).

        ``G``/``lower``/``upper`` are views into the stacked problem: write every entry,
        every step. ``lb``/``ub`` arrive holding the bounds of earlier limits: only tighten.
        """

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Optional fast path: a writer filling ``block`` each step (see
        :mod:`ddwmmr.qp.blocks`). The default, None, has :meth:`compute` called instead."""
        return None
