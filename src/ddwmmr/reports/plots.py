"""Figures of a tracking run: paths with the robot drawn, errors, rates, metrics, animation.

All functions take a :class:`ddwmmr.sim.SimulationResult`; ``save_run_figures`` writes the
standard set of PNGs that ``python -m ddwmmr.track`` produces. World frame, metres, radians.

By default a figure is made here, not by pyplot (:mod:`ddwmmr.reports.canvas`): importing
or using this module leaves the matplotlib backend as the user chose it. Such a figure is
saved with ``fig.savefig`` or shown as a Jupyter cell's value (once the inline backend is
active: ``%matplotlib inline``, or after a pyplot figure), but ``plt.show()`` does not
show it. To look at a run in a window, draw into pyplot's figures instead:
``plot_path(result, ax=ax)`` into an axes of ``plt.subplots()`` (the figure is laid out
so that the legend beside the axes stays on it), and
``plot_errors(result, fig=plt.figure())`` (likewise ``plot_rates``, ``plot_metrics``),
then ``plt.show()``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypedDict, overload

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure
from matplotlib.layout_engine import PlaceHolderLayoutEngine
from matplotlib.lines import Line2D
from matplotlib.patches import Circle

from ddwmmr.errors import (
    ParameterError,
    as_path,
    check_instance,
    check_int_at_least,
    iterable,
    shown,
)
from ddwmmr.model import Robot
from ddwmmr.reports import palette
from ddwmmr.reports.canvas import checked_gif_options, frame_indices, new_figure, save_gif
from ddwmmr.reports.legends import legend_beside, place_legend

if TYPE_CHECKING:
    from matplotlib.text import Text

    from ddwmmr.qp.limits.obstacles import Circle as CircleObstacle
    from ddwmmr.sim import SimulationResult

    #: A configuration ``[x, y, phi, th1, th2]`` (m, rad): a sequence or an array.
    Configuration = Sequence[float] | np.ndarray
    #: Circular obstacles: :class:`~ddwmmr.qp.limits.obstacles.Circle` s or
    #: ``(x, y, radius)`` triples (m), or None for none.
    Obstacles = Iterable[CircleObstacle | Sequence[float]] | None

    class _Tolerance(TypedDict):
        """The keywords of :func:`numpy.allclose` that :func:`wheels_follow_measured` passes."""

        rtol: float
        atol: float
        equal_nan: bool


FIGURE_NAMES = ("path.png", "errors.png", "rates.png", "metrics.png")
#: PNG text chunks: none (not even the matplotlib version), so equal runs give
#: byte-identical figures.
PNG_METADATA = {"Software": None}
#: Floor (m) of every logarithmic position-error axis (track, compare, the GUI): errors
#: below it are drawn at it. Converged runs reach 1e-10 m and less, which stays visible.
ERROR_FLOOR = 1e-12


def robot_outline(robot: Robot, q: Configuration) -> dict[str, np.ndarray]:
    """Polylines (world frame, m) of the robot at q: ``footprint`` (closed) and ``arm``."""
    x, y, phi, th1, _ = (float(v) for v in q)
    c, s = math.cos(phi), math.sin(phi)
    hl, hw = robot.base_length / 2, robot.base_width / 2
    corners = np.array([[hl, hw], [-hl, hw], [-hl, -hw], [hl, -hw], [hl, hw]])
    footprint = corners @ np.array([[c, s], [-s, c]]) + [x, y]
    elbow = (x + robot.L1 * math.cos(phi + th1), y + robot.L1 * math.sin(phi + th1))
    tip = robot.fk(q)[:2]
    arm = np.array([[x, y], elbow, tip])
    heading = np.array([[x, y], [x + hl * c, y + hl * s]])
    return {"footprint": footprint, "arm": arm, "heading": heading}


def wheel_outlines(robot: Robot, q: Configuration, width: float | None = None) -> list[np.ndarray]:
    """Closed polylines (world frame, m) of the left and right drive wheels at q.

    Each wheel is a ``2 r x width`` rectangle along the heading, centred on the axle at
    ``+-track_width/2`` (left first); ``width`` defaults to ``r / 2``.
    """
    x, y, phi = (float(v) for v in q[:3])
    c, s = math.cos(phi), math.sin(phi)
    r = robot.wheel_radius
    hw = (r / 2 if width is None else width) / 2
    local = np.array([[r, hw], [-r, hw], [-r, -hw], [r, -hw], [r, hw]])
    rotation = np.array([[c, s], [-s, c]])
    wheels = []
    for side in (1.0, -1.0):  # left wheel is on the +y side of the base frame
        centre = np.array(
            [x - side * robot.track_width / 2 * s, y + side * robot.track_width / 2 * c]
        )
        wheels.append(local @ rotation + centre)
    return wheels


def snapshot_indices(ts: Mapping[str, np.ndarray], count: int, spacing: float = 0.0) -> np.ndarray:
    """Up to ``count`` evenly spaced sample indices of a run, the first and the last (the
    final pose) always included. With ``spacing`` (m), another instant whose base lies
    closer than that to an instant already kept is left out: a base that hardly moves (a
    reach on the spot) shows a few robots apart rather than a tangle of footprints."""
    candidates = np.linspace(0, len(ts["t"]) - 1, count).round().astype(int)
    # The first and the last instant first: where the run starts and ends matters most.
    ends = [int(candidates[0])] if count < 2 else [int(candidates[0]), int(candidates[-1])]
    kept = list(dict.fromkeys(ends))
    for k in candidates:
        if k not in kept and all(
            math.hypot(ts["x"][k] - ts["x"][j], ts["y"][k] - ts["y"][j]) >= spacing for j in kept
        ):
            kept.append(int(k))
    return np.array(sorted(kept), dtype=int)


def footprint_spacing(robot: Robot) -> float:
    """Distance (m) between two bases beyond which neither lies inside the other's
    footprint, whatever their headings: half the footprint's diagonal."""
    return 0.5 * math.hypot(robot.base_length, robot.base_width)


