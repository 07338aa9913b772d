"""The simulator window driven through its widgets under Agg (no display).

Buttons are pressed with mouse events on the canvas; text fields get text and Enter;
sliders are set. What the window plots is compared with an independent call of
:func:`ddwmmr.simulate` with the same settings.
"""

import inspect
import math
from typing import ClassVar

import numpy as np
import pytest
from matplotlib.backend_bases import MouseEvent
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import ddwmmr.gui.settings as gui_settings
import ddwmmr.sim
from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.gui import App, Settings
from ddwmmr.gui.layout import FIGSIZE, SPEEDS
from ddwmmr.gui.view import ERROR_FLOOR
from ddwmmr.reports.plots import robot_outline

#: Short runs keep the suite fast.
DURATION = 1.0


def new_app(settings=None, interactive=False, dpi=40):
    figure = Figure(figsize=FIGSIZE, dpi=dpi)
    FigureCanvasAgg(figure)
    return App(figure, settings or Settings(duration=DURATION), interactive=interactive)


def click(ax):
    """Press and release the left mouse button at the centre of ``ax``."""
    canvas = ax.figure.canvas
    x, y = ax.transAxes.transform((0.5, 0.5))
    for name in ("button_press_event", "button_release_event"):
        canvas.callbacks.process(name, MouseEvent(name, canvas, x, y, button=1))


def click_radio(buttons, label, taken=True):
    """Click the radio button labelled ``label`` (``taken``: the app keeps the choice)."""
    ax = buttons.ax
    canvas = ax.figure.canvas
    (text,) = [t for t in buttons.labels if t.get_text() == label]
    x0, y0, x1, y1 = text.get_window_extent().extents
    x, y = (x0 + x1) / 2, (y0 + y1) / 2
    for name in ("button_press_event", "button_release_event"):
        canvas.callbacks.process(name, MouseEvent(name, canvas, x, y, button=1))
    assert (buttons.value_selected == label) == taken


def press_run(app):
    click(app.transport["run"].ax)
    app.wait()
    assert app.results is not None, app.message


def lines(app, key, run=0):
    return app.view.runs[run].lines[key]


def test_run_plots_what_simulate_returns():
    app = new_app(Settings(methods=("ats", None)))
    app.geometry_fields["T"].submit("20")
    app.duration_field.submit("1.5")
    app.payload_slider.set_val(2.0)
    app.time_slider.set_val(0.0)
    press_run(app)
    app.time_slider.set_val(1.0)  # scrub to the end
    robot = Robot().with_payload(2.0)
    expected = simulate(robot, load_trajectory("ellipse", T=20.0), "ats", duration=1.5)
    ts = expected.timeseries
    assert app.view.index == len(ts["t"]) - 1 == 150  # T/N = 0.01 s
    series = {
        "position": [np.maximum(ts["position_error_m"], ERROR_FLOOR)],
        "orientation": [ts["orientation_error_rad"]],
        "wheels": [ts["wheel_left_rad_s"], ts["wheel_right_rad_s"]],
        "stability": [ts["stability"]],
        "manipulability": [ts["manipulability"]],
    }
    for key, columns in series.items():
        for line, column in zip(lines(app, key), columns):
            np.testing.assert_array_equal(line.get_xdata(), ts["t"])
            np.testing.assert_array_equal(line.get_ydata(), column)
    run = app.view.runs[0]
    np.testing.assert_array_equal(run.ee_trail.get_xdata(), ts["xE"])
    np.testing.assert_array_equal(run.base_trail.get_ydata(), ts["y"])
    q = expected.configurations()[-1]
    np.testing.assert_allclose(run.footprint.get_xy(), robot_outline(robot, q)["footprint"])
    np.testing.assert_allclose(np.c_[run.arm.get_data()], robot_outline(robot, q)["arm"])
    assert (
        app.results[0].summary["rms_position_error_m"] == expected.summary["rms_position_error_m"]
    )
    assert "t = 1.50 s" in app.view.path_ax.get_title()


