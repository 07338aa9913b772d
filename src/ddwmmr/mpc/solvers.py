"""Solvers of the MPC's OCP: Gauss-Newton SQP / real-time iteration, and CasADi's nlpsol.

* :class:`GaussNewtonSQP` (names ``"rti"`` and ``"sqp"``, QP backend ``qp_solver``): the
  cost is a sum of squares ``0.5 ||r(w)||^2 + c' w``, so the Gauss-Newton Hessian
  ``J_r' J_r`` is a positive semi-definite, stage-wise block-diagonal matrix and every
  iteration is one convex QP in the stage-wise OCP structure::

      min_d  0.5 d' (J_r' J_r + eps I) d + (J_r' r + c)' d
      s.t.   lbg - g(w) <= J_g d <= ubg - g(w),   lbw - w <= d <= ubw - w

  followed by the full step ``w += d``. ``"rti"`` does one iteration per control step
  (the real-time iteration: the warm start comes from the shifted previous solution, so one
  step tracks the moving optimum); ``"sqp"`` iterates until the step is below
  ``tolerance``. The QP data (Hessian, gradient, constraint Jacobian) are one CasADi
  function of (w, p).
* :class:`NLPSolver` (``"ipopt"``, ``"sqpmethod"``, ``"fatrop"``): CasADi's ``nlpsol`` on the
  same problem with exact Hessians, warm-started with the primal guess (and the previous
  multipliers).

A failed solve raises :class:`SolverFailure`; the controller falls back to the ``qp``
command for that step.
"""

from __future__ import annotations

import weakref
from typing import Any

import casadi as ca
import numpy as np

from ddwmmr import interrupts
from ddwmmr.errors import ParameterError, one_of, shown
from ddwmmr.mpc.ocp import ShootingOCP

#: Levenberg-Marquardt floor added to the Gauss-Newton Hessian (keeps it positive definite).
HESSIAN_FLOOR = 1e-6
#: QP backends reachable through ``casadi.conic`` that handle this problem.
QP_SOLVERS = ("hpipm", "qrqp", "osqp", "daqp", "proxqp")
#: The QP backend of the Gauss-Newton solvers unless one is asked for.
DEFAULT_QP_SOLVER = "hpipm"
#: Solver names accepted by :func:`make_solver`.
SOLVERS = ("rti", "sqp", "ipopt", "sqpmethod", "fatrop")
#: The solvers of :data:`SOLVERS` that solve QPs with a ``qp_solver`` backend (the
#: Gauss-Newton ones; the others are CasADi's ``nlpsol`` plugins, which take none).
QP_BACKED_SOLVERS = ("rti", "sqp")
#: HPIPM return codes accepted: 0 converged, 1 iteration limit (its iterate is used, see
#: docs/mpc.md, "Solver choice (measured)"); 2 (minimum step) and 3 (NaN) are failures.
HPIPM_ACCEPTED = (0, 1)


def installed_solvers() -> list[str]:
    """The names of :data:`SOLVERS` this CasADi build has (the Gauss-Newton ones always)."""
    return [n for n in SOLVERS if n in QP_BACKED_SOLVERS or ca.has_nlpsol(n)]


def installed_qp_solvers() -> list[str]:
    """The names of :data:`QP_SOLVERS` this CasADi build has."""
    return [n for n in QP_SOLVERS if ca.has_conic(n)]


class SolverFailure(RuntimeError):
    """The OCP solve failed (infeasible QP, iteration failure, non-finite result)."""


def _conic_options(ocp: ShootingOCP, name: str) -> dict[str, Any]:
    options: dict[str, Any] = {"error_on_fail": False}
    if name == "hpipm":
        options.update(
            N=ocp.N,
            nx=[ocp.nx] * (ocp.N + 1),
            nu=[ocp.nu] * ocp.N + [0],
            ng=list(ocp.ng),
            hpipm={"mode": "speed", "iter_max": 30},
        )
    elif name == "qrqp":
        options.update(print_iter=False, print_header=False, print_info=False)
    elif name == "osqp":
        options["osqp"] = {"verbose": False, "eps_abs": 1e-6, "eps_rel": 1e-6, "max_iter": 4000}
    return options


