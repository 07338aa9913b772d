"""What the simulator window's fields make of text a user types (off-screen, Agg): numbers
read as the command lines read them, a folder name on one line, and every message whole
on one line, whatever the quoted value holds."""

from __future__ import annotations

import threading

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import ddwmmr.gui.app as app_module
from ddwmmr.errors import ParameterError
from ddwmmr.gui import App, Settings
from ddwmmr.gui.layout import FIGSIZE
from ddwmmr.gui.widgets import describe_error, message_line
from ddwmmr.gui.worker import Worker
from figure_checks import text_collisions


def offscreen_app() -> App:
    figure = Figure(figsize=FIGSIZE, dpi=30)
    FigureCanvasAgg(figure)
    return App(figure, Settings(duration=1.0))


FIELDS = {
    "x0": lambda app: app.geometry_fields["x0"],
    "N": lambda app: app.geometry_fields["N"],
    "T": lambda app: app.geometry_fields["T"],
    "dt": lambda app: app.dt_field,
    "duration": lambda app: app.duration_field,
    "offset": lambda app: app.offset_field,
}


@pytest.mark.parametrize("name", sorted(FIELDS))
@pytest.mark.parametrize("typed", ["1_000", "0_02", "0.0_1", "\uff11", "\uff10.\uff15"])
def test_a_number_field_reads_numbers_as_the_command_lines_do(name: str, typed: str) -> None:
    """``1_000`` and full-width digits are no numbers to ``--dt``, ``--N``... (Python's
    float reads them): the field refuses them naming itself and keeps its value."""
    app = offscreen_app()
    field = FIELDS[name](app)
    before, shown = app.settings, field.text
    text = f"{typed} 0" if name == "offset" else typed
    field.submit(text)
    assert app.message_is_error and app.message.startswith(name), app.message
    assert app.settings == before and field.text == shown


@pytest.mark.parametrize("typed", ["0,3", "0,0", "-0,03 -0,03", "0.1,0.2"])
def test_the_offset_refuses_a_comma_between_digits(typed: str) -> None:
    """The text 0,3 is 0.3 to a reader of decimal commas, (0, 3) to one of lists: the offset
    field takes neither reading and says how to write the two numbers; a comma beside a
    space or a sign stays a separator."""
    app = offscreen_app()
    before, shown = app.settings, app.offset_field.text
    app.offset_field.submit(typed)
    assert app.message_is_error, app.message
    assert app.message.startswith("offset must be two numbers dx dy in m, a point the decimal")
    assert "a comma between digits could be a decimal comma; write e.g. 0 0.3 or 0, 0.3" in (
        app.message
    )
    assert app.settings == before and app.offset_field.text == shown
    for accepted in ("0, 0.3", "0 0.3", "0.01,-0.02", "0.01 , 0.02"):
        app.offset_field.submit(accepted)
        assert not app.message_is_error, (accepted, app.message)
    assert app.settings.offset == (0.01, 0.02)


def test_an_export_folder_name_on_more_than_one_line_is_refused(tmp_path) -> None:
    app = offscreen_app()
    for name in (f"{tmp_path}/runs\ngui", f"{tmp_path}/a\rb", f"{tmp_path}/tab\there"):
        app.export_field.submit(name)
        assert app.message_is_error and app.message.startswith("export:"), app.message
        assert "one line of printable characters" in app.message
        assert "\n" not in app.message and app.export_field.text == "runs/gui"
    assert list(tmp_path.iterdir()) == []
    app.export_field.submit(str(tmp_path / "runs"))  # the next good name is taken
    assert not app.message_is_error and app.export_field.text == str(tmp_path / "runs")


def test_a_files_error_is_shown_whole_when_its_name_holds_a_newline(tmp_path) -> None:
    """The reason comes after the name: cutting the message at the name's newline left
    ``traj: .../new`` alone in the window."""
    path = tmp_path / "new\nline.csv"
    path.write_text("t,x,y\n0,0,0\n1,1,1\n")
    app = offscreen_app()
    app.file_field.submit(str(path))
    assert app.message_is_error and app.message.startswith("traj:")
    assert "new\\nline.csv" in app.message and "at least 3 rows" in app.message
    assert app.settings.trajectory == "ellipse"