def test_robot_drawing_matches_the_robot_geometry():
    app = new_app(Settings(methods=("clrrmc-ts", None), duration=DURATION))
    press_run(app)
    app.show_time(0.6)
    robot = Robot()
    ts = app.results[0].timeseries
    k = app.view.index
    x, y, phi = ts["x"][k], ts["y"][k], ts["phi"][k]
    heading = np.array([math.cos(phi), math.sin(phi)])
    left = np.array([-math.sin(phi), math.cos(phi)])
    run = app.view.runs[0]
    corners = run.footprint.get_xy()[:4]
    np.testing.assert_allclose(corners.mean(axis=0), [x, y], atol=1e-12)
    sides = sorted(np.linalg.norm(np.diff(np.r_[corners, corners[:1]], axis=0), axis=1))
    np.testing.assert_allclose(sides, [0.35, 0.35, 0.45, 0.45], atol=1e-12)
    for wheel, side in zip(run.wheels, (1.0, -1.0)):
        outline = wheel.get_xy()[:4]
        centre = [x, y] + side * robot.track_width / 2 * left
        np.testing.assert_allclose(outline.mean(axis=0), centre, atol=1e-12)
        along = np.abs((outline - outline.mean(axis=0)) @ heading)
        np.testing.assert_allclose(along, robot.wheel_radius, atol=1e-12)
    elbow, tip = run.arm.get_xydata()[1:]
    assert np.hypot(*(elbow - [x, y])) == pytest.approx(robot.L1)
    assert np.hypot(*(tip - elbow)) == pytest.approx(robot.L2)
    np.testing.assert_allclose(run.payload.get_xydata()[0], [ts["xE"][k], ts["yE"][k]])


def test_transport_step_pause_reset_speed():
    app = new_app(Settings(methods=("pi", None), duration=DURATION))
    press_run(app)
    assert app.playing and app.view.index == 0
    app.speed_slider.set_val(SPEEDS.index(2.0))
    assert app.speed == 2.0
    app.advance(0.1)  # 0.1 s of wall-clock time at 2x real time
    assert app.view.time == pytest.approx(0.2)
    click(app.transport["pause"].ax)
    assert not app.playing
    app.advance(0.1)
    assert app.view.time == pytest.approx(0.2)
    index = app.view.index
    click(app.transport["step"].ax)
    assert app.view.index == index + 1
    app.time_slider.set_val(0.5)
    assert app.view.time == pytest.approx(0.5 * app.view.duration)
    click(app.transport["reset"].ax)
    assert app.view.index == 0 and not app.playing
    click(app.transport["run"].ax)  # plays the same run again, no new simulation
    assert app.worker is None and app.playing
    app.advance(100.0)
    assert app.view.index == app.view.last_index and not app.playing
    click(app.transport["step"].ax)  # at the end: said, not silently nothing
    assert app.view.index == app.view.last_index
    assert app.message == f"step: the run ends here (t = {DURATION:.2f} s); Reset goes to 0"


def test_side_by_side_overlays_two_methods_with_their_own_options():
    app = new_app(Settings(methods=("clrrmc-ts", None), duration=DURATION))
    click_radio(app.method_radios[1], "clrrmc-ts")
    assert app.options_title.get_text() == "Options of B: clrrmc-ts"
    group = app._groups[(1, "clrrmc-ts")]
    tau_field = dict(group.page(0))[next(s for s in group.specs if s.name == "tau")]
    tau_field.submit("0.2")
    assert app.settings.options == ({}, {"tau": 0.2})
    press_run(app)
    app.time_slider.set_val(1.0)
    trajectory = load_trajectory("ellipse")
    a = simulate(Robot(), trajectory, "clrrmc-ts", duration=DURATION)
    b = simulate(Robot(), trajectory, "clrrmc-ts", duration=DURATION, tau=0.2)
    position_ax = app.view.plot_axes["position"]
    for number, expected in enumerate((a, b)):
        (line,) = lines(app, "position", number)
        assert line.axes is position_ax  # both errors on one plot
        error = np.maximum(expected.timeseries["position_error_m"], ERROR_FLOOR)
        np.testing.assert_array_equal(line.get_ydata(), error)
    # The faster loop (tau 0.2 s) ends with the smaller error.
    assert b.timeseries["position_error_m"][-1] < a.timeseries["position_error_m"][-1]
    assert app.labels() == ["A-clrrmc-ts", "B-clrrmc-ts"]
    assert "A-clrrmc-ts" in app.summary_text.get_text()
    assert "B-clrrmc-ts" in app.summary_text.get_text()
    click_radio(app.method_radios[1], "off")
    assert app.settings.methods == ("clrrmc-ts", None) and app.results is None


