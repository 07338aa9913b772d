"""Figures show their data: nothing under a legend or a label, axes that hold what they
draw, no text off the canvas (tests/figure_checks.py), for the track and compare figures
and the legend placement they use."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.transforms import Bbox

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.reports import compare_plots, palette, plots
from ddwmmr.reports.legends import covers_data, place_legend
from figure_checks import (
    SavedFigures,
    assert_figure_shows_its_data,
    figure_problems,
    segments_crossing,
)

# -- the check itself -------------------------------------------------------------------


def test_segments_crossing_counts_segments_through_a_box():
    box = Bbox.from_extents(0, 0, 10, 10)
    assert segments_crossing(box, np.array([[-5.0, 5.0], [15.0, 5.0]])) == 1  # no vertex in
    assert segments_crossing(box, np.array([[-5.0, 20.0], [15.0, 20.0]])) == 0
    assert segments_crossing(box, np.array([[5.0, 5.0]])) == 1
    assert segments_crossing(box, np.array([[0.0, 0.0], [np.nan, np.nan], [5.0, -1.0]])) == 0


def test_the_check_finds_a_legend_on_a_line_a_cut_line_and_text_off_the_canvas():
    fig, ax = plt.subplots(figsize=(4, 3))
    t = np.linspace(0, 1, 50)
    ax.plot(t, np.ones_like(t), label="flat")
    ax.set_ylim(0.99, 1.01)  # the line runs through the middle, where the legend goes
    ax.legend(loc="center")
    assert any("legend covers" in p for p in figure_problems(fig))
    ax.set_ylim(0.0, 0.5)  # the line is now above the axes
    assert any("outside the axes" in p for p in figure_problems(fig))
    ax.set_ylim(0.0, 2.0)
    ax.legend(loc="lower right")
    assert figure_problems(fig) == []
    fig.text(0.95, 0.5, "a long caption that cannot fit")
    assert any("runs off the figure" in p for p in figure_problems(fig))
    plt.close(fig)


def test_the_check_finds_a_label_on_a_line_and_labels_on_each_other():
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.plot([0, 1], [0, 1])
    ax.annotate("on the line", (0.5, 0.5))
    ax.annotate("A", (0.1, 0.8))
    ax.annotate("B", (0.1, 0.8))
    problems = figure_problems(fig)
    assert any("'on the line' covers" in p for p in problems)
    assert any("'A' overlaps label 'B'" in p for p in problems)
    plt.close(fig)


def test_place_legend_finds_a_free_corner_or_makes_room():
    fig, ax = plt.subplots(figsize=(4, 3))
    t = np.linspace(0, 10, 200)
    ax.plot(t, np.sin(t), label="sin")
    ax.plot(t, np.cos(t), label="cos")
    ax.set_ylim(-1.05, 1.05)  # every corner has data under it at this size
    legend = place_legend(ax)
    assert not covers_data(ax, legend)
    assert ax.get_ylim()[1] > 1.05  # it raised the top to make room
    assert_figure_shows_its_data(fig)
    plt.close(fig)


# -- track figures ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def rectangle_run():
    return simulate(None, load_trajectory("rectangle"), "clrrmc-ts")


@pytest.mark.parametrize("make", [plots.plot_errors, plots.plot_rates, plots.plot_metrics])
def test_track_time_figures_show_their_data(rectangle_run, make):
    fig = make(rectangle_run)
    assert_figure_shows_its_data(fig)
    plt.close(fig)


def test_track_path_holds_every_robot_and_names_their_times(rectangle_run):
    fig = plots.plot_path(rectangle_run, obstacles=[(0.0, 0.0, 0.4)])
    assert_figure_shows_its_data(fig)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    # Six instants, the final pose among them (drawn darkest, over the first on a closed path).
    times = [t for t in texts if t.startswith("robot at t = ")]
    t = rectangle_run.timeseries["t"]  # 2001 samples over 40 s: every 2000/5th one
    expected = t[np.round(np.arange(6) * (len(t) - 1) / 5).astype(int)]
    assert times == [f"robot at t = {x:.3g} s" for x in expected]
    assert "desired end effector" in texts and "obstacle" in texts
    plt.close(fig)


def test_path_of_a_reach_on_the_spot_draws_robots_apart():
    """qp's sideways reach hardly moves the base (its six evenly spaced instants lie within
    0.45 m): the path keeps the first instant and those whose base lies outside every
    drawn footprint, each named with its time."""
    result = simulate(Robot().with_payload(3.0), load_trajectory("sideways_reach"), "qp")
    ts = result.timeseries
    spacing = plots.footprint_spacing(result.robot)
    assert spacing == pytest.approx(0.5 * np.hypot(0.45, 0.35))
    evenly = plots.snapshot_indices(ts, 6)
    kept = plots.snapshot_indices(ts, 6, spacing)
    assert len(evenly) == 6 and kept[0] == 0 and 2 <= len(kept) < 6
    assert set(kept) <= set(evenly)
    for i, a in enumerate(kept):
        for b in kept[i + 1 :]:
            assert np.hypot(ts["x"][a] - ts["x"][b], ts["y"][a] - ts["y"][b]) >= spacing
    fig = plots.plot_path(result)
    assert_figure_shows_its_data(fig)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert [t for t in texts if t.startswith("robot at")] == [
        f"robot at t = {ts['t'][k]:.3g} s" for k in kept
    ]
    plt.close(fig)


def test_rates_put_the_base_yaw_rate_apart_and_name_the_limits(rectangle_run):
    fig = plots.plot_rates(rectangle_run)
    joints, base, wheels = fig.axes
    assert [line.get_label() for line in base.lines] == ["w (base yaw rate)"]
    assert "w" not in " ".join(line.get_label() for line in joints.lines).split()
    robot = rectangle_run.robot
    joint_labels = [t.get_text() for t in joints.get_legend().get_texts()]
    wheel_labels = [t.get_text() for t in wheels.get_legend().get_texts()]
    assert f"joint limit +-{robot.joint_speed_limit:g} rad/s" in joint_labels
    assert f"wheel limit +-{robot.wheel_speed_limit:g} rad/s" in wheel_labels
    # The yaw rate reaches -3 rad/s, beyond the joint limit: it is not on that axis.
    assert np.min(rectangle_run.timeseries["w"]) < -robot.joint_speed_limit
    plt.close(fig)


def test_track_animation_frames_show_the_robot(rectangle_run, tmp_path, monkeypatch):
    """Every frame of ``track --gif`` is checked as it is grabbed."""
    saved = SavedFigures(monkeypatch)
    plots.save_animation(rectangle_run, tmp_path / "animation.gif", frames=6)
    assert len(saved.problems) >= 6
    assert saved.failing() == {}


# -- compare figures --------------------------------------------------------------------

METHODS = ("pi", "ats", "ap", "clrrmc-ts")


@pytest.fixture(scope="module")
def compare_series():
    """Full-period runs on both trajectories: pi and ap leave the path (their panels must
    widen), ats keeps its offset, clrrmc-ts tracks."""
    return {
        name: {m: simulate(None, load_trajectory(name), m).timeseries for m in METHODS}
        for name in ("ellipse", "rectangle")
    }


@pytest.mark.parametrize("name", ["ellipse", "rectangle"])
def test_compare_trajectory_figures_show_their_data(compare_series, name):
    series = compare_series[name]
    colors = palette.method_colors(list(series))
    robot = Robot()
    figures = {
        "paths": compare_plots.plot_paths(
            series, colors, name, [("A", 0.0, 0.13), ("B", 10, None)]
        ),
        "errors": compare_plots.plot_errors(series, colors, name),
        "wheels": compare_plots.plot_wheels(series, colors, robot.wheel_speed_limit, name),
        "methods": compare_plots.plot_small_multiples(series, colors, robot, name),
    }
    for kind, fig in figures.items():
        zooms = fig.axes[1:] if kind == "paths" else ()
        problems = figure_problems(fig, cropped=zooms)
        assert not problems, (kind, problems[:5])
        plt.close(fig)


def test_every_wheel_panel_has_its_time_axis_and_the_limit_is_named(compare_series):
    series = compare_series["rectangle"]
    fig = compare_plots.plot_wheels(series, palette.method_colors(list(series)), 15.0, "r")
    fig.canvas.draw()
    for ax in [a for a in fig.axes if a.get_visible()]:
        assert ax.get_xlabel() == "t (s)"
        assert any(label.get_visible() and label.get_text() for label in ax.get_xticklabels())
    legend_texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "limit +-15 rad/s (dotted)" in legend_texts
    plt.close(fig)


def test_small_multiples_draw_every_instant_inside_its_panel(compare_series):
    series = compare_series["rectangle"]
    robot = Robot()
    fig = compare_plots.plot_small_multiples(series, palette.method_colors(METHODS), robot, "r")
    ap = fig.axes[METHODS.index("ap")]
    x_low, x_high = ap.get_xlim()
    # ap leaves the frame of the desired rectangle (x within +-2 m, +-3.2 m with the
    # margin): its panel widened to hold its whole path.
    assert np.max(series["ap"]["xE"]) > 3.5
    xs = np.concatenate([line.get_xdata() for line in ap.lines])
    assert x_low <= np.min(xs) and np.max(xs) <= x_high
    assert_figure_shows_its_data(fig)
    plt.close(fig)


def test_compare_study_and_plant_figures_show_their_data(compare_series):
    """The study figures and the plant figure on curves of the real runs (the studies
    only change which runs feed them)."""
    series = compare_series["ellipse"]
    colors = palette.method_colors(METHODS)
    t = series["ats"]["t"]
    error = {m: series[m]["position_error_m"] for m in METHODS}
    taus = (0.1, 0.3, 1.0, 3.0)
    curves = {m: {tau: (t, 0.04 * np.exp(-t / tau)) for tau in taus} for m in METHODS[3:]}
    convergence = {m: {tau: 3.0 * tau for tau in taus} for m in METHODS[3:]}
    offsets = (0.0, 0.02, 0.04, 0.08)
    final = {m: {x: max(error[m][-1], x if m == "ats" else 0.0) for x in offsets} for m in METHODS}
    integrator = {m: {"euler": (t, error[m] + 1e-4), "rk4": (t, error[m])} for m in METHODS}
    quarter = 10.0
    rectangle = compare_series["rectangle"]
    figures = [
        compare_plots.plot_tau_study(curves, convergence, -np.log(0.05), colors),
        compare_plots.plot_integrator_study(integrator, colors, 0.02),
        compare_plots.plot_init_study(final, {x: (t, error["clrrmc-ts"] + x) for x in offsets},
                                      "clrrmc-ts", colors),
        compare_plots.plot_corner_study(rectangle, colors, quarter, [10.0, 20.0, 30.0]),
        compare_plots.plot_plant_errors(series, rectangle, colors, "thesis", "plants"),
    ]  # fmt: skip
    for fig in figures:
        assert_figure_shows_its_data(fig)
        plt.close(fig)


def test_coinciding_groups_pair_lines_within_the_factor():
    lines = {
        "a": [1.0, 2.0, 3.0],
        "b": [1.1, 2.1, 3.2],  # within 15 % of a everywhere
        "c": [1.0, 2.0, 4.0],  # 33 % off a at the last point
        "d": [1e-3, 1e-4, 1e-5],
        "e": [1.05e-3, 0.95e-4, 1.1e-5],
    }
    assert compare_plots.coinciding_groups(lines) == [["a", "b"], ["d", "e"]]


def test_dt_study_names_the_lines_lying_on_each_other():
    steps = (0.01, 0.02, 0.04)
    drift = {
        "pi": {"euler": dict.fromkeys(steps, 3.0), "rk4": dict.fromkeys(steps, 3.1)},
        "ats": {"euler": {s: 0.2 * s for s in steps}, "rk4": {s: 1e-3 * s**4 for s in steps}},
    }
    fig = compare_plots.plot_dt_study(drift, palette.method_colors(["pi", "ats"]))
    legend = fig.axes[0].get_legend()
    assert "pi (euler) = pi (rk4)" in legend.get_title().get_text()
    widths = {line.get_label(): line.get_linewidth() for line in fig.axes[0].lines}
    assert widths["pi (euler)"] > widths["pi (rk4)"]  # wide under thin: both visible
    assert_figure_shows_its_data(fig)
    plt.close(fig)


def test_init_study_names_the_methods_lying_on_each_other():
    offsets = (0.0, 0.02, 0.04)
    final = {
        "pi": dict.fromkeys(offsets, 3.0),
        "ap": dict.fromkeys(offsets, 3.2),  # within 15 % of pi: on the same spot
        "ats": {x: max(x, 1e-11) for x in offsets},
    }
    t = np.linspace(0.0, 10.0, 50)
    curves = {x: (t, (x + 1e-3) * np.exp(-t)) for x in offsets}
    fig = compare_plots.plot_init_study(final, curves, "ats", palette.method_colors(list(final)))
    left = fig.axes[0]
    assert "pi = ap" in left.get_legend().get_title().get_text()
    widths = {line.get_label(): line.get_linewidth() for line in left.lines}
    assert widths["pi"] > widths["ap"]  # wide under thin: both visible
    assert_figure_shows_its_data(fig)
    plt.close(fig)


# -- the GUI ----------------------------------------------------------------------------


def _window(*argv: str):
    """The simulator window off-screen (as ``--snapshot`` builds it), run to the end and
    shown at its last instant."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ddwmmr.cli.gui import build_parser, settings_from_arguments
    from ddwmmr.gui.app import App
    from ddwmmr.gui.layout import DPI, FIGSIZE

    settings = settings_from_arguments(build_parser().parse_args(list(argv)))
    figure = Figure(figsize=FIGSIZE, dpi=DPI)
    FigureCanvasAgg(figure)
    app = App(figure, settings)
    app.run()
    app.wait()
    app.show_index(app.view.last_index)
    return app


