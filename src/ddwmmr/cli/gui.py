"""``python -m ddwmmr.gui`` (console script ``ddwmmr-gui``): the interactive simulator
window, or its headless snapshot.

Examples::

    python -m ddwmmr.gui                                   # desktop window (Tk)
    python -m ddwmmr.gui --method qp --payload 3 \
        --option obstacles=trajectories/obstacles/ellipse_post.toml
    python -m ddwmmr.gui --snapshot gui.png --method ats --compare clrrmc-ts --traj rectangle

``--snapshot PATH`` builds the same window off-screen (Agg), runs the simulation to the
end, draws the final state and saves the whole window (controls and plots) to PATH, in the
image format of its suffix (.png, .svg, .pdf...). An existing file is never replaced
without ``--force``, unless an earlier snapshot wrote it (its metadata says so: .png,
.svg, .pdf, .eps, .ps). Bad input, an output path that cannot be written included, prints one
line on stderr and exits with status 2 before anything is built or run (nothing is
written).
"""

from __future__ import annotations

import argparse
import io
import sys
from collections.abc import Sequence
from pathlib import Path

from ddwmmr.cli.common import (
    ArgumentParser,
    integer_type,
    number_type,
    offset_type,
    payload_type,
    refuse_plant_option_argument,
    run_main,
    seconds_type,
)
from ddwmmr.controllers.base import available_methods
from ddwmmr.errors import (
    DURATION_RANGE_S,
    LENGTH_RANGE_M,
    MAX_ANGLE_RAD,
    MAX_COORDINATE_M,
    MAX_TRAJECTORY_SAMPLES,
    ParameterError,
    check_range,
)
from ddwmmr.gui.layout import desktop_figure
from ddwmmr.gui.options import parse_option, plant_names
from ddwmmr.gui.paths import (
    SNAPSHOT_FORMATS,
    check_existing_snapshot,
    check_export_root,
    check_snapshot_path,
    snapshot_format,
    snapshot_metadata,
)
from ddwmmr.gui.settings import (
    GEOMETRY,
    GEOMETRY_HELP,
    Settings,
    check_geometry,
    check_run_length,
    check_settings,
)
from ddwmmr.outputs import missing_folders, remove_created, write_atomic
from ddwmmr.plants.kinematic import INTEGRATORS
from ddwmmr.sim.simulate import plant_integrator
from ddwmmr.trajectories import available_trajectories

#: Exit status when no window can be opened or a snapshot's run fails (not bad input).
EXIT_NO_DISPLAY = 1
#: Allowed ``--dpi``: at 600 dpi the 16 x 10 in window is 9600 x 6000 px (about 0.4 GB
#: while it is drawn; 1200 dpi needs 1.3 GB and 16 s).
DPI_RANGE = (10, 600)

#: The argparse type of each geometry option: the range its check gives (its help's).
GEOMETRY_TYPES = {
    "x0": number_type(f"in [-{MAX_COORDINATE_M:g}, {MAX_COORDINATE_M:g}] m"),
    "y0": number_type(f"in [-{MAX_COORDINATE_M:g}, {MAX_COORDINATE_M:g}] m"),
    "a": number_type(f"in [{LENGTH_RANGE_M[0]:g}, {LENGTH_RANGE_M[1]:g}] m"),
    "b": number_type(f"in [{LENGTH_RANGE_M[0]:g}, {LENGTH_RANGE_M[1]:g}] m"),
    "beta": number_type(f"in [-{MAX_ANGLE_RAD:g}, {MAX_ANGLE_RAD:g}] rad"),
    # a number: its check refuses 1.5 naming the value as a number, like the panel's field
    "N": number_type(f"(an integer) in [2, {MAX_TRAJECTORY_SAMPLES}]"),
    "T": number_type(f"in [{DURATION_RANGE_S[0]:g}, {DURATION_RANGE_S[1]:g}] s"),
}


class RunFailed(RuntimeError):
    """The simulation of a snapshot failed for a reason other than bad input."""


