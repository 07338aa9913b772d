"""The stacked QP: preallocated dense arrays that tasks and limits fill in place.

Decision vector ``x = (u, s)``: the inputs ``u = (v, w, th1dot, th2dot)`` and the slack
``s`` of every slack task (the tracking rows). In DAQP's layout the problem is

    minimise    0.5 x' H x + f' x
    subject to  lower[:n] <= x <= upper[:n]              (box)
                lower[n:] <= C x <= upper[n:]            (rows)

Rows come in order: slack-task equalities ``J u - s = e`` (lower = upper = e), then the
limit rows. The cost of the non-slack tasks is ``sum_i w_i ||J_i u - e_i||^2``, stacked as
``||W^(1/2) (J u - e)||^2`` so one product builds it. Nothing is allocated per step except
inside numpy's small products.
"""

from __future__ import annotations

from collections.abc import Sequence
from ctypes import c_int

import numpy as np

from ddwmmr.errors import ParameterError
from ddwmmr.qp.context import NU, StepContext
from ddwmmr.qp.limits.base import INF, Limit
from ddwmmr.qp.tasks.base import Task

#: Added to the Hessian diagonal so it stays positive definite whatever the weights (-).
HESSIAN_FLOOR = 1e-7
#: DAQP's code for an equality row.
EQUALITY = 5


class QPProblem:
    """Preallocated arrays of the stacked problem and the views each piece writes into.

    Args:
        tasks: soft objectives; those with ``slack = True`` (and cost tasks flagged
            ``primary``) form the primary level of the hierarchical mode.
        limits: hard constraints.
    """

    def __init__(self, tasks: Sequence[Task], limits: Sequence[Limit]) -> None:
        for task in tasks:
            if not isinstance(task, Task):
                raise ParameterError(f"tasks must be ddwmmr.qp.tasks.Task instances (got {task!r})")
        for limit in limits:
            if not isinstance(limit, Limit):
                raise ParameterError(
                    f"limits must be ddwmmr.qp.limits.Limit instances (got {limit!r})"
                )
        self.tasks = list(tasks)
        self.limits = list(limits)
        self.slack_tasks = [t for t in self.tasks if t.slack]
        self.cost_tasks = [t for t in self.tasks if not t.slack]
        self.n_slack = sum(t.rows for t in self.slack_tasks)
        self.n = n = NU + self.n_slack
        self.m_eq = self.n_slack
        self.m = m = self.m_eq + sum(limit.rows for limit in self.limits)
        rows = sum(t.rows for t in self.cost_tasks)

        self.H = np.zeros((n, n))
        self.f = np.zeros(n)
        self.C = np.zeros((m, n))
        self.lower = np.zeros(n + m)
        self.upper = np.zeros(n + m)
        self.lb, self.ub = self.lower[:n], self.upper[:n]
        self.cl, self.cu = self.lower[n:], self.upper[n:]
        self.sense = np.zeros(n + m, dtype=c_int)
        self.sense[n : n + self.m_eq] = EQUALITY

        # Cost tasks: unweighted rows, then their weighted copies.
        self.J = np.zeros((rows, NU))
        self.e = np.zeros(rows)
        self.Jw = np.zeros((rows, NU))
        self.ew = np.zeros(rows)
        self._cost_views = []
        start = 0
        for task in self.cost_tasks:
            self._cost_views.append(
                (task, self.J[start : start + task.rows], self.e[start : start + task.rows])
            )
            start += task.rows

        # Slack tasks: J u - s = e, the -I block is constant.
        self._slack_views = []
        start = 0
        for task in self.slack_tasks:
            stop = start + task.rows
            self._slack_views.append((task, self.C[start:stop, :NU], self.cu[start:stop]))
            start = stop
        self.C[: self.m_eq, NU:] = -np.eye(self.n_slack)

        self._limit_views = []
        start = self.m_eq
        for limit in self.limits:
            stop = start + limit.rows
            self._limit_views.append(
                (limit, self.C[start:stop, :NU], self.cl[start:stop], self.cu[start:stop])
            )
            start = stop
        self.refresh_weights()

    def refresh_weights(self) -> None:
        """Re-read task weights (call after changing a task's ``weight``)."""
        cost = [t.row_weights() for t in self.cost_tasks]
        self.sqrt_w = np.sqrt(np.concatenate(cost)) if cost else np.zeros(0)
        level = [np.full(t.rows, 1.0 if t.primary else 0.0) for t in self.cost_tasks]
        self.primary_rows = np.concatenate(level) if level else np.zeros(0)
        slack = [t.row_weights() for t in self.slack_tasks]
        self.slack_weights = np.concatenate(slack) if slack else np.zeros(0)

    def build(self, ctx: StepContext) -> None:
        """Fill every array for this step (weighted mode: all tasks in one cost)."""
        for task, jac, error in self._cost_views:
            task.compute(ctx, jac, error)
        for task, jac, error in self._slack_views:
            task.compute(ctx, jac, error)
        self.cl[: self.m_eq] = self.cu[: self.m_eq]
        lb, ub = self.lb, self.ub
        lb.fill(-INF)
        ub.fill(INF)
        u_lb, u_ub = lb[:NU], ub[:NU]
        for limit, G, low, up in self._limit_views:
            limit.compute(ctx, G, low, up, u_lb, u_ub)
        self.set_cost(secondary=1.0, primary=1.0)

    def set_cost(self, secondary: float, primary: float, ridge: float = 0.0) -> None:
        """Hessian and gradient with the secondary cost tasks scaled by ``secondary`` and
        the slack penalties and primary cost tasks by ``primary`` (the hierarchical mode
        runs one level at a time); ``ridge`` is added to the input block's diagonal."""
        if secondary == primary:
            sqrt_w = self.sqrt_w if primary == 1.0 else self.sqrt_w * np.sqrt(primary)
        else:
            scale = secondary + (primary - secondary) * self.primary_rows
            sqrt_w = self.sqrt_w * np.sqrt(scale)
        np.multiply(self.J, sqrt_w[:, None], out=self.Jw)
        np.multiply(self.e, sqrt_w, out=self.ew)
        H, f = self.H, self.f
        jw_t = self.Jw.T
        H[:NU, :NU] = np.dot(jw_t, self.Jw)
        f[:NU] = np.dot(jw_t, self.ew)
        np.negative(f[:NU], out=f[:NU])
        for i in range(NU):
            H[i, i] += HESSIAN_FLOOR + ridge
        for i, w in enumerate(self.slack_weights.tolist()):
            H[NU + i, NU + i] = primary * w + HESSIAN_FLOOR

    def box_consistent(self) -> bool:
        """True when every box has lb <= ub (limits can conflict in the box)."""
        return bool(np.all(self.lb <= self.ub))