@pytest.mark.parametrize("method", ["qp", "mpc"])
def test_the_dt_option_shows_the_note_the_command_lines_give(method):
    """The qp's and mpc's option dt reads as the run's step; the command lines' --help
    says what it is (option_specs.NOTES), the window's option fields said nothing."""
    from ddwmmr.controllers.option_specs import NOTES

    app = new_app(Settings(methods=(method, None), duration=DURATION))
    group = app._groups[(0, method)]
    page = [s.name for s in group.specs].index("dt") // len(group.page(0)) + 1
    assert app.message == "" and "dt" not in app.options_note.get_text()
    app.say("tau must be > 0", error=True)  # an error is not overwritten by the note
    app._apply_options_page(page)
    assert app.message == "tau must be > 0"
    app.say("")
    app._apply_options_page(1)
    app._apply_options_page(page)
    assert app.message == f"dt ({method}): {NOTES['dt']}" and not app.message_is_error
    assert app.options_note.get_text().endswith("; dt: see the note below")
    assert not app.message_text.get_text().endswith("...")  # the whole note fits its box
    assert " ".join(app.message_text.get_text().split()) == app.message


def test_method_list_and_option_widgets_follow_the_registry(registered):
    from ddwmmr.gui.options import method_options
    from ddwmmr.registry import CONTROLLERS

    class Horizon:
        """Test method: holds still; remembers its horizon."""

        made: ClassVar[list] = []

        def __init__(self, robot, horizon: int = 10, smooth: bool = True):
            self.horizon, self.smooth = horizon, smooth
            Horizon.made.append(self)
            from ddwmmr.controllers import StepInfo

            self.last = StepInfo()

        def reset(self, trajectory, q0):
            pass

        def command(self, t, q, pose_d, velocity_d):
            return np.zeros(4)

    registered(CONTROLLERS, "hold-test", Horizon, description="test")
    method_options.cache_clear()
    try:
        app = new_app(Settings(duration=0.2))
        click_radio(app.method_radios[0], "hold-test")
        shown = dict(app._groups[(0, "hold-test")].page(0))
        horizon, smooth = (shown[s] for s in method_options("hold-test"))
        horizon.submit("2.5")
        assert "horizon must be an integer" in app.message and horizon.text == "10"
        horizon.submit("25")
        click(smooth.ax)
        assert smooth.button.label.get_text() == "smooth: off"
        press_run(app)
        assert (Horizon.made[-1].horizon, Horizon.made[-1].smooth) == (25, False)
    finally:
        method_options.cache_clear()


