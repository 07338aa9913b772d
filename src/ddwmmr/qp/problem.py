"""The stacked QP: preallocated dense arrays that tasks and limits fill in place.

Decision vector ``x = (u, s)``: the inputs ``u = (v, w, th1dot, th2dot)`` and the slack
``s`` of every slack task (the tracking rows). In DAQP's layout the problem is

    minimise    0.5 x' H x + f' x
    subject to  lower[:n] <= x <= upper[:n]              (box)
                lower[n:] <= C x <= upper[n:]            (rows)

The first input is the base speed in the problem's length unit, ``v / unit`` (``unit``:
the robot's, :func:`~ddwmmr.resolution.kernels.length_unit`; 1.0 = m/s): a robot scaled by
a power of two then has the default robot's problem to the last bit (docs/qp.md, "Robot
size"). A piece whose own :attr:`~ddwmmr.qp.tasks.base.Task.unit` differs (a user's piece
works in metres) has its ``v`` column converted after its ``compute``; the box on ``v``
too, around a limit's ``compute``.

Rows come in order: slack-task equalities ``J u - s = e`` (lower = upper = e), then the
limit rows. The cost of the non-slack tasks is ``sum_i w_i ||J_i u - e_i||^2``, stacked as
``||W^(1/2) (J u - e)||^2``: the problem keeps the weighted rows ``Jw = W^(1/2) J`` and
``ew = W^(1/2) e``, so two products build the Hessian block and the gradient.

Each piece is filled one of two ways (see :mod:`ddwmmr.qp.blocks`): built-in pieces are
*compiled* once into writers that store only the entries that change, as Python floats,
straight into memoryviews of these arrays; any other piece (a user's task or limit, or a
subclass overriding ``compute``) is called through its generic ``compute`` on numpy views,
and a cost task's rows are then weighted with one numpy product. Both give the same
numbers to the last bit. Nothing is allocated per step except inside numpy's two products.
A user's piece (a class from outside the library) is called through a guard
(:func:`guarded_task`, :func:`guarded_limit`; :func:`guarded_writer` for the writer of
one that implements ``compile``) that checks what it wrote every step before the solve
and names it in one line when it raises; the library's own pieces run unguarded.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from ctypes import c_int
from typing import TYPE_CHECKING, cast

import numpy as np

from ddwmmr.errors import (
    ParameterError,
    check_int_at_least,
    check_positive,
    raise_plugin_error,
    real_number,
    shown,
)
from ddwmmr.inheritance import from_library
from ddwmmr.model.kinematics import U_NAMES
from ddwmmr.qp.blocks import CONSTANT, LimitBlock, TaskBlock
from ddwmmr.qp.context import NU, StepContext
from ddwmmr.qp.limits.base import INF, Limit
from ddwmmr.qp.tasks.base import Task

if TYPE_CHECKING:
    from typing_extensions import Buffer

#: Added to the Hessian diagonal so it stays positive definite whatever the weights (-).
HESSIAN_FLOOR = 1e-7
#: DAQP's code for an equality row.
EQUALITY = 5
#: The input box before any limit tightens it: lower bounds, then upper bounds.
_OPEN_BOX = (-INF,) * NU + (INF,) * NU


def piece_name(piece: Task | Limit) -> str:
    """A task's or limit's ``name``, or its class name when it kept the base class's
    placeholder (``"task"``, ``"limit"``)."""
    name = getattr(piece, "name", None)
    if not isinstance(name, str) or name in (Task.name, Limit.name):
        return type(piece).__name__
    return name


def piece_label(piece: Task | Limit) -> str:
    """How an error names a task or limit: its class and its ``name``, or the class alone
    when it has no name of its own (:func:`piece_name`)."""
    kind, name = type(piece).__name__, piece_name(piece)
    return kind if name == kind else f"{kind} {name!r}"


def piece_unit(piece: Task | Limit) -> float | None:
    """A piece's ``unit`` (m): a finite length > 0, or None (no ``v`` column); anything
    else is refused in one line naming the piece."""
    unit = getattr(piece, "unit", 1.0)
    if unit is None:
        return None
    number = real_number(unit)
    if number is None or not 0.0 < number < math.inf:
        raise ParameterError(
            f"{piece_label(piece)}: unit must be a finite length > 0 (m), or None for rows "
            f"without v (got {shown(unit)})"
        )
    return number


def _refuse_v(label: str, ctx: StepContext, what: str, by: str = "compute()") -> None:
    """Refuse (one-line :class:`ParameterError`) the piece ``label`` whose ``unit`` is None
    (rows without ``v``) but whose ``compute`` (or what ``by`` names) did ``what`` to
    ``v``: the problem would read that ``v`` in its own length unit, not in m/s."""
    raise ParameterError(
        f"{label}: unit = None (rows without v) but {by} {what} at t = {ctx.t:g} s "
        "(declare unit = 1.0 for v in m/s, or a length in m for v in that unit per second)"
    )


def _refuse_written(
    label: str,
    ctx: StepContext,
    by: str = "compute()",
    **written: np.ndarray | tuple[np.ndarray, ...],
) -> None:
    """Refuse (one-line :class:`ParameterError`) the piece ``label`` whose ``compute``
    (or what ``by`` names: :data:`WRITER`) wrote NaN into any of ``written``, or an
    infinite value into any but its ``bounds`` (an infinite bound leaves a side open)."""
    for what, value in written.items():
        arrays = value if isinstance(value, tuple) else (value,)
        bad = any(
            np.isnan(a).any() if what == "bounds" else not np.isfinite(a).all() for a in arrays
        )
        if bad:
            rule = (
                "must not be NaN; +-inf leaves a side open"
                if what == "bounds"
                else "must be finite"
            )
            raise ParameterError(
                f"{label}: {by} wrote a non-finite value into its {what} "
                f"at t = {ctx.t:g} s (they {rule})"
            )


TaskCompute = Callable[[StepContext, np.ndarray, np.ndarray], None]
LimitCompute = Callable[
    [StepContext, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray], None
]


def guarded_task(task: Task) -> TaskCompute:
    """``task.compute``; for a user's task (a class from outside the library) wrapped so
    that what it raises stops the run in one line naming it and the arrays' shapes."""
    if from_library(task):
        return task.compute
    label, compute, rows = piece_label(task), task.compute, task.rows
    contract = f"it fills jac ({rows} x 4) and error ({rows},) in place: rows = {rows}"

    def guarded(ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
        try:
            compute(ctx, jac, error)
        except Exception as exc:
            raise_plugin_error(f"{label}: compute()", exc, f" at t = {ctx.t:g} s ({contract})")

    return guarded


def _refuse_widened(
    label: str,
    ctx: StepContext,
    before: list[float],
    lb: list[float],
    ub: list[float],
    by: str = "compute()",
) -> None:
    """Refuse (one-line :class:`ParameterError`) the limit ``label`` if its ``compute``
    (or what ``by`` names) loosened a bound of the input box it was given: ``before``
    holds ``lb`` then ``ub`` as they arrived (the earlier limits' box), ``lb``, ``ub``
    what it left. An open side (``+-INF``, or beyond) may be written ``+-inf``; a NaN
    passes here (:func:`_refuse_written`'s to refuse)."""
    for i in range(NU):
        side, old, new = "lb", before[i], lb[i]
        if not (new < old and old > -INF):
            side, old, new = "ub", before[NU + i], ub[i]
            if not (new > old and old < INF):
                continue
        raise ParameterError(
            f"{label}: {by} widened the input box at t = {ctx.t:g} s: {side}[{i}] "
            f"({U_NAMES[i]}) from {old:.9g} to {new:.9g} (a limit only tightens lb, ub, which "
            f"hold the earlier limits' bounds: lb[i] = max(lb[i], ...), ub[i] = min(ub[i], ...))"
        )


def guarded_limit(limit: Limit) -> LimitCompute:
    """``limit.compute``, for a user's limit wrapped like :func:`guarded_task` and refused
    in one line when it widens the input box it was given (:func:`_refuse_widened`): the
    box holds the earlier limits' bounds, the library's among them, which hold whatever
    a user's limit asks. The library's own limits only tighten by construction and run
    unwrapped."""
    if from_library(limit):
        return limit.compute
    label, compute, rows = piece_label(limit), limit.compute, limit.rows
    contract = (
        f"it fills G ({rows} x 4), lower and upper ({rows},) in place and only tightens "
        f"lb, ub (4,): rows = {rows}"
    )

    def guarded(
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        before = lb.tolist() + ub.tolist()
        try:
            compute(ctx, G, lower, upper, lb, ub)
        except Exception as exc:
            raise_plugin_error(f"{label}: compute()", exc, f" at t = {ctx.t:g} s ({contract})")
        after_lb, after_ub = lb.tolist(), ub.tolist()
        if after_lb + after_ub != before:  # a tightened (or NaN) bound: which, if any, widened
            _refuse_widened(label, ctx, before, after_lb, after_ub)

    return guarded


#: How a refusal names a user's compiled writer (what its ``compile`` returned).
WRITER = "compile()'s writer"


def guarded_writer(
    piece: Task | Limit,
    writer: Callable[[StepContext], None],
    rows: np.ndarray,
    targets: tuple[np.ndarray, ...],
    box: list[float] | None,
    v_free: bool,
) -> Callable[[StepContext], None]:
    """The writer a user's piece's ``compile`` returned, checked every step as its
    ``compute`` would be (:func:`guarded_task`, :func:`guarded_limit`): what it raises
    is a one-line :class:`~ddwmmr.errors.PluginError` naming it; a NaN (or, outside a
    limit's bounds, an infinite value) among the entries of its block, ``rows`` (its
    rows of the stacked matrix, C-contiguous, as stored) and ``targets`` (a task's
    targets, a limit's lower and upper bounds), a NaN or a widened bound of the input
    ``box`` (a limit's, else None), and, for ``v_free`` (``unit = None``), a ``v``
    entry or bound, are each refused in one line. The library's writers run unwrapped."""
    label = piece_label(piece)
    flat = rows.reshape(-1)
    assert rows.size == 0 or np.shares_memory(flat, rows)
    # the sums of a block's few entries (cheaper than ndarray.dot at this size): NaN or
    # infinite when one entry is, or past 1e308 when none is (then refuse() returns)
    if box is None:
        finite = [flat, *targets]

        def written_ok() -> bool:
            return all(math.isfinite(sum(array.tolist())) for array in finite)

        def refuse(ctx: StepContext) -> None:
            _refuse_written(label, ctx, WRITER, jacobian=rows, error=targets)

    else:
        lower, upper = targets

        def written_ok() -> bool:
            return (
                math.isfinite(sum(flat.tolist()))
                and not math.isnan(sum(lower.tolist()))
                and not math.isnan(sum(upper.tolist()))
            )

        def refuse(ctx: StepContext) -> None:
            _refuse_written(label, ctx, WRITER, matrix=rows, bounds=targets)

    def guarded(ctx: StepContext) -> None:
        before = box[:] if box is not None else None
        try:
            writer(ctx)
        except Exception as exc:
            raise_plugin_error(f"{label}: {WRITER}", exc, f" at t = {ctx.t:g} s")
        if not written_ok():
            refuse(ctx)
        if v_free and rows[:, 0].any():
            column = shown(rows[:, 0].tolist())
            _refuse_v(label, ctx, f"wrote {column} into its v column", WRITER)
        if box is None or before is None or box == before:
            return
        if math.isnan(sum(box)) and any(map(math.isnan, box)):  # the sum: -inf + inf too
            raise ParameterError(
                f"{label}: {WRITER} wrote a NaN into the input box at t = {ctx.t:g} s "
                "(bounds must not be NaN; +-inf leaves a side open)"
            )
        _refuse_widened(label, ctx, before, box[:NU], box[NU:], WRITER)
        if v_free and (box[0], box[NU]) != (before[0], before[NU]):
            _refuse_v(label, ctx, "bounded v in lb, ub", WRITER)

    return guarded


def _flat(array: np.ndarray) -> memoryview[float]:
    """A flat, writable memoryview of a C-contiguous float array (shares its memory)."""
    flat = array.reshape(-1)
    assert array.size == 0 or np.shares_memory(flat, array)
    # cast: numpy's stubs make an ndarray a Buffer only from Python 3.12 on, and the
    # memoryview of a float64 array (format "d") holds floats
    return cast("memoryview[float]", memoryview(cast("Buffer", flat)))


class QPProblem:
    """Preallocated arrays of the stacked problem and the views each piece writes into.

    Args:
        tasks: soft objectives; those with ``slack = True`` (and cost tasks flagged
            ``primary``) form the primary level of the hierarchical mode.
        limits: hard constraints.
        compiled: use the built-in pieces' compiled writers (default); False calls every
            piece through its generic ``compute`` (same numbers, slower: for benchmarks
            and tests of the generic path).
        unit: the length unit (m) of the decision vector's ``v`` (``x[0] = v / unit``).
    """

    def __init__(
        self,
        tasks: Sequence[Task],
        limits: Sequence[Limit],
        compiled: bool = True,
        unit: float = 1.0,
    ) -> None:
        for task in tasks:
            if not isinstance(task, Task):
                raise ParameterError(
                    f"tasks must be ddwmmr.qp.tasks.Task instances (got {shown(task)})"
                )
            check_int_at_least(f"rows of {piece_label(task)}", task.rows, 0)
        for limit in limits:
            if not isinstance(limit, Limit):
                raise ParameterError(
                    f"limits must be ddwmmr.qp.limits.Limit instances (got {shown(limit)})"
                )
            check_int_at_least(f"rows of {piece_label(limit)}", limit.rows, 0)
        self.tasks = list(tasks)
        self.limits = list(limits)
        self.compiled = bool(compiled)
        self.unit: float = check_positive("unit", unit)
        self.slack_tasks = [t for t in self.tasks if t.slack]
        self.cost_tasks = [t for t in self.tasks if not t.slack]
        self.n_slack = sum(t.rows for t in self.slack_tasks)
        self.n = n = NU + self.n_slack
        self.m_eq = self.n_slack
        self.m = m = self.m_eq + sum(limit.rows for limit in self.limits)
        self.cost_rows = rows = sum(t.rows for t in self.cost_tasks)

        self.H = np.zeros((n, n))
        self.f = np.zeros(n)
        self.C = np.zeros((m, n))
        self.lower = np.zeros(n + m)
        self.upper = np.zeros(n + m)
        self.lb, self.ub = self.lower[:n], self.upper[:n]
        self.cl, self.cu = self.lower[n:], self.upper[n:]
        self.lb.fill(-INF)
        self.ub.fill(INF)
        self.sense = np.zeros(n + m, dtype=c_int)
        self.sense[n : n + self.m_eq] = EQUALITY
        self.C[: self.m_eq, NU:] = -np.eye(self.n_slack)
        # Weighted cost rows (what the Hessian is built from) and, for generic cost tasks,
        # the unweighted rows their compute() fills.
        self.Jw = np.zeros((rows, NU))
        self.ew = np.zeros(rows)
        self.J = np.zeros((rows, NU))
        self.e = np.zeros(rows)
        self._jw_t = self.Jw.T
        self._mv = {
            name: _flat(getattr(self, name)) for name in ("H", "C", "lower", "upper", "Jw", "ew")
        }
        #: The input box as Python floats, shared by the compiled limits (see LimitBlock).
        self.box = list(_OPEN_BOX)
        #: Whether the last build left lb <= ub on every input (see box_consistent).
        self.box_ok = True
        self.refresh_weights()

    # -- set-up ---------------------------------------------------------------------------
    def refresh_weights(self) -> None:
        """Re-read task weights and recompile the pieces (call after changing a task's
        ``weight`` or a piece's parameters: compiled writers read them here)."""
        cost = [t.row_weights() for t in self.cost_tasks]
        self.sqrt_w = np.sqrt(np.concatenate(cost)) if cost else np.zeros(0)
        level = [np.full(t.rows, 1.0 if t.primary else 0.0) for t in self.cost_tasks]
        self.primary_rows = np.concatenate(level) if level else np.zeros(0)
        slack = [t.row_weights() for t in self.slack_tasks]
        self.slack_weights = np.concatenate(slack) if slack else np.zeros(0)
        for i, w in enumerate(self.slack_weights.tolist()):
            self.H[NU + i, NU + i] = 1.0 * w + HESSIAN_FLOOR  # as set_cost(primary=1) does
        self._compile()

    def _compile(self) -> None:
        """Writers for the compiled pieces, views for the generic ones."""
        mv, n = self._mv, self.n
        sqrt_w = self.sqrt_w.tolist()
        self._writers: list[Callable[[StepContext], None]] = []
        self._generic_cost = []
        self._generic_slack = []
        self._generic_limits = []
        start = 0
        block: TaskBlock | LimitBlock
        for task in self.cost_tasks:
            stop = start + task.rows
            block = TaskBlock(
                jac=mv["Jw"],
                rows=tuple(NU * r for r in range(start, stop)),
                target_views=(mv["ew"],),
                targets=tuple(range(start, stop)),
                scales=tuple(sqrt_w[start:stop]),
                slack=False,
            )
            targets: tuple[np.ndarray, ...] = (self.ew[start:stop],)
            if not self._add_writer(task, block, self.Jw[start:stop], targets):
                self._generic_cost.append(
                    (
                        task,
                        guarded_task(task),
                        self.J[start:stop],
                        self.e[start:stop],
                        self.Jw[start:stop],
                        self.ew[start:stop],
                        self.sqrt_w[start:stop, None],
                        self.sqrt_w[start:stop],
                        self._v_ratio(task),
                    )
                )
            start = stop
        start = 0
        for task in self.slack_tasks:
            stop = start + task.rows
            block = TaskBlock(
                jac=mv["C"],
                rows=tuple(n * r for r in range(start, stop)),
                target_views=(mv["lower"], mv["upper"]),
                targets=tuple(n + r for r in range(start, stop)),
                scales=(1.0,) * task.rows,
                slack=True,
            )
            targets = (self.cl[start:stop], self.cu[start:stop])
            if not self._add_writer(task, block, self.C[start:stop], targets):
                self._generic_slack.append(
                    (
                        task,
                        guarded_task(task),
                        self.C[start:stop, :NU],
                        self.cl[start:stop],
                        self.cu[start:stop],
                        self._v_ratio(task),
                    )
                )
            start = stop
        start = self.m_eq
        for limit in self.limits:
            stop = start + limit.rows
            block = LimitBlock(
                matrix=mv["C"],
                rows=tuple(n * r for r in range(start, stop)),
                lower=mv["lower"],
                upper=mv["upper"],
                bounds=tuple(n + r for r in range(start, stop)),
                box=self.box,
            )
            targets = (self.lower[n + start : n + stop], self.upper[n + start : n + stop])
            if not self._add_writer(limit, block, self.C[start:stop], targets):
                self._generic_limits.append(
                    (
                        limit,
                        guarded_limit(limit),
                        self.C[start:stop, :NU],
                        self.cl[start:stop],
                        self.cu[start:stop],
                        self._v_ratio(limit),
                    )
                )
            start = stop
        self._all_compiled = not (self._generic_cost or self._generic_slack or self._generic_limits)
        self._watch_generic()

    def _watch_generic(self) -> None:
        """The arrays the generic pieces write into, for :meth:`_written_ok`: those that
        must be finite, those that must not hold NaN. None when every generic piece is the
        library's (``compiled=False``): :meth:`_refuse_user_pieces` refuses only a user's,
        so checking theirs would cost every step and never refuse."""
        generic = (*self._generic_cost, *self._generic_slack, *self._generic_limits)
        self._check_written = not all(from_library(piece) for piece, *_ in generic)
        self._finite: list[np.ndarray] = []
        self._no_nan: list[np.ndarray] = []
        if not self._check_written:
            return
        finite = self._finite
        if self._generic_cost:
            finite += [self.J.reshape(-1), self.e]
        if self._generic_slack or self._generic_limits:
            finite.append(self.C.reshape(-1))
        if self._generic_slack:
            finite.append(self.cu[: self.m_eq])
        if self._generic_limits:
            self._no_nan += [self.lower, self.upper]

    def _v_ratio(self, piece: Task | Limit) -> float | None:
        """``problem.unit / piece.unit``: what the piece's ``v`` column is multiplied by
        (1.0 when they agree, or for a library piece whose ``unit`` is None); None for a
        user's piece whose ``unit`` is None, whose ``v`` entries are checked to stay zero
        (and the box on ``v`` untouched) every step. A bad ``unit`` is refused here, when
        the problem is compiled."""
        unit = piece_unit(piece)
        if unit is None:
            return 1.0 if from_library(piece) else None
        return self.unit / unit

    def _add_writer(
        self,
        piece: Task | Limit,
        block: TaskBlock | LimitBlock,
        rows: np.ndarray,
        targets: tuple[np.ndarray, ...],
    ) -> bool:
        """Compile ``piece`` into ``block``; False when it has no fast path (or works in
        another length unit than the problem's: a writer has no ``v`` column to convert).
        A user's piece's writer, :data:`~ddwmmr.qp.blocks.CONSTANT` too, is checked every
        step (:func:`guarded_writer`) in its ``rows`` (of the stacked matrix) and
        ``targets`` (a task's targets, a limit's bounds), and what its ``compile`` raises
        named in one line; the library's run unchecked."""
        ratio = self._v_ratio(piece)
        if not (self.compiled and (ratio is None or ratio == 1.0)):
            return False
        user = not from_library(piece)
        try:
            # ignore: the callers pair a task with its TaskBlock, a limit with its LimitBlock
            writer = piece.compile(block)  # type: ignore[arg-type]
        except Exception as exc:
            if not user:
                raise
            raise_plugin_error(f"{piece_label(piece)}: compile()", exc, " (building the QP)")
        if writer is None:
            return False
        if user:
            box = block.box if isinstance(block, LimitBlock) else None
            writer = guarded_writer(piece, writer, rows, targets, box, ratio is None)
        if writer is not CONSTANT:
            self._writers.append(writer)
        return True

    # -- per step -------------------------------------------------------------------------
    def build(self, ctx: StepContext) -> None:
        """Fill every array for this step (weighted mode: all tasks in one cost)."""
        box = self.box
        box[:] = _OPEN_BOX
        for writer in self._writers:
            writer(ctx)
        if not self._all_compiled:
            self._build_generic(ctx)
        else:
            lower, upper = self._mv["lower"], self._mv["upper"]
            lower[0], lower[1], lower[2], lower[3] = box[0], box[1], box[2], box[3]
            upper[0], upper[1], upper[2], upper[3] = box[4], box[5], box[6], box[7]
            self.box_ok = (
                box[0] <= box[4] and box[1] <= box[5] and box[2] <= box[6] and box[3] <= box[7]
            )
        self._weighted_cost()

    def _build_generic(self, ctx: StepContext) -> None:
        """The pieces without a compiled writer, through ``compute`` on numpy views."""
        for task, compute, jac, error, jac_w, error_w, column, sqrt_w, ratio in self._generic_cost:
            compute(ctx, jac, error)
            if ratio != 1.0:
                self._convert_v(task, ctx, jac, ratio)
            np.multiply(jac, column, out=jac_w)
            np.multiply(error, sqrt_w, out=error_w)
        for task, compute, jac, low, up, ratio in self._generic_slack:
            compute(ctx, jac, up)
            if ratio != 1.0:
                self._convert_v(task, ctx, jac, ratio)
            low[:] = up
        box = self.box
        self.lb[:NU] = box[:NU]
        self.ub[:NU] = box[NU:]
        u_lb, u_ub = self.lb[:NU], self.ub[:NU]
        for limit, fill, G, low, up, ratio in self._generic_limits:
            if ratio == 1.0:
                fill(ctx, G, low, up, u_lb, u_ub)
                continue
            low_v, high_v = float(u_lb[0]), float(u_ub[0])
            if ratio is None:  # no v column: nor a bound on v
                fill(ctx, G, low, up, u_lb, u_ub)
                if u_lb[0] != low_v or u_ub[0] != high_v:
                    _refuse_v(piece_label(limit), ctx, "bounded v in lb, ub")
                self._convert_v(limit, ctx, G, ratio)
                continue
            u_lb[0], u_ub[0] = low_v * ratio, high_v * ratio  # in the piece's unit
            fill(ctx, G, low, up, u_lb, u_ub)
            G[:, 0] *= ratio
            # back to the problem's unit; an untouched side as it was (INF stays INF)
            u_lb[0] = low_v if u_lb[0] == low_v * ratio else u_lb[0] / ratio
            u_ub[0] = high_v if u_ub[0] == high_v * ratio else u_ub[0] / ratio
        self.box_ok = bool(np.all(u_lb <= u_ub))
        if self._check_written and not self._written_ok():
            self._refuse_user_pieces(ctx)

    @staticmethod
    def _convert_v(
        piece: Task | Limit, ctx: StepContext, rows: np.ndarray, ratio: float | None
    ) -> None:
        """Multiply the ``v`` column of a piece's ``rows`` by ``ratio``; for None (a user's
        piece without a ``v`` column), refuse the piece if it wrote a nonzero entry there."""
        if ratio is not None:
            rows[:, 0] *= ratio
        elif any(column := rows[:, 0].tolist()):  # a list: a third of ndarray.any's cost
            _refuse_v(piece_label(piece), ctx, f"wrote {shown(column)} into its v column")

    def _written_ok(self) -> bool:
        """Whether the arrays the generic pieces fill hold what every solver takes: finite
        rows and targets, no NaN bound (``+-inf`` is an open side). Checked every step
        before the solve, not after a failure: DAQP and quadprog drop a NaN row and solve
        without it. One dot product an array, ``x . x``: NaN only when an entry is NaN,
        finite when every entry is finite and below 1e154 (a larger one only sends the
        step to :meth:`_refuse_user_pieces`, which looks entry by entry)."""
        for array in self._finite:
            if not math.isfinite(array.dot(array)):
                return False
        return not any(math.isnan(array.dot(array)) for array in self._no_nan)

    def _refuse_user_pieces(self, ctx: StepContext) -> None:
        """Refuse (one-line :class:`ParameterError`) the user's piece that wrote NaN, or an
        infinite Jacobian, error or constraint row, this step; returns when none did (a
        library piece's non-finite value leaves the solve to fail and fall back)."""
        for task, _, jac, error, *_ in self._generic_cost:
            if not from_library(task):
                _refuse_written(piece_label(task), ctx, jacobian=jac, error=error)
        for task, _, jac, _, up, _ in self._generic_slack:
            if not from_library(task):
                _refuse_written(piece_label(task), ctx, jacobian=jac, error=up)
        users = [limit for limit, *_ in self._generic_limits if not from_library(limit)]
        for limit, _, G, low, up, _ in self._generic_limits:
            if not from_library(limit):
                _refuse_written(piece_label(limit), ctx, matrix=G, bounds=(low, up))
        if users and np.isnan(self.lb[:NU] + self.ub[:NU]).any():
            names = ", ".join(repr(piece_name(limit)) for limit in users)
            raise ParameterError(
                f"limits: a compute() of {names} wrote a NaN into the input box lb, ub at "
                f"t = {ctx.t:g} s (bounds must not be NaN; +-inf leaves a side open)"
            )

    def _weighted_cost(self) -> None:
        """``H_uu = Jw' Jw + floor I``, ``f_u = -Jw' ew`` (set_cost(1, 1) without scaling)."""
        H, f, jw_t = self.H, self.f, self._jw_t
        H[:NU, :NU] = np.dot(jw_t, self.Jw)
        f_u = f[:NU]
        np.dot(jw_t, self.ew, out=f_u)
        np.negative(f_u, out=f_u)
        hess = self._mv["H"]
        step = self.n + 1
        for i in range(0, NU * step, step):
            hess[i] += HESSIAN_FLOOR

    def set_cost(self, secondary: float, primary: float, ridge: float = 0.0) -> None:
        """Hessian and gradient with the secondary cost tasks scaled by ``secondary`` and
        the slack penalties and primary cost tasks by ``primary`` (the hierarchical mode
        runs one level at a time); ``ridge`` is added to the input block's diagonal."""
        if secondary == primary == 1.0 and ridge == 0.0:
            self._weighted_cost()
            return
        if secondary == primary:
            scale = np.full(self.cost_rows, math.sqrt(primary))
        else:
            scale = np.sqrt(secondary + (primary - secondary) * self.primary_rows)
        jw = self.Jw * scale[:, None]
        ew = self.ew * scale
        H, f = self.H, self.f
        jw_t = jw.T
        H[:NU, :NU] = np.dot(jw_t, jw)
        f[:NU] = np.dot(jw_t, ew)
        np.negative(f[:NU], out=f[:NU])
        for i in range(NU):
            H[i, i] += HESSIAN_FLOOR + ridge
        for i, w in enumerate(self.slack_weights.tolist()):
            H[NU + i, NU + i] = primary * w + HESSIAN_FLOOR

    def box_consistent(self) -> bool:
        """True when the input box has lb <= ub (limits can conflict in the box; the
        slack box is open, or pinned consistently by the hierarchical mode)."""
        return self.box_ok

    def reset_slack_box(self) -> None:
        """Open the slack box again (after the hierarchical mode pinned it)."""
        self.lb[NU:] = -INF
        self.ub[NU:] = INF
