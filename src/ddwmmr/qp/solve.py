"""Solve the stacked QP with any qpsolvers backend (DAQP called directly by default).

:func:`solve` runs one control step's optimisation in either mode:

* ``"weighted"``: one QP, every task in the cost (slack tasks heavily weighted);
* ``"hierarchical"``: strict lexicographic order. Level 1 minimises the slack of the
  tracking task (plus tasks flagged ``primary``) with a ridge of :data:`TIE_BREAK` times
  the largest slack weight on u to make the optimum unique; level 2 freezes that slack
  (to :data:`SLACK_TOLERANCE`) and minimises the remaining tasks in what is left. Limits
  are hard at both levels (DAQP solves both to :data:`STRICT_PRIMAL_TOL`).

Backends: ``"daqp"`` calls ``daqp.solve`` directly on the preallocated arrays (its rows
take two-sided bounds and equalities natively: no conversion). Every other name goes
through :func:`qpsolvers.solve_qp`, converting the problem to ``G x <= h, A x = b``.
"""

from __future__ import annotations

import importlib.util
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Protocol

import numpy as np

from ddwmmr.errors import ParameterError, one_of, shown
from ddwmmr.qp.limits.base import INF
from ddwmmr.qp.problem import QPProblem

MODES = ("weighted", "hierarchical")
#: Level-1 ridge on u relative to the slack weight in hierarchical mode (uniqueness only).
TIE_BREAK = 1e-6
#: Slack frozen after level 1 to within this band (the tracking rows' units/s: the
#: problem's length unit per second, or rad/s).
SLACK_TOLERANCE = 1e-7
#: DAQP's primal feasibility tolerance in hierarchical mode: its default, 1e-6, is ten
#: times the frozen slack band, so a level-2 answer could overrun a limit by up to that.
STRICT_PRIMAL_TOL = 1e-9
#: Rows and bounds at least this large are treated as absent by the generic path.
_BIG = 0.5 * INF


def _qpsolvers() -> ModuleType:
    """The qpsolvers package, imported on first use: it loads scipy.sparse and every
    installed solver (several times the rest of the library), which a run that builds no
    qpsolvers backend (any method but ``qp``, or ``qp`` on direct DAQP) does not pay."""
    import qpsolvers

    return qpsolvers


def check_mode(mode: str) -> str:
    """Validate the ``mode`` option."""
    if not one_of(mode, MODES):
        raise ParameterError(f"mode must be one of {', '.join(MODES)} (got {shown(mode)})")
    return mode


def check_solver(solver: str) -> str:
    """Validate the ``solver`` option against the installed qpsolvers backends."""
    available = _qpsolvers().available_solvers
    if not one_of(solver, available):
        raise ParameterError(f"solver must be one of {', '.join(available)} (got {shown(solver)})")
    return solver


@dataclass
class SolveResult:
    """Outcome of :func:`solve`: the decision vector (or None on failure) and solve count."""

    x: np.ndarray | None
    solves: int


class Backend(Protocol):
    """What :func:`solve` calls (:func:`make_backend` builds one): ``backend(problem)``
    gives the decision vector or None; ``reset()`` forgets a warm start."""

    name: str

    def reset(self) -> None: ...

    def __call__(self, problem: QPProblem) -> np.ndarray | None: ...


class DaqpBackend:
    """DAQP's low-level ``daqp.solve`` on the problem's own arrays (no copies, no checks)."""

    name = "daqp"

    def __init__(self, warm_start: bool = False) -> None:
        import daqp  # local: only this backend needs it

        # daqp.solve (a compiled module, no hints): (x, fval, exitflag, info)
        self._solve: Callable[..., tuple[np.ndarray, float, int, dict[str, Any]]] = daqp.solve
        self.warm_start = warm_start
        self._previous: np.ndarray | None = None

    def reset(self) -> None:
        """Forget the warm start."""
        self._previous = None

    def __call__(self, problem: QPProblem) -> np.ndarray | None:
        """Solve; None when DAQP reports anything but an optimum."""
        return self._run(problem)

    def strict(self, problem: QPProblem) -> np.ndarray | None:
        """:meth:`__call__` with every bound and row met to :data:`STRICT_PRIMAL_TOL`."""
        return self._run(problem, primal_tol=STRICT_PRIMAL_TOL)

    def _run(self, problem: QPProblem, **settings: Any) -> np.ndarray | None:
        """One DAQP solve with ``settings`` (warm-started from the last answer when
        ``warm_start``); None when DAQP reports anything but an optimum."""
        if self.warm_start and self._previous is not None:
            settings["primal_start"] = self._previous
        x, _, flag, _ = self._solve(
            problem.H,
            problem.f,
            problem.C,
            problem.upper,
            problem.lower,
            problem.sense.copy(),  # DAQP may mark active rows in place
            **settings,
        )
        if flag <= 0:
            return None
        self._previous = x
        return x


#: Solvers given sparse matrices although they take dense ones: ProxQP's dense backend, in
#: the AVX2/AVX-512 builds proxsuite loads on such CPUs, returns results that differ in
#: the last bits from call to call on the same problem (its vectorised loops depend on
#: where its workspace lands in memory), so a run was not repeatable; its sparse backend
#: is (see docs/qp.md, Solvers).
SPARSE_FOR_REPEATABILITY = frozenset({"proxqp"})


