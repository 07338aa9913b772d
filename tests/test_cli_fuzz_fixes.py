"""Bad input a systematic fuzz of the tools found taken silently or worded wrongly: an
empty value taken as "not given", an empty path shown as ".", a number of the wrong type
refused without its range, two lines for one refusal, the wrong option or range named.

Each tool runs in-process through its ``main(argv)`` in a fresh working folder; every
refusal is one line on stderr, status 2, and nothing is written.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import pytest

from ddwmmr.cli.bench import main as bench_main
from ddwmmr.cli.common import (
    given_text,
    integer_type,
    number_type,
    robot_from_arguments,
    split_names,
)
from ddwmmr.cli.compare import main as compare_main
from ddwmmr.cli.gui import build_parser as gui_parser
from ddwmmr.cli.gui import main as gui_main
from ddwmmr.cli.gui import settings_from_arguments
from ddwmmr.cli.scenarios import build_parser as scenarios_parser
from ddwmmr.cli.scenarios import main as scenarios_main
from ddwmmr.cli.track import build_parser as track_parser
from ddwmmr.cli.track import main as track_main
from ddwmmr.errors import ParameterError
from in_process import call_main

MAINS = {
    "track": track_main,
    "compare": compare_main,
    "scenarios": scenarios_main,
    "bench": bench_main,
    "gui": gui_main,
}
#: Arguments that make each tool's run small (the cases add the bad part).
BASE = {
    "track": ["--method", "pi", "--traj", "ellipse", "--duration", "0.1"],
    "compare": ["--methods", "pi", "--only", "ellipse", "--study", "none", "--jobs", "1"],
    "scenarios": ["--controller", "qp", "--plant", "kinematic", "--n", "1", "--jobs", "1"],
    "bench": ["--repeats", "1", "--calls", "10", "--scenarios", "0", "--method", "pi"],
    "gui": ["--snapshot", "shot.png", "--duration", "0.1"],
}


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    """A fresh, empty working folder."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def run(tool: str, args: list[str], capsys) -> tuple[int, list[str]]:
    """``tool`` with BASE (its options replaced by those ``args`` gives) + ``args`` and
    --no-progress (track: --no-plots); the status and stderr's lines."""
    base, i = [], 0
    given = {a for a in args if a.startswith("--")}
    while i < len(BASE[tool]):
        option, value = BASE[tool][i], BASE[tool][i + 1]
        if option not in given:
            base += [option, value]
        i += 2
    progress = {"gui": [], "track": ["--no-progress", "--no-plots"]}.get(tool, ["--no-progress"])
    status, _, err = call_main(MAINS[tool], [*base, *args, *progress], capsys)
    return status, err.strip().splitlines()


def refused(tool: str, args: list[str], capsys, workdir: Path) -> str:
    """The one line ``tool`` refuses ``args`` with (status 2, nothing written)."""
    status, lines = run(tool, args, capsys)
    assert status == 2 and len(lines) == 1, lines
    assert sorted(p.name for p in workdir.iterdir()) == []
    return lines[0]


# -- an empty value is not "not given" ----------------------------------------------------
@pytest.mark.parametrize("tool", ["track", "compare"])
def test_an_empty_robot_file_is_refused_not_the_default_robot(tool, workdir, capsys):
    line = refused(tool, ["--robot", "", "--out", "out"], capsys, workdir)
    assert line == "error: robot: give the path of a robot TOML file (got an empty path)"


def test_robot_from_arguments_refuses_an_empty_path_and_keeps_none():
    with pytest.raises(ParameterError, match=r"^robot: give the path"):
        robot_from_arguments(argparse.Namespace(robot="", payload=None))
    robot = robot_from_arguments(argparse.Namespace(robot=None, payload=2.0))
    assert robot.payload == pytest.approx(2.0, abs=0.0)


def test_an_empty_scheduler_is_refused_not_the_local_pool(workdir, capsys):
    line = refused("scenarios", ["--scheduler", "", "--out", "out"], capsys, workdir)
    assert line == "error: scheduler: give a Dask scheduler address (got an empty address)"


