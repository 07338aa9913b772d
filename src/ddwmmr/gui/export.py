"""Export of the app's current run: CSV/JSON, a PNG of the window, an animation.

Every file is written on its own with :func:`ddwmmr.outputs.write_new` (its content by
the result's own ``stream_csv``/``summary_text`` where there is one). Nothing in the
export folder is ever deleted or overwritten: a name that exists gets a ``-2``, ``-3``...
suffix, and the name is taken atomically, so two apps exporting into the same folder at
the same moment each keep their files; a run's folder is taken the same way.

Layout of one run's export folder (``<root>/<A>[-vs-<B>]-<trajectory>-<stamp>/``)::

    timeseries.csv, summary.json     one method: the files `python -m ddwmmr.track` writes,
                                     the summary with the record that
                                     `python -m ddwmmr.track --rerun summary.json` repeats;
                                     its ``command`` is the `track` command of the settings
    A-<method>/timeseries.csv ...    side-by-side mode: one sub-folder per slot
    trajectory.csv | trajectory.toml a trajectory moved by the geometry controls, sampled
                                     or parametric (the records and commands name it)
    window.png                       the whole window
    support_loads.png                a physics run's support loads and base tilt (the
                                     figure `track` writes; A-<method>/ per slot)
    animation.gif | animation.mp4    the view (paths, robot, plots) over the run
"""

from __future__ import annotations

import dataclasses
import io
import json
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import animation as mpl_animation
from matplotlib import rcParams
from matplotlib.artist import Artist
from matplotlib.backend_bases import RendererBase
from matplotlib.figure import Figure
from numpy.typing import NDArray

from ddwmmr import provenance
from ddwmmr.errors import ParameterError
from ddwmmr.gui.options import format_choice, method_options, plant_keywords
from ddwmmr.gui.settings import Settings, build_robot, build_trajectory
from ddwmmr.outputs import (
    first_free,
    folder_mode,
    nearest_existing,
    unwritable_message,
    write_new,
)
from ddwmmr.reports.canvas import frame_indices, new_figure, saved_frames, saved_gif_bytes
from ddwmmr.sim.simulate import plant_integrator
from ddwmmr.trajectories import SampledTrajectory
from ddwmmr.trajectories.files import SHAPES, find_trajectory_file, is_name
from ddwmmr.trajectories.sampled import csv_text

#: Animation formats and the matplotlib writer each needs.
ANIMATION_WRITERS = {"gif": "pillow", "mp4": "ffmpeg"}


def run_folder(root: Path, name: str) -> Path:
    """A new folder for one run's files under ``root`` (made here, with ``root`` if
    missing): ``name``, or the first free ``name-2``, ``name-3``... taken with an
    exclusive ``mkdir``, so two apps exporting at the same moment get one each."""
    while True:
        candidate = first_free(Path(root) / name, folder=True)
        try:
            candidate.parent.mkdir(parents=True, exist_ok=True, mode=folder_mode())
            candidate.mkdir(mode=folder_mode())
            return candidate
        except FileExistsError:
            continue  # taken between the look and the mkdir: the next one
        except OSError as exc:
            existing = nearest_existing(Path(root))
            message = unwritable_message("export", str(root), Path(root), existing, exc)
            raise ParameterError(message) from exc


def write_run_data(
    folder: Path,
    results: Sequence[Any],
    labels: Sequence[str],
    settings: Settings | None = None,
) -> list[Path]:
    """timeseries.csv and summary.json of every run (in a sub-folder per run when two).

    With the ``settings`` of the runs, each summary.json carries the ``run`` record of
    `python -m ddwmmr.track` (method and every option, robot, trajectory, step, plant), so
    `python -m ddwmmr.track --rerun summary.json` repeats the run bit for bit."""
    written: list[Path] = []
    records: list[dict[str, Any] | None] = [None] * len(results)
    if settings is not None:
        trajectory = build_trajectory(settings)
        source = trajectory_source(settings, trajectory, folder, written)
        records = [
            run_record(settings, slot, result, trajectory, source)
            for slot, result in zip(settings.active_slots, results)
        ]
    for result, label, record in zip(results, labels, records):
        target = slot_folder(folder, results, label)
        csv_path = write_new(target / "timeseries.csv", result.stream_csv)
        extra = {} if record is None else {"run": record}
        json_path = write_new(target / "summary.json", result.summary_text(**extra))
        written += [csv_path, json_path]
    return written


