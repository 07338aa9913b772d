"""The simulator's settings refuse a methods/options value that is not one entry per slot,
and its export folder names the real reason a folder cannot be made (and clears it when a
good one follows). Off-screen (Agg canvas): no display is needed."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ddwmmr.errors import ParameterError
from ddwmmr.gui import App, Settings
from ddwmmr.gui.paths import check_export_root

#: A path below /proc, where Linux takes no new files or folders (not even as root).
PROC_CHILD = "/proc/ddwmmr-h77-nope"
needs_proc = pytest.mark.skipif(
    not os.path.isdir("/proc/self"), reason="needs Linux's /proc, which takes no new folders"
)


def offscreen_app(settings: Settings | None = None) -> App:
    figure = Figure(figsize=(16, 10), dpi=30)
    FigureCanvasAgg(figure)
    return App(figure, settings)


@pytest.mark.parametrize(
    ("methods", "got"),
    [
        (("clrrmc-ts",), "got 1: ('clrrmc-ts',)"),
        (("ats", "ap", "pi"), "got 3: ('ats', 'ap', 'pi')"),
        ("clrrmc-ts", "got 'clrrmc-ts'"),
        (None, "got None"),
    ],
)
def test_methods_must_be_one_entry_per_slot(methods, got) -> None:
    with pytest.raises(ParameterError) as refused:
        Settings(methods=methods)
    message = str(refused.value)
    assert message.startswith("methods must be a pair (A, B)") and "\n" not in message
    assert "('clrrmc-ts', None)" in message and got in message


def test_the_app_refuses_a_one_entry_methods_before_its_widgets() -> None:
    """What used to be an IndexError in the widget sync is the settings' one line."""
    with pytest.raises(ParameterError, match=r"^methods must be a pair"):
        offscreen_app(Settings(methods=("clrrmc-ts",), duration=1.0))


def test_options_must_be_one_mapping_per_slot() -> None:
    with pytest.raises(ParameterError, match=r"^options must be a pair .*got 1: \(\{\},\)\)$"):
        Settings(options=({},))


def test_a_list_of_two_methods_is_kept_as_the_pair() -> None:
    settings = Settings(methods=["ats", None])
    assert settings.methods == ("ats", None) and settings.active_slots == [0]
    assert settings.with_method(1, "pi").methods == ("ats", "pi")


@needs_proc
def test_a_folder_that_cannot_be_made_is_named_with_the_reason() -> None:
    with pytest.raises(ParameterError) as refused:
        check_export_root(PROC_CHILD)
    assert str(refused.value) == (
        f"export: cannot make the folder {PROC_CHILD}: /proc takes no new files or folders; "
        "choose a folder elsewhere"
    )


@needs_proc
def test_a_good_folder_after_a_refused_one_clears_the_error(tmp_path: Path) -> None:
    app = offscreen_app(Settings(duration=1.0))
    app.export_field.submit(PROC_CHILD)
    assert app.message.startswith(f"export: cannot make the folder {PROC_CHILD}")
    assert app.message_text.get_text().startswith("error: ")
    good = str(tmp_path / "exports")
    app.export_field.submit(good)
    assert app.export_field.text == good
    assert app.message == f"export folder: {good}"
    shown = app.message_text.get_text()  # the message wrapped at 62 characters
    assert shown.startswith("export folder:") and "error" not in shown
    assert app.message_text.get_color() != "tab:red"
    assert not (tmp_path / "exports").exists()  # checked only: made by the first export
