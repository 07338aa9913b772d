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


def _run(solver: str = "daqp", **options):
    robot = Robot()
    controller = make_controller("qp", robot, solver=solver, **options)
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


class _Box(Limit):
    """Sets the box on input ``index`` to ``[-cap, cap]``: by assignment (``assign``,
    which widens a tighter box it was given) or as the contract has it (max / min)."""

    name = "box"

    def __init__(self, index: int, cap: float, assign: bool, unit: float = 1.0) -> None:
        self.index, self.cap, self.assign, self.unit = index, cap, assign, unit

    def compute(self, ctx, G, lower, upper, lb, ub):
        i, cap = self.index, self.cap
        if self.assign:
            lb[i], ub[i] = -cap, cap
        else:
            lb[i], ub[i] = max(lb[i], -cap), min(ub[i], cap)


def test_a_limit_widening_the_box_it_was_given_is_refused_in_one_line():
    """The joints' speed limit (2 rad/s, less the solver's margin) is in the box a user's
    limit receives: assigning +-10 rad/s lifted it (the run went on at up to 10 rad/s)."""
    with pytest.raises(ParameterError) as info:
        _run(limits=[_Box(2, 10.0, assign=True)])
    message = str(info.value)
    assert message.startswith(
        "_Box 'box': compute() widened the input box at t = 0 s: lb[2] (th1dot) from "
        "-1.999998 to -10 (a limit only tightens lb, ub"
    )
    assert "\n" not in message


@pytest.mark.parametrize("unit", [1.0, 0.5])  # 0.5: the box on v passes through its unit
def test_a_limit_that_tightens_or_keeps_the_box_runs(unit):
    for index in range(4):
        for cap, assign in ((0.1, False), (0.1, True), (1e9, False)):  # 1e9: kept as given
            result = _run(limits=[_Box(index, cap, assign, unit)], max_base_speed=0.5)
            rate = np.abs(result.timeseries[("v", "w", "th1dot", "th2dot")[index]])
            assert np.max(rate) <= min(cap * (unit if index == 0 else 1.0), 2.0) + 1e-6


def test_a_limit_may_write_inf_on_an_open_side():
    """w's box is open (+-INF, 1e30) by default: +-inf there leaves it open."""
    _run(limits=[_Box(1, math.inf, assign=True)])


def test_a_limit_widening_v_in_its_own_unit_is_refused():
    """max_base_speed 0.5 m/s: +-1 in a unit of 0.5 m; +-1000 widens it."""
    with pytest.raises(
        ParameterError,
        match=r"^_Box 'box': compute\(\) widened .* lb\[0\] \(v\) "
        r"from -1 to -1000 ",
    ):
        _run(limits=[_Box(0, 1e3, assign=True, unit=0.5)], max_base_speed=0.5)


class _CompiledRow(Limit):
    """_RowLimit's row, and _Box's box on ``th1dot``, written by a compiled writer
    (``compile``) that ``how`` spoils; ``unit = None`` declares rows without ``v``."""

    rows = 1

    def __init__(self, how: str = "", unit: float | None = 1.0) -> None:
        self.how, self.unit = how, unit

    def compute(self, ctx, G, lower, upper, lb, ub):
        G[0] = (0.0, 1.0, 0.0, 0.0) if self.unit is None else (1.0, 1.0, 0.0, 0.0)
        lower[0], upper[0] = -0.1, 0.1
        lb[2], ub[2] = max(lb[2], -1.0), min(ub[2], 1.0)

    def compile(self, block):
        if self.how == "compile raise":
            raise ValueError("no block for me")
        (row,), (bound,), how, box = block.rows, block.bounds, self.how, block.box
        G, lower, upper = block.matrix, block.lower, block.upper

        def write(ctx):
            G[row], G[row + 1] = (0.0 if self.unit is None else 1.0), 1.0
            lower[bound], upper[bound] = -0.1, 0.1
            box[2], box[6] = max(box[2], -1.0), min(box[6], 1.0)
            if how == "G nan":
                G[row + 1] = math.nan
            elif how == "upper nan":
                upper[bound] = math.nan
            elif how == "box nan":
                box[6] = math.nan
            elif how == "widen":
                box[2] = -10.0
            elif how == "v":
                G[row] = 1.0
            elif how == "raise":
                raise RuntimeError("writer broke")

        return write


