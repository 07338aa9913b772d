"""Figures of the method comparison (``python -m ddwmmr.compare``).

Every function takes plain data (time series as ``dict[str, np.ndarray]`` with the columns
of :data:`ddwmmr.sim.simulate.COLUMNS`, keyed by a label) and returns a matplotlib Figure;
:func:`save` writes it as PNG. World frame, SI units (m, rad, s). The figures are not
pyplot's (:mod:`ddwmmr.reports.canvas`): importing this module leaves the matplotlib
backend alone.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle

from ddwmmr.model import Robot
from ddwmmr.reports.canvas import new_figure
from ddwmmr.reports.legends import legend_beside, place_legend
from ddwmmr.reports.plots import (  # errors are clipped to the floor on log axes
    ERROR_FLOOR,
    break_wraps,
)

#: Resolution of the saved PNGs (dots per inch).
DPI = 100
#: Narrowest figure of :func:`plot_small_multiples` (in): two panels' width, which holds
#: its title and legend when one or two methods are compared.
MIN_MULTIPLES_WIDTH_IN = 8.8

Series = Mapping[str, Mapping[str, np.ndarray]]


def save(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as PNG to ``path``. The figure is not pyplot's
    (:func:`~ddwmmr.reports.canvas.new_figure`): nothing to close, it is freed with its
    last reference."""
    path = Path(path)
    fig.savefig(path, dpi=DPI)
    return path


def _floor(values: np.ndarray) -> np.ndarray:
    floored: np.ndarray = np.maximum(np.abs(values), ERROR_FLOOR)
    return floored


def _log_bottom(series: Sequence[np.ndarray]) -> float:
    """Bottom (m) of a log error axis drawn from ``series``: half the smallest error drawn
    (floored at :data:`ERROR_FLOOR`), so the axis stops where the data do instead of
    running decades below them."""
    finite = [v[np.isfinite(v)] for v in (_floor(np.asarray(s, dtype=float)) for s in series)]
    lowest = min((float(v.min()) for v in finite if v.size), default=ERROR_FLOOR)
    return lowest / 2.0


def _line_widths(count: int) -> list[float]:
    """Widths from wide to thin, so lines drawn in this order stay visible where they
    coincide (each one is a thinner stroke on top of the previous)."""
    return list(np.linspace(3.2, 1.0, count)) if count > 1 else [1.4]


def _grid_shape(count: int) -> tuple[int, int]:
    columns = min(3, max(count, 1))
    return math.ceil(max(count, 1) / columns), columns


def _path_limits(ax: Axes, series: Series, margin: float, obstacles: Sequence[Any] = ()) -> None:
    """Frame the desired path plus ``margin`` (m), grown to hold every method's path and
    the ``obstacles``."""
    from ddwmmr.reports.plots import fit_equal

    reference = next(iter(series.values()))
    x0, y0 = reference["xE_d"], reference["yE_d"]
    cx, cy = _obstacle_extent(obstacles)
    xs = np.r_[x0.min() - margin, x0.max() + margin, cx, *[ts["xE"] for ts in series.values()]]
    ys = np.r_[y0.min() - margin, y0.max() + margin, cy, *[ts["yE"] for ts in series.values()]]
    fit_equal(ax, xs, ys, 0.05)


def _obstacle_extent(obstacles: Sequence[Any]) -> tuple[np.ndarray, np.ndarray]:
    """The x and y (m) of the bounding boxes' sides of the ``obstacles`` (circles or (x, y,
    radius) triples), so a frame fitted to them holds every disc whole."""
    from ddwmmr.reports.plots import circles_of

    circles = np.array(circles_of(obstacles)).reshape(-1, 3)
    x, y, radius = circles.T
    return np.r_[x - radius, x + radius], np.r_[y - radius, y + radius]