def test_a_message_is_one_printable_line() -> None:
    assert message_line("a\nb\tc\x00d\udcff ") == "a\\nb\\tc\\x00d\\udcff"
    assert message_line("plain text, é") == "plain text, é"
    assert describe_error(ParameterError("x: one\ntwo")) == "x: one\\ntwo"
    assert describe_error(OSError("disk full\nmore")) == "OSError: disk full"  # first line


def test_a_failed_runs_message_keeps_what_follows_a_newline() -> None:
    def job(_progress):
        raise ParameterError("plan: /tmp/a\nb.npz is not a plan")

    worker = Worker(job, 1)
    worker.start()
    worker.join()
    assert worker.state == "failed" and worker.error == "plan: /tmp/a\\nb.npz is not a plan"


@pytest.fixture
def held_run(monkeypatch):
    """Runs of the window wait for ``release.set()`` before they simulate, reporting
    progress (a run is still being simulated, whatever the machine's speed)."""
    release = threading.Event()
    real = app_module.simulate_settings

    def held(settings, progress):
        while not release.wait(0.01):  # a cancel ends it at a progress report
            progress(0, 0, 1)
        return real(settings, progress)

    monkeypatch.setattr(app_module, "simulate_settings", held)
    yield release
    release.set()


@pytest.mark.parametrize("change", ["plant", "duration"])
def test_a_setting_changed_while_simulating_says_the_run_stopped(change: str, held_run) -> None:
    """The run is cancelled: "simulating ..." must not stay in the window."""
    app = offscreen_app()
    app.run()
    assert app.worker is not None and not app.worker.finished
    if change == "plant":
        app._on_plant("thesis")
    else:
        app.duration_field.submit("2")
    assert app.message == "settings changed: simulation stopped; press Run"
    assert app.worker is None and app.results is None
    held_run.set()
    app.run()
    app.wait()
    assert app.results is not None, app.message


@pytest.mark.parametrize("typed", ["$$", "$\\frac{$", "a$x^$b"])
def test_dollar_signs_in_a_message_are_drawn_as_typed(typed: str) -> None:
    """A message quotes what was typed; as mathtext, ``$$`` made every later draw of the
    window raise (the field's Enter too), until another message replaced it."""
    app = offscreen_app()
    app.dt_field.submit(typed)
    assert app.message == f"dt must be a number > 0 in s, or blank (got {typed!r})"
    app.figure.canvas.draw()  # raised ValueError (mathtext) before
    assert repr(typed) in app.message_text.get_text()
    app.dt_field.submit("0.02")
    assert app.settings.dt == 0.02


def test_a_trajectory_file_named_with_dollars_runs_and_is_drawn(tmp_path) -> None:
    path = tmp_path / "a$x^$.csv"
    path.write_text("t,x,y\n" + "".join(f"{k / 10},{k / 100},0\n" for k in range(41)))
    app = offscreen_app()
    app.file_field.submit(str(path))
    assert app.settings.trajectory == str(path), app.message
    app.run()
    app.wait()
    assert app.results is not None, app.message
    app.figure.canvas.draw()
    assert "on a$x^$" in app.view.path_ax.get_title()


def test_a_glyph_the_font_lacks_is_shown_as_its_escape(recwarn) -> None:
    app = offscreen_app()
    app.dt_field.submit("\uff11")
    app.figure.canvas.draw()
    assert "(got '\\uff11')" in app.message_text.get_text()
    assert not [w for w in recwarn if "missing from font" in str(w.message)]