class _CompiledStill(_ArmStill):
    """_ArmStill by a compiled writer; ``how = "nan"`` writes a NaN target."""

    def compile(self, block):
        (target,), how = block.target_views, self.how
        block.write_constant_rows([[0, 0, 1, 0], [0, 0, 0, 1]])

        def write(ctx):
            target[block.targets[0]] = target[block.targets[1]] = 0.0
            if how == "nan":
                target[block.targets[1]] = math.nan

        return write


def test_a_user_piece_s_compiled_writer_runs_as_its_compute_does():
    """Its writer is used, not its compute, and the run is the compute path's to the bit."""
    from ddwmmr.qp.problem import QPProblem

    controller = make_controller("qp", Robot(), limits=[_CompiledRow()])
    problem = QPProblem(controller.tasks, controller.limits)
    assert all(limit.__module__.startswith("ddwmmr.") for limit, *_ in problem._generic_limits)
    compiled = _run(limits=[_CompiledRow()])
    generic = _run(limits=[_RowLimit(), _Box(2, 1.0, assign=False)])
    for column in ("v", "w", "th1dot", "th2dot"):
        np.testing.assert_array_equal(compiled.timeseries[column], generic.timeseries[column])
    assert np.max(np.abs(compiled.timeseries["th1dot"])) <= 1.0 + 1e-6
    still = simulate(Robot(), Ellipse(), _with_task(_CompiledStill(1.0)), duration=0.2)
    plain = simulate(Robot(), Ellipse(), _with_task(_ArmStill(1.0)), duration=0.2)
    np.testing.assert_array_equal(still.timeseries["th1dot"], plain.timeseries["th1dot"])


def _with_task(task):
    """A qp controller with the user's ``task``."""
    return make_controller("qp", Robot(), tasks=[task])


@pytest.mark.parametrize(
    ("how", "message"),
    [
        ("G nan", "wrote a non-finite value into its matrix at t = 0 s (they must be finite)"),
        ("upper nan", "wrote a non-finite value into its bounds at t = 0 s (they must not be "),
        ("box nan", "wrote a NaN into the input box at t = 0 s (bounds must not be NaN; "),
        ("widen", "widened the input box at t = 0 s: lb[2] (th1dot) from -1.999998 to -10 "),
    ],
)
def test_a_user_piece_s_compiled_writer_is_checked_as_its_compute_is(how, message):
    with pytest.raises(ParameterError) as info:
        _run(limits=[_CompiledRow(how)])
    assert str(info.value).startswith(f"_CompiledRow: compile()'s writer {message}")
    assert "\n" not in str(info.value)


def test_a_user_task_s_compiled_writer_is_checked_and_what_it_raises_named():
    with pytest.raises(
        ParameterError,
        match=r"^_CompiledStill 'armstill': compile\(\)'s writer "
        r"wrote a non-finite value into its error at t = 0 s",
    ):
        simulate(Robot(), Ellipse(), _with_task(_CompiledStill(1.0, "nan")), duration=0.2)
    with pytest.raises(
        PluginError,
        match=r"^_CompiledRow: compile\(\)'s writer raised "
        r"RuntimeError: writer broke at t = 0 s$",
    ):
        _run(limits=[_CompiledRow("raise")])
    with pytest.raises(
        PluginError,
        match=r"^_CompiledRow: compile\(\) raised ValueError: "
        r"no block for me \(building the QP\)$",
    ):
        _run(limits=[_CompiledRow("compile raise")])


def test_a_compiled_writer_without_v_that_writes_v_is_refused():
    _run(limits=[_CompiledRow(unit=None)])
    with pytest.raises(
        ParameterError,
        match=r"^_CompiledRow: unit = None \(rows without v\) "
        r"but compile\(\)'s writer wrote \[1\.0\] into its v column at t = 0 s",
    ):
        _run(limits=[_CompiledRow("v", unit=None)])