def zoom_window(
    series: Series, t_center: float, half_width: float | None = None, window: float = 1.0
) -> tuple[float, float, float]:
    """Centre (m) and half-width (m) of a zoom on the desired position at ``t_center``.

    Without ``half_width``: 1.5 x the largest error, within ``window`` s after
    ``t_center``, of the methods that stay within 0.3 m there (so the panel shows how far
    the tracking methods are off), at least 2 cm and at most 0.3 m.
    """
    reference = next(iter(series.values()))
    k = int(np.argmin(np.abs(reference["t"] - t_center)))
    cx, cy = float(reference["xE_d"][k]), float(reference["yE_d"][k])
    if half_width is None:
        peaks = []
        for ts in series.values():
            mask = (ts["t"] >= t_center) & (ts["t"] <= t_center + window)
            peak = float(np.max(ts["position_error_m"][mask])) if np.any(mask) else math.nan
            if peak < 0.3:
                peaks.append(peak)
        half_width = 1.5 * max(peaks) if peaks else 0.3
    return cx, cy, float(np.clip(half_width, 0.02, 0.3))


def plot_paths(
    series: Series,
    colors: Mapping[str, str],
    title: str,
    zooms: Sequence[tuple[str, float, float | None]] = (),
    obstacles: Sequence[Any] = (),
) -> Figure:
    """End-effector paths of every method on the desired path, with zoom panels.

    The methods are drawn from wide to thin lines, so methods that follow each other stay
    visible, and the desired path over them, thin and dashed, so it shows where they
    follow it.

    Args:
        zooms: ``(label, t, half_width)`` per zoom panel: the region around the desired
            position at time t (s), half-width in m (None: from the errors, see
            :func:`zoom_window`); each method's position at time t is marked with a dot.
        obstacles: the runs' circular obstacles (circles or (x, y, radius) triples, m),
            drawn as grey discs in every panel; the main frame holds them.
    """
    fig = new_figure((11.5, 6.8))
    grid = fig.add_gridspec(max(len(zooms), 1), 2, width_ratios=(1.5, 1))
    ax = fig.add_subplot(grid[:, 0])
    _draw_paths(ax, series, colors, obstacles=obstacles)
    _path_limits(ax, series, 0.5, obstacles)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    for row, (label, t_center, half_width) in enumerate(zooms):
        cx, cy, h = zoom_window(series, t_center, half_width)
        zoom = fig.add_subplot(grid[row, 1])
        _draw_paths(zoom, series, colors, mark_time=t_center, obstacles=obstacles)
        zoom.set_xlim(cx - h, cx + h)
        zoom.set_ylim(cy - h, cy + h)
        zoom.set_aspect("equal", adjustable="box")
        zoom.set_title(f"{label}: around t = {t_center:g} s (dots: positions at t)", fontsize=9)
        zoom.tick_params(labelsize=7)
        zoom.set_xlabel("x (m)", fontsize=8)
        zoom.set_ylabel("y (m)", fontsize=8)
        ax.add_patch(
            Rectangle((cx - h, cy - h), 2 * h, 2 * h, fill=False, color="0.3", lw=0.9, zorder=6)
        )
        ax.annotate(label, (cx + h, cy + h), fontsize=9, color="0.2", zorder=6)
    handles, labels = ax.get_legend_handles_labels()
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8, frameon=False)
    return fig


def _draw_paths(
    ax: Axes,
    series: Series,
    colors: Mapping[str, str],
    mark_time: float | None = None,
    obstacles: Sequence[Any] = (),
) -> None:
    from ddwmmr.reports.plots import draw_obstacles

    draw_obstacles(ax, obstacles)
    reference = next(iter(series.values()))
    # The desired path over the methods, thin and dashed: visible where they follow it.
    ax.plot(
        reference["xE_d"], reference["yE_d"], "--", color="k", lw=0.9, label="desired", zorder=3
    )
    for width, (label, ts) in zip(_line_widths(len(series)), series.items()):
        ax.plot(ts["xE"], ts["yE"], color=colors[label], lw=width, label=label, alpha=0.9)
        ax.plot(ts["xE"][0], ts["yE"][0], "o", color=colors[label], ms=4)
        if mark_time is not None:
            k = int(np.argmin(np.abs(ts["t"] - mark_time)))
            ax.plot(ts["xE"][k], ts["yE"][k], "o", color=colors[label], ms=5, mec="k", mew=0.5)
    if mark_time is not None:
        k = int(np.argmin(np.abs(reference["t"] - mark_time)))
        ax.plot(reference["xE_d"][k], reference["yE_d"][k], "x", color="k", ms=7)
    ax.grid(alpha=0.3)


