"""The per-step check of what the generic pieces wrote (``QPProblem._written_ok``) runs
only when a user's piece is among them: it exists to refuse a user's NaN row, and the
library's own pieces on the generic path (``compiled=False``) are never refused. The
benchmark's "+ user task, limit" row uses pieces that count as a user's, so it times
that check."""

import math

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, make_controller
from ddwmmr.bench.qp_classes import _UserSpin, qp_class_cases
from ddwmmr.errors import ParameterError
from ddwmmr.inheritance import from_library
from ddwmmr.qp.limits import Limit
from ddwmmr.qp.problem import QPProblem


class _NanLimit(Limit):
    """A user's limit whose row turns NaN from t = 0.05 s on."""

    rows = 1

    def compute(self, ctx, G, lower, upper, lb, ub):
        G[0] = (0.0, 0.0, 1.0, 1.0)
        lower[0], upper[0] = -1.0, math.nan if ctx.t >= 0.05 else 1.0


def _checks_per_step(controller, steps: int = 10) -> int:
    """Calls of the written check over ``steps`` commands along the ellipse, driven as the
    benchmark drives a controller (no simulate: its plant hand-over rebuilds the problem)."""
    problem, calls = controller.problem, []
    check = problem._written_ok
    problem._written_ok = lambda: calls.append(1) or check()
    trajectory, q = Ellipse(), np.array([0.0, 0.0, 0.0, 0.5, 0.5])
    controller.reset(trajectory, q)
    for k in range(steps):
        t = 0.02 * k
        controller.command(t, q, trajectory.pose(t), trajectory.velocity(t))
    return len(calls)


def _generic(controller):
    controller.problem = QPProblem(controller.tasks, controller.limits, compiled=False)
    return controller


def test_library_pieces_on_the_generic_path_are_not_checked():
    assert _checks_per_step(_generic(make_controller("qp", Robot()))) == 0


def test_a_user_piece_among_them_is_checked_every_step():
    class _Open(Limit):
        rows = 1

        def compute(self, ctx, G, lower, upper, lb, ub):
            G[0] = (0.0, 0.0, 1.0, 1.0)
            lower[0], upper[0] = -math.inf, math.inf

    controller = _generic(make_controller("qp", Robot(), limits=[_Open()]))
    assert _checks_per_step(controller) == 10


def test_a_user_nan_row_is_still_refused_beside_generic_library_pieces():
    controller = _generic(make_controller("qp", Robot(), limits=[_NanLimit()]))
    with pytest.raises(ParameterError, match=r"^_NanLimit: compute\(\) wrote a non-finite"):
        _checks_per_step(controller)


def test_the_bench_user_row_pays_what_a_user_pays():
    tasks, limits = _UserSpin.pieces()
    assert not any(from_library(piece) for piece in (*tasks, *limits))
    cases = qp_class_cases(Robot(), {}, reference=False)
    assert _checks_per_step(cases["qp + user task, limit"]) == 10
    assert _checks_per_step(cases["qp (generic path)"]) == 0