def snapshot_colors(count: int) -> list[str]:
    """One grey per drawn instant, light (first) to dark (last), evenly spaced over the
    levels of :data:`~ddwmmr.reports.palette.SNAPSHOT_GREYS` without the band
    :data:`~ddwmmr.reports.palette.SNAPSHOT_SKIP` around the base path's grey: time reads
    as darkening, in no hue of a path or method line and not in the base's grey."""
    first, last = palette.SNAPSHOT_GREYS
    low, high = palette.SNAPSHOT_SKIP
    span = (first - high) + (low - last)  # the levels used, above and below the band
    levels = (first - span * i / max(count - 1, 1) for i in range(count))
    return [f"{level if level >= high else level - (high - low):.3f}" for level in levels]


def draw_snapshots(
    ax: Axes,
    robot: Robot,
    ts: Mapping[str, np.ndarray],
    indices: Sequence[int] | np.ndarray,
    lw: float = 1.0,
) -> list[Line2D]:
    """The robot (footprint, heading, arm) at the samples ``indices`` of the time series
    ``ts``, each instant in its own colour (:func:`snapshot_colors`); returns one legend
    handle per instant, labelled with its time. Times are told by colour, not by text
    next to the robots, so that no label covers a path."""
    q = np.column_stack([ts[k] for k in ("x", "y", "phi", "th1", "th2")])
    handles = []
    for k, color in zip(indices, snapshot_colors(len(indices))):
        shape = robot_outline(robot, q[k])
        ax.plot(*shape["footprint"].T, color=color, lw=lw)
        ax.plot(*shape["heading"].T, color=color, lw=lw)
        ax.plot(*shape["arm"].T, color=color, lw=1.5 * lw, marker="o", ms=2.5)
        handles.append(Line2D([], [], color=color, lw=2, label=f"robot at t = {ts['t'][k]:.3g} s"))
    return handles


