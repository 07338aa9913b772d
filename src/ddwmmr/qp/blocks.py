"""Where a task or limit writes in the stacked problem: the compiled (fast) path.

Every task and limit has a generic :meth:`compute` that fills numpy views (easy to write;
its cost per piece and step: docs/qp.md, "Architecture"). The built-in pieces also implement
``compile(block)``: called once when the :class:`~ddwmmr.qp.problem.QPProblem` is built, it
writes the rows' constant entries and returns a *writer* ``writer(ctx)`` that fills only
what changes, as Python floats, straight into flat ``memoryview`` s of the problem's arrays
(cheaper per write than numpy, and nothing is allocated).

``compile`` returns:

* a writer, called every step;
* :data:`CONSTANT` when nothing changes from step to step (the rows written at compile
  time stay as they are);
* None (the default of the base classes) to be called through ``compute`` instead: a user's
  own piece plugs in unchanged and pays the generic path's cost only for itself.

A user's piece may implement ``compile`` too: its writer is checked every step as its
``compute`` would be (:func:`ddwmmr.qp.problem.guarded_writer`), and it writes only its
block's entries (``rows``, ``targets``/``bounds``) and tightens ``box``.

A built-in piece whose ``compute`` a subclass overrides falls back to the generic path
(see :func:`overrides`), so a subclass never has its ``compute`` silently bypassed.

Each built-in piece writes its formula once, in one method on floats (``values``,
``targets``, ``joint_bounds``, ``lower_bound``, ``envelope``, ``row``); ``compute`` and the
writer both call it and differ only in where they store the numbers (docs/api.md, "Fast
paths", has what the compiled path buys).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ddwmmr import inheritance


def _constant(ctx: Any) -> None:
    """Nothing to write: the rows were written at compile time."""


#: Writer returned by ``compile`` for rows that never change (the problem drops it).
CONSTANT: Callable[[Any], None] = _constant


@dataclass(frozen=True)
class TaskBlock:
    """The rows of one task in the stacked problem.

    Row ``i``, input ``j`` of the task Jacobian is stored at ``jac[rows[i] + j]`` and its
    target rate at ``view[targets[i]]`` for every view in ``target_views``. Both are stored
    multiplied by ``scales[i]``: the square root of the row weight for a cost task (the
    problem keeps ``W^(1/2) J`` and ``W^(1/2) e``), 1 for a slack task, whose rows are
    equalities (lower and upper bound are both views).
    """

    jac: memoryview[float]
    rows: tuple[int, ...]
    target_views: tuple[memoryview[float], ...]
    targets: tuple[int, ...]
    scales: tuple[float, ...]
    slack: bool

    def write_constant_rows(self, matrix: Any) -> None:
        """Store a constant ``rows x 4`` Jacobian (nested sequences), scaled."""
        for i, row in enumerate(matrix):
            for j, value in enumerate(row):
                self.jac[self.rows[i] + j] = value * self.scales[i]

    def write_constant_targets(self, values: Any) -> None:
        """Store constant target rates (one per row), scaled."""
        for i, value in enumerate(values):
            for view in self.target_views:
                view[self.targets[i]] = value * self.scales[i]


@dataclass(frozen=True)
class LimitBlock:
    """The rows of one limit and the shared input box.

    Row ``i``, input ``j`` of ``G`` is ``matrix[rows[i] + j]``; its bounds are
    ``lower[bounds[i]]`` and ``upper[bounds[i]]``. ``box`` is the input box as a list of
    Python floats, ``box[j]`` the lower and ``box[4 + j]`` the upper bound of ``u_j``: it
    arrives each step holding the bounds of earlier limits (start: +-INF); only tighten.
    """

    matrix: memoryview[float]
    rows: tuple[int, ...]
    lower: memoryview[float]
    upper: memoryview[float]
    bounds: tuple[int, ...]
    box: list[float]

    def write_constant_rows(self, matrix: Any) -> None:
        """Store a constant ``rows x 4`` block of ``G`` (nested sequences)."""
        for i, row in enumerate(matrix):
            for j, value in enumerate(row):
                self.matrix[self.rows[i] + j] = value

    def write_constant_bounds(self, lower: Any, upper: Any) -> None:
        """Store constant bounds (one pair per row)."""
        for i, (low, up) in enumerate(zip(lower, upper)):
            self.lower[self.bounds[i]] = low
            self.upper[self.bounds[i]] = up


def overrides(piece: object, owner: type, name: str = "compute") -> bool:
    """True when ``piece``'s class redefines ``owner.<name>`` (then the fast path of
    ``owner`` does not describe it and the generic path must be used)."""
    return inheritance.overrides(piece, owner, name)