def build_parser() -> ArgumentParser:
    """The argument parser (every option sets the matching control of the window)."""
    methods = available_methods()
    parser = ArgumentParser(
        prog="python -m ddwmmr.gui",
        description=(
            "Interactive simulator: pick a trajectory and a method, run, watch the robot and "
            "the plots, compare two methods, export. Options preset the window's controls."
        ),
    )
    parser.add_argument(
        "--snapshot",
        metavar="PATH",
        help="headless: run to the end, save the whole window to PATH and exit (no display "
        "needed); the suffix picks the format: "
        f"{', '.join('.' + f for f in SNAPSHOT_FORMATS)}",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="with --snapshot: replace an existing file at PATH (never a folder or a "
        "special file); without it an existing file is refused unless an earlier snapshot "
        "wrote it (.png, .svg, .pdf, .eps, .ps carry a mark saying so)",
    )
    parser.add_argument(
        "--dpi",
        type=integer_type(*DPI_RANGE, checked_later=True),
        default=None,
        metavar="DPI",
        help=f"with --snapshot: its resolution, {DPI_RANGE[0]:g} to {DPI_RANGE[1]:g} "
        "(default 100: 1600 x 1000 px)",
    )
    parser.add_argument(
        "--method",
        choices=methods,
        default=Settings().methods[0],
        help=f"method of slot A (default {Settings().methods[0]})",
    )
    parser.add_argument(
        "--compare",
        choices=methods,
        metavar="METHOD",
        help="method of slot B, shown side by side with A (default: none, slot A alone)",
    )
    parser.add_argument(
        "--traj",
        default=Settings().trajectory,
        metavar="NAME|FILE",
        help=f"trajectory ({', '.join(available_trajectories())}) or a "
        ".toml/.csv path (default ellipse)",
    )
    geometry = parser.add_argument_group("trajectory geometry (default: the file's)")
    for name, unit, _ in GEOMETRY:
        geometry.add_argument(
            f"--{name}",
            type=GEOMETRY_TYPES[name],
            metavar="N" if name == "N" else unit.upper(),
            help=GEOMETRY_HELP[name],
        )
    parser.add_argument(
        "--option",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="option of method A (repeatable), e.g. tau=0.3, aux=sum, "
        "stability_min=1.5, obstacles=FILE",
    )
    parser.add_argument(
        "--compare-option",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="option of method B (repeatable)",
    )
    parser.add_argument(
        "--plant",
        choices=plant_names(),
        default=Settings().plant,
        help=f"what the commands drive (default {Settings().plant})",
    )
    refuse_plant_option_argument(parser, "the simulator")
    parser.add_argument(
        "--payload",
        type=payload_type,
        metavar="KG",
        help=f"payload in kg (default {Settings().payload:g})",
    )
    parser.add_argument(
        "--integrator",
        choices=INTEGRATORS,
        help=f"integrator of the kinematic plant (default {Settings().integrator}; the other "
        "plants integrate their own dynamics and refuse it)",
    )
    parser.add_argument(
        "--dt",
        type=seconds_type,
        metavar="S",
        help="step in s (default: the trajectory's own, T/N, 0.02 s for the shipped ones; "
        "for a CSV without --N its row spacing made no coarser than 0.02 s)",
    )
    parser.add_argument(
        "--duration",
        type=seconds_type,
        metavar="S",
        help="simulated time in s (default one period T)",
    )
    parser.add_argument(
        "--offset",
        type=offset_type,
        nargs=2,
        metavar=("DX", "DY"),
        help="initial end-effector offset in m, in the end effector's start frame, each "
        f"within the arm's reach (default {Settings().offset[0]:.2f} {Settings().offset[1]:.2f})",
    )
    parser.add_argument(
        "--export",
        metavar="DIR",
        help="folder the window's Export buttons write to (default runs/gui); not with "
        "--snapshot, which exports nothing",
    )
    return parser


def settings_from_arguments(args: argparse.Namespace) -> Settings:
    """The :class:`Settings` the options describe (checked)."""
    if args.compare == args.method and sorted(args.compare_option) == sorted(args.option):
        raise ParameterError(
            f"compare: slot B would repeat slot A ({args.method}, the same options); give "
            "another method, other --compare-option values, or leave --compare out"
        )
    settings = Settings(trajectory=args.traj).with_method(0, args.method)
    settings = settings.with_method(1, args.compare)
    for slot, texts in ((0, args.option), (1, args.compare_option)):
        if texts and settings.methods[slot] is None:
            raise ParameterError("compare-option needs --compare METHOD")
        what = ("option", "compare-option")[slot]
        for text in texts:
            # ignore: the slot has a method when it has texts (refused above otherwise)
            name, value = parse_option(settings.methods[slot], text, what)  # type: ignore[arg-type]
            settings = settings.with_option(slot, name, value)
    for name, _, _ in GEOMETRY:
        value = getattr(args, name)
        if value is not None:
            settings = settings.with_geometry(name, check_geometry(name, value))
    # An explicit --integrator on a plant that integrates its own dynamics is refused.
    integrator = plant_integrator(args.plant, args.integrator) or Settings().integrator
    changes: dict[str, object] = {"plant": args.plant, "integrator": integrator}
    for name in ("payload", "dt", "duration"):
        if getattr(args, name) is not None:
            changes[name] = getattr(args, name)
    if args.offset is not None:
        changes["offset"] = tuple(args.offset)
    settings = check_settings(settings.replace(**changes))
    check_run_length(settings)  # before the window is built, naming --N, --T, --duration
    return settings


