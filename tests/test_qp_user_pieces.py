"""A user's QP task or limit that writes non-finite values, raises or has the wrong shape
is refused in one line naming it, on every solver (docs/qp.md, "Failure handling")."""

import math

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, make_controller, simulate
from ddwmmr.errors import ParameterError, PluginError
from ddwmmr.qp.limits import Limit
from ddwmmr.qp.tasks import Task


class _RowLimit(Limit):
    """-0.1 <= v + w <= 0.1 (one row); ``how`` spoils it."""

    rows = 1

    def __init__(self, how: str = "") -> None:
        self.how = how

    def compute(self, ctx, G, lower, upper, lb, ub):
        G[0] = (1.0, 1.0, 0.0, 0.0)
        lower[0], upper[0] = -0.1, 0.1
        if self.how == "G nan":
            G[0, 0] = math.nan
        elif self.how == "G inf":
            G[0, 1] = math.inf
        elif self.how == "upper nan":
            upper[0] = math.nan
        elif self.how == "raise":
            raise RuntimeError("rowlimit broke")


class _ArmStill(Task):
    """Both joint rates to zero (2 rows); ``how = "rows"`` writes 3 rows."""

    name = "armstill"
    rows = 2

    def __init__(self, weight: float, how: str = "") -> None:
        super().__init__(weight)
        self.how = how

    def compute(self, ctx, jac, error):
        if self.how == "rows":
            jac[:] = [[0, 0, 1, 0], [0, 0, 0, 1], [0, 0, 0, 0]]
        jac[:] = [[0, 0, 1, 0], [0, 0, 0, 1]]
        error[:] = 0.0


def _run(solver: str = "daqp", **pieces):
    robot = Robot()
    controller = make_controller("qp", robot, solver=solver, **pieces)
    return simulate(robot, Ellipse(a=2.0, b=1.5, T=40.0), controller, duration=1.0)


def test_a_valid_row_limit_holds():
    result = _run(limits=[_RowLimit()])
    assert np.max(result.timeseries["v"] + result.timeseries["w"]) == pytest.approx(0.1, abs=1e-6)


@pytest.mark.parametrize("solver", ["daqp", "quadprog"])  # both solved without the NaN row
@pytest.mark.parametrize(
    ("how", "what"), [("G nan", "matrix"), ("G inf", "matrix"), ("upper nan", "bounds")]
)
def test_a_non_finite_row_is_refused_before_the_solve(solver, how, what):
    with pytest.raises(ParameterError) as info:
        _run(solver, limits=[_RowLimit(how)])
    message = str(info.value)
    assert message.startswith(
        f"_RowLimit: compute() wrote a non-finite value into its {what} at t = 0 s"
    )
    assert "\n" not in message


def test_a_raising_limit_is_named_by_its_class_with_its_shapes():
    with pytest.raises(PluginError) as info:
        _run(limits=[_RowLimit("raise")])
    assert str(info.value) == (
        "_RowLimit: compute() raised RuntimeError: rowlimit broke at t = 0 s (it fills G "
        "(1 x 4), lower and upper (1,) in place and only tightens lb, ub (4,): rows = 1)"
    )
    assert isinstance(info.value.__cause__, RuntimeError)


def test_a_task_of_the_wrong_shape_names_itself_and_the_shape():
    with pytest.raises(PluginError) as info:
        _run(tasks=[_ArmStill(1.0, "rows")])
    message = str(info.value)
    assert message.startswith("_ArmStill 'armstill': compute() raised ValueError: ")
    assert "(3,4) into shape (2,4)" in message
    assert message.endswith("(it fills jac (2 x 4) and error (2,) in place: rows = 2)")


def test_a_negative_rows_is_refused():
    class _Bad(_RowLimit):
        rows = -1

    with pytest.raises(ParameterError, match=r"^rows of _Bad must be an integer >= 0 \(got -1\)$"):
        make_controller("qp", Robot(), limits=[_Bad()])


def test_library_pieces_run_unguarded_on_the_generic_path():
    from ddwmmr.qp.problem import QPProblem

    controller = make_controller("qp", Robot(), limits=[_RowLimit()])
    problem = QPProblem(controller.tasks, controller.limits, compiled=False)
    for piece, compute, *_ in problem._generic_cost + problem._generic_limits:
        assert (compute == piece.compute) == (piece.__module__.startswith("ddwmmr."))
