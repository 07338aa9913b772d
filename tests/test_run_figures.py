"""Run figures agree with their data: the yaw rate drawn is the one the wheel speeds come
from, titles name a non-kinematic plant, one log-error floor for every figure, and the
path figure draws the final pose in a grey ramp."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.colors import to_rgb

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.gui import view
from ddwmmr.reports import compare_plots, physics_plots, plots


@pytest.fixture(scope="module")
def ellipse_run():
    """clrrmc-ts on the default ellipse (kinematic): converges to ~3e-10 m by 10 s."""
    return simulate(None, load_trajectory("ellipse"), "clrrmc-ts")


@pytest.fixture(scope="module")
def thesis_run():
    """The same on the thesis plant for 2 s: the base starts at rest, the command does not."""
    return simulate(None, load_trajectory("ellipse"), "clrrmc-ts", plant="thesis", duration=2.0)


def yaw_axis(fig):
    return fig.axes[1]


def test_rates_on_the_thesis_plant_draw_the_measured_yaw_rate_the_wheels_follow(thesis_run):
    ts, robot = thesis_run.timeseries, thesis_run.robot
    assert ts["w"][0] == pytest.approx(0.315, abs=0.005)  # commanded at t = 0
    assert ts["w_measured"][0] == 0.0 and ts["wheel_left_rad_s"][0] == 0.0
    fig = plots.plot_rates(thesis_run)
    measured, commanded = yaw_axis(fig).lines[:2]
    assert measured.get_label() == "w measured"
    assert commanded.get_label() == "w commanded" and commanded.get_linestyle() == "--"
    assert commanded.get_linewidth() < measured.get_linewidth()
    implied = (
        robot.wheel_radius * (ts["wheel_right_rad_s"] - ts["wheel_left_rad_s"]) / robot.track_width
    )
    np.testing.assert_allclose(measured.get_ydata(), implied, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(commanded.get_ydata(), ts["w"])
    assert measured.get_ydata()[0] == 0.0
    plt.close(fig)


def test_rates_on_the_kinematic_plant_keep_the_command_which_is_the_motion(ellipse_run):
    assert not plots.wheels_follow_measured(ellipse_run)
    fig = plots.plot_rates(ellipse_run)
    lines = yaw_axis(fig).get_lines()
    assert [line.get_label() for line in lines] == ["w (base yaw rate)"]
    np.testing.assert_array_equal(lines[0].get_ydata(), ellipse_run.timeseries["w"])
    plt.close(fig)


def test_titles_name_the_plant_unless_kinematic(ellipse_run, thesis_run):
    figs = [plots.plot_rates(thesis_run), plots.plot_rates(ellipse_run)]
    assert figs[0].axes[0].get_title() == "clrrmc-ts on ellipse (thesis plant): rates"
    assert figs[1].axes[0].get_title() == "clrrmc-ts on ellipse: rates"
    for fig in figs:
        plt.close(fig)
    assert plots.run_title({"method": "pi", "trajectory": "line"}, "") == "pi on line"


def test_animation_frames_name_the_plant(thesis_run, tmp_path, monkeypatch):
    titles: list[str] = []
    original = Axes.set_title

    def recording(self, label, *args, **kwargs):
        titles.append(label)
        return original(self, label, *args, **kwargs)

    monkeypatch.setattr(Axes, "set_title", recording)
    plots.save_animation(thesis_run, tmp_path / "a.gif", frames=2)
    assert titles and all(t.startswith("clrrmc-ts on ellipse (thesis plant) t = ") for t in titles)


def test_support_loads_name_the_run_and_the_edge_load():
    traj = load_trajectory("sideways_reach")
    robot = Robot().with_payload(3.0)
    q0 = robot.base_for_end_effector(traj.pose(0.0), 1.0, 1.6)
    run = simulate(robot, traj, "qp", plant="mujoco", q0=q0, dt=0.02, duration=0.4)
    fig = physics_plots.plot_support_loads(run, floor_n=13.0)
    ax = fig.axes[0]
    assert ax.get_title() == (
        "qp on sideways_reach (mujoco plant): support loads, unloaded "
        f"{run.summary.get('unloaded_time_s', 0.0):.2f} s (shaded)"
    )
    assert ax.get_ylabel() == "load on each edge (N)"
    (floor,) = [line for line in ax.get_lines() if line.get_label() == "floor 13.0 N"]
    assert floor.get_linestyle() == "--" and floor.get_ydata()[0] == pytest.approx(13.0)
    plt.close(fig)


def test_one_error_floor_below_a_converged_run(ellipse_run):
    assert plots.ERROR_FLOOR == 1e-12
    assert compare_plots.ERROR_FLOOR is plots.ERROR_FLOOR is view.ERROR_FLOOR
    ts = ellipse_run.timeseries
    late = ts["t"] >= 9.0
    assert 2e-10 < ts["position_error_m"][late].min() < 4e-10
    fig = plots.plot_errors(ellipse_run)
    drawn = fig.axes[0].lines[0].get_ydata()
    np.testing.assert_array_equal(drawn[late], ts["position_error_m"][late])
    assert fig.axes[0].get_ylim()[0] < 3e-10
    plt.close(fig)
    gui = view.plotted_series(ts, len(ts["t"]) - 1)["position"][0]
    np.testing.assert_array_equal(gui[late], ts["position_error_m"][late])


def test_a_flat_error_above_the_floor_still_gets_whole_decades():
    """A constant 3e-10 m error gets the decades around it (at_least_a_decade), a constant
    orientation error a 1 % span (at_least_a_percent)."""
    t = np.linspace(0.0, 1.0, 11)
    ts = {"t": t, "position_error_m": np.full(11, 3e-10), "orientation_error_rad": 0.0 * t + 0.02}
    result = type("Run", (), {"timeseries": ts, "summary": {"method": "m", "trajectory": "c"}})
    fig = plots.plot_errors(result)
    assert fig.axes[0].get_ylim() == pytest.approx((1e-10, 1e-9))
    assert fig.axes[1].get_ylim() == pytest.approx((0.0199, 0.0201))  # at_least_a_percent
    plt.close(fig)


def test_path_draws_the_final_pose_on_a_closed_path_in_greys():
    """pi on the ellipse leaves the path and ends at (1.6, 3): that pose is drawn last,
    darkest, in greys no path line uses."""
    run = simulate(None, load_trajectory("ellipse"), "pi")
    ts = run.timeseries
    assert np.hypot(ts["xE_d"][-1] - ts["xE_d"][0], ts["yE_d"][-1] - ts["yE_d"][0]) < 1e-3
    assert (ts["xE"][-1], ts["yE"][-1]) == pytest.approx((1.6, 3.0), abs=0.05)
    indices = plots.snapshot_indices(ts, 6, plots.footprint_spacing(run.robot))
    assert indices[0] == 0 and indices[-1] == len(ts["t"]) - 1
    fig = plots.plot_path(run)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    robots = [t for t in texts if t.startswith("robot at t = ")]
    assert robots[0] == "robot at t = 0 s" and robots[-1] == "robot at t = 40 s"
    # The final arm ends at the actual end effector's last point.
    arms = [
        line for line in ax.get_lines() if line.get_marker() == "o" and len(line.get_xdata()) == 3
    ]
    assert (arms[-1].get_xdata()[-1], arms[-1].get_ydata()[-1]) == pytest.approx(
        (ts["xE"][-1], ts["yE"][-1]), abs=1e-9
    )
    greys = [to_rgb(c) for c in plots.snapshot_colors(len(robots))]
    assert all(r == g == b for r, g, b in greys)  # no hue: unlike every method colour
    levels = [r for r, _, _ in greys]
    assert levels == sorted(levels, reverse=True) and levels[0] - levels[-1] > 0.5
    plt.close(fig)


def test_snapshot_greys_skip_the_base_paths_grey():
    """A robot drawn in the base path's 0.45 grey read as the base line (legend included)."""
    from ddwmmr.reports import palette

    low, high = palette.SNAPSHOT_SKIP
    base = float(palette.BASE)
    assert low < base < high
    for count in (2, 3, 6, 10):
        levels = [float(c) for c in plots.snapshot_colors(count)]
        assert levels == sorted(levels, reverse=True) and len(set(levels)) == count
        assert levels[0] == palette.SNAPSHOT_GREYS[0] and levels[-1] == pytest.approx(0.08)
        assert all(not low < level < high for level in levels)
