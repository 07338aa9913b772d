"""What a user of the desktop window sees beyond the panel's own widgets: the window takes
the screen's pixels at a legible resolution, its texts stand apart, and a long message
stays inside the message box. Off-screen (Agg canvases) at the size the window takes on a
1366 x 768 screen (:func:`window_size`: 1032 x 645 px, 12.74 x 7.96 in at 81 dpi)."""

from __future__ import annotations

import io
import re

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ddwmmr.gui import App, Settings
from ddwmmr.gui.layout import DPI, FIGSIZE, MAX_TEXT_SCALE, MIN_DPI, text_scale, window_size
from ddwmmr.gui.options import method_options
from ddwmmr.gui.widgets import FONT, CycleButton
from figure_checks import drawn_texts, text_collisions

LAPTOP = (1366, 768)
#: A trajectory file's refusal as the window shows it (153 characters).
LONG_MESSAGE = (
    "traj: /tmp/bad.csv: trajectory samples: need at least 3 rows (t, x, y): times must be "
    "a 1-D sequence of at least 3 sample times (got shape (2,))"
)


def window_app(
    screen: tuple[int, int] = LAPTOP, canvas_class=FigureCanvasAgg, settings=None
) -> App:
    """The window as :func:`desktop_figure` sizes it on a ``screen`` (width, height px)."""
    figsize, dpi = window_size(*screen)
    figure = Figure(figsize=figsize, dpi=dpi)
    canvas_class(figure)
    return App(figure, settings or Settings(duration=1.0))


def laptop_app(canvas_class=FigureCanvasAgg, settings: Settings | None = None) -> App:
    return window_app(LAPTOP, canvas_class, settings)


def test_the_window_takes_the_screens_pixels_at_a_legible_resolution():
    assert window_size(1920, 1080) == (FIGSIZE, pytest.approx(90.72))  # 1451 x 907 px
    assert window_size(2560, 1440) == (FIGSIZE, DPI)
    laptop, dpi = window_size(*LAPTOP)
    assert (round(laptop[0] * dpi), round(laptop[1] * dpi)) == (1032, 645)  # 16 x 10 in at 64.5
    assert dpi == MIN_DPI  # ... laid out on 12.7 x 8 in instead
    assert text_scale(Figure(figsize=laptop)) == pytest.approx(MIN_DPI / 64.5, rel=1e-3)
    assert text_scale(Figure(figsize=FIGSIZE)) == text_scale(Figure(figsize=(20, 12.5))) == 1.0
    # Tk multiplies the dpi by its pixel ratio (tk scaling against 96 px per inch).
    assert window_size(*LAPTOP, ratio=1.25) == (laptop, MIN_DPI / 1.25)
    (width, _), dpi = window_size(800, 600)  # the text grows by MAX_TEXT_SCALE at most
    assert FIGSIZE[0] / width == pytest.approx(MAX_TEXT_SCALE) and dpi < MIN_DPI


def test_a_narrow_figure_of_the_callers_gets_the_largest_scales_layout():
    """App takes any figure: one narrower than window_size ever makes (5 in) gets the
    layout of MAX_TEXT_SCALE, whose gaps stay on the figure. An uncapped scale (3.2) made
    the duration field's width negative (matplotlib's ValueError)."""
    assert text_scale(Figure(figsize=(5.0, 3.125))) == MAX_TEXT_SCALE
    figure = Figure(figsize=(5.0, 3.125), dpi=100)
    FigureCanvasAgg(figure)
    app = App(figure, Settings(duration=1.0))
    assert app.text_scale == MAX_TEXT_SCALE
    for ax in figure.axes:
        x0, y0, width, height = ax.get_position().bounds
        assert width > 0 and height > 0 and x0 >= 0 and y0 >= 0, ax