def test_an_accepted_folder_the_font_lacks_is_named_once_not_warned(recwarn, tmp_path) -> None:
    """A folder name in a script the font lacks is taken as typed: the message names it
    with its characters escaped, the box keeps (and draws) the name itself, and no draw
    warns on the console, whatever text or size the box is drawn at."""
    app = offscreen_app()
    folder = f"{tmp_path}/runs-\u65e5\u672c"
    app.export_field.submit(folder)
    assert not app.message_is_error and app.export_field.text == folder
    assert app.message_text.get_text().endswith("runs-\\u65e5\\u672c")
    box = app.export_field.box.text_disp
    app.figure.canvas.draw()
    box.set_text(folder + "2")  # as typing it changes
    box.get_window_extent(app.figure.canvas.get_renderer())
    app.figure.canvas.draw()
    app.figure.set_dpi(40)
    app.figure.canvas.draw()
    assert not [w for w in recwarn if "missing from font" in str(w.message)]


def test_a_near_constant_error_plot_keeps_short_tick_labels() -> None:
    """tau = inf disables the correction (a documented value): the orientation error then
    drifts by 1e-13 rad, and its ticks, labelled in their last digits, ran over the top
    view."""
    figure = Figure(figsize=FIGSIZE, dpi=60)
    FigureCanvasAgg(figure)
    app = App(figure, Settings(duration=1.0, options=({"tau": float("inf")}, {})))
    app.run()
    app.wait()
    assert app.results is not None, app.message
    app.show_index(0)
    figure.canvas.draw()
    assert text_collisions(figure) == []
    labels = [t.get_text() for t in app.view.plot_axes["orientation"].get_yticklabels()]
    assert labels and max(len(label) for label in labels) <= 8, labels


@pytest.mark.parametrize(("trajectory", "name"), [("figure8", "x0"), ("sideways_reach", "beta")])
def test_a_geometry_value_placing_samples_out_of_range_is_named(trajectory, name) -> None:
    """The samples' own check named no field ("trajectory samples: points ... (got
    1e+06)"), though the field had taken a value within its stated range."""
    app = offscreen_app()
    app.apply(app.settings.replace(trajectory=trajectory))
    app.geometry_fields[name].submit("1e6")
    assert app.message.startswith(f"{name}: placing the samples of {trajectory} there: ")
    assert "must be <= 1e+06" in app.message and app.settings.geometry == {}
    app.geometry_fields[name].submit("5")
    assert app.settings.geometry == {name: 5.0} and not app.message_is_error


def test_export_and_step_during_a_run_say_it_is_still_simulated(tmp_path, held_run) -> None:
    """ "no finished run yet (press Run)" sent the user to a button that does nothing
    while the run is simulated."""
    app = offscreen_app()
    app.export_field.submit(str(tmp_path / "runs"))
    app.run()
    for action, what in ((app.export_data, "export"), (app.step, "step")):
        action()
        assert app.message == f"{what}: the run is still being simulated; wait for it"
    held_run.set()
    app.wait()
    assert app.export_data() and not app.message_is_error


def test_a_tilde_in_the_export_folder_is_the_home_folder(tmp_path, monkeypatch) -> None:
    """No shell reads the field: "~/runs" made a folder named "~" in the current one."""
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.chdir(tmp_path)
    app = offscreen_app()
    app.export_field.submit("~/runs")
    assert app.export_field.text == str(tmp_path / "home" / "runs"), app.message
    app.run()
    app.wait()
    app.export_data()
    assert not app.message_is_error, app.message
    assert not (tmp_path / "~").exists() and len(list((tmp_path / "home/runs").iterdir())) == 1


def test_an_export_folder_name_too_long_is_refused_at_the_field(tmp_path) -> None:
    """It was taken, and the export failed later with the reason cut from the box."""
    app = offscreen_app()
    long_name = "x" * 300
    app.export_field.submit(str(tmp_path / long_name / "runs"))
    assert app.message == (
        "export: the name xxxxxxxxxxxxxxxxxxxx... is too long (300 bytes, at most 255)"
    )
    assert app.export_field.text == "runs/gui"
    app.export_field.submit(str(tmp_path / ("a/" * 2100)))
    assert app.message == "export: the path is too long (at most 4095 bytes)"
    app.export_field.submit(str(tmp_path / ("y" * 255)))  # the longest name is taken
    assert not app.message_is_error
