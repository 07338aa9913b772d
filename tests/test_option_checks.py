"""Bad input to the ``mpc``'s and the ``qp``'s options: a QP backend with a solver that
takes none, a stability floor above S's cap, the ``stability_min`` range at both ends, and
a start inside the ``mpc``'s obstacle keep-out."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, make_controller
from ddwmmr.behaviours.obstacle import base_bubble
from ddwmmr.cli.scenarios import main as scenarios_main
from ddwmmr.cli.track import main as track_main
from ddwmmr.model.stability import STABILITY_CAP
from ddwmmr.mpc.options import MPCOptions
from ddwmmr.qp.limits.base import INF

ROBOT = Robot()
#: A start pose heading along +x (x, y m, phi, th1, th2 rad).
START = np.array([0.0, 0.0, 0.0, -0.3, 0.6])


# -- qp_solver with a solver that takes no QP backend ---------------------------------------
@pytest.mark.parametrize("solver", ["ipopt", "sqpmethod", "fatrop"])
def test_a_qp_backend_with_an_nlp_solver_is_refused_naming_both(solver):
    with pytest.raises(ParameterError) as error:
        MPCOptions(solver=solver, qp_solver="osqp")
    message = str(error.value)
    assert "\n" not in message
    assert message == (
        f"qp_solver needs solver rti or sqp: solver '{solver}' uses no QP backend "
        "(got qp_solver 'osqp')"
    )


@pytest.mark.parametrize(("solver", "qp_solver"), [("rti", "osqp"), ("sqp", "daqp")])
def test_a_qp_backend_of_a_gauss_newton_solver_is_kept(solver, qp_solver):
    assert MPCOptions(solver=solver, qp_solver=qp_solver).qp_solver == qp_solver


def test_the_command_line_refuses_a_qp_backend_with_ipopt(capsys, tmp_path):
    argv = ["--method", "mpc", "--traj", "ellipse", "--duration", "0.1", "--no-plots"]
    argv += ["--no-progress", "--out", str(tmp_path / "out")]
    argv += ["--option", "solver=ipopt", "--option", "qp_solver=osqp"]
    assert track_main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "qp_solver needs solver rti or sqp" in err
    assert not (tmp_path / "out" / "summary.json").exists()


# -- a floor at or above S's cap ------------------------------------------------------------
@pytest.mark.parametrize(
    ("stability_min", "margin", "room"),
    [(1.25, 100.0, "8.75"), (1.25, 8.75, "8.75"), (9.995, 0.02, "0.005")],
)
def test_a_margin_that_lifts_the_floor_to_the_cap_is_refused(stability_min, margin, room):
    with pytest.raises(ParameterError) as error:
        MPCOptions(stability_min=stability_min, stability_margin=margin)
    assert str(error.value) == (
        f"stability_margin must be in [0, {room}) with stability_min {stability_min:g}: the "
        "OCP keeps S >= stability_min + stability_margin, and S is capped at 10 "
        f"(got {margin:g})"
    )


@pytest.mark.parametrize("stability_min", [9.99, 9.995])
def test_a_floor_that_the_default_margin_lifts_to_the_cap_names_the_floor(stability_min):
    """`--option stability_min=9.99` named stability_margin, which the user never set, and
    its range as [0, 0.009999999999999787)."""
    with pytest.raises(ParameterError) as error:
        MPCOptions(stability_min=stability_min)
    assert str(error.value) == (
        "stability_min must be in (0, 9.99) with stability_margin 0.01: the OCP keeps S >= "
        f"stability_min + stability_margin, and S is capped at 10 (got {stability_min:g})"
    )


def test_a_margin_just_below_the_cap_is_kept():
    options = MPCOptions(stability_min=1.25, stability_margin=8.749)
    assert options.stability_min + options.stability_margin == pytest.approx(9.999, abs=1e-12)
    assert options.stability_min + options.stability_margin < STABILITY_CAP


def test_the_scenario_tool_refuses_a_margin_above_the_cap(capsys, tmp_path):
    argv = ["--controller", "mpc", "--n", "1", "--no-progress", "--out", str(tmp_path / "o")]
    argv += ["--option", "stability_margin=100"]
    assert scenarios_main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "stability_margin must be in [0, 8.75)" in err


def test_the_qp_has_no_margin_option_and_meets_a_floor_near_the_cap():
    """The qp's damper aims 0.01 above its floor, a fixed target and no option; at a floor
    just below the cap the target lies above it, yet the row only asks a term below the
    cap to rise (a capped term is free), so the floor itself stays one S can meet."""
    with pytest.raises(ParameterError, match="unknown option 'stability_margin'"):
        make_controller("qp", ROBOT, stability_margin=0.5)
    qp = make_controller("qp", ROBOT, stability_min=9.995)
    assert qp.stability_min == 9.995 and qp.stability.margin == 0.01
    assert qp.stability.lower_bound(STABILITY_CAP, 0.3, 0.1) == -INF
    # below the cap: the bound asks for a rise, capped at half the joints' top rate
    assert qp.stability.lower_bound(9.0, 0.3, 0.1) == pytest.approx(0.5 * 2.0 * 0.4, rel=1e-12)


# -- the stability_min range at both ends ----------------------------------------------------
@pytest.mark.parametrize("method", ["mpc", "qp"])
@pytest.mark.parametrize(("value", "got"), [(0.0, "0"), (-1.0, "-1")])
def test_stability_min_names_its_range_at_the_low_end(method, value, got):
    _assert_range_message(method, value, got)


@pytest.mark.parametrize("method", ["mpc", "qp"])
@pytest.mark.parametrize(("value", "got"), [(10.0, "10"), (11.0, "11")])
def test_stability_min_names_its_range_at_the_cap(method, value, got):
    _assert_range_message(method, value, got)


def _assert_range_message(method: str, value: float, got: str) -> None:
    with pytest.raises(ParameterError) as error:
        make_controller(method, ROBOT, stability_min=value)
    assert str(error.value) == f"stability_min must be in (0, 10) (got {got})"


# -- a start inside the mpc's keep-out ------------------------------------------------------
def _behind(gap: float, radius: float = 0.1) -> tuple[float, float, float]:
    """A circle straight behind START whose edge is ``gap`` (m) from the base's rear."""
    return (-(0.5 * ROBOT.base_length + gap + radius), 0.0, radius)