def test_bad_fields_show_a_message_and_keep_the_previous_value(tmp_path):
    app = new_app(Settings(methods=("clrrmc-ts", None), duration=DURATION))
    period = app.geometry_fields["T"]
    period.submit("20")
    period.submit("-5")
    assert (
        "T must be in [1e-06, 1e+09] s (got -5)" in app.message
        and "error" in app.message_text.get_text()
    )
    assert period.text == "20" and app.settings.geometry["T"] == 20.0
    app.geometry_fields["a"].submit("wide")
    message = "a must be a finite number in [1e-06, 1000] m (got 'wide')"  # names the range
    assert message in app.message and app.geometry_fields["a"].text == "2"
    app.geometry_fields["N"].submit("2.5")
    assert "N must be an integer in [2, 1000000] (got 2.5)" in app.message
    not_a_trajectory = tmp_path / "notes.txt"
    not_a_trajectory.write_text("shopping list\n")
    app.file_field.submit(str(not_a_trajectory))
    assert app.message.startswith("traj:") and app.settings.trajectory == "ellipse"
    assert app.file_field.text == ""
    no_shape = tmp_path / "shape.toml"
    no_shape.write_text("[trajectory]\na = 1.0\n")
    app.file_field.submit(str(no_shape))
    assert "needs shape" in app.message and app.traj_radio.value_selected == "ellipse"
    click_radio(app.traj_radio, "file", taken=False)  # no path typed yet
    assert "type a .toml or .csv path" in app.message
    assert app.traj_radio.value_selected == "ellipse"
    group = app._groups[(0, "clrrmc-ts")]
    tau = dict(group.page(0))[group.specs[0]]
    tau.submit("-1")
    assert "tau must be > 0" in app.message and tau.text == "0.5"
    tau.submit("fast")  # the method's range, as for nan (an audit's: "must be a number")
    assert "tau must be > 0 s (at least 0.0001 s), or inf to disable a channel (got 'fast')" in (
        app.message
    )
    assert tau.text == "0.5" and app.settings.options[0] == {}
    app.dt_field.submit("0")
    assert "dt must be > 0" in app.message and app.settings.dt is None
    app.offset_field.submit("0.1")
    assert "offset must be two numbers" in app.message
    assert app.settings == Settings(
        methods=("clrrmc-ts", None), duration=DURATION, geometry={"T": 20.0}
    )