def plot_errors(series: Series, colors: Mapping[str, str], title: str) -> Figure:
    """Position error (log scale) and orientation error vs time for every method."""
    fig = new_figure((9, 6))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for label, ts in series.items():
        ax1.semilogy(ts["t"], _floor(ts["position_error_m"]), color=colors[label], label=label)
        ax2.plot(*break_wraps(ts["t"], ts["orientation_error_rad"]), color=colors[label], lw=1)
    ax1.set_ylabel("position error (m, log)")
    ax1.set_ylim(bottom=ERROR_FLOOR / 2)
    ax1.grid(alpha=0.3, which="major")
    ax1.set_title(title)
    ax2.set_ylabel("orientation error (rad, wrapped)")
    _pi_ticks(ax2)
    ax2.set_xlabel("t (s)")
    ax2.grid(alpha=0.3)
    legend_beside(ax1, fontsize=8)
    fig.tight_layout()
    return fig


def _pi_ticks(ax: Axes) -> None:
    ax.set_ylim(-math.pi * 1.05, math.pi * 1.05)
    ax.set_yticks([-math.pi, -math.pi / 2, 0, math.pi / 2, math.pi])
    ax.set_yticklabels(["-pi", "-pi/2", "0", "pi/2", "pi"])


def plot_wheels(series: Series, colors: Mapping[str, str], limit: float, title: str) -> Figure:
    """Small multiples: left and right wheel speeds (rad/s) per method, with the limit;
    every panel has its time axis labelled, one legend (above the panels) names the
    styles."""
    rows, columns = _grid_shape(len(series))
    fig = new_figure((4 * columns, 2.7 * rows + 0.6))
    axes = fig.subplots(rows, columns, sharey=True, squeeze=False)
    for ax, (label, ts) in zip(axes.flat, series.items()):
        ax.plot(ts["t"], ts["wheel_left_rad_s"], color=colors[label], lw=1)
        ax.plot(ts["t"], ts["wheel_right_rad_s"], color=colors[label], lw=1, ls="--")
        for sign in (-1.0, 1.0):
            ax.axhline(sign * limit, color="0.4", ls=":", lw=1)
        ax.set_title(label, fontsize=9, color=colors[label])
        ax.grid(alpha=0.3)
        ax.set_xlabel("t (s)", fontsize=8)
        ax.tick_params(labelsize=8, labelleft=True)
    for ax in axes.flat[len(series) :]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel("wheel speed (rad/s)")
    styles = [
        Line2D([], [], color="0.2", lw=1, label="left wheel (solid)"),
        Line2D([], [], color="0.2", lw=1, ls="--", label="right wheel (dashed)"),
        Line2D([], [], color="0.4", lw=1, ls=":", label=f"limit +-{limit:g} rad/s (dotted)"),
    ]
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.45 / fig.get_figheight()))
    fig.legend(
        handles=styles,
        loc="upper right",
        ncol=3,
        fontsize=8,
        frameon=False,
        bbox_to_anchor=(1.0, 1.0 - 0.3 / fig.get_figheight()),
    )
    return fig