def trajectory_source(
    settings: Settings, trajectory: Any, folder: Path, written: list[Path]
) -> Path | None:
    """The file a record and its command should name for ``trajectory`` (built from
    ``settings``): the loaded file, or, for a trajectory moved by the geometry controls,
    the one written into ``folder`` (appended to ``written``): ``trajectory.csv`` for a
    sampled one, ``trajectory.toml`` (:func:`toml_text`) for a parametric one. None for a
    trajectory known by name only."""
    source = find_trajectory_file(settings.trajectory)
    if not settings.geometry:
        return source
    if isinstance(trajectory, SampledTrajectory):
        source = write_new(folder / "trajectory.csv", csv_text(trajectory))
        written.append(source)
    elif type(trajectory) in SHAPES.values():  # `track --traj` takes it as a file only
        source = write_new(folder / "trajectory.toml", toml_text(trajectory))
        written.append(source)
    return source


def toml_text(trajectory: Any) -> str:
    """A parametric ``trajectory`` (ellipse or rectangle) as a TOML file that
    :func:`ddwmmr.trajectories.files.read_toml` reads back as the same trajectory: every
    parameter, floats at full precision (``phi`` only with the constant orientation, the
    one that takes it)."""
    shape = next(k for k, cls in SHAPES.items() if type(trajectory) is cls)
    lines = ["[trajectory]", f"shape = {json.dumps(shape)}"]
    for field in dataclasses.fields(trajectory):
        value = getattr(trajectory, field.name)
        if field.name == "phi" and trajectory.orientation != "constant":
            continue
        text = json.dumps(value) if isinstance(value, str) else repr(value)
        lines.append(f"{field.name} = {text}")
    return "\n".join(lines) + "\n"


def run_record(
    settings: Settings, slot: int, result: Any, trajectory: Any, trajectory_file: Path | None
) -> dict[str, Any]:
    """The ``run`` record `python -m ddwmmr.track` writes, for slot ``slot`` of
    ``settings`` (tool ``"gui"``) and its built ``trajectory``; step and duration are the
    ones the run used, the integrator the one :func:`plant_keywords` gave the run.
    Its ``command`` and ``argv`` are the `track` command that repeats the run
    (:func:`track_arguments`); where a setting has no `track` argument, ``command_note``
    says which, and only ``track --rerun`` repeats the run."""
    inputs = provenance.RunInputs(
        method=str(settings.methods[slot]),
        options=dict(settings.options[slot]),
        robot=build_robot(settings),
        trajectory=trajectory,
        trajectory_file=trajectory_file,
        dt=float(result.summary["dt"]),
        duration=float(result.summary["duration"]),
        integrator=plant_integrator(
            settings.plant, plant_keywords(settings.plant, settings.integrator).get("integrator")
        ),
        # ignore: the checked settings hold two numbers (dx, dy)
        offset=tuple(settings.offset),  # type: ignore[arg-type]
        label=Path(settings.trajectory).stem,
        plant=settings.plant,
    )
    argv, missing = track_arguments(settings, inputs)
    record = provenance.run_record(
        inputs, argv=argv, rerun=None, tool="gui", prog=provenance.TRACK_PROG
    )
    if missing:
        record["command_note"] = (
            f"the command lacks {', '.join(missing)} (no track argument gives "
            f"{'it' if len(missing) == 1 else 'them'}); track --rerun this summary.json "
            "repeats the run"
        )
    return record