class QPBuffers:
    """The QP data function and the conic of a :class:`GaussNewtonSQP`, evaluated on numpy
    arrays bound once (``casadi.Function.buffer``): each call reads its inputs from and
    writes its outputs to these arrays, with no conversion to and from CasADi matrices
    (that conversion cost a third of the time around HPIPM, docs/mpc.md "Where an MPC
    step's time goes").

    Inputs: :attr:`w`, :attr:`p` of the data function; :attr:`lba`, :attr:`uba`,
    :attr:`lbx`, :attr:`ubx` of the QP (its Hessian, gradient and Jacobian are the data
    function's outputs, bound as they are: same sparsity). Outputs: :attr:`g` (the
    constraints at ``w``), :attr:`step` (the QP's solution), :attr:`lam_a`, :attr:`lam_x`.
    The QP's statistics (:meth:`qp_stats`) are those of its last call.
    """

    def __init__(self, data: ca.Function, qp: ca.Function) -> None:
        def zeros(count: int) -> np.ndarray:
            return np.zeros(count, dtype=float)

        self.w, self.p = zeros(data.nnz_in(0)), zeros(data.nnz_in(1))
        self.hessian, self.gradient = zeros(data.nnz_out(0)), zeros(data.nnz_out(1))
        self.jacobian, self.g = zeros(data.nnz_out(2)), zeros(data.nnz_out(3))
        ng, nw = self.g.size, self.w.size
        self.lba, self.uba, self.lbx, self.ubx = zeros(ng), zeros(ng), zeros(nw), zeros(nw)
        self.step, self.lam_a, self.lam_x = zeros(nw), zeros(ng), zeros(nw)
        self._data, self.evaluate_data = data.buffer()
        # ignore: CasADi's hints ask for a size its binding reads from the buffer; numpy's
        # give ndarray the buffer protocol only from Python 3.12
        for i, array in enumerate((self.w, self.p)):
            self._data.set_arg(i, memoryview(array))  # type: ignore[call-arg, arg-type]
        for i, array in enumerate((self.hessian, self.gradient, self.jacobian, self.g)):
            self._data.set_res(i, memoryview(array))  # type: ignore[call-arg, arg-type]
        self._qp_function = qp
        inputs = {"h": self.hessian, "g": self.gradient, "a": self.jacobian}
        inputs.update(lba=self.lba, uba=self.uba, lbx=self.lbx, ubx=self.ubx)
        # the initial guesses as the keyword call leaves them: zeros
        inputs.update({n: zeros(qp.nnz_in(n)) for n in qp.name_in() if n not in inputs})
        for name, array in inputs.items():
            if qp.nnz_in(name) != array.size:
                raise ValueError(f"QP input {name}: {qp.nnz_in(name)} nonzeros, data {array.size}")
        # ignore: numpy's hints give ndarray the buffer protocol only from Python 3.12
        self._qp_inputs = [(qp.index_in(n), memoryview(a)) for n, a in inputs.items()]  # type: ignore[arg-type]
        outputs = (("x", self.step), ("lam_a", self.lam_a), ("lam_x", self.lam_x))
        self._qp_outputs = [(qp.index_out(n), memoryview(a)) for n, a in outputs]  # type: ignore[arg-type]
        self._last_stats: dict[str, Any] = {}

    def solve_qp(self) -> None:
        """Solve the QP of the bound arrays into :attr:`step`, :attr:`lam_a`, :attr:`lam_x`.

        A fresh buffer each call, released after it: the conic's work vectors carry values
        from one call into the next on a reused buffer (HPIPM then returned other steps
        than the keyword call, and status 2 on the second), fresh ones start at zero as
        the keyword call's do; released, the next call checks out the same memory.
        """
        buffer, solve = self._qp_function.buffer()
        # ignore: CasADi's hints ask for a size its binding reads from the buffer
        for index, view in self._qp_inputs:
            buffer.set_arg(index, view)  # type: ignore[call-arg]
        for index, view in self._qp_outputs:
            buffer.set_res(index, view)  # type: ignore[call-arg]
        self.step.fill(0.0)
        self.lam_a.fill(0.0)
        self.lam_x.fill(0.0)
        solve()
        self._last_stats = buffer.stats()

    def qp_stats(self) -> dict[str, Any]:
        """The conic's statistics after its last call (the times and call counts in them
        add up over the calls on the same conic)."""
        return self._last_stats