def plot_small_multiples(
    series: Series,
    colors: Mapping[str, str],
    robot: Robot,
    title: str,
    snapshots: int = 6,
    obstacles: Sequence[Any] = (),
) -> Figure:
    """One panel per method: desired and actual end-effector path, base path, the robot
    at ``snapshots`` instants, one grey per instant (named in the figure's legend: no
    text next to the robots, which would cover the paths), and the runs' ``obstacles``
    (circles or (x, y, radius) triples, m) as grey discs. Each panel holds everything it
    draws: the frame of the desired path, grown for a method that leaves it. The figure is
    at least :data:`MIN_MULTIPLES_WIDTH_IN` wide, so one or two panels leave room for the
    title and legend."""
    from ddwmmr.reports.plots import (
        draw_obstacles,
        draw_snapshots,
        fit_equal,
        outline_points,
        snapshot_indices,
    )

    rows, columns = _grid_shape(len(series))
    width = max(4.4 * columns, MIN_MULTIPLES_WIDTH_IN)
    fig = new_figure((width, 4.2 * rows))
    axes = fig.subplots(rows, columns, squeeze=False)
    handles: list[Line2D] = []
    cx, cy = _obstacle_extent(obstacles)
    for ax, (label, ts) in zip(axes.flat, series.items()):
        draw_obstacles(ax, obstacles)
        indices = snapshot_indices(ts, snapshots)
        handles = draw_snapshots(ax, robot, ts, indices, lw=0.8)
        ax.plot(ts["x"], ts["y"], color="0.6", lw=0.9)
        ax.plot(ts["xE"], ts["yE"], color=colors[label], lw=2.0, alpha=0.85)
        ax.plot(ts["xE_d"], ts["yE_d"], "k--", lw=0.9)
        outline = outline_points(robot, ts, indices)
        frame = robot.reach + 0.4
        fit_equal(
            ax,
            np.r_[
                ts["xE_d"].min() - frame,
                ts["xE_d"].max() + frame,
                ts["xE"],
                ts["x"],
                outline[:, 0],
                cx,
            ],
            np.r_[
                ts["yE_d"].min() - frame,
                ts["yE_d"].max() + frame,
                ts["yE"],
                ts["y"],
                outline[:, 1],
                cy,
            ],
            0.1,
        )
        ax.set_title(label, fontsize=9, color=colors[label])
        ax.tick_params(labelsize=7)
        ax.set_xlabel("x (m)", fontsize=8)
        ax.set_ylabel("y (m)", fontsize=8)
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(series) :]:
        ax.set_visible(False)
    fig.suptitle(
        f"{title}: dashed desired, colour end effector, grey base path; "
        f"the robot at {snapshots} instants"
    )
    empty = rows * columns - len(series)
    if empty:  # the legend in the free panels of the last row
        fig.tight_layout()
        corner = axes.flat[len(series)].get_position()
        fig.legend(
            handles=handles,
            loc="upper left",
            bbox_to_anchor=(corner.x0, corner.y1),
            fontsize=9,
            title="robot colour: time",
            title_fontsize=9,
        )
    else:
        # under three panels one row of legend entries is wider than the figure: two rows
        ncol = len(handles) if columns >= 3 else math.ceil(len(handles) / 2)
        legend_rows = math.ceil(len(handles) / max(ncol, 1))
        fig.tight_layout(rect=(0, 0.06 + 0.11 * (legend_rows - 1), 1, 1))
        fig.legend(handles=handles, loc="lower center", ncol=ncol, fontsize=9, frameon=False)
    return fig


def plot_tau_study(
    error_curves: Mapping[str, Mapping[float, tuple[np.ndarray, np.ndarray]]],
    convergence: Mapping[str, Mapping[float, float]],
    theory: float,
    colors: Mapping[str, str],
) -> Figure:
    """Time-constant sweep: error vs time per tau (first method), and convergence time
    divided by tau vs tau for every method.

    Dividing by tau turns the first-order prediction ``-ln(fraction) tau`` into a
    horizontal line, so a method that follows it lies on the line and one that does not
    stands out; methods with equal values are drawn with different markers and slightly
    offset in tau (by a few per cent) so none hides another.

    Args:
        error_curves: method -> tau (s) -> (t, position error) arrays.
        convergence: method -> tau (s) -> convergence time (s, NaN if never).
        theory: convergence time / tau of a first-order decay (-ln of the fraction).
    """
    fig = new_figure((11, 4.2))
    ax1, ax2 = fig.subplots(1, 2)
    first = next(iter(error_curves))
    cmap = matplotlib.colormaps["viridis"]
    taus = sorted(error_curves[first])
    for i, tau in enumerate(taus):
        t, e = error_curves[first][tau]
        ax1.semilogy(t, _floor(e), color=cmap(i / max(len(taus) - 1, 1)), label=f"tau = {tau:g} s")
    ax1.set_xlabel("t (s)")
    ax1.set_ylabel("position error (m, log)")
    ax1.set_title(f"{first}: error vs time")
    ax1.set_ylim(bottom=ERROR_FLOOR / 2)
    ax1.grid(alpha=0.3)
    markers = "osD^vP*X"
    count = len(convergence)
    for i, (method, values) in enumerate(convergence.items()):
        xs = sorted(values)
        dodge = 1.0 + 0.04 * (i - (count - 1) / 2)
        ax2.plot(
            [x * dodge for x in xs],
            [values[x] / x for x in xs],
            marker=markers[i % len(markers)],
            ls="-",
            lw=1,
            ms=6,
            mfc="none",
            color=colors[method],
            label=method,
        )
    ax2.axhline(theory, color="k", ls=":", label=f"first order: {theory:.3f}")
    if not any(math.isfinite(v) for values in convergence.values() for v in values.values()):
        _say_none_converged(ax2, [tau for values in convergence.values() for tau in values])
    ax2.set_xscale("log")
    ax2.set_ylim(0.0, 2.0 * theory)
    ax2.set_xlabel("tau (s) (methods offset by a few % to stay visible)")
    ax2.set_ylabel("convergence time / tau")
    ax2.set_title("convergence time is proportional to tau")
    ax2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    place_legend(ax1, fontsize=8)
    place_legend(ax2, fontsize=8)
    return fig


