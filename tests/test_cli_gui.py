"""``python -m ddwmmr.gui``: headless snapshots, options, bad input (one line, exit 2)."""

import os
import subprocess
import sys
import tkinter
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

import ddwmmr.gui.settings as gui_settings
from ddwmmr import ParameterError, Robot, available_methods, available_trajectories, simulate
from ddwmmr.cli import gui as cli
from ddwmmr.cli.gui import build_parser, main, settings_from_arguments
from ddwmmr.gui import App, Settings
from ddwmmr.gui.layout import FIGSIZE
from ddwmmr.gui.settings import build_trajectory
from ddwmmr.reports.plots import robot_outline
from in_process import call_main

#: Snapshot resolution of the tests (the window is 16 x 10 in): 480 x 300 px.
DPI = "30"
ROOT = Path(__file__).resolve().parents[1]


def trajectory_files(tmp_path):
    toml = tmp_path / "wide.toml"
    toml.write_text('[trajectory]\nshape = "ellipse"\na = 2.5\nb = 1.6\nT = 45\n')
    csv = tmp_path / "line.csv"
    rows = [f"{0.05 * k:.2f},{1.0 + 0.01 * k:.3f},{0.05 * np.sin(0.3 * k):.4f}" for k in range(61)]
    csv.write_text("t,x,y\n" + "\n".join(rows) + "\n")  # 3 s, a sample every 0.05 s
    return [str(toml), str(csv)]


def test_every_trajectory_and_method_is_offered():
    assert {"ellipse", "rectangle", "figure8", "sideways_reach"} <= set(available_trajectories())
    assert len(available_methods()) >= 6


@pytest.mark.parametrize("number", range(len(available_methods())))
def test_snapshot_for_every_method(number, tmp_path, capsys):
    """Every method once, the trajectories in turn (every name and both file kinds)."""
    method = available_methods()[number]
    trajectories = [*available_trajectories(), *trajectory_files(tmp_path)]
    trajectory = trajectories[number % len(trajectories)]
    path = tmp_path / "shot.png"
    status = main(
        [
            "--snapshot",
            str(path),
            "--dpi",
            DPI,
            "--method",
            method,
            "--traj",
            trajectory,
            "--duration",
            "0.4",
        ]
    )
    assert status == 0, capsys.readouterr().err
    assert capsys.readouterr().out.strip() == f"wrote {path}"
    with Image.open(path) as image:
        assert image.size == (480, 300)
        pixels = np.asarray(image.convert("L"), dtype=float)
    assert pixels.std() > 20  # widgets, plots and text, not a blank page


@pytest.mark.parametrize("option", ["position_weight=0", "orientation_weight=0"])
def test_snapshot_of_the_mpc_with_a_zero_cost_weight(option, tmp_path, capsys):
    """Documented >= 0: the terminal cost's LQR design used to raise LinAlgError here."""
    path = tmp_path / "shot.png"
    argv = ["--snapshot", str(path), "--dpi", DPI, "--method", "mpc", "--traj", "ellipse"]
    status = main([*argv, "--duration", "0.2", "--option", option])
    assert status == 0, capsys.readouterr().err
    assert capsys.readouterr().out.strip() == f"wrote {path}"
    with Image.open(path) as image:
        assert image.size == (480, 300)


def test_remaining_trajectories_snapshot(tmp_path, capsys):
    """Trajectories the method rotation above did not reach (if any), with side by side."""
    trajectories = [*available_trajectories(), *trajectory_files(tmp_path)]
    reached = {trajectories[n % len(trajectories)] for n in range(len(available_methods()))}
    for trajectory in [t for t in trajectories if t not in reached] or trajectories[:1]:
        path = tmp_path / f"{Path(trajectory).stem}.png"
        argv = [
            "--snapshot",
            str(path),
            "--dpi",
            DPI,
            "--traj",
            trajectory,
            "--method",
            "ats",
            "--compare",
            "clrrmc-ts",
            "--duration",
            "0.4",
        ]
        assert main(argv) == 0, capsys.readouterr().err
        assert path.is_file()


def test_every_method_and_every_trajectory_draws_the_final_state(tmp_path):
    """The window (one, reused) shows where simulate() leaves the robot: every method on
    the first trajectory, and every trajectory (the built-in ones and a file of each kind)
    under ``mpc``, the method that reads the trajectory ahead of the step. The window hands
    the two to simulate() independently, so a cross covers what all pairs did."""
    figure = Figure(figsize=FIGSIZE, dpi=30)
    FigureCanvasAgg(figure)
    app = App(figure, Settings(duration=0.2))
    trajectories = [*available_trajectories(), *trajectory_files(tmp_path)]
    pairs = [(method, trajectories[0]) for method in available_methods()]
    pairs += [("mpc", trajectory) for trajectory in trajectories[1:]]
    for method, trajectory in pairs:
        settings = Settings(trajectory=trajectory, methods=(method, None), duration=0.3, dt=0.05)
        app.apply(settings)
        app.run()
        app.wait()
        assert app.results is not None, (method, trajectory, app.message)
        app.show_index(app.view.last_index)
        expected = simulate(Robot(), build_trajectory(settings), method, duration=0.3, dt=0.05)
        final = robot_outline(Robot(), expected.configurations()[-1])["footprint"]
        np.testing.assert_allclose(app.view.runs[0].footprint.get_xy(), final, atol=1e-12)