class GaussNewtonSQP:
    """Gauss-Newton SQP on a :class:`ShootingOCP`; ``iterations=1`` is the RTI scheme.

    Args:
        ocp: the problem.
        qp_solver: a ``casadi.conic`` plugin from :data:`QP_SOLVERS`.
        iterations: maximum SQP iterations per call.
        tolerance: stop when ``max|d|`` falls below it.
        proximal: weight of ``|d_u / u_scale|^2`` added to the QP (a Levenberg-Marquardt /
            proximal term on the input steps).
    """

    def __init__(
        self,
        ocp: ShootingOCP,
        qp_solver: str = DEFAULT_QP_SOLVER,
        iterations: int = 1,
        tolerance: float = 1e-6,
        proximal: float = 0.0,
    ) -> None:
        if not one_of(qp_solver, QP_SOLVERS):
            raise ParameterError(
                f"qp_solver must be one of {', '.join(QP_SOLVERS)} (got {shown(qp_solver)})"
            )
        self.ocp = ocp
        self.qp_solver = qp_solver
        self.iterations = iterations
        self.tolerance = tolerance
        self._qp_buffers = QPBuffers(*_compiled_qp(ocp, qp_solver, proximal))
        self.last_iterations = 0
        #: Multipliers (constraints, bounds) of the last QP: at a converged point (step
        #: zero) they are the NLP's multipliers.
        self.last_multipliers: tuple[Any, Any] | None = None

    def solve(
        self,
        w0: np.ndarray,
        p: np.ndarray,
        lbw: np.ndarray,
        ubw: np.ndarray,
        lbg: np.ndarray,
        ubg: np.ndarray,
    ) -> np.ndarray:
        """Iterate from ``w0``; returns the new decision vector or raises SolverFailure."""
        w = np.asarray(w0, dtype=float)
        buffers = self._qp_buffers
        for iteration in range(1, self.iterations + 1):
            # Two calls (data, then QP): CasADi 3.8 crashes when the HPIPM conic is
            # embedded in an MX function, so the QP is not fused with its data.
            try:
                buffers.w[:] = w
                buffers.p[:] = p
                buffers.evaluate_data()
                np.subtract(lbg, buffers.g, out=buffers.lba)
                np.subtract(ubg, buffers.g, out=buffers.uba)
                np.subtract(lbw, w, out=buffers.lbx)
                np.subtract(ubw, w, out=buffers.ubx)
                buffers.solve_qp()
            except RuntimeError as error:  # CasADi reports solver exceptions this way
                interrupts.raise_pending()  # ... and an interrupt during the solve too
                raise SolverFailure(f"{self.qp_solver}: {str(error).splitlines()[-1]}") from None
            interrupts.raise_pending()
            self._check()
            d = buffers.step
            if not np.all(np.isfinite(d)):
                raise SolverFailure(f"{self.qp_solver}: non-finite step")
            w = w + d
            self.last_multipliers = (buffers.lam_a.copy(), buffers.lam_x.copy())
            self.last_iterations = iteration
            if np.max(np.abs(d)) < self.tolerance:
                break
        return w

    def _check(self) -> None:
        stats = self._qp_buffers.qp_stats()
        if self.qp_solver == "hpipm":
            status = stats.get("return_status")
            if status not in HPIPM_ACCEPTED:
                raise SolverFailure(f"hpipm: return status {status}")
        elif not stats.get("success", False):
            raise SolverFailure(f"{self.qp_solver}: {stats.get('return_status')}")


#: The QP data function and the QP solver of each (OCP, backend, proximal weight), shared
#: by every solver on that OCP: building them (the Jacobians, the CSE'd function, the
#: conic) is most of the OCP's set-up cost (:func:`ddwmmr.mpc.cache.shared_ocp`),
#: and neither keeps anything from one call to the next that a later call reads (a run on
#: a shared one repeats a fresh one to the last bit, tests/test_mpc.py).
_COMPILED: weakref.WeakKeyDictionary[ShootingOCP, dict[tuple[str, float], tuple[Any, Any]]] = (
    weakref.WeakKeyDictionary()
)


def _compiled_qp(ocp: ShootingOCP, qp_solver: str, proximal: float) -> tuple[Any, Any]:
    """``(qp_data, qp)`` of :class:`GaussNewtonSQP` on ``ocp``, built once (see
    :data:`_COMPILED`)."""
    per_ocp = _COMPILED.setdefault(ocp, {})
    key = (qp_solver, float(proximal))
    if key not in per_ocp:
        per_ocp[key] = _build_qp(ocp, qp_solver, proximal)
    return per_ocp[key]


def _build_qp(ocp: ShootingOCP, qp_solver: str, proximal: float) -> tuple[Any, Any]:
    """The Gauss-Newton QP's data as one CasADi function of (w, p), and its conic."""
    w, p = ocp.w, ocp.p
    jr = ca.jacobian(ocp.residual, w)
    jg = ca.jacobian(ocp.g, w)
    diagonal = np.full(ocp.nw, HESSIAN_FLOOR)
    scale = np.asarray(ocp.model.u_scale, dtype=float)
    reference = float(np.max(ocp.lengths))
    for s, length in zip(ocp.u_slices, ocp.lengths):
        # Proximal term on the inputs, per second of interval like the cost: damps the
        # step from the warm start, so that one iteration per control step cannot
        # jump between two distant plans.
        diagonal[s] += proximal * (length / reference) / scale**2
    hessian = ca.mtimes(jr.T, jr) + ca.diag(ca.DM(diagonal))
    # dense vectors: their nonzeros are the QP's gradient and the bounds' offsets as they are
    gradient = ca.densify(ca.mtimes(jr.T, ocp.residual) + ca.DM(ocp.linear_cost))
    data = ca.Function("qp_data", [w, p], [hessian, gradient, jg, ca.densify(ocp.g)], {"cse": True})
    qp = ca.conic(
        "qp",
        qp_solver,
        {"h": hessian.sparsity(), "a": jg.sparsity()},
        _conic_options(ocp, qp_solver),
    )
    return data, qp