def _say_none_converged(ax: Axes, taus: Sequence[float]) -> None:
    """Mark the convergence panel of a sweep in which no run converged (every time NaN):
    a note below the first-order line (drawn at half the panel's height), and its tau
    axis (log) spanning ``taus`` (s), which the NaN points, drawn nowhere, do not set."""
    low, high = min(taus), max(taus)
    ax.set_xlim(low / 1.5, high * 1.5)
    ax.text(
        0.5,
        0.25,
        "no run converged within the simulated time",
        transform=ax.transAxes,
        ha="center",
        va="center",
        fontsize=10,
        color="0.3",
    )


#: Two lines of the initial-offset study coincide when they are this close (px) at every
#: offset: about two line widths at the figure's resolution.
COINCIDE_PX = 4.0

#: Two lines of the step-size study coincide on the plot when they are within this
#: factor of each other at every step (a few line widths on its log axis).
COINCIDE_FACTOR = 1.15


def coinciding_groups(
    lines: Mapping[str, Sequence[float]], factor: float = COINCIDE_FACTOR
) -> list[list[str]]:
    """Groups (of two or more names, in the given order) of lines whose values agree
    within ``factor`` at every point: drawn on a log axis they lie on each other. Each
    line belongs to at most one group (the first that it matches)."""
    names = list(lines)
    logs = {n: np.log(np.maximum(np.asarray(lines[n], float), ERROR_FLOOR)) for n in names}
    limit = math.log(factor)
    groups: list[list[str]] = []
    placed: set[str] = set()
    for i, name in enumerate(names):
        if name in placed:
            continue
        group = [name]
        for other in names[i + 1 :]:
            same_shape = other not in placed and logs[other].shape == logs[name].shape
            if same_shape and np.max(np.abs(logs[other] - logs[name])) <= limit:
                group.append(other)
        if len(group) > 1:
            groups.append(group)
            placed.update(group)
    return groups


def coinciding_looks(
    lines: Mapping[str, Sequence[float]], factor: float = COINCIDE_FACTOR
) -> tuple[dict[str, tuple[float, str]], list[list[str]]]:
    """Line width and marker of every line in a :func:`coinciding_groups` group (from
    wide to thin, a different marker each, so that each stays visible), and the groups."""
    groups = coinciding_groups(lines, factor)
    look: dict[str, tuple[float, str]] = {}
    for group in groups:
        for width, marker, name in zip(_line_widths(len(group)), "os^D", group):
            look[name] = (width + 0.6, marker)
    return look, groups


def coinciding_note(groups: list[list[str]]) -> str | None:
    """A legend title naming the lines that lie on each other (None: there are none)."""
    if not groups:
        return None
    return "lying on each other\n(wide to thin):\n" + "\n".join(" = ".join(g) for g in groups)