def track_arguments(
    settings: Settings, inputs: provenance.RunInputs
) -> tuple[list[str], list[str]]:
    """``(argv, missing)``: the `python -m ddwmmr.track` arguments that run what
    ``inputs`` (one slot of ``settings``) hold, every input explicit (step and
    duration in s, offset in m, payload in kg, at full precision), and the settings no
    argument gives (a trajectory the geometry controls moved that has no file, an option
    value whose text `--option` would read as another value)."""
    missing: list[str] = []
    if inputs.trajectory_file is not None and (
        settings.geometry or not is_name(settings.trajectory)
    ):
        traj = str(Path(inputs.trajectory_file).resolve())
    else:
        traj = settings.trajectory
        if settings.geometry:
            missing.append("the trajectory geometry")
    argv = ["--method", inputs.method, "--traj", traj]
    argv += ["--dt", repr(inputs.dt), "--duration", repr(inputs.duration)]
    argv += ["--plant", inputs.plant]
    if inputs.integrator is not None:
        argv += ["--integrator", inputs.integrator]
    argv += ["--payload", repr(float(settings.payload))]
    argv += ["--offset", *(repr(float(v)) for v in inputs.offset)]
    for name, value in inputs.options.items():
        text = option_text(inputs.method, name, value)
        if text is None:
            missing.append(f"option {name}")
        else:
            argv += ["--option", f"{name}={text}"]
    return argv, missing


def option_text(method: str, name: str, value: Any) -> str | None:
    """The text of ``--option NAME=TEXT`` that `track` parses as ``value`` (the
    simulator's field parses it alike), or None when no text does."""
    spec = {s.name: s for s in method_options(method)}.get(name)
    if spec is None:
        return None
    if spec.kind == "choice":
        text = format_choice(value)
    elif value is None:
        text = ""
    elif isinstance(value, list | tuple):
        text = ",".join(repr(float(v)) for v in value)
    elif isinstance(value, float | int) and not isinstance(value, bool):
        text = repr(value)
    else:
        text = str(value)
    try:
        same = provenance.encode(spec.parse(text)) == provenance.encode(value)
    except ParameterError:
        same = False
    return text if same else None


def slot_folder(folder: Path, results: Sequence[Any], label: str) -> Path:
    """Where the files of run ``label`` go: ``folder`` itself for one run, its sub-folder
    ``label`` side by side."""
    return folder if len(results) == 1 else folder / label


def write_support_loads(folder: Path, results: Sequence[Any], labels: Sequence[str]) -> list[Path]:
    """``support_loads.png`` of every physics run (:func:`slot_folder`): the support-load
    panel of :func:`ddwmmr.reports.physics_plots.draw_support_loads`, the figure a physics
    ``track`` run writes, drawn on a canvas of its own (never the window's).
    ParameterError when no run is a physics run."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from ddwmmr.reports import physics_plots as pp
    from ddwmmr.reports.plots import PNG_METADATA

    physics = [(r, label) for r, label in zip(results, labels) if pp.is_physics_run(r)]
    if not physics:
        raise ParameterError(
            "support loads: only a run on a physics plant measures them: choose plant "
            "mujoco and Run"
        )
    written = []
    for result, label in physics:
        figure = Figure(figsize=pp.SUPPORT_LOADS_FIGSIZE)
        FigureCanvasAgg(figure)
        pp.draw_support_loads(figure, result)
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=pp.SUPPORT_LOADS_DPI, metadata=PNG_METADATA)
        path = slot_folder(folder, results, label) / pp.SUPPORT_LOADS_FIGURE
        written.append(write_new(path, buffer.getvalue()))
    return written


def write_window_png(figure: Figure, folder: Path, dpi: float | None = None) -> Path:
    """The whole window as ``window.png``."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi or figure.dpi)
    return write_new(folder / "window.png", buffer.getvalue())


def animation_available(fmt: str) -> bool:
    """True if matplotlib can write ``fmt`` here. MP4 needs ffmpeg: on PATH, or the copy
    the optional ``imageio-ffmpeg`` package ships (``pip install 'ddwmmr[video]'``), which
    is then given to matplotlib (``animation.ffmpeg_path``) unless that is set already."""
    writer = ANIMATION_WRITERS[fmt]
    if writer == "ffmpeg" and not mpl_animation.writers.is_available(writer):
        _use_packaged_ffmpeg()
    return mpl_animation.writers.is_available(writer)


