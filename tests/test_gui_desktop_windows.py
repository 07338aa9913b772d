"""What a user of the desktop window sees beyond the panel's own widgets: a long message
stays inside the message box. Off-screen (Agg canvases) at the size the window takes on a
1366 x 768 screen (16 x 10 in at 64.5 dpi, the dpi :func:`desktop_figure` picks there)."""

from __future__ import annotations

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ddwmmr.gui import App, Settings
from ddwmmr.gui.layout import FIGSIZE

LAPTOP_DPI = 1032 / FIGSIZE[0]  # the window is 1032 px wide on a 1366 x 768 screen
#: A trajectory file's refusal as the window shows it (153 characters).
LONG_MESSAGE = (
    "traj: /tmp/bad.csv: trajectory samples: need at least 3 rows (t, x, y): times must be "
    "a 1-D sequence of at least 3 sample times (got shape (2,))"
)


def laptop_app(canvas_class=FigureCanvasAgg, settings: Settings | None = None) -> App:
    figure = Figure(figsize=FIGSIZE, dpi=LAPTOP_DPI)
    canvas_class(figure)
    return App(figure, settings or Settings(duration=1.0))


def message_extent(app: App):
    return app.message_text.get_window_extent(app.figure.canvas.get_renderer())


def test_a_long_error_stays_inside_the_message_box_whole() -> None:
    app = laptop_app()
    box = app.message_text.axes.bbox
    app.say(LONG_MESSAGE, error=True)
    extent = message_extent(app)
    assert extent.y0 >= box.y0 and extent.x1 <= box.x1  # in the panel font it took 3 lines
    shown = app.message_text.get_text()
    assert shown.replace("\n", " ") == "error: " + LONG_MESSAGE  # every word, none cut
    assert app.message_text.get_fontsize() < 8


def test_a_message_too_long_for_the_box_is_cut_at_a_line_end() -> None:
    app = laptop_app()
    box = app.message_text.axes.bbox
    app.say(" ".join([LONG_MESSAGE] * 4), error=True)
    extent = message_extent(app)
    assert extent.y0 >= box.y0
    shown = app.message_text.get_text()
    assert shown.startswith("error: traj: /tmp/bad.csv:") and shown.endswith(" ...")
    assert app.message == " ".join([LONG_MESSAGE] * 4)  # the app keeps the whole text


def test_a_short_message_keeps_the_panel_font_and_its_lines() -> None:
    app = laptop_app()
    app.say("run finished (50 steps per method): playing; drag time to scrub")
    assert app.message_text.get_fontsize() == 8
    assert app.message_text.get_text() == (
        "run finished (50 steps per method): playing; drag time to\nscrub"
    )