def plot_dt_study(
    drift: Mapping[str, Mapping[str, Mapping[float, float]]], colors: Mapping[str, str]
) -> Figure:
    """Step-size sweep: largest position error vs dt (log-log), Euler solid, RK4 dashed.

    Lines that lie on each other (:func:`coinciding_groups`) are drawn from wide to thin
    with different markers, so each stays visible, and the legend names them.

    Args:
        drift: method -> integrator -> dt (s) -> largest position error (m).
    """
    fig = new_figure((10, 5))
    ax = fig.subplots()
    styles = {"euler": "-", "rk4": "--"}
    steps = sorted({x for by in drift.values() for values in by.values() for x in values})
    lines = {
        f"{method} ({integrator})": [values.get(x, math.nan) for x in steps]
        for method, by_integrator in drift.items()
        for integrator, values in by_integrator.items()
    }
    look, groups = coinciding_looks(lines)
    for method, by_integrator in drift.items():
        for integrator, values in by_integrator.items():
            name = f"{method} ({integrator})"
            width, marker = look.get(name, (1.4, "o"))
            xs = sorted(values)
            ax.loglog(
                xs,
                [max(values[x], ERROR_FLOOR) for x in xs],
                styles.get(integrator, "-."),
                marker=marker,
                ms=3 + width,
                mfc="none" if name in look else colors[method],
                lw=width,
                color=colors[method],
                label=name,
            )
    ax.set_xlabel("step dt (s)")
    ax.set_ylabel("largest position error (m)")
    ax.set_title("drift vs step size: Euler (solid) is first order, RK4 (dashed) fourth")
    ax.grid(alpha=0.3, which="both")
    legend_beside(ax, fontsize=8, title=coinciding_note(groups), title_fontsize=8, alignment="left")
    fig.tight_layout()
    return fig


def plot_integrator_study(
    curves: Mapping[str, Mapping[str, tuple[np.ndarray, np.ndarray]]],
    colors: Mapping[str, str],
    dt: float,
) -> Figure:
    """Euler vs RK4 at the default step: position error vs time per method.

    Args:
        curves: method -> integrator -> (t, position error) arrays.
        dt: the step (s), for the title.
    """
    fig = new_figure((9.5, 5))
    ax = fig.subplots()
    styles = {"euler": "-", "rk4": "--"}
    for method, by_integrator in curves.items():
        for integrator, (t, e) in by_integrator.items():
            style = styles.get(integrator, "-.")
            label = f"{method} ({integrator})"
            ax.semilogy(t, _floor(e), style, color=colors[method], lw=1.1, label=label)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("position error (m, log), no initial offset")
    ax.set_ylim(bottom=ERROR_FLOOR / 2)
    ax.set_title(f"Euler (solid) vs RK4 (dashed) at dt = {dt:g} s")
    ax.grid(alpha=0.3)
    legend_beside(ax, fontsize=8)
    fig.tight_layout()
    return fig