class NLPSolver:
    """CasADi ``nlpsol`` (``ipopt``, ``sqpmethod``, ``fatrop``) on a :class:`ShootingOCP`."""

    def __init__(self, ocp: ShootingOCP, name: str, options: dict[str, Any] | None = None):
        self.ocp = ocp
        self.name = name
        objective = 0.5 * ca.sumsqr(ocp.residual) + ca.dot(ca.DM(ocp.linear_cost), ocp.w)
        nlp = {"x": ocp.w, "p": ocp.p, "f": objective, "g": ocp.g}
        opts: dict[str, Any] = {"error_on_fail": False}
        if name == "ipopt":
            opts.update(
                {
                    "print_time": False,
                    "ipopt.print_level": 0,
                    "ipopt.sb": "yes",
                    "ipopt.warm_start_init_point": "yes",
                    "ipopt.tol": 1e-6,
                    "ipopt.max_iter": 200,
                }
            )
        elif name == "sqpmethod":
            opts.update(
                {
                    "qpsol": "qrqp",
                    "qpsol_options": {"print_iter": False, "print_header": False},
                    "print_header": False,
                    "print_iteration": False,
                    "print_status": False,
                    "print_time": False,
                    "max_iter": 50,
                    "convexify_strategy": "regularize",
                }
            )
        elif name == "fatrop":
            opts.update(
                {
                    "structure_detection": "manual",
                    "N": ocp.N,
                    "nx": [ocp.nx] * (ocp.N + 1),
                    "nu": [ocp.nu] * ocp.N + [0],
                    "ng": list(ocp.ng),
                    "print_time": False,
                    "fatrop.print_level": 0,
                }
            )
        opts.update(options or {})
        self._solver = ca.nlpsol("mpc", name, nlp, opts)
        self._lam_g: np.ndarray | None = None
        self._lam_x: np.ndarray | None = None
        self.last_iterations = 0

    def solve(
        self,
        w0: np.ndarray,
        p: np.ndarray,
        lbw: np.ndarray,
        ubw: np.ndarray,
        lbg: np.ndarray,
        ubg: np.ndarray,
    ) -> np.ndarray:
        """Solve from the primal guess ``w0``; raises SolverFailure."""
        args = {"x0": w0, "p": p, "lbx": lbw, "ubx": ubw, "lbg": lbg, "ubg": ubg}
        if self._lam_g is not None:
            # ignore: the solve that sets _lam_g sets _lam_x with it
            args.update(lam_g0=self._lam_g, lam_x0=self._lam_x)  # type: ignore[arg-type]
        try:
            solution = self._solver(**args)
        except RuntimeError as error:  # CasADi reports solver exceptions this way
            interrupts.raise_pending()  # ... and an interrupt during the solve too
            raise SolverFailure(f"{self.name}: {str(error).splitlines()[-1]}") from None
        interrupts.raise_pending()
        stats = self._solver.stats()
        self.last_iterations = int(stats.get("iter_count", 0))
        if not stats.get("success", False):
            raise SolverFailure(f"{self.name}: {stats.get('return_status')}")
        w = np.asarray(solution["x"], dtype=float).ravel()
        if not np.all(np.isfinite(w)):
            raise SolverFailure(f"{self.name}: non-finite solution")
        self._lam_g = np.asarray(solution["lam_g"], dtype=float).ravel()
        self._lam_x = np.asarray(solution["lam_x"], dtype=float).ravel()
        return w

    def reset(self) -> None:
        """Forget the multipliers of the previous solve."""
        self._lam_g = self._lam_x = None


def make_solver(
    name: str,
    ocp: ShootingOCP,
    qp_solver: str = DEFAULT_QP_SOLVER,
    *,
    proximal: float = 0.0,
    iterations: int | None = None,
) -> Any:
    """The solver ``name`` (see :data:`SOLVERS`) for ``ocp``.

    ``rti`` is one Gauss-Newton iteration, ``sqp`` up to ``iterations`` (default 20);
    ``proximal`` damps the input steps of both.
    """
    if name == "rti":
        return GaussNewtonSQP(ocp, qp_solver, iterations=1, proximal=proximal)
    if name == "sqp":
        return GaussNewtonSQP(ocp, qp_solver, iterations=iterations or 20, proximal=proximal)
    if name in ("ipopt", "sqpmethod", "fatrop"):
        return NLPSolver(ocp, name)
    raise ParameterError(f"solver must be one of {', '.join(SOLVERS)} (got {shown(name)})")
