"""Export from the simulator window: the run's files as `track` writes them, a PNG of the
window, an animation; files are written one by one and nothing is deleted or replaced."""

import csv
import json

import numpy as np
import pytest
from matplotlib.backend_bases import MouseEvent
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from ddwmmr.cli.track import main as track
from ddwmmr.gui import App, Settings
from ddwmmr.gui.export import animation_available
from ddwmmr.gui.layout import FIGSIZE

DURATION = 1.0


def finished_app(settings, export_root):
    figure = Figure(figsize=FIGSIZE, dpi=30)
    FigureCanvasAgg(figure)
    app = App(figure, settings)
    app.export_field.submit(str(export_root))
    app.run()
    app.wait()
    assert app.results is not None, app.message
    return app


def click(ax):
    canvas = ax.figure.canvas
    x, y = ax.transAxes.transform((0.5, 0.5))
    for name in ("button_press_event", "button_release_event"):
        canvas.callbacks.process(name, MouseEvent(name, canvas, x, y, button=1))


def read_csv(path):
    with path.open(newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


def test_data_export_equals_the_track_files(tmp_path):
    app = finished_app(Settings(methods=("clrrmc-cs", None), duration=DURATION), tmp_path / "gui")
    click(app.export_buttons["data"].ax)
    (folder,) = (tmp_path / "gui").iterdir()
    assert folder.name.startswith("clrrmc-cs-ellipse-")
    assert sorted(p.name for p in folder.iterdir()) == ["summary.json", "timeseries.csv"]
    status = track(
        [
            "--method",
            "clrrmc-cs",
            "--traj",
            "ellipse",
            "--duration",
            str(DURATION),
            "--out",
            str(tmp_path / "track"),
            "--no-plots",
            "--no-progress",
        ]
    )
    assert status == 0
    header, values = read_csv(folder / "timeseries.csv")
    track_header, track_values = read_csv(tmp_path / "track" / "timeseries.csv")
    assert header == track_header
    timing = header.index("step_us")  # wall-clock time of each controller call
    keep = [i for i in range(len(header)) if i != timing]
    np.testing.assert_array_equal(values[:, keep], track_values[:, keep])
    summary = json.loads((folder / "summary.json").read_text())
    track_summary = json.loads((tmp_path / "track" / "summary.json").read_text())
    summary.pop("median_step_us")
    track_summary.pop("median_step_us")
    # Both carry the record of what ran (to --rerun it); the results are the same.
    assert track_summary.pop("run")["tool"] == "track"
    record = summary.pop("run")
    assert record["tool"] == "gui" and record["method"] == "clrrmc-cs"
    assert summary == track_summary


def _rerun_equals_the_export(tmp_path, settings, names):
    """Export the app's run, repeat every exported summary with track --rerun and compare
    the time series (all but the wall-clock column) bit for bit."""
    app = finished_app(settings, tmp_path / "gui")
    written = app.export_data()
    summaries = sorted(p for p in written if p.name == "summary.json")
    assert len(summaries) == len(names)
    for number, path in enumerate(summaries):
        out = tmp_path / f"rerun-{number}"
        assert track(["--rerun", str(path), "--out", str(out), "--no-plots", "--no-progress"]) == 0
        header, values = read_csv(path.parent / "timeseries.csv")
        rerun_header, rerun_values = read_csv(out / "timeseries.csv")
        assert header == rerun_header
        keep = [i for i, name in enumerate(header) if name != "step_us"]
        np.testing.assert_array_equal(values[:, keep], rerun_values[:, keep])
        record = json.loads(path.read_text())["run"]
        assert record["method"] == names[number]
        assert json.loads((out / "summary.json").read_text())["run"]["rerun_of"] == str(
            path.resolve()
        )
    return written


def test_exported_runs_repeat_bit_for_bit_with_track_rerun(tmp_path):
    settings = Settings(
        methods=("qp", "ats"),
        options=({"stability_min": 1.3, "tau": 0.4}, {}),
        geometry={"a": 1.8, "beta": 0.3},
        payload=2.0,
        offset=(0.02, -0.01),
        duration=DURATION,
    )
    _rerun_equals_the_export(tmp_path, settings, ["qp", "ats"])


def test_a_moved_sampled_trajectory_is_exported_with_the_run(tmp_path):
    settings = Settings(
        trajectory="figure8",
        methods=("clrrmc-ts", None),
        geometry={"x0": 0.5, "T": 30.0},
        plant="thesis",
        duration=DURATION,
    )
    written = _rerun_equals_the_export(tmp_path, settings, ["clrrmc-ts"])
    (moved,) = [p for p in written if p.name == "trajectory.csv"]
    record = json.loads(next(p for p in written if p.name == "summary.json").read_text())["run"]
    assert record["trajectory"]["file"] == str(moved.resolve())
    assert record["plant"] == {"name": "thesis"} and record["integrator"] is None


def test_exports_never_delete_or_replace_files(tmp_path):
    root = tmp_path / "exports"
    root.mkdir()
    (root / "keep.txt").write_text("mine")
    app = finished_app(Settings(methods=("ats", "pi"), duration=DURATION), root)
    first = app.export_data()
    csv_a = next(p for p in first if p.name == "timeseries.csv")
    before = csv_a.read_bytes()
    second = app.export_data()
    assert {p.name for p in first} == {"timeseries.csv", "summary.json"}
    assert {p.name for p in second} == {"timeseries-2.csv", "summary-2.json"}
    assert {p.parent.name for p in first} == {"A-ats", "B-pi"}
    assert csv_a.read_bytes() == before
    window = app.export_png()
    again = app.export_png()
    assert (window.name, again.name) == ("window.png", "window-2.png")
    with Image.open(window) as image:
        assert image.size == (480, 300)  # 16 x 10 in at the figure's 30 dpi
    assert (root / "keep.txt").read_text() == "mine"
    (run_folder,) = [p for p in root.iterdir() if p.is_dir()]
    assert run_folder.name.startswith("ats-vs-pi-ellipse-")
    assert not [p for p in run_folder.rglob("*") if p.name.endswith(".tmp")]


def test_gif_has_the_frames_of_the_run(tmp_path):
    # Half the other tests' run: 26 recorded instants show the frame count and
    # the motion as clearly, at half the frames to draw and encode.
    app = finished_app(Settings(methods=("clrrmc-ts", "ats"), duration=DURATION / 2), tmp_path)
    click(app.export_buttons["gif"].ax)
    (path,) = tmp_path.rglob("animation.gif")
    with Image.open(path) as movie:
        assert movie.n_frames == 26 and movie.size == (880, 448)  # one per step; 80 dpi
        assert movie.convert("RGB").getpixel((2, 2)) == (255, 255, 255)  # white, not near
        first = np.asarray(movie.convert("L"), dtype=float)
        movie.seek(movie.n_frames - 1)
        last = np.asarray(movie.convert("L"), dtype=float)
    assert np.mean(np.abs(first - last) > 30) > 0.002  # the robot moved, plots grew
    assert app.message == f"wrote {path}"


def test_mp4_has_the_frames_of_the_run(tmp_path):
    """With ffmpeg (on PATH, or imageio-ffmpeg's, which the test extras install) the MP4
    holds one frame per recorded instant, each the view at its instant (as a full render
    of the view draws it, to the encoder's loss); without ffmpeg, a message."""
    from ddwmmr.gui.view import animation_figure

    # A fifth of the other tests' run: 11 recorded instants, over which the time cursors
    # cross the plots, so each instant's picture is told from its neighbours'.
    app = finished_app(Settings(methods=("ats", None), duration=DURATION / 5), tmp_path)
    click(app.export_buttons["mp4"].ax)
    movies = list(tmp_path.rglob("*.mp4"))
    if not animation_available("mp4"):
        assert not movies
        assert "mp4 export needs the ffmpeg writer" in app.message
        return
    (path,) = movies
    assert app.message == f"wrote {path}"
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg", reason="reads the MP4 back")
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    width, height = meta["size"]
    frames = [np.frombuffer(f, dtype=np.uint8).reshape(height, width, 3) for f in reader]
    assert len(frames) == 11 and (width, height) == (880, 448)  # one per step; 80 dpi
    assert meta["fps"] == pytest.approx(12.0) and meta["codec"] == "h264"
    assert meta["pix_fmt"].startswith("yuv420p")  # what players take
    figure, view = animation_figure(80.0)
    view.set_runs(app.results, app.labels(), [])  # ats avoids no obstacles
    renders = []
    for index in range(11):
        view.show_index(index)
        figure.canvas.draw()
        renders.append(np.asarray(figure.canvas.buffer_rgba())[..., :3].astype(float))
    for index, frame in enumerate(frames):
        difference = [np.mean(np.abs(frame - render)) for render in renders]
        assert difference[index] < 2.0, index  # of 255: h264's loss, antialiased edges
        assert np.argmin(difference) == index  # this instant's picture, not a neighbour's
        wrong = np.abs(frame - renders[index]).max(axis=2) > 100
        assert np.mean(wrong) < 5e-4, index  # the colours too (a few edges differ)
    assert np.mean(np.abs(renders[0] - renders[-1]).max(axis=2) > 30) > 0.002  # it moved


def animation_frame(app, folder, fmt, rc):
    """The last frame of the run's ``fmt`` animation (3 frames) written under the
    rcParams ``rc``, decoded as RGBA; None when matplotlib cannot write ``fmt`` here."""
    import matplotlib as mpl

    from ddwmmr.gui import export

    if not animation_available(fmt):
        return None
    with mpl.rc_context(rc):
        path = export.write_animation(app.results, app.labels(), [], folder, fmt, frames=3)
    if fmt == "gif":
        with Image.open(path) as movie:
            movie.seek(movie.n_frames - 1)
            return np.asarray(movie.convert("RGBA"), dtype=int)
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg", reason="reads the MP4 back")
    reader = imageio_ffmpeg.read_frames(str(path))
    width, height = next(reader)["size"]
    *_, last = reader
    rgb = np.frombuffer(last, dtype=np.uint8).reshape(height, width, 3).astype(int)
    return np.dstack([rgb, np.full((height, width), 255)])


def test_animations_are_painted_as_savefig_paints_a_png(tmp_path):
    """The exported animation takes the user's savefig colours, as `track --animate`'s
    GIF and the window's PNG do: the figure's face in ``savefig.facecolor``; under
    ``savefig.transparent`` a GIF's figure and axes backgrounds are transparent, while an
    MP4 (no alpha) shows them white, as matplotlib's own movie writer does."""
    app = finished_app(Settings(methods=("ats", None), duration=DURATION / 5), tmp_path)
    corner = (3, 3)  # the figure's face, outside every axes
    inside = (200, 300)  # the top view's background, away from the paths
    for fmt in ("gif", "mp4"):
        folder = tmp_path / fmt
        folder.mkdir()
        plain = animation_frame(app, folder / "plain", fmt, {})
        if plain is None:
            continue  # no ffmpeg here: test_mp4_has_the_frames_of_the_run says so
        assert (np.abs(plain[corner] - 255) <= 3).all(), fmt
        dark = animation_frame(app, folder / "dark", fmt, {"savefig.facecolor": "black"})
        assert (np.abs(dark[corner][:3]) <= 3).all() and dark[corner][3] == 255, fmt
        assert (np.abs(dark[inside] - 255) <= 3).all(), fmt  # the axes keep theirs
        clear = animation_frame(app, folder / "clear", fmt, {"savefig.transparent": True})
        if fmt == "gif":
            assert clear[corner][3] == 0 and clear[inside][3] == 0
            assert np.mean(clear[..., 3] == 255) < 0.2  # the lines and texts only
        else:
            assert np.mean(np.abs(clear - plain)) < 1.0  # as without: white


def test_export_before_a_run_is_a_message(tmp_path):
    figure = Figure(figsize=FIGSIZE, dpi=30)
    FigureCanvasAgg(figure)
    app = App(figure, Settings(duration=DURATION))
    app.export_field.submit(str(tmp_path))
    click(app.export_buttons["png"].ax)
    assert app.message == "export: no finished run yet (press Run)"
    assert not list(tmp_path.iterdir())
    app.export_field.submit(" ")
    assert app.message == "export folder must not be empty"
    assert app.export_field.text == str(tmp_path)


def test_support_loads_button_draws_the_track_panel_of_a_physics_run(tmp_path):
    """A MuJoCo run's Support loads button writes support_loads.png, drawn by the function
    that draws track's figure: each edge's measured load (N) with the floor the optimiser
    held, and the base's tilt (mrad), the same numbers as the run's time series."""
    from ddwmmr.reports.physics_plots import draw_support_loads, edge_load_series

    settings = Settings(methods=("qp", None), plant="mujoco", duration=DURATION, payload=3.0)
    app = finished_app(settings, tmp_path / "gui")
    click(app.export_buttons["loads"].ax)
    (folder,) = (tmp_path / "gui").iterdir()
    with Image.open(folder / "support_loads.png") as image:
        assert image.size == (825, 572)  # 7.5 x 5.2 in at 110 dpi, as track's
    (result,) = app.results
    figure = draw_support_loads(Figure(), result)
    ax_load, ax_tilt = figure.axes
    names, loads = edge_load_series(result.timeseries, result.robot)
    edges = [line for line in ax_load.lines if line.get_label().endswith(" edge")]
    assert [line.get_label() for line in edges] == [f"{name} edge" for name in names]
    for j, line in enumerate(edges):
        np.testing.assert_allclose(line.get_ydata(), loads[:, j])
    assert loads.min() > 14.0  # the qp kept every edge loaded on this short run
    floor = result.summary["min_edge_load_floor_n"]
    assert floor == pytest.approx(0.1 * result.robot.total_mass * 9.81)
    (floor_line,) = [line for line in ax_load.lines if line.get_label().startswith("floor")]
    assert floor_line.get_ydata()[0] == pytest.approx(floor)
    (tilt,) = ax_tilt.lines
    np.testing.assert_allclose(tilt.get_ydata(), 1e3 * result.timeseries["base_tilt_rad"])


def test_support_loads_of_a_run_without_physics_is_a_message(tmp_path):
    app = finished_app(Settings(methods=("clrrmc-cs", None), duration=DURATION), tmp_path / "gui")
    click(app.export_buttons["loads"].ax)
    assert "only a run on a physics plant measures them: choose plant mujoco and Run" in app.message
    assert not list((tmp_path / "gui").iterdir())  # no empty run folder left behind
    click(app.export_buttons["data"].ax)  # the next export makes its folder anew
    (folder,) = (tmp_path / "gui").iterdir()
    assert sorted(p.name for p in folder.iterdir()) == ["summary.json", "timeseries.csv"]


def test_a_failed_export_keeps_what_earlier_exports_wrote(tmp_path, monkeypatch):
    """A failing writer (an MP4 encoder missing) leaves no empty folder, and never takes
    away a folder an earlier export of the run wrote into."""
    from ddwmmr.errors import ParameterError
    from ddwmmr.gui import export

    def unavailable(*_args, **_kwargs):
        raise ParameterError("export: mp4 needs ffmpeg")

    monkeypatch.setattr(export, "write_animation", unavailable)
    app = finished_app(Settings(methods=("ats", None), duration=DURATION), tmp_path / "gui")
    click(app.export_buttons["mp4"].ax)
    assert app.message == "export: mp4 needs ffmpeg"
    assert not list((tmp_path / "gui").iterdir())
    click(app.export_buttons["data"].ax)
    click(app.export_buttons["mp4"].ax)
    (folder,) = (tmp_path / "gui").iterdir()
    assert sorted(p.name for p in folder.iterdir()) == ["summary.json", "timeseries.csv"]