# -- an empty path is not "." ---------------------------------------------------------------
@pytest.mark.parametrize(
    ("tool", "message"),
    [
        ("track", "error: out: give an output folder (got an empty path)"),
        ("compare", "error: out: give an output folder (got an empty path)"),
        ("scenarios", "error: out: give an output folder (got an empty path)"),
        ("bench", "error: out: give a report file (got an empty path)"),  # --out is its JSON
    ],
)
def test_an_empty_out_is_refused_naming_out(tool, message, workdir, capsys):
    assert refused(tool, ["--out", ""], capsys, workdir) == message


def test_an_empty_bounds_out_and_bounds_file_are_refused(workdir, capsys):
    from ddwmmr.cli.bounds import main as bounds_main

    assert bounds_main(["--scenarios", "1", "--lower-only", "--out", ""]) == 2
    assert capsys.readouterr().err.strip() == (
        "error: out: give an output folder (got an empty path)"
    )
    line = refused("scenarios", ["--bounds", "", "--out", "out"], capsys, workdir)
    assert line == "error: bounds: give the path of a bounds run's bounds.csv (got an empty path)"


def test_an_empty_obstacle_file_is_refused_naming_obstacles(workdir, capsys):
    args = ["--method", "qp", "--obstacles", "", "--out", "out"]
    line = refused("track", args, capsys, workdir)
    assert line == (
        "error: obstacles: give a shipped obstacle name or a TOML file (got an empty text)"
    )


def test_given_text_refuses_blank_and_passes_the_rest():
    assert given_text("out", None, "a folder") is None
    assert given_text("out", "runs/a", "a folder") == "runs/a"
    with pytest.raises(ParameterError, match=r"^out: give a folder \(got an empty path\)$"):
        given_text("out", "  ", "a folder")


# -- a value of the wrong type: the option and its range ------------------------------------
@pytest.mark.parametrize(
    ("tool", "args", "text"),
    [
        ("track", ["--dt", "abc"], "argument --dt: must be a number > 0 s (got 'abc')"),
        ("track", ["--tau", ""], "argument --tau: must be a number > 0 s (at least 0.0001 s)"),
        ("track", ["--payload", ""], "argument --payload: must be a number in [0, 100000] kg"),
        ("track", ["--offset", "abc", "0"], "argument --offset: must be a number in [-reach"),
        ("track", ["--horizon", ""], "argument --horizon: must be a number in [0.0001, 100] s"),
        ("compare", ["--jobs", "1.5"], "argument --jobs: must be an integer in [1, 256]"),
        ("compare", ["--jobs", "nan"], "argument --jobs: must be an integer in [1, 256]"),
        ("compare", ["--jobs", "inf"], "argument --jobs: must be an integer in [1, 256]"),
        ("compare", ["--duration", ""], "argument --duration: must be a number > 0 s (got '')"),
        ("scenarios", ["--n", "nan"], "argument --n: must be an integer in [1, 100000]"),
        ("scenarios", ["--n", "1.5"], "argument --n: must be an integer in [1, 100000]"),
        ("scenarios", ["--seed", "1e308"], "argument --seed: must be an integer >= 0"),
        (
            "scenarios",
            ["--arbiter-seed", "1.5"],
            "argument --arbiter-seed: must be an integer >= 0",
        ),
        ("scenarios", ["--jobs", "inf"], "argument --jobs: must be an integer in [1, 256]"),
        ("scenarios", ["--dt", "x"], "argument --dt: must be a number in (0, 0.1] s"),
        ("gui", ["--offset", "abc", "0"], "argument --offset: must be a number in [-reach"),
        ("gui", ["--a", "abc"], "argument --a: must be a number in [1e-06, 1000] m"),
    ],
)
def test_a_value_of_the_wrong_type_names_the_option_and_its_range(
    tool, args, text, workdir, capsys
):
    assert text in refused(
        tool, [*args, "--out", "out"] if tool != "gui" else args, capsys, workdir
    )


def test_numbers_of_the_right_type_parse_as_before():
    args = track_parser().parse_args(["--dt", "0.01", "--tau", "inf", "0.5", "1e-3"])
    assert args.dt == pytest.approx(0.01, abs=0.0)
    assert math.isinf(args.tau[0]) and args.tau[1:] == [0.5, 0.001]
    args = scenarios_parser().parse_args(["--n", "0", "--seed", "7", "--jobs", "300"])
    assert (args.n, args.seed, args.jobs) == (0, 7, 300)  # ranges: the later checks' own