def _use_packaged_ffmpeg() -> None:
    """Point matplotlib at imageio-ffmpeg's binary when it is installed and matplotlib's
    ffmpeg path is still its default (a path the user chose is left alone)."""
    if rcParams["animation.ffmpeg_path"] != "ffmpeg":
        return
    try:
        # ignore: imageio-ffmpeg ships no type hints
        import imageio_ffmpeg
    except ImportError:
        return
    try:
        rcParams["animation.ffmpeg_path"] = imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError:  # the package is there but its binary is not (unsupported platform)
        return


def write_animation(
    results: Sequence[Any],
    labels: Sequence[str],
    obstacles: Sequence[Any],
    folder: Path,
    fmt: str = "gif",
    frames: int = 60,
    fps: int = 12,
    dpi: float = 80.0,
) -> Path:
    """``animation.<fmt>``: the view (robot, paths, plots) at ``frames`` evenly spaced times.

    Drawn by the window's own :class:`ddwmmr.gui.view.RunView` in a separate figure at
    ``dpi``, each frame painted as ``savefig`` paints a PNG under the user's rcParams
    (:func:`ddwmmr.reports.canvas.saved_frames`: ``savefig.facecolor``, ``edgecolor``,
    and ``transparent`` in a GIF; an MP4 has no alpha, its clear parts show white); a run
    shorter than ``frames`` recorded instants gives one frame per instant.
    """
    from ddwmmr.gui.view import animation_figure

    if fmt not in ANIMATION_WRITERS:
        raise ParameterError(f"animation format must be one of {', '.join(ANIMATION_WRITERS)}")
    if not animation_available(fmt):
        raise ParameterError(
            f"{fmt} export needs the {ANIMATION_WRITERS[fmt]} writer, which matplotlib cannot "
            "find here (install ffmpeg on PATH or pip install imageio-ffmpeg, or export a GIF)"
        )
    figure, view = animation_figure(dpi)
    view.set_runs(results, labels, obstacles)
    indices = frame_indices(view.last_index, frames)
    update = _view_update(view, indices)
    path = folder / f"animation.{fmt}"
    if fmt == "gif":
        return write_new(path, saved_gif_bytes(figure, update, len(indices), fps, dpi=dpi))
    writer = mpl_animation.FFMpegWriter(fps=fps)
    # The writer's figure only shows each frame, drawn by the view's figure.
    screen = new_figure((figure.get_figwidth(), figure.get_figheight()), dpi=dpi)
    shown = _Picture()
    screen.add_artist(shown)
    with tempfile.TemporaryDirectory() as scratch:
        temporary = Path(scratch) / path.name
        with writer.saving(screen, str(temporary), dpi):
            # setup may have rounded the size to even pixels for the codec: the view is
            # drawn at that size. An MP4 has no alpha: savefig.transparent is left aside
            # and what is left clear shows white, as matplotlib's Animation.save does.
            figure.set_size_inches(screen.get_figwidth(), screen.get_figheight())
            for rgba in saved_frames(figure, update, len(indices), dpi, transparent=False):
                shown.rgba = rgba
                writer.grab_frame(facecolor="white", transparent=False)
        return write_new(path, temporary.read_bytes())


class _Picture(Artist):
    """An RGBA picture (``rgba``: a ``(height, width, 4)`` array) drawn pixel for pixel
    from the figure's lower left corner, over its face."""

    def __init__(self) -> None:
        super().__init__()
        self.rgba: NDArray[np.uint8] = np.zeros((1, 1, 4), dtype=np.uint8)

    def draw(self, renderer: RendererBase) -> None:
        gc = renderer.new_gc()
        renderer.draw_image(gc, 0, 0, self.rgba[::-1])  # its rows from the bottom up
        gc.restore()


def _view_update(view: Any, indices: Sequence[int]) -> Callable[[int], list[Any]]:
    """The ``update`` of :func:`ddwmmr.reports.canvas.saved_frames` that shows the view
    at the recorded ``indices``: the moving artists are the view's
    :meth:`~ddwmmr.gui.view.RunView.dynamic_artists`; the legends belong to the still
    background, placed for the whole run (the last index drawn first)."""

    def update(frame: int) -> list[Any]:
        view.show_index(indices[frame])
        artists: list[Any] = view.dynamic_artists(legends=False)
        return artists

    return update