def _view_problems(app) -> list[str]:
    view = app.view
    cursors = set(view._cursors)  # the playback cursor sweeps under everything
    return figure_problems(
        app.figure,
        ignore=lambda artist: artist in cursors,
        only=[view.path_ax, *view.plot_axes.values(), app.message_text.axes],
    )


def test_gui_view_shows_both_runs_and_no_legend_on_them():
    post = Path(__file__).resolve().parent.parent / "trajectories/obstacles/ellipse_post.toml"
    app = _window(
        "--method", "qp", "--payload", "3", "--option", f"obstacles={post}",
        "--compare", "clrrmc-ts", "--traj", "ellipse", "--duration", "20",
    )  # fmt: skip
    assert _view_problems(app) == []
    a, b = app.view.runs
    # B is drawn over A, thinner: where the two coincide A shows on both sides of B.
    assert a.ee_trail.get_linewidth() > 2 * b.ee_trail.get_linewidth()
    assert a.ee_trail.get_zorder() <= b.ee_trail.get_zorder()
    # Tick labels at least 10 px high at the window's resolution.
    for ax in [app.view.path_ax, *app.view.plot_axes.values()]:
        for label in ax.get_yticklabels() + ax.get_xticklabels():
            assert label.get_fontsize() * app.figure.dpi / 72 >= 10.0