def test_the_converters_state_the_range_and_check_it_where_asked():
    assert integer_type(1, 5)("3") == 3
    with pytest.raises(argparse.ArgumentTypeError, match=r"in \[1, 5\] \(got '6'\)"):
        integer_type(1, 5)("6")
    assert integer_type(1, 5, checked_later=True)("6") == 6
    assert math.isnan(number_type("> 0 s")("nan"))
    with pytest.raises(argparse.ArgumentTypeError, match=r"^must be a number > 0 s \(got 'nan'\)"):
        number_type("> 0 s", finite=True)("nan")


# -- one refusal, one line; the right option and range ---------------------------------------
def test_a_mujoco_step_refused_without_the_uneven_duration_note(workdir, capsys):
    args = ["--plant", "mujoco", "--dt", "0.003", "--duration", "0.1", "--out", "out"]
    line = refused("track", args, capsys, workdir)
    assert line.startswith("error: dt must be a whole multiple of the MuJoCo timestep 0.002 s")


def test_only_names_only_for_an_unknown_trajectory(workdir, capsys):
    line = refused("compare", ["--only", "abc", "--out", "out"], capsys, workdir)
    assert line.startswith("error: only: unknown trajectory 'abc' (known: ")
    line = refused("compare", ["--traj", "abc", "--out", "out"], capsys, workdir)
    assert line.startswith("error: traj: unknown trajectory 'abc' (known: ")


def test_scenarios_mujoco_step_gives_the_scenarios_range(workdir, capsys):
    args = ["--controller", "thesis", "--plant", "mujoco", "--dt", "0.003", "--out", "out"]
    line = refused("scenarios", args, capsys, workdir)
    assert line == (
        "error: dt must be a whole multiple of the mujoco plant's engine step 0.002 s in "
        "(0, 0.1] s (0.002, 0.004, 0.006, ...) (got 0.003)"
    )


def test_scenarios_connect_timeout_nan_gives_the_range(workdir, capsys):
    args = ["--executor", "dask", "--scheduler", "tcp://127.0.0.1:1", "--connect-timeout", "nan"]
    line = refused("scenarios", [*args, "--out", "out"], capsys, workdir)
    assert line.endswith("argument --connect-timeout: must be a number in (0, 600] s (got 'nan')")


def test_scenarios_horizon_worded_as_track(workdir, capsys):
    line = refused("scenarios", ["--horizon", "2", "--out", "out"], capsys, workdir)
    assert (
        line == "error: horizon: --horizon is taken only by --controller mpc (got --controller qp)"
    )


# -- cosmetic ----------------------------------------------------------------------------------
def test_an_empty_name_inside_a_list_is_refused():
    assert split_names(["pi, ats", "pi"], "methods") == ["pi", "ats"]
    with pytest.raises(ParameterError, match=r"^methods: an empty name in the list"):
        split_names(["pi,,pi"], "methods")


def test_bench_refuses_an_empty_name_in_its_method_list(workdir, capsys):
    line = refused("bench", ["--method", "pi,,pi", "--out", "b.json"], capsys, workdir)
    assert line == "error: --method: an empty name in the list (got 'pi,,pi')"


def test_gui_slot_b_repeating_slot_a_is_refused(workdir, capsys):
    line = refused("gui", ["--method", "pi", "--compare", "pi"], capsys, workdir)
    assert line.startswith("error: compare: slot B would repeat slot A (pi, the same options)")
    args = gui_parser().parse_args(
        ["--method", "qp", "--compare", "qp", "--compare-option", "tau=0.3"]
    )
    assert settings_from_arguments(args).methods == ("qp", "qp")


def test_gui_dpi_is_an_integer(workdir, capsys):
    assert refused("gui", ["--dpi", "10.5"], capsys, workdir).endswith(
        "argument --dpi: must be an integer in [10, 600] (got '10.5')"
    )
    assert "(got '1e20')" in refused("gui", ["--dpi", "1e20"], capsys, workdir)
    dpi = gui_parser().parse_args(["--dpi", "150"]).dpi
    assert dpi == 150 and isinstance(dpi, int)