def outline_points(
    robot: Robot, ts: Mapping[str, np.ndarray], indices: Sequence[int] | np.ndarray
) -> np.ndarray:
    """Every vertex of the robot outlines drawn at ``indices`` (world frame, m), to fit
    the axes around them."""
    q = np.column_stack([ts[k] for k in ("x", "y", "phi", "th1", "th2")])
    shapes = [robot_outline(robot, q[k]) for k in indices]
    return np.concatenate([np.r_[s["footprint"], s["arm"]] for s in shapes]).reshape(-1, 2)


def fit_equal(ax: Axes, xs: np.ndarray, ys: np.ndarray, margin: float) -> None:
    """Equal-scale limits holding every finite point of ``xs``, ``ys`` plus ``margin``
    (m); the axes box shrinks to the limits' shape."""
    xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
    xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
    ax.set_xlim(xs.min() - margin, xs.max() + margin)
    ax.set_ylim(ys.min() - margin, ys.max() + margin)
    ax.set_aspect("equal", adjustable="box")


def circles_of(obstacles: Obstacles) -> list[tuple[float, float, float]]:
    """Obstacles as ``(x, y, radius)`` triples (m): from circles (anything with ``x``,
    ``y`` and ``radius``), triples or None, checked as the ``obstacles`` option of ``qp``
    and ``mpc`` is (:func:`ddwmmr.qp.limits.obstacles.as_circles`: finite centres, radii >
    0, at most :data:`~ddwmmr.errors.MAX_OBSTACLES`; anything else a one-line
    :class:`~ddwmmr.errors.ParameterError` naming ``obstacles``)."""
    from ddwmmr.qp.limits.obstacles import as_circles  # the qp's package: on first use

    def triple(item: Any) -> Any:  # a circle of another class, as as_circles reads it
        return (item.x, item.y, item.radius) if hasattr(item, "radius") else item

    given: Any = obstacles  # as given: as_circles refuses what is none of its kinds
    if iterable(given) and not isinstance(given, str | bytes | Mapping):
        given = [triple(item) for item in given]
    return [(c.x, c.y, c.radius) for c in as_circles(given)]


def draw_obstacles(ax: Axes, obstacles: Obstacles, label: str = "obstacle") -> None:
    """Grey discs for circular obstacles (world frame, m); one legend entry."""
    for i, (x, y, radius) in enumerate(circles_of(obstacles)):
        disc = Circle(
            (x, y), radius, color="0.55", alpha=0.45, lw=1, label=label if i == 0 else None
        )
        ax.add_patch(disc)
        ax.update_datalim([(x - radius, y - radius), (x + radius, y + radius)])