def test_gui_animation_frames_show_both_runs():
    """The figure of the GUI's GIF/MP4 export (the view alone) at six instants."""
    from ddwmmr.gui.view import animation_figure
    from ddwmmr.reports.canvas import frame_indices

    trajectory = load_trajectory("ellipse")
    results = [simulate(None, trajectory, m, duration=10.0) for m in ("qp", "ap")]
    figure, view = animation_figure()
    view.set_runs(results, ["A-qp", "B-ap"], [])
    cursors = set(view._cursors)
    for index in frame_indices(view.last_index, 6):
        view.show_index(index)
        problems = figure_problems(figure, ignore=lambda artist: artist in cursors)
        assert problems == [], (index, problems[:5])


def test_gui_summary_of_a_physics_run_fits_the_window_and_names_the_folder(tmp_path, monkeypatch):
    from ddwmmr.cli.gui import build_parser, settings_from_arguments, snapshot
    from ddwmmr.gui.app import App

    said: list[str] = []
    original = App.say
    monkeypatch.setattr(
        App, "say", lambda self, text, error=False: (said.append(text), original(self, text, error))
    )
    settings = settings_from_arguments(
        build_parser().parse_args(
            ["--method", "qp", "--compare", "clrrmc-ts", "--plant", "mujoco", "--duration", "2"]
        )
    )
    path = tmp_path / "shots" / "mujoco.png"
    snapshot(settings, path)
    assert said[-1].endswith(f"(--snapshot {path})")
    app = _window(
        "--method", "qp", "--compare", "clrrmc-ts", "--plant", "mujoco", "--duration", "2"
    )
    assert "stood (physics" in app.summary_text.get_text()
    assert _view_problems(app) == []  # the summary is checked against the canvas too
    right = app.summary_text.get_window_extent(app.figure.canvas.get_renderer()).x1
    assert right <= app.figure.bbox.width


