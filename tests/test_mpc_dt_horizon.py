"""The loop's control step against the mpc's horizon: a step with no room left in the
horizon is refused naming dt (it was refused as a first_interval the user never set), and
a long step that fits runs through to its summary."""

from __future__ import annotations

import pytest

from ddwmmr import ParameterError, Robot, load_trajectory, make_controller, simulate
from ddwmmr.cli.track import main as track
from ddwmmr.mpc.ocp import check_step_in_horizon, shooting_grid
from ddwmmr.mpc.options import MPCOptions


@pytest.mark.parametrize(
    ("dt", "message"),
    [
        ("1", "error: dt: the mpc's step must be < its horizon, 1 s (got 1)\n"),
        ("2", "error: dt: the mpc's step must be < its horizon, 1 s (got 2)\n"),
        (
            "0.9999",
            "error: dt: the mpc's step must leave its 9 later intervals at least 0.0001 s "
            "each of its 1 s horizon, <= 0.9991 s (got 0.9999)\n",
        ),
    ],
)
def test_track_refuses_a_step_as_long_as_the_horizon(tmp_path, capsys, dt, message):
    out = tmp_path / "run"
    args = ["--method", "mpc", "--traj", "ellipse", "--dt", dt, "--duration", "10"]
    assert track([*args, "--no-plots", "--out", str(out)]) == 2
    assert capsys.readouterr().err.splitlines()[-1] + "\n" == message
    assert not out.exists()


def test_the_api_names_dt_too():
    with pytest.raises(ParameterError, match=r"^dt: the mpc's step must be < its horizon, 1 s"):
        simulate(Robot(), load_trajectory("ellipse"), "mpc", dt=1.0, duration=10.0)


def test_the_dt_option_with_the_default_horizon_names_dt():
    """The user set dt, not the horizon."""
    with pytest.raises(ParameterError, match=r"^dt: the mpc's step must be < its horizon, 1 s"):
        make_controller("mpc", Robot(), dt=1.0)
    with pytest.raises(ParameterError, match=r"^horizon must be > the control step dt = 1 s"):
        make_controller("mpc", Robot(), dt=1.0, horizon=1.0)


def test_a_long_step_that_fits_reaches_its_summary():
    """dt 0.6 s in the 1 s tracking horizon: the controller shortens the first interval to
    0.4 / 9 s; the summary's record of the grid used the unshortened 0.05 s and failed
    after the whole run ('horizon must be >= ... = 1.05 s')."""
    run = simulate(Robot(), load_trajectory("ellipse"), "mpc", dt=0.6, duration=3.0)
    record = run.summary["mpc_options"]
    assert record["dt"] == 0.6
    assert record["first_interval"] == pytest.approx(0.4 / 9)
    n, first, horizon = MPCOptions().grid_at("tracking", 0.6)
    assert (n, horizon) == (10, 1.0) and first == pytest.approx(0.4 / 9)


def test_the_grid_check_itself():
    assert check_step_in_horizon(0.02, 1.0, 10) == 0.02
    assert shooting_grid(10, 0.9991, 1e-4, 1.0)[0] == 0.9991
    with pytest.raises(ParameterError, match=r"^dt must be > 0"):
        check_step_in_horizon(0.0, 1.0, 10)


@pytest.mark.parametrize("value", ["1e-300", "5e-324", "9.9e-05"])
def test_the_dt_option_below_the_least_interval_is_refused(tmp_path, capsys, value):
    """The mpc's plan starts with an interval of dt: ``--option dt=1e-300`` used to run
    (and report "tracked") with a first interval 1e-300 s long, where first_interval and
    every later interval must be >= 1e-4 s."""
    out = tmp_path / "run"
    args = ["--method", "mpc", "--traj", "ellipse", "--option", f"dt={value}", "--no-plots"]
    assert track([*args, "--out", str(out)]) == 2
    err = capsys.readouterr().err.splitlines()[-1]
    assert (
        err == f"error: dt: the mpc's step must be >= 0.0001 s, the least interval of its "
        f"plan (got {float(value):g})"
    )
    assert not out.exists()
    make_controller("mpc", Robot(), dt=1e-4)  # the least interval itself is accepted