def _reset_warnings(controller) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        controller.reset(None, START)
    return [str(w.message) for w in caught if issubclass(w.category, UserWarning)]


def test_a_start_inside_the_keep_out_warns_once_naming_the_obstacle():
    circle = _behind(0.02)
    controller = make_controller("mpc", ROBOT, obstacles=[(5.0, 5.0, 0.2), circle])
    messages = _reset_warnings(controller)
    bubble = base_bubble(ROBOT)
    overlap = bubble - (0.5 * ROBOT.base_length + 0.02)  # the circle enters the bubble
    assert overlap == pytest.approx(0.0400438562747845, abs=1e-12)
    assert messages == [
        "obstacles: the start pose is inside the mpc's keep-out of obstacle 2 (x -0.345 m, "
        "y 0 m, radius 0.1 m): the base's enclosing circle (radius 0.285 m) overlaps it by "
        "0.04 m, within obstacle_margin 0.05 m; the run starts violating its obstacle "
        "constraint"
    ]


def test_a_start_within_the_margin_names_the_nearest_of_several():
    near, nearer = (0.0, 0.42, 0.1), (0.0, -0.41, 0.1)  # clear of the bubble by 0.035, 0.025
    controller = make_controller("mpc", ROBOT, obstacles=[near, nearer], obstacle_margin=0.05)
    (message,) = _reset_warnings(controller)
    assert "obstacle 2 (x 0 m, y -0.41 m, radius 0.1 m) (and 1 more)" in message
    assert "is 0.025 m from it, within obstacle_margin 0.05 m" in message


def test_a_start_clear_of_the_keep_out_does_not_warn():
    controller = make_controller("mpc", ROBOT, obstacles=[(0.0, 0.44, 0.1)])  # 0.055 clear
    assert _reset_warnings(controller) == []


def test_the_qp_runs_the_same_start_without_refusing_it():
    """The warning, not a refusal, because the qp takes the same start: its footprint is
    0.02 m clear of the circle (so the tools' start check passes), within its 0.05 m
    margin, and its obstacle row asks the clearance to grow at 2 (0.05 - 0.02) m/s."""
    circle = _behind(0.02)
    qp = make_controller("qp", ROBOT, obstacles=[circle])
    assert _reset_warnings(qp) == []
    u = qp.command(0.0, START, ROBOT.fk(START), np.zeros(3))
    limit = next(piece for piece in qp.limits if piece.name == "obstacles")
    rate_v, rate_w, lower = limit.row(qp.ctx, limit.circles[0])
    assert (rate_v, rate_w) == (pytest.approx(1.0), pytest.approx(0.0, abs=1e-12))
    assert lower == pytest.approx(0.06, rel=1e-9)
    assert u[0] >= 0.06 - 1e-6  # it drives forward, away from the circle behind


@pytest.mark.parametrize("margin", ["1e300", "1.7976931348623157e308", "1000001"])
def test_an_mpc_obstacle_margin_beyond_any_coordinate_is_refused(tmp_path, capsys, margin):
    """The mpc took any finite margin and squares it building its OCP: 1e300 with an
    obstacle ended in OverflowError, a traceback. Capped as an obstacle's coordinates."""
    out = tmp_path / "run"
    args = ["--method", "mpc", "--traj", "ellipse", "--obstacles", "ellipse_post"]
    assert track_main([*args, "--option", f"obstacle_margin={margin}", "--out", str(out)]) == 2
    err = capsys.readouterr().err.splitlines()[-1]
    assert err == f"error: obstacle_margin must be in [0, 1e+06] m (got {float(margin):g})"
    assert not out.exists()
    make_controller("mpc", ROBOT, obstacle_margin=1e6)  # the cap itself is accepted