def test_wrap_to_width_breaks_at_commas_within_the_room():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ddwmmr.gui.widgets import wrap_to_width

    figure = Figure(figsize=(6, 2), dpi=100)
    FigureCanvasAgg(figure)
    text = figure.text(0.1, 0.9, "", fontsize=8)
    line = ", ".join(f"item {i} = {i * 1.5:g} units" for i in range(12))
    wrapped = wrap_to_width(line, text, 0.9)
    renderer = figure.canvas.get_renderer()
    room = 0.8 * 600
    lines = wrapped.split("\n")
    assert len(lines) > 1
    for piece in lines:
        text.set_text(piece)
        assert text.get_window_extent(renderer).width <= room
    assert " ".join(piece.strip() for piece in lines) == line


def test_wrap_to_width_breaks_a_piece_wider_than_the_room_at_its_spaces():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ddwmmr.gui.widgets import wrap_to_width

    figure = Figure(figsize=(6, 2), dpi=100)
    FigureCanvasAgg(figure)
    text = figure.text(0.1, 0.9, "", fontsize=8)
    long_piece = " ".join(f"word{i}" for i in range(40))  # no comma in 240 characters
    line = f"head, {long_piece}, tail"
    lines = wrap_to_width(line, text, 0.9).split("\n")
    renderer = figure.canvas.get_renderer()
    for piece in lines:
        text.set_text(piece)
        assert text.get_window_extent(renderer).width <= 0.8 * 600, piece
    assert lines[0] == "head," and lines[-1] == "    tail" and len(lines) > 3
    assert " ".join(piece.strip() for piece in lines) == line