def break_wraps(t: np.ndarray, angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(t, angle)`` with a NaN gap where a wrapped angle jumps across +-pi.

    A wrapped error that crosses pi reappears at -pi; a line drawn through the jump
    would be a false vertical stroke, so the line is broken there instead.
    """
    t, angle = np.asarray(t, dtype=float), np.asarray(angle, dtype=float)
    jumps = np.flatnonzero(np.abs(np.diff(angle)) > math.pi) + 1
    return np.insert(t, jumps, np.nan), np.insert(angle, jumps, np.nan)


@overload
def plot_path(
    result: SimulationResult,
    ax: None = None,
    snapshots: int = 6,
    obstacles: Obstacles = None,
) -> Figure: ...


@overload
def plot_path(
    result: SimulationResult,
    ax: Axes,
    snapshots: int = 6,
    obstacles: Obstacles = None,
) -> Figure | SubFigure: ...


def plot_path(
    result: SimulationResult,
    ax: Axes | None = None,
    snapshots: int = 6,
    obstacles: Obstacles = None,
) -> Figure | SubFigure:
    """Desired vs actual end-effector path, base path, the robot at up to ``snapshots``
    times, no base inside another's footprint (one grey per time, named in the legend; see
    :func:`snapshot_indices`) and the obstacles (``(x, y, radius)``
    circles, m) if any. The axes hold everything drawn; the legend sits beside them.

    Without ``ax`` the figure is made here, 8.6 inches wide and as tall as the equal-scale
    path needs, and returned. An ``ax`` of the caller's is drawn into as it is (other
    runs' paths may share it) and its figure keeps its size; it is laid out as
    :func:`plot_errors` lays out a caller's figure (by its own layout engine, else
    ``tight_layout``), so that the legend beside the axes stays on the figure, and the
    figure ``ax`` is on is returned: a :class:`~matplotlib.figure.SubFigure` for axes in
    one (``plt.figure().subfigures(1, 2)``), whose whole figure is what is laid out."""
    ts = _run(result).timeseries
    if ax is not None:
        check_instance("ax", ax, Axes)
    # more instants than samples draw each sample once
    count = min(check_int_at_least("snapshots", snapshots, 1), len(ts["t"]))
    # read (a file) and checked once, before anything is drawn
    obstacles = circles_of(obstacles)
    own_figure = ax is None
    fig, ax = _axes(ax, figsize=(8.6, 5.6))
    draw_obstacles(ax, obstacles)
    indices = snapshot_indices(ts, count, footprint_spacing(result.robot))
    robots = draw_snapshots(ax, result.robot, ts, indices, lw=0.9)
    # The desired path on top of the actual one, dashed: visible where they coincide.
    ax.plot(
        ts["xE"],
        ts["yE"],
        color=palette.END_EFFECTOR,
        lw=2.2,
        alpha=0.8,
        label="actual end effector",
    )
    ax.plot(ts["xE_d"], ts["yE_d"], "k--", lw=1, label="desired end effector")
    ax.plot(ts["x"], ts["y"], color=palette.BASE, lw=1, label="base (axle midpoint)")
    ax.plot(ts["xE"][0], ts["yE"][0], "o", color=palette.END_EFFECTOR, ms=5, label="start")
    outline = outline_points(result.robot, ts, indices)
    circles = np.array(circles_of(obstacles)).reshape(-1, 3)
    fit_equal(
        ax,
        np.r_[
            ts["xE"],
            ts["xE_d"],
            ts["x"],
            outline[:, 0],
            circles[:, 0] - circles[:, 2],
            circles[:, 0] + circles[:, 2],
        ],
        np.r_[
            ts["yE"],
            ts["yE_d"],
            ts["y"],
            outline[:, 1],
            circles[:, 1] - circles[:, 2],
            circles[:, 1] + circles[:, 2],
        ],
        0.15,
    )
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(_title(result, "paths"))
    handles, _ = ax.get_legend_handles_labels()
    legend_beside(ax, handles=[*handles, *robots], fontsize=8)
    ax.grid(alpha=0.3)
    if isinstance(fig, SubFigure):  # only the whole figure has a size and a layout
        _lay_out(fig.figure, own=False)
    elif own_figure:
        _fit_path_figure(fig, ax)
    else:  # make room for the legend beside the axes, as the other makers do
        _lay_out(fig, own=False)
    return fig


#: The path figure's width and its margins (inches): left of the axes, right of them (the
#: legend), below and above; its height follows the data (:func:`_fit_path_figure`).
PATH_WIDTH_IN = 8.6
PATH_MARGINS_IN = (0.77, 2.32, 0.5, 0.39)
#: Bounds of the path figure's height (inches): the legend's height, and a page's.
PATH_HEIGHT_IN = (4.0, 9.0)


def _fit_path_figure(fig: Figure, ax: Axes) -> None:
    """Give the figure the height at which the equal-scale axes fill their width: the axes
    box then meets the margins instead of leaving empty bands above and below (a wide
    path) or, within :data:`PATH_HEIGHT_IN`, beside it (a tall one)."""
    left, right, bottom, top = PATH_MARGINS_IN
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    width = PATH_WIDTH_IN - left - right
    low, high = PATH_HEIGHT_IN
    height = min(max(width * (y1 - y0) / (x1 - x0) + bottom + top, low), high)
    fig.set_size_inches(PATH_WIDTH_IN, height)
    fig.subplots_adjust(
        left=left / PATH_WIDTH_IN,
        right=1.0 - right / PATH_WIDTH_IN,
        bottom=bottom / height,
        top=1.0 - top / height,
    )


def plot_errors(result: SimulationResult, *, fig: Figure | None = None) -> Figure:
    """End-effector position error (log scale, floored at :data:`ERROR_FLOOR`) and
    orientation error vs time; returns the figure.

    Drawn on a 7 x 5 inch figure of its own, or into ``fig``, an empty figure of the
    caller's (``plt.figure()``: then ``plt.show()`` shows it), kept at its size and layout
    engine; anything else as ``fig`` (not a Figure, one holding axes or of zero width or
    height) is a one-line :class:`~ddwmmr.errors.ParameterError` naming ``fig``."""
    ts = _run(result).timeseries
    fig, own = _figure_for(fig, (7, 5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    position = np.maximum(ts["position_error_m"], ERROR_FLOOR)
    ax1.semilogy(ts["t"], position, color="tab:blue")
    at_least_a_decade(ax1, position)
    ax1.set_ylabel("position error (m)")
    ax1.grid(alpha=0.3, which="both")
    ax2.plot(*break_wraps(ts["t"], ts["orientation_error_rad"]), color="tab:red")
    at_least_a_percent(ax2, ts["orientation_error_rad"])
    ax2.set_ylabel("orientation error (rad)\nwrapped to [-pi, pi)")
    ax2.set_xlabel("t (s)")
    ax2.grid(alpha=0.3)
    ax1.set_title(_title(result, "tracking errors"))
    _lay_out(fig, own)
    return fig


def at_least_a_decade(ax: Axes, values: np.ndarray) -> None:
    """Give the log-scaled y axis of ``ax`` whole decades around ``values`` (> 0 where
    finite) if they span less than a factor of 3. Such a span may hold only one of the
    log ticks ``m 10^k`` (``m`` = 1..9); matplotlib then falls back to linear ticks and
    labels each tick of a near-constant series with the same rounded number. A factor of
    3 always holds two log ticks, so wider data keep matplotlib's limits."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite) & (finite > 0.0)]
    if finite.size == 0 or finite.max() >= 3.0 * finite.min():
        return
    low = math.floor(math.log10(finite.min()))
    high = max(math.ceil(math.log10(finite.max())), low + 1)
    ax.set_ylim(10.0**low, 10.0**high)