class QpsolversBackend:
    """Any qpsolvers backend through :func:`qpsolvers.solve_qp` (sparse where it wants,
    and for :data:`SPARSE_FOR_REPEATABILITY`)."""

    def __init__(self, solver: str, warm_start: bool = True) -> None:
        self.name = self.solver = check_solver(solver)
        qpsolvers = _qpsolvers()
        self._solve_qp: Callable[..., np.ndarray | None] = qpsolvers.solve_qp
        self.sparse = solver in SPARSE_FOR_REPEATABILITY or (
            solver in qpsolvers.sparse_solvers and solver not in qpsolvers.dense_solvers
        )
        self.warm_start = warm_start
        self._previous: np.ndarray | None = None

    def reset(self) -> None:
        """Forget the warm start."""
        self._previous = None

    def __call__(self, problem: QPProblem) -> np.ndarray | None:
        """Convert to ``G x <= h, A x = b`` (finite sides only) and solve."""
        P, q, G, h, A, b = to_standard_form(problem)
        if self.sparse:
            from scipy import sparse

            P, G, A = sparse.csc_matrix(P), sparse.csc_matrix(G), sparse.csc_matrix(A)
        initvals = self._previous if self.warm_start else None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            x = self._solve_qp(P, q, G, h, A, b, solver=self.solver, initvals=initvals)
        if x is None or not np.all(np.isfinite(x)):
            return None
        self._previous = x
        return x


def to_standard_form(
    problem: QPProblem,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(P, q, G, h, A, b)`` with ``G x <= h`` from the finite box and row bounds and
    ``A x = b`` from the equality rows. Box entries pinned to a narrow band (the frozen
    slack of hierarchical mode) become equalities: a band thinner than a solver's
    feasibility tolerance can make it report infeasibility."""
    n, m_eq = problem.n, problem.m_eq
    eye = np.eye(n)
    rows_c = problem.C[m_eq:]
    cl, cu = problem.cl[m_eq:], problem.cu[m_eq:]
    lb, ub = problem.lb, problem.ub
    pinned = (ub - lb) <= 2.0 * SLACK_TOLERANCE
    up_box, lo_box = (ub < _BIG) & ~pinned, (lb > -_BIG) & ~pinned
    up_row, lo_row = cu < _BIG, cl > -_BIG
    G = np.vstack([eye[up_box], -eye[lo_box], rows_c[up_row], -rows_c[lo_row]])
    h = np.concatenate([ub[up_box], -lb[lo_box], cu[up_row], -cl[lo_row]])
    A = np.vstack([problem.C[:m_eq], eye[pinned]])
    b = np.concatenate([problem.cu[:m_eq], 0.5 * (lb[pinned] + ub[pinned])])
    return problem.H, problem.f, G, h, A, b


def installed_solvers() -> list[str]:
    """Solver names :func:`make_backend` accepts on this machine (qpsolvers' installed
    backends, plus ``qpsolvers-daqp`` when DAQP is one of them)."""
    names = sorted(_qpsolvers().available_solvers)
    return [*names, "qpsolvers-daqp"] if "daqp" in names else names


def make_backend(solver: str, warm_start: bool | None = None) -> DaqpBackend | QpsolversBackend:
    """The backend for ``solver``: DAQP direct for ``"daqp"``, qpsolvers for the rest.

    ``"qpsolvers-daqp"`` forces DAQP through qpsolvers (for comparisons). A solver that is
    not installed raises :class:`ParameterError` naming the installed ones.
    """
    if isinstance(solver, str) and solver == "daqp" and importlib.util.find_spec("daqp"):
        return DaqpBackend(warm_start=bool(warm_start))
    installed = installed_solvers()
    if not one_of(solver, installed):
        raise ParameterError(
            f"solver must be one of the installed QP solvers: {', '.join(installed)} "
            f"(got {shown(solver)})"
        )
    if solver == "qpsolvers-daqp":
        backend = QpsolversBackend("daqp", warm_start=bool(warm_start))
        backend.name = solver
        return backend
    return QpsolversBackend(solver, warm_start=True if warm_start is None else warm_start)


def solve(problem: QPProblem, backend: Backend, mode: str = "weighted") -> SolveResult:
    """Solve the built ``problem`` (see :meth:`QPProblem.build`) in ``mode``.

    Returns the decision vector ``x = (u, s)`` or None if a level failed (infeasible
    limits, solver error, non-finite output).
    """
    if not problem.box_consistent():
        return SolveResult(None, 0)
    if mode == "weighted" or problem.n_slack == 0:
        return SolveResult(_checked(backend(problem)), 1)
    # Both levels strict: level 2 could otherwise trade the frozen slack band for a
    # limit overrun, and level 1's answer is the step's when level 2 fails.
    strict = getattr(backend, "strict", backend)  # a qpsolvers backend as it is
    ridge = TIE_BREAK * float(problem.slack_weights.max())
    problem.set_cost(secondary=0.0, primary=1.0, ridge=ridge)
    first = _checked(strict(problem))
    if first is None:
        return SolveResult(None, 1)
    slack = first[problem.n - problem.n_slack :]
    problem.lb[problem.n - problem.n_slack :] = slack - SLACK_TOLERANCE
    problem.ub[problem.n - problem.n_slack :] = slack + SLACK_TOLERANCE
    problem.set_cost(secondary=1.0, primary=1.0)
    try:
        second = _checked(strict(problem))
    finally:
        problem.reset_slack_box()
    # Level 2 can only fail numerically (level 1's answer is feasible): keep level 1.
    return SolveResult(first if second is None else second, 2)


def _checked(x: np.ndarray | None) -> np.ndarray | None:
    """``x`` if every entry is finite, else None."""
    if x is None or not all(map(math.isfinite, x.tolist())):
        return None
    return x