def test_a_good_file_is_loaded_and_its_geometry_shown(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text('[trajectory]\nshape = "rectangle"\na = 1.5\nb = 1.2\nT = 30\nN = 600\n')
    app = new_app()
    app.file_field.submit(str(path))
    assert app.settings.trajectory == str(path) and app.traj_radio.value_selected == "file"
    assert app.geometry_fields["a"].text == "1.5" and app.geometry_fields["N"].text == "600"
    click_radio(app.traj_radio, "figure8")
    assert app.settings.trajectory == "figure8" and app.settings.geometry == {}
    app.geometry_fields["beta"].submit("0.5")
    assert app.settings.geometry == {"beta": 0.5}


def test_qp_obstacles_field_and_bad_path(tmp_path):
    app = new_app(Settings(methods=("qp", None), duration=0.4, payload=3.0))
    group = app._groups[(0, "qp")]
    specs = {s.name: s for s in group.specs}
    obstacles = dict(group.page(0))[specs["obstacles"]]
    obstacles.submit(str(tmp_path / "missing.toml"))
    assert "obstacles: cannot read" in app.message and obstacles.text == ""
    post = tmp_path / "post.toml"
    post.write_text("[[obstacle]]\nx = 1.0\ny = 1.0\nradius = 0.25\n")
    obstacles.submit(str(post))
    assert app.settings.options[0] == {"obstacles": str(post)}
    press_run(app)
    circles = [p for p in app.view.path_ax.patches if hasattr(p, "get_radius")]
    assert [(c.center, c.get_radius()) for c in circles] == [((1.0, 1.0), 0.25)]
    assert app.results[0].summary["min_obstacle_clearance_m"] is not None


def test_failed_runs_show_a_message(monkeypatch):
    app = new_app(Settings(methods=("ats", None), duration=DURATION))
    app.dt_field.submit("5")
    press = app.transport["run"].ax
    click(press)
    app.wait()
    assert app.results is None and app.message.startswith("dt must be <= duration")
    app.dt_field.submit("")

    def broken(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(gui_settings, "simulate", broken)
    click(press)
    app.wait()
    assert app.message == "run failed: RuntimeError: boom" and app.results is None


def test_a_blank_dt_longer_than_the_run_is_named_as_t_over_n():
    """dt left blank is T/N = 1e9 s / 2000: Run names where that 500000 s came from (as
    the command line does), not "dt must be <= duration (4 s) (got 500000)"."""
    app = new_app(Settings(methods=("ats", None)))
    app.geometry_fields["T"].submit("1e9")
    app.duration_field.submit("4")
    assert app.settings.dt is None and app.message == ""
    click(app.transport["run"].ax)
    app.wait()
    assert app.results is None
    assert app.message == (
        "duration must be >= one step T/N = 1e+09 s / 2000 = 500000 s (got 4); "
        "raise N or duration, lower T, or set dt"
    )


def test_plant_choice_from_the_engine_list(monkeypatch):
    monkeypatch.setattr(
        ddwmmr.sim, "available_plants", lambda: ["kinematic", "thesis"], raising=False
    )
    app = new_app()
    assert [t.get_text() for t in app.plant_radio.labels] == ["kinematic", "thesis"]
    takes_plant = "plant" in inspect.signature(ddwmmr.sim.simulate).parameters
    click_radio(app.plant_radio, "thesis", taken=takes_plant)
    if takes_plant:
        assert app.settings.plant == "thesis"
    else:
        assert "plant must be kinematic" in app.message
        assert app.plant_radio.value_selected == "kinematic"


def test_settings_change_drops_the_run_and_previews():
    app = new_app(Settings(methods=("ats", None), duration=DURATION))
    press_run(app)
    click_radio(app.integrator_radio, "euler")
    assert app.results is None and app.settings.integrator == "euler"
    assert app.message == "settings changed: press Run"
    assert app.view.path_ax.get_title() == "desired path (press Run)"
    press_run(app)
    assert app.results[0].summary["integrator"] == "euler"


def test_blitted_frames_match_a_full_render():
    """On a canvas that blits (desktop), playback redraws only the moving artists; the
    picture must be the one a full render gives. Only antialiased edges where a moving
    line crosses a fixed one of the same z-order may differ (drawing order)."""
    settings = Settings(methods=("clrrmc-ts", "ats"), duration=DURATION)
    figure = Figure(figsize=FIGSIZE, dpi=30)
    # Agg renders at every draw_idle; a desktop canvas defers them (drawn once below).
    FigureCanvasAgg(figure).draw_idle = lambda *args, **kwargs: None
    fast, full = App(figure, settings, interactive=True), new_app(settings, dpi=30)
    for app in (fast, full):
        press_run(app)
    fast.figure.canvas.draw()  # saves the background without the moving artists
    start = np.asarray(fast.figure.canvas.buffer_rgba()).astype(int)
    fast.show_time(0.7)  # a blitted frame
    full.show_time(0.7)
    full.figure.canvas.draw()
    blitted = np.asarray(fast.figure.canvas.buffer_rgba()).astype(int)
    rendered = np.asarray(full.figure.canvas.buffer_rgba()).astype(int)
    height = blitted.shape[0]
    for ax in [fast.view.path_ax, *fast.view.plot_axes.values()]:
        x0, y0, x1, y1 = (round(v) for v in ax.bbox.extents)
        region = (slice(height - y1, height - y0), slice(x0, x1))
        difference = np.abs(blitted[region] - rendered[region]).max(axis=2)
        assert difference.max() <= 32 and np.mean(difference > 0) < 0.01, ax.get_ylabel()
        moved = np.abs(blitted[region] - start[region]).max(axis=2)
        assert np.mean(moved > 32) > 0.001, ax.get_ylabel()  # the frame did change
    assert fast.view.runs[0].footprint.get_animated()


def test_docs_page_snippet_runs(capsys):
    """The python block of docs/gui.md runs and prints the same number twice."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "gui.md").read_text()
    (block,) = [part.split("```")[0] for part in text.split("```python")[1:]]
    exec(compile(block, "docs/gui.md", "exec"), {})
    printed = capsys.readouterr().out.split()
    assert len(printed) == 2 and float(printed[0]) == pytest.approx(float(printed[1]))


def test_a_payload_above_the_slider_range_widens_the_slider_to_it():
    """--payload 5.5 stands (the start's limit is 9.338 kg) but the slider spanned 0-5 kg:
    it showed 5.50 kg past its end. It now ends at the payload given."""
    heavy = new_app(Settings(duration=DURATION, payload=5.5))
    assert heavy.payload_slider.valmax == 5.5 and heavy.payload_slider.val == 5.5
    assert new_app().payload_slider.valmax == 5.0  # the default range