def test_options_reach_the_window_settings():
    argv = [
        "--method",
        "qp",
        "--compare",
        "ats",
        "--option",
        "stability_min=1.5",
        "--option",
        "tau=0.2 0.3 0.4",
        "--compare-option",
        "aux=sum",
        "--traj",
        "rectangle",
        "--T",
        "30",
        "--payload",
        "3",
        "--integrator",
        "euler",
        "--dt",
        "0.05",
        "--duration",
        "2",
        "--offset",
        "0",
        "0.01",
    ]
    settings = settings_from_arguments(build_parser().parse_args(argv))
    assert settings == Settings(
        trajectory="rectangle",
        geometry={"T": 30.0},
        methods=("qp", "ats"),
        options=({"stability_min": 1.5, "tau": (0.2, 0.3, 0.4)}, {"aux": "sum"}),
        payload=3.0,
        integrator="euler",
        dt=0.05,
        duration=2.0,
        offset=(0.0, 0.01),
    )


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--method", "nope"], "invalid choice: 'nope'"),
        (["--T", "-1"], "T must be in [1e-06, 1e+09] s (got -1)"),
        (["--N", "1.5"], "N must be an integer in [2, 1000000] (got 1.5)"),
        (["--N", "1"], "N must be an integer in [2, 1000000] (got 1)"),
        (["--traj", "nowhere.csv"], "traj: no such file nowhere.csv"),
        (["--option", "bogus=1"], "has no option 'bogus'"),
        (["--option", "tau=-1"], "tau must be > 0 s"),
        (["--option", "tau"], "option must be NAME=VALUE"),
        (["--compare-option", "aux=sum"], "compare-option needs --compare METHOD"),
        (["--duration", "1", "--dt", "5"], "dt must be <= duration"),
        (
            ["--N", "2", "--duration", "1"],
            "duration must be >= one step T/N = 40 s / 2 = 20 s (got 1); raise N or duration, "
            "lower T, or set dt",
        ),
        (["--traj", "figure8", "--duration", "0.01"], "one step T/N = 60 s / 3000 = 0.02 s"),
        (["--offset", "1", "1"], "offset must be in [-0.65, 0.65] m (the arm's reach) (got 1)"),
        (["--offset", "0", "-0.7"], "offset must be in [-0.65, 0.65] m (the arm's reach)"),
        (
            ["--plant", "thesis", "--integrator", "euler"],
            "error: integrator: only the kinematic plant takes an integrator (plant 'thesis')",
        ),
        (
            ["--plant", "mujoco", "--integrator", "rk4"],
            "error: integrator: only the kinematic plant takes an integrator (plant 'mujoco')",
        ),
        (["--dpi", "0"], "dpi must be in [10, 600] (got 0)"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(argv, message, tmp_path, capsys):
    path = tmp_path / "shot.png"
    dpi = [] if "--dpi" in argv else ["--dpi", DPI]  # a tool refuses an option given twice
    status, _, err = call_main(main, ["--snapshot", str(path), *dpi, *argv], capsys)
    assert status == 2
    assert len(err.strip().splitlines()) == 1 and message in err, err
    assert not path.exists() and not list(tmp_path.iterdir())


def test_the_integrator_is_only_refused_when_given():
    settings = settings_from_arguments(build_parser().parse_args(["--plant", "thesis"]))
    assert (settings.plant, settings.integrator) == ("thesis", "rk4")
    settings = settings_from_arguments(build_parser().parse_args(["--integrator", "euler"]))
    assert (settings.plant, settings.integrator) == ("kinematic", "euler")


def test_export_with_snapshot_is_refused(tmp_path, capsys):
    path, export = tmp_path / "shot.png", tmp_path / "exports"
    argv = ["--snapshot", str(path), "--dpi", DPI, "--export", str(export)]
    status, _, err = call_main(main, argv, capsys)
    assert status == 2
    assert err == (
        "error: export: --export cannot be combined with --snapshot (it sets the folder of "
        "the window's Export buttons; a snapshot saves only the image)\n"
    )
    assert list(tmp_path.iterdir()) == []


def test_geometry_places_a_sampled_trajectory():
    """--a, --x0, --N on the figure-eight (a CSV) are applied, not ignored."""
    argv = ["--traj", "figure8", "--a", "2", "--x0", "0.5", "--N", "120"]
    settings = settings_from_arguments(build_parser().parse_args(argv))
    points = build_trajectory(settings).points[:, :2]
    low, high = points.min(axis=0), points.max(axis=0)
    np.testing.assert_allclose((high - low) / 2, [2.0, 1.5], atol=1e-12)
    np.testing.assert_allclose((high + low) / 2, [0.5, 0.0], atol=1e-12)
    assert gui_settings.control_step(settings, build_trajectory(settings)) == 0.5  # 60 s / 120
    own = settings_from_arguments(build_parser().parse_args(["--traj", "figure8", "--a", "3"]))
    assert own.geometry == {}  # the file's own a: the file's trajectory unchanged


def test_geometry_a_sampled_trajectory_cannot_take_is_refused(tmp_path, capsys):
    flat = tmp_path / "flat.csv"
    flat.write_text("t,x,y\n0,0.0,1.0\n1,0.5,1.0\n2,1.0,1.0\n")  # y never changes
    argv = ["--snapshot", str(tmp_path / "shot.png"), "--traj", str(flat), "--b", "0.5"]
    status, _, err = call_main(main, argv, capsys)
    assert status == 2
    assert err == (
        f"error: b: {flat} does not move along y, so it has no b to change (leave b at its "
        "own value, 0)\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flat.csv"]


def test_help_states_the_defaults(capsys):
    status, out, _ = call_main(main, ["--help"], capsys)
    assert status == 0
    text = " ".join(out.split())
    for words in (
        "--compare METHOD method of slot B, shown side by side with A (default: none",
        "--plant {kinematic,thesis,mujoco} what the commands drive (default kinematic)",
        "--integrator {euler,rk4} integrator of the kinematic plant (default rk4;",
        "(default -0.03 -0.03)",
        "not with --snapshot",
    ):
        assert words in text, words


@pytest.mark.parametrize(
    ("name", "words", "inside", "outside"),
    [
        ("x0", "--x0 M centre x in m, world frame (|x0| <= 1e+06)", -1e6, 1.01e6),
        ("a", "--a M semi-axis along the shape's own x in m, in [1e-06, 1000]", 1e-6, 1001.0),
        ("beta", "(|beta| <= 1e+06)", 1e6, -1.01e6),
        ("N", "--N N samples per period, an integer in [2, 1000000]", 2, 1),
        ("T", "--T S period in s, in [1e-06, 1e+09]", 1e9, 1.1e9),
    ],
)
def test_help_says_what_each_geometry_value_is_and_its_range(capsys, name, words, inside, outside):
    status, out, _ = call_main(main, ["--help"], capsys)
    assert status == 0
    assert words in " ".join(out.split())
    gui_settings.check_geometry(name, inside)  # the range the help states is the checked one
    with pytest.raises(ParameterError, match=rf"^{name} must be"):
        gui_settings.check_geometry(name, outside)


def test_dpi_without_a_snapshot_is_refused_as_force_is(capsys):
    assert main(["--dpi", "50"]) == 2
    assert capsys.readouterr().err == (
        "error: dpi needs --snapshot PATH (it sets the snapshot's resolution)\n"
    )
    assert main(["--dpi", "5000"]) == 2  # out of range is said first, with the range
    assert "dpi must be in [10, 600]" in capsys.readouterr().err


def test_not_a_trajectory_file_is_bad_input(tmp_path, capsys):
    notes = tmp_path / "notes.toml"
    notes.write_text("[shopping]\nmilk = 1\n")
    status = main(["--snapshot", str(tmp_path / "shot.png"), "--traj", str(notes)])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "needs shape" in err


def test_a_crashing_run_exits_1_with_one_line(tmp_path, capsys, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("solver exploded")

    monkeypatch.setattr(gui_settings, "simulate", broken)
    status = main(["--snapshot", str(tmp_path / "shot.png"), "--duration", "0.2"])
    err = capsys.readouterr().err
    assert status == 1 and err == "error: run failed: RuntimeError: solver exploded\n"
    assert not list(tmp_path.iterdir())


def test_no_display_is_one_line(monkeypatch, capsys):
    def no_display():
        raise tkinter.TclError("no display name and no $DISPLAY environment variable")

    monkeypatch.setattr(cli, "desktop_figure", no_display)
    assert main(["--duration", "1"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot open a window (no display name" in err
    assert "--snapshot PATH" in err


def test_module_runs_headless_as_a_process(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "MPLBACKEND")}
    path = tmp_path / "gui.png"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "ddwmmr.gui",
            "--snapshot",
            str(path),
            "--dpi",
            DPI,
            "--method",
            "clrrmc-ts",
            "--compare",
            "ats",
            "--duration",
            "0.5",
        ],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout == f"wrote {path}\n" and path.is_file()
    bad = subprocess.run(
        [sys.executable, "-m", "ddwmmr.gui", "--snapshot", str(tmp_path / "x.png"), "--T", "-3"],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=300,
    )
    assert bad.returncode == 2 and bad.stderr == "error: T must be in [1e-06, 1e+09] s (got -3)\n"
    assert not (tmp_path / "x.png").exists()
