"""The same QP built naively, for benchmarks: fresh dense arrays and a fresh OSQP setup
through :func:`qpsolvers.solve_qp` every step.

Same tasks, limits, modes and safety logic as :class:`~ddwmmr.qp.controller.QPController`;
only problem construction and solving differ, so timing the two side by side measures
what preallocation and the direct DAQP call save. Not a registered method: the benchmark
builds it by import path.
"""

from __future__ import annotations

import warnings

import numpy as np
import qpsolvers

from ddwmmr.qp.context import StepContext
from ddwmmr.qp.controller import QPController
from ddwmmr.qp.problem import QPProblem
from ddwmmr.qp.solve import solve, to_standard_form


class NaiveOsqpBackend:
    """Dense matrices handed to ``qpsolvers.solve_qp(..., solver="osqp")``, no warm start."""

    name = "osqp-naive"

    def reset(self) -> None:
        """Stateless."""

    def __call__(self, problem: QPProblem) -> np.ndarray | None:
        """Solve from scratch (qpsolvers converts to sparse and sets OSQP up anew)."""
        P, q, G, h, A, b = to_standard_form(problem)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the dense->sparse conversion warning
            x = qpsolvers.solve_qp(P, q, G, h, A, b, solver="osqp")
        return None if x is None else np.asarray(x)


class NaiveQPController(QPController):
    """QP task priorities built naively (fresh arrays + OSQP setup each step); for benches."""

    name = "qp-naive"

    def _make_backend(self, solver: str, warm_start: bool | None) -> NaiveOsqpBackend:
        """Always naive OSQP, whatever ``solver`` says."""
        self.solver = NaiveOsqpBackend.name
        return NaiveOsqpBackend()

    def _solve(self, ctx: StepContext) -> list[float] | None:
        """Allocate a new problem (every piece through its generic ``compute``), build it,
        solve it."""
        problem = QPProblem(self.tasks, self.limits, compiled=False, unit=self.unit)
        problem.build(ctx)
        x = solve(problem, self.backend, self.mode).x
        return None if x is None else x.tolist()