def plot_init_study(
    final: Mapping[str, Mapping[float, float]],
    curves: Mapping[float, tuple[np.ndarray, np.ndarray]],
    curve_method: str,
    colors: Mapping[str, str],
) -> Figure:
    """Initial-offset sweep: settled-end RMS error vs initial offset, and one method's error
    curves. Methods whose errors lie on each other are drawn from wide to thin and named
    in the legend's title (:func:`coinciding_looks`).

    Args:
        final: method -> initial offset (m) -> settled-end RMS position error (m,
            ``final_position_error_m``).
        curves: initial offset (m) -> (t, position error) for ``curve_method``.
    """
    fig = new_figure((11, 4.2))
    ax1, ax2 = fig.subplots(1, 2)
    drawn = {}
    for method, values in final.items():
        xs = sorted(values)
        errors = [max(values[x], ERROR_FLOOR) for x in xs]
        (drawn[method],) = ax1.plot(
            [1000 * x for x in xs], errors, "o-", color=colors[method], label=method
        )
    ax1.set_yscale("log")
    ax1.set_xlabel("initial end-effector offset (mm)")
    ax1.set_ylabel("settled-end RMS position error (m, log)")
    ax1.set_title("open loop keeps the offset, closed loop removes it")
    ax1.grid(alpha=0.3, which="both")
    cmap = matplotlib.colormaps["viridis"]
    offsets = sorted(curves)
    for i, offset in enumerate(offsets):
        t, e = curves[offset]
        colour = cmap(i / max(len(offsets) - 1, 1))
        ax2.semilogy(t, _floor(e), color=colour, label=f"{1000 * offset:.0f} mm")
    ax2.set_ylim(bottom=ERROR_FLOOR / 2)
    ax2.set_xlabel("t (s)")
    ax2.set_ylabel("position error (m, log)")
    ax2.set_title(f"{curve_method}: error vs time per initial offset")
    ax2.grid(alpha=0.3)
    legend_beside(ax1, fontsize=8)
    fig.tight_layout()
    # Lines within a few pixels of each other at every offset lie on each other here.
    low, high = ax1.get_ylim()
    pixels_per_decade = ax1.get_window_extent().height / math.log10(high / low)
    factor = 10 ** (COINCIDE_PX / pixels_per_decade)
    look, groups = coinciding_looks(
        {m: [v[x] for x in sorted(v)] for m, v in final.items()}, factor
    )
    for method, (width, marker) in look.items():
        line = drawn[method]
        line.set(lw=width, marker=marker, ms=4 + width, mfc="none")
    legend_beside(
        ax1, fontsize=8, title=coinciding_note(groups), title_fontsize=8, alignment="left"
    )
    place_legend(ax2, fontsize=8)
    fig.tight_layout()
    return fig


def plot_corner_study(
    series: Series, colors: Mapping[str, str], quarter: float, corners: Sequence[float]
) -> Figure:
    """Rectangle: position and orientation error vs alpha / (pi/2), corners marked.

    Args:
        quarter: time (s) per quarter period T/4, i.e. per pi/2 of alpha.
        corners: corner times (s), alpha = k pi/2.
    """
    fig = new_figure((9, 6))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for label, ts in series.items():
        x = ts["t"] / quarter
        ax1.semilogy(x, _floor(ts["position_error_m"]), color=colors[label], lw=1.1, label=label)
        ax2.plot(*break_wraps(x, ts["orientation_error_rad"]), color=colors[label], lw=1.1)
    for ax in (ax1, ax2):
        for corner in corners:
            ax.axvline(corner / quarter, color="0.4", ls=":", lw=0.9)
        ax.grid(alpha=0.3)
    ax1.set_ylim(bottom=ERROR_FLOOR / 2)
    ax1.set_ylabel("position error (m, log)")
    ax1.set_title("rectangle: errors peak at the corners (dotted, alpha = k pi/2)")
    _pi_ticks(ax2)
    ax2.set_ylabel("orientation error (rad, wrapped)")
    ax2.set_xlabel("alpha / (pi/2)")
    legend_beside(ax1, fontsize=8)
    fig.tight_layout()
    return fig


def plot_plant_errors(
    kinematic: Series, plant: Series, colors: Mapping[str, str], plant_name: str, title: str
) -> Figure:
    """Position error vs time per method: kinematic plant (dashed) and ``plant`` (solid),
    on a log axis that ends below the smallest error drawn (:func:`_log_bottom`)."""
    fig = new_figure((9, 4))
    ax = fig.subplots()
    drawn = []
    for label, ts in plant.items():
        base = kinematic[label]
        drawn += [base["position_error_m"], ts["position_error_m"]]
        ax.semilogy(
            base["t"], _floor(base["position_error_m"]), color=colors[label], ls="--", lw=0.8
        )
        ax.semilogy(
            ts["t"], _floor(ts["position_error_m"]), color=colors[label], lw=1.2, label=label
        )
    ax.set_ylabel("position error (m, log)")
    ax.set_xlabel("t (s)")
    ax.set_ylim(bottom=_log_bottom(drawn))
    ax.grid(alpha=0.3, which="major")
    ax.set_title(title)
    legend_beside(ax, fontsize=8, title=f"solid: {plant_name}\ndashed: kinematic", title_fontsize=8)
    fig.tight_layout()
    return fig
