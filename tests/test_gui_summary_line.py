"""The simulator window's summary line in the units and labels of the other tools: errors
in mm, the smallest manipulability to three significant digits, and the limits a run held
(which ``saturated steps``, the plant's clipping, does not count); and the longest lines of
two runs fit between the view and the transport buttons."""

import re
from types import SimpleNamespace

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.gui import App, Settings
from ddwmmr.gui.app import _summary_line
from ddwmmr.gui.layout import FIGSIZE, MIN_DPI, SUMMARY_RIGHT, window_size
from ddwmmr.gui.widgets import FONT, wrap_to_width


def new_app(settings: Settings, dpi: int = 100) -> App:
    figure = Figure(figsize=FIGSIZE, dpi=dpi)
    FigureCanvasAgg(figure)
    return App(figure, settings, interactive=False)


def number_after(text: str, label: str, unit: str = "") -> float:
    (found,) = re.findall(rf"{re.escape(label)} ([-+0-9.e]+){re.escape(unit)}", text)
    return float(found)


def test_a_qp_run_on_the_thesis_plant_reads_as_track_prints_it():
    """qp on the rectangle, thesis plant, one period: the line gives the errors in mm and
    eta as ``track`` does (to 3 digits) and names the limits held, which saturated steps 0
    alone hid."""
    app = new_app(Settings(methods=("qp", None), trajectory="rectangle", plant="thesis"))
    app.run()
    app.wait()
    assert app.results is not None, app.message
    summary = app.results[0].summary
    expected = simulate(Robot(), load_trajectory("rectangle"), "qp", plant="thesis").summary
    assert summary["steps"] == expected["steps"] == 2000
    text = app.summary_text.get_text().replace("\n    ", " ")
    rms_mm = number_after(text, "RMS pos", " mm,")
    assert rms_mm == pytest.approx(1000.0 * expected["rms_position_error_m"], rel=5e-3)
    assert rms_mm > 10.0  # in mm, not m (0.0993 m)
    max_mm = number_after(text, "max pos", " mm,")
    assert max_mm == pytest.approx(1000.0 * expected["max_position_error_m"], rel=5e-3)
    eta = number_after(text, "min manip.", ",")
    assert eta == pytest.approx(expected["min_manipulability"], rel=5e-3)
    assert 0.01 < eta < 0.1  # three significant digits, not 0.06
    assert number_after(text, "saturated steps", ",") == expected["saturated_steps"] == 0
    rate = f"a joint at its rate limit on {expected['joint_rate_limit_steps']} of 2000 steps"
    force = f"a wheel at its force limit for {expected['actuator_saturated_time_s']:.3g} of 40 s"
    assert expected["joint_rate_limit_steps"] > 100
    assert f"; limits held: {force}, {rate}" in text


def test_a_vanishing_manipulability_keeps_its_digits():
    """pi on the rectangle reaches eta = 1.22e-16: the line says so, not 0.00."""
    summary = {
        "rms_position_error_m": 2.394, "max_position_error_m": 4.316,
        "rms_orientation_error_rad": 1.92, "max_wheel_speed_rad_s": 8.32,
        "min_stability": 2.01, "min_manipulability": 1.2246e-16, "saturated_steps": 82,
        "fallback_steps": 0, "steps": 2000, "duration": 40.0, "dt": 0.02,
    }  # fmt: skip
    line = _summary_line("pi", SimpleNamespace(summary=summary))
    assert (
        "RMS pos 2394 mm, max pos 4316 mm, RMS orient 1.92 rad, max wheel speed 8.32 rad/s" in line
    )
    assert "min manip. 1.22e-16, saturated steps 82, fallbacks 0" in line
    assert "limits held" not in line


#: Two runs that each lost support and held three limits (summary of each).
LONG_SUMMARY = {
    "rms_position_error_m": 2.394, "max_position_error_m": 4.316,
    "rms_orientation_error_rad": 1.92, "max_wheel_speed_rad_s": 18.32,
    "min_stability": 1.2345, "min_manipulability": 1.2246e-16, "saturated_steps": 1234,
    "fallback_steps": 1999, "steps": 2000, "duration": 40.0, "dt": 0.02,
    "wheel_limit_steps": 1500, "joint_rate_limit_steps": 1800,
    "actuator_saturated_time_s": 33.3, "plant": "mujoco", "tipped": False,
    "tip_time_s": None, "min_physics_stability": 1.21, "support_lost": True,
    "unloaded_time_s": 12.3,
    "verdict_reasons": [
        "singular_most_of_run", "final_error_above_limit", "rms_error_above_limit"
    ],
}  # fmt: skip


def test_two_long_lines_fit_above_the_transport_buttons():
    """Two runs that each lost support and held three limits: four lines each, wrapped
    to the window, end above the Run button."""
    app = new_app(Settings(duration=1.0))
    lines = [_summary_line(label, SimpleNamespace(summary=LONG_SUMMARY)) for label in "AB"]
    wrapped = wrap_to_width("\n".join(lines), app.summary_text, SUMMARY_RIGHT)
    assert wrapped.count("\n") == 7
    app.summary_text.set_text(wrapped)
    renderer = app.figure.canvas.get_renderer()
    bottom = app.summary_text.get_window_extent(renderer).y0
    button_top = app.transport["run"].ax.get_window_extent(renderer).y1
    assert bottom > button_top + 2.0


def test_two_long_lines_fit_above_the_buttons_of_a_laptop_window():
    """The same lines in the window a 1366 x 768 screen gets (its text larger against the
    layout): in a smaller font, still legible, they end above the Run button, inside it."""
    figsize, dpi = window_size(1366, 768)
    figure = Figure(figsize=figsize, dpi=dpi)
    FigureCanvasAgg(figure)
    app = App(figure, Settings(duration=1.0))
    lines = [_summary_line(label, SimpleNamespace(summary=LONG_SUMMARY)) for label in "AB"]
    app._show_summary("\n".join(lines))
    extent = app.summary_text.get_window_extent(figure.canvas.get_renderer())
    assert extent.y0 > app.transport["run"].ax.bbox.y1 and extent.x1 <= figure.bbox.width
    assert app.summary_text.get_fontsize() * dpi / 72 >= (FONT - 2) * MIN_DPI / 72
    assert app.summary_text.get_text().replace("\n    ", " ") == "\n".join(lines)


@pytest.mark.parametrize(
    "figsize, dpi",
    [(FIGSIZE, 100), (FIGSIZE, MIN_DPI), window_size(1366, 768), window_size(1920, 1080)],
)
def test_the_summary_starts_below_the_plots_time_label(figsize, dpi):
    """The first summary line, running under the plots, starts below their ``t (s)``
    label with a pixel to spare, in the snapshot's window and in the desktop's."""
    figure = Figure(figsize=figsize, dpi=dpi)
    FigureCanvasAgg(figure)
    app = App(figure, Settings(duration=1.0), interactive=False)
    app.run()
    app.wait()
    assert app.results is not None, app.message
    lines = [_summary_line(label, SimpleNamespace(summary=LONG_SUMMARY)) for label in "AB"]
    app._show_summary("\n".join(lines))
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    label = app.view.plot_axes["manipulability"].xaxis.label
    assert label.get_text() == "t (s)" and label.get_visible()
    below = label.get_window_extent(renderer)
    summary = app.summary_text.get_window_extent(renderer)
    assert summary.x1 > below.x1  # the first line runs under the label
    assert below.y0 - summary.y1 >= 1.0