@pytest.mark.parametrize("screen", [LAPTOP, (1920, 1080)], ids=lambda s: "x".join(map(str, s)))
def test_the_texts_are_legible_and_stand_apart(screen):
    """After a run, with a long error in the smallest font, and on the option pages with
    the longest names: every text at least (FONT - 2) pt at MIN_DPI (6.75 px), the panel
    font at least 9 px, no text on another, on a widget or plot not its own, or off the
    window; every option label whole."""
    app = window_app(screen, settings=Settings(methods=("clrrmc-ts", "qp"), duration=2.0))
    app.run()
    app.wait()
    app.show_index(app.view.last_index)
    app.say(LONG_MESSAGE, error=True)
    dpi = app.figure.dpi
    pixels = {
        text.get_text()[:30]: text.get_fontsize() * dpi / 72 for text in drawn_texts(app.figure)
    }
    smallest = min(pixels, key=pixels.__getitem__)
    assert pixels[smallest] >= (FONT - 2) * MIN_DPI / 72, (smallest, pixels[smallest])
    assert app.dt_field.box.label.get_fontsize() * dpi / 72 >= FONT * MIN_DPI / 72
    assert text_collisions(app.figure) == []
    for method, pages in (("qp", 2), ("mpc", 3)):
        app.apply(app.settings.replace(methods=(method, None)))
        for page in range(pages):
            assert text_collisions(app.figure) == [], (method, page + 1)
            app.options_page_button.click()
        group = app._groups[(0, method)]
        for number, widget in group.widgets.items():
            label = widget.button.label if isinstance(widget, CycleButton) else widget.box.label
            spaceless = re.sub(r"\s", "", label.get_text())
            assert spaceless.startswith(re.sub(r"\s", "", method_options(method)[number].label))


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
        "run finished (50 steps per method): playing; drag\ntime to scrub"
    )


def canvas_resized(app: App, width: float, height: float) -> bool:
    """What the Tk canvas does to the figure when the user resizes the window to a
    ``width`` x ``height`` px canvas (new inches at the same dpi), then what the app does
    once the resizing pauses (:meth:`App.fit_canvas`)."""
    figure = app.figure
    figure.set_size_inches(width / figure.dpi, height / figure.dpi, forward=False)
    return app.fit_canvas()


def window_png(app: App) -> bytes:
    buffer = io.BytesIO()
    app.figure.savefig(buffer, format="png")
    return buffer.getvalue()


def test_a_resized_window_is_laid_out_for_its_new_size():
    """The 1920 x 1080 screen's window (1451 x 907 px at 90.72 px per inch) resized to a
    1366 x 768 laptop's maximised canvas takes that screen's 81 px per inch and its larger
    text scale, to a larger canvas a larger resolution; its texts stand apart and the
    message stays in its box at every size; resized back, it is drawn as it opened, byte
    for byte; a pixel more keeps the layout. Before, the dpi and the text scale chosen at
    the start stayed: the text did not grow with the window nor shrink with it."""
    app = window_app((1920, 1080), settings=Settings(methods=("clrrmc-ts", "qp"), duration=1.0))
    app.run()
    app.wait()
    app.show_index(app.view.last_index)
    app.say(LONG_MESSAGE, error=True)
    opened, (width, height) = window_png(app), app.figure.bbox.size
    panel_px = {}
    for canvas in [(1366, 718), (1920, 1030), (800, 550), (1366, 718)]:
        assert canvas_resized(app, *canvas), canvas
        assert app.figure.bbox.size == pytest.approx(canvas)
        panel_px[canvas] = app.dt_field.box.label.get_fontsize() * app.figure.dpi / 72
        assert text_collisions(app.figure) == [], canvas
        box = app.message_text.axes.bbox
        assert message_extent(app).y0 >= box.y0 and message_extent(app).x1 <= box.x1, canvas
    assert app.text_scale == pytest.approx(MIN_DPI / 71.8)  # 718 px / 10 in: 71.8 px per in
    assert panel_px[(1366, 718)] == pytest.approx(FONT * MIN_DPI / 72)  # 9 px
    assert panel_px[(1920, 1030)] == pytest.approx(FONT * 103 / 72)  # 11.4 px
    assert canvas_resized(app, width, height)
    assert (app.figure.dpi, app.text_scale) == (pytest.approx(90.72), 1.0)
    assert window_png(app) == opened
    assert not canvas_resized(app, width + 1, height)
    assert not canvas_resized(app, 300, 20)  # too small to follow: the layout stays
    assert (app.figure.dpi, app.text_scale) == (pytest.approx(90.72), 1.0)
