"""A field of the simulator window takes back its own red error once it accepts a valid
value, whether or not a run was there to be dropped. Off-screen (Agg canvas)."""

from __future__ import annotations

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ddwmmr.gui import App, Settings


def offscreen_app() -> App:
    figure = Figure(figsize=(16, 10), dpi=30)
    FigureCanvasAgg(figure)
    return App(figure, Settings(duration=1.0))


def shows_error(app: App, start: str) -> bool:
    return (
        app.message_is_error
        and app.message.startswith(start)
        and app.message_text.get_text().startswith("error: ")
        and app.message_text.get_color() == "tab:red"
    )


@pytest.mark.parametrize(
    ("field", "bad", "error", "good", "setting", "value"),
    [
        ("dt_field", "-1", "dt must be > 0 s", "0.02", "dt", 0.02),
        ("duration_field", "abc", "duration must be", "2.5", "duration", 2.5),
        ("offset_field", "1", "offset must be two numbers", "0.01 -0.02", "offset", (0.01, -0.02)),
    ],
)
def test_a_valid_value_clears_the_fields_own_error(field, bad, error, good, setting, value):
    app = offscreen_app()
    widget = getattr(app, field)
    widget.submit(bad)
    assert shows_error(app, error), app.message
    widget.submit(good)
    assert getattr(app.settings, setting) == pytest.approx(value, abs=1e-12)
    assert app.message == "" and not app.message_is_error
    assert app.message_text.get_text() == ""


def test_a_geometry_field_clears_its_error_too() -> None:
    app = offscreen_app()
    widget = app.geometry_fields["a"]  # the default ellipse has a semi-axis a
    widget.submit("-5")
    assert shows_error(app, "a must be in [1e-06, 1000] m"), app.message
    widget.submit("0.3")
    assert app.settings.geometry["a"] == pytest.approx(0.3, abs=1e-12)
    assert app.message == ""


def test_resubmitting_the_valid_value_shown_after_an_error_clears_it() -> None:
    app = offscreen_app()
    app.dt_field.submit("0")
    assert shows_error(app, "dt must be > 0 s")
    app.dt_field.submit(app.dt_field.valid_text)  # the box shows it again; Enter
    assert app.message == ""


def test_another_fields_error_is_left_alone() -> None:
    app = offscreen_app()
    app.dt_field.submit("0")
    app.offset_field.submit("x")
    assert shows_error(app, "offset must be two numbers")
    app.dt_field.submit("0.02")  # dt's own error is no longer shown: nothing to take back
    assert shows_error(app, "offset must be two numbers")
    app.offset_field.submit("0.01 0")
    assert app.message == ""