# -- scenario figures -------------------------------------------------------------------


def test_scenario_figures_show_their_data(tmp_path, monkeypatch):
    """Every figure `scenarios` draws, on three scenarios (one with the obstacle study's
    two obstacles), state machine and competitive arbiter."""
    from ddwmmr.cli.scenarios import _draw_figures
    from ddwmmr.scenarios import report
    from ddwmmr.scenarios.generator import generate
    from ddwmmr.scenarios.protocol import RunConfig, run_scenario
    from ddwmmr.scenarios.studies import obstacle_scenarios

    problems: dict[str, list[str]] = {}

    def check(fig, path, rect=None):
        fig.tight_layout(rect=rect)  # as report._save lays it out
        problems[Path(path).name] = figure_problems(fig)
        plt.close(fig)

    monkeypatch.setattr(report, "_save", check)
    scenarios = generate(3, 0)
    scenarios[0] = obstacle_scenarios(generate(10, 0))[0]
    for arbiter in ("state-machine", "competitive"):
        config = RunConfig(arbiter=arbiter)
        outcomes = [run_scenario(s, config) for s in scenarios]
        _draw_figures(tmp_path, scenarios, outcomes, config)
    assert {"paths.png", "timeline.png", "weights.png"} <= set(problems)
    assert {name: found for name, found in problems.items() if found} == {}


def test_support_loads_figure_shows_its_data():
    """The physics track figure: each edge's load, the floor and the tilt, nothing under
    the legend or off the canvas."""
    from ddwmmr.reports.physics_plots import plot_support_loads

    traj = load_trajectory("sideways_reach")
    robot = Robot().with_payload(3.0)
    q0 = robot.base_for_end_effector(traj.pose(0.0), 1.0, 1.6)
    run = simulate(robot, traj, "qp", plant="mujoco", q0=q0, dt=0.02, duration=2.0)
    fig = plot_support_loads(run)
    assert_figure_shows_its_data(fig)
    plt.close(fig)