def snapshot(
    settings: Settings,
    path: str | Path,
    dpi: float | None = None,
    force: bool = False,
) -> Path:
    """Build the window off-screen, run to the end, draw the final state, save it in the
    format of the path's suffix. The path is checked first (:func:`check_snapshot_path`:
    an existing file only with ``force``), and again just before the file is written."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ddwmmr.gui.app import App
    from ddwmmr.gui.layout import DPI, FIGSIZE

    text = str(path)
    target = check_snapshot_path(text, force)
    fmt = snapshot_format(text)
    if dpi is not None:
        dpi = check_dpi(dpi)
    figure = Figure(figsize=FIGSIZE, dpi=DPI)
    FigureCanvasAgg(figure)
    app = App(figure, settings)
    app.run()
    app.wait()
    if app.results is None:
        message, bad_input = app.failure or ("the run did not finish", False)
        if bad_input:
            raise ParameterError(message)
        raise RunFailed(message)
    app.show_index(app.view.last_index)
    app.say(f"snapshot: final state at t = {app.view.time:.2f} s (--snapshot {path})")
    buffer = io.BytesIO()
    figure.savefig(buffer, format=fmt, dpi=dpi or DPI, metadata=snapshot_metadata(fmt))
    check_existing_snapshot(target, text, force)  # appeared during the run?
    created = missing_folders(target.parent)
    try:
        write_atomic(target, buffer.getvalue())
    except ParameterError:  # the folder turned unwritable during the run: its own words
        remove_created(created)  # leave no empty folder behind
        raise
    except OSError as exc:
        remove_created(created)
        raise RunFailed(f"snapshot: cannot write {text} ({exc.strerror or exc})") from None
    return Path(path)


def check_dpi(dpi: float) -> float:
    """``--dpi``: a finite number in :data:`DPI_RANGE`."""
    return check_range("dpi", dpi, *DPI_RANGE)


def open_window(settings: Settings, export_dir: str | None = None) -> int:
    """Open the desktop window (Tk) and run its event loop until it is closed."""
    import matplotlib.pyplot as plt

    from ddwmmr.gui.app import App

    try:
        figure = desktop_figure()
    except Exception as exc:  # no display, no Tk: say so in one line
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(
            f"error: cannot open a window ({first}); use --snapshot PATH headless", file=sys.stderr
        )
        return EXIT_NO_DISPLAY
    app = App(figure, settings, interactive=True)
    if export_dir:
        app.export_field.show(export_dir)
    # ignore: an attribute of our own on the figure, which matplotlib's hints do not declare
    figure.ddwmmr_app = app  # type: ignore[attr-defined]  # keeps the app alive with the window
    plt.show()
    return 0


def _main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    # The output checks first: they are quick, and the settings load files.
    if args.snapshot is not None:
        check_snapshot_path(args.snapshot, args.force)
    elif args.force:
        raise ParameterError("force needs --snapshot PATH (it only lets a snapshot replace a file)")
    if args.dpi is not None:
        check_dpi(args.dpi)
        if args.snapshot is None:  # the window fits its own resolution to the screen
            raise ParameterError("dpi needs --snapshot PATH (it sets the snapshot's resolution)")
    if args.export is not None:
        check_export_root(args.export)
        if args.snapshot is not None:
            raise ParameterError(
                "export: --export cannot be combined with --snapshot (it sets the folder of "
                "the window's Export buttons; a snapshot saves only the image)"
            )
    settings = settings_from_arguments(args)
    if args.snapshot is not None:
        try:
            path = snapshot(settings, args.snapshot, args.dpi, args.force)
        except RunFailed as exc:
            print(f"error: {exc}", file=sys.stderr)
            return EXIT_NO_DISPLAY
        print(f"wrote {path}")
        return 0
    return open_window(settings, args.export)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; bad input prints one line on stderr and returns 2."""
    return run_main(_main, argv)