def at_least_a_percent(ax: Axes, values: np.ndarray) -> None:
    """Give the linear y axis of ``ax`` a span of at least 1 % of the largest magnitude of
    ``values`` (centred on them), and tick labels without an offset: a near-constant
    series would otherwise read as an offset such as "1e-13-2.607e-2" above ticks of
    its last digits. Data varying by more keep matplotlib's limits."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    ax.ticklabel_format(axis="y", useOffset=False)
    if finite.size == 0:
        return
    low, high = float(finite.min()), float(finite.max())
    span = 0.01 * max(abs(low), abs(high))
    if high - low < span:
        centre = 0.5 * (low + high)
        ax.set_ylim(centre - 0.5 * span, centre + 0.5 * span)


def plot_rates(result: SimulationResult, *, fig: Figure | None = None) -> Figure:
    """Arm joint rates, base yaw rate and wheel speeds vs time (rad/s), each on its own
    axis, with the robot's limits drawn and named (the base yaw rate has no limit of its
    own: the wheel limit bounds it). The yaw rate drawn is the one the wheel speeds come
    from: the measured one on a plant whose base lags its command (the command then a thin
    dashed line), else the command, which is the motion (:func:`wheels_follow_measured`).

    Drawn on an 8.6 x 6.4 inch figure of its own, or into ``fig`` as :func:`plot_errors`
    does; returns the figure."""
    ts, robot = _run(result).timeseries, result.robot
    fig, own = _figure_for(fig, (8.6, 6.4))
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    ax1.plot(ts["t"], ts["th1dot"], label="th1dot")
    ax1.plot(ts["t"], ts["th2dot"], label="th2dot")
    _limit_lines(ax1, robot.joint_speed_limit, "joint limit")
    ax1.set_ylabel("arm joint rate\n(rad/s)")
    if wheels_follow_measured(result):
        ax2.plot(ts["t"], ts["w_measured"], color="tab:green", label="w measured")
        ax2.plot(ts["t"], ts["w"], color="k", ls="--", lw=0.8, label="w commanded")
    else:
        ax2.plot(ts["t"], ts["w"], color="tab:green", label="w (base yaw rate)")
    ax2.set_ylabel("base yaw rate\n(rad/s)")
    ax3.plot(ts["t"], ts["wheel_left_rad_s"], label="left wheel")
    ax3.plot(ts["t"], ts["wheel_right_rad_s"], ls="--", label="right wheel")
    _limit_lines(ax3, robot.wheel_speed_limit, "wheel limit")
    ax3.set_ylabel("wheel speed\n(rad/s)")
    ax3.set_xlabel("t (s)")
    ax1.set_title(_title(result, "rates"))
    for ax in (ax1, ax2, ax3):
        ax.grid(alpha=0.3)
        legend_beside(ax, fontsize=8)
    _lay_out(fig, own)
    return fig


def wheels_follow_measured(result: SimulationResult) -> bool:
    """True when the run's wheel speeds are those of its measured base velocities
    (``v_measured``, ``w_measured``: a plant whose base has dynamics) rather than of the
    command: the yaw rate the wheels imply, ``r (right - left) / track_width`` (rad/s),
    equals ``w_measured`` and differs from the commanded ``w`` somewhere."""
    ts, robot = result.timeseries, result.robot
    if "w_measured" not in ts:
        return False
    implied = (
        robot.wheel_radius * (ts["wheel_right_rad_s"] - ts["wheel_left_rad_s"]) / robot.track_width
    )
    measured, commanded = np.asarray(ts["w_measured"]), np.asarray(ts["w"])
    tolerance: _Tolerance = {"rtol": 1e-9, "atol": 1e-12, "equal_nan": True}
    return bool(
        np.allclose(implied, measured, **tolerance)
        and not np.allclose(measured, commanded, **tolerance)
    )


def _limit_lines(ax: Axes, limit: float, name: str) -> None:
    """Dotted lines at +-limit with one legend entry naming the value."""
    for sign in (-1, 1):
        ax.axhline(
            sign * limit,
            color="0.4",
            ls=":",
            lw=1,
            label=f"{name} +-{limit:g} rad/s" if sign > 0 else None,
        )


def plot_metrics(result: SimulationResult, *, fig: Figure | None = None) -> Figure:
    """Manipulability eta and tip-over stability S vs time (S = 1 tips); returns the figure.

    Drawn on a 7 x 5 inch figure of its own, or into ``fig`` as :func:`plot_errors` does."""
    ts = _run(result).timeseries
    fig, own = _figure_for(fig, (7, 5))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(ts["t"], ts["manipulability"], color="tab:purple")
    ax1.set_ylim(0, 1.05)
    ax1.set_ylabel("manipulability eta")
    ax1.grid(alpha=0.3)
    ax2.plot(ts["t"], ts["stability"], color="tab:brown", label="S = min(S_lon, S_lat)")
    ax2.axhline(1.0, color="tab:red", ls="--", lw=1, label="tip-over (S = 1)")
    stability_min = result.summary.get("stability_min")
    if stability_min:
        ax2.axhline(
            stability_min, color="tab:orange", ls=":", lw=1, label=f"S_min = {stability_min:g}"
        )
    ax2.set_ylabel("stability S")
    ax2.set_xlabel("t (s)")
    ax2.grid(alpha=0.3)
    ax1.set_title(_title(result, "performance metrics"))
    _lay_out(fig, own)
    place_legend(ax2, fontsize=8)
    return fig


def save_run_figures(
    result: SimulationResult, folder: str | Path, obstacles: Obstacles = None
) -> list[Path]:
    """Write path.png (with ``obstacles``), errors.png, rates.png, metrics.png in
    ``folder``, an existing folder; anything else, or a file that cannot be written, is a
    one-line :class:`~ddwmmr.errors.ParameterError` naming ``folder``."""
    _run(result)
    folder = as_path(folder, "folder")
    if not folder.is_dir():
        raise ParameterError(f"folder: {folder} is not an existing folder")
    paths = []
    makers: tuple[Callable[[SimulationResult], Figure], ...] = (
        lambda r: plot_path(r, obstacles=obstacles),
        plot_errors,
        plot_rates,
        plot_metrics,
    )
    for name, make in zip(FIGURE_NAMES, makers):
        fig = make(result)
        path = folder / name
        try:
            fig.savefig(path, dpi=110, metadata=PNG_METADATA)
        except OSError as exc:
            raise ParameterError(f"folder: cannot write {path} ({exc.strerror or exc})") from None
        paths.append(path)
    return paths


def save_animation(
    result: SimulationResult,
    path: str | Path,
    frames: int = 80,
    fps: int = 15,
    obstacles: Obstacles = None,
    progress: bool = False,
) -> Path:
    """Write a GIF of the robot following the trajectory: ``frames`` evenly spaced
    recorded instants (every instant of a run with fewer), ``fps`` per second;
    ``progress`` shows the encoding on stderr (:mod:`ddwmmr.progress`). ``frames`` is an
    integer >= 1, ``fps`` one in [1, 100] (a GIF times its frames in hundredths of a
    second); a ``path`` that is not one, or cannot be written, is a one-line
    :class:`~ddwmmr.errors.ParameterError` naming it."""
    from ddwmmr.progress import ProgressBar

    path, frames, fps = checked_gif_options(path, frames, fps)
    obstacles = circles_of(obstacles)  # read and checked once, before anything is drawn
    ts, robot = _run(result).timeseries, result.robot
    q = result.configurations()
    fig = new_figure((5, 4.5))
    ax = fig.subplots()
    draw_obstacles(ax, obstacles)
    ax.plot(ts["xE_d"], ts["yE_d"], "k--", lw=1)
    reach = robot.reach + robot.base_length
    ax.set_xlim(
        min(ts["x"].min(), ts["xE"].min()) - reach, max(ts["x"].max(), ts["xE"].max()) + reach
    )
    ax.set_ylim(
        min(ts["y"].min(), ts["yE"].min()) - reach, max(ts["y"].max(), ts["yE"].max()) + reach
    )
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    (trace,) = ax.plot([], [], color="tab:blue", lw=1.2)
    (footprint,) = ax.plot([], [], color="0.3")
    (arm,) = ax.plot([], [], color="tab:orange", lw=2, marker="o", ms=3)
    indices = frame_indices(len(q) - 1, frames)

    def update(frame: int) -> tuple[Line2D, Line2D, Line2D, Text]:
        k = indices[frame]
        shape = robot_outline(robot, q[k])
        trace.set_data(ts["xE"][: k + 1], ts["yE"][: k + 1])
        footprint.set_data(*shape["footprint"].T)
        arm.set_data(*shape["arm"].T)
        title = ax.set_title(f"{_title(result, '')} t = {ts['t'][k]:.1f} s")
        return trace, footprint, arm, title

    with ProgressBar(len(indices), "track: animation.gif", enabled=progress, unit="frame") as bar:
        try:
            save_gif(fig, update, len(indices), path, fps, bar.advance)
        except OSError as exc:
            raise ParameterError(f"path: cannot write {path} ({exc.strerror or exc})") from None
    return path


def _run(result: SimulationResult) -> SimulationResult:
    """``result`` if it holds a ``timeseries`` mapping, as a
    :class:`~ddwmmr.sim.SimulationResult` does, else a one-line
    :class:`~ddwmmr.errors.ParameterError` naming ``result``."""
    if not isinstance(getattr(result, "timeseries", None), Mapping):
        raise ParameterError(f"result must be a SimulationResult (got {shown(result, 60)})")
    return result


def _figure_for(fig: object, figsize: tuple[float, float]) -> tuple[Figure, bool]:
    """``(figure, own)``: a new figure of ``figsize`` (width, height in inches) made here
    when ``fig`` is None (``own`` True), else ``fig``, the caller's, checked by
    :func:`_figure_to_draw_into` (``own`` False)."""
    if fig is None:
        return new_figure(figsize), True
    return _figure_to_draw_into(fig), False


def _figure_to_draw_into(fig: object) -> Figure:
    """``fig`` if it is a :class:`~matplotlib.figure.Figure` holding no axes, with a
    positive width and height (inches), else a one-line
    :class:`~ddwmmr.errors.ParameterError` naming ``fig``.

    A figure that already holds axes is refused rather than cleared or drawn over: the
    panels are laid out over the whole figure, so they would hide the caller's axes, and
    clearing would throw the caller's drawing away. (An axes passed to :func:`plot_path`
    is drawn into as it is: one more path on a map is a meaningful overlay.)"""
    if not isinstance(fig, Figure):
        raise ParameterError(
            f"fig: must be a matplotlib Figure, e.g. plt.figure() (got {type(fig).__name__})"
        )
    if fig.axes:
        raise ParameterError(
            f"fig: must be an empty Figure (it holds {len(fig.axes)} axes); "
            "pass a new one, e.g. plt.figure(), or call fig.clear() first"
        )
    width, height = fig.get_size_inches()
    if not (width > 0.0 and height > 0.0):  # no panel fits: matplotlib's layout divides by 0
        raise ParameterError(
            f"fig: must have a positive width and height (it is {width:g} x {height:g} "
            "inches); pass e.g. plt.figure(figsize=(7, 5))"
        )
    return fig


def _lay_out(fig: Figure, own: bool) -> None:
    """Lay the panels of ``fig`` out: ``tight_layout`` on a figure made here (``own``) or
    on a caller's without a layout engine; a caller's figure with an engine of its own
    (``plt.figure(layout="constrained")``) is laid out by that engine, which it keeps
    (``tight_layout`` would drop it with a warning)."""
    engine = fig.get_layout_engine()
    if own or engine is None or isinstance(engine, PlaceHolderLayoutEngine):
        fig.tight_layout()
    else:
        engine.execute(fig)


def _axes(ax: Axes | None, figsize: tuple[float, float]) -> tuple[Figure | SubFigure, Axes]:
    """``ax`` and the figure it is on (a caller's axes in a SubFigure: that subfigure), or
    a new figure of ``figsize`` (inches) and its one axes."""
    if ax is not None:
        return ax.figure, ax
    fig = new_figure(figsize)
    return fig, fig.subplots()


def _title(result: SimulationResult, what: str) -> str:
    """``"<method> on <trajectory>: <what>"``, with ``" (<plant> plant)"`` after the
    trajectory when the run's plant is not the kinematic model."""
    return run_title(result.summary, what)


def run_title(summary: Mapping[str, Any], what: str) -> str:
    """Title of a figure of the run whose summary is ``summary``: method, trajectory, the
    plant unless it is the kinematic model (a summary without one is kinematic), then
    ``what`` after a colon (left out when empty)."""
    plant = summary.get("plant") or "kinematic"
    named = "" if plant == "kinematic" else f" ({plant} plant)"
    head = f"{summary.get('method', '?')} on {summary.get('trajectory', '?')}{named}"
    return f"{head}: {what}".rstrip(": ")
