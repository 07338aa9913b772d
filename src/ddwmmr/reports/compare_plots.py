"""Figures of the method comparison (``python -m ddwmmr.compare``).

Every function takes plain data (time series as ``dict[str, np.ndarray]`` with the columns
of :data:`ddwmmr.sim.simulate.COLUMNS`, keyed by a label) and returns a matplotlib Figure;
:func:`save` writes it as PNG and closes it. World frame, SI units (m, rad, s).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: the report never needs a screen
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from ddwmmr.model import Robot

#: Errors are clipped to this floor (m) on log axes: converged runs reach ~1e-12 m.
ERROR_FLOOR = 1e-12
#: Resolution of the saved PNGs (dots per inch).
DPI = 100

Series = Mapping[str, Mapping[str, np.ndarray]]


def save(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as PNG to ``path`` and close it."""
    path = Path(path)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def method_colors(labels: Sequence[str]) -> dict[str, str]:
    """A fixed colour per label (tab10 order), so a method looks the same in every figure."""
    return {label: f"C{i % 10}" for i, label in enumerate(labels)}


def _floor(values: np.ndarray) -> np.ndarray:
    return np.maximum(np.abs(values), ERROR_FLOOR)


def break_wraps(t: np.ndarray, angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(t, angle)`` with a NaN inserted wherever a wrapped angle jumps by more than pi
    between samples (a crossing of +-pi, not a real step), so the line is broken there
    instead of drawing a false vertical jump across the plot."""
    jumps = np.nonzero(np.abs(np.diff(angle)) > math.pi)[0] + 1
    return np.insert(t.astype(float), jumps, np.nan), np.insert(angle.astype(float), jumps, np.nan)


def _line_widths(count: int) -> list[float]:
    """Widths from wide to thin, so lines drawn in this order stay visible where they
    coincide (each one is a thinner stroke on top of the previous)."""
    return list(np.linspace(3.2, 1.0, count)) if count > 1 else [1.4]


def _grid_shape(count: int) -> tuple[int, int]:
    columns = min(3, max(count, 1))
    return math.ceil(max(count, 1) / columns), columns


def _path_limits(ax: Axes, ts: Mapping[str, np.ndarray], margin: float) -> None:
    """Frame the desired path plus ``margin`` (m): runs that diverge leave the frame."""
    x, y = ts["xE_d"], ts["yE_d"]
    ax.set_xlim(x.min() - margin, x.max() + margin)
    ax.set_ylim(y.min() - margin, y.max() + margin)
    ax.set_aspect("equal", adjustable="box")


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
) -> Figure:
    """End-effector paths of every method on the desired path, with zoom panels.

    The desired path is drawn first (thin, dashed) and the methods on top of it from wide
    to thin lines, so methods that follow the path, or each other, stay visible.

    Args:
        zooms: ``(label, t, half_width)`` per zoom panel: the region around the desired
            position at time t (s), half-width in m (None: from the errors, see
            :func:`zoom_window`); each method's position at time t is marked with a dot.
    """
    fig = plt.figure(figsize=(11.5, 6.8))
    grid = fig.add_gridspec(max(len(zooms), 1), 2, width_ratios=(1.5, 1))
    ax = fig.add_subplot(grid[:, 0])
    _draw_paths(ax, series, colors)
    reference = next(iter(series.values()))
    _path_limits(ax, reference, 0.5)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=4)
    for row, (label, t_center, half_width) in enumerate(zooms):
        cx, cy, h = zoom_window(series, t_center, half_width)
        zoom = fig.add_subplot(grid[row, 1])
        _draw_paths(zoom, series, colors, mark_time=t_center)
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
    fig.tight_layout()
    return fig


def _draw_paths(
    ax: Axes, series: Series, colors: Mapping[str, str], mark_time: float | None = None
) -> None:
    reference = next(iter(series.values()))
    ax.plot(
        reference["xE_d"], reference["yE_d"], "--", color="k", lw=0.9, label="desired", zorder=1
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
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for label, ts in series.items():
        ax1.semilogy(ts["t"], _floor(ts["position_error_m"]), color=colors[label], label=label)
        ax2.plot(*break_wraps(ts["t"], ts["orientation_error_rad"]), color=colors[label], lw=1)
    ax1.set_ylabel("position error (m, log)")
    ax1.set_ylim(bottom=ERROR_FLOOR / 2)
    ax1.grid(alpha=0.3, which="major")
    ax1.legend(fontsize=8, ncol=3)
    ax1.set_title(title)
    ax2.set_ylabel("orientation error (rad, wrapped)")
    _pi_ticks(ax2)
    ax2.set_xlabel("t (s)")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def _pi_ticks(ax: Axes) -> None:
    ax.set_ylim(-math.pi * 1.05, math.pi * 1.05)
    ax.set_yticks([-math.pi, -math.pi / 2, 0, math.pi / 2, math.pi])
    ax.set_yticklabels(["-pi", "-pi/2", "0", "pi/2", "pi"])


def plot_wheels(series: Series, colors: Mapping[str, str], limit: float, title: str) -> Figure:
    """Small multiples: left and right wheel speeds (rad/s) per method, with the limit."""
    rows, columns = _grid_shape(len(series))
    fig, axes = plt.subplots(
        rows, columns, figsize=(4 * columns, 2.6 * rows), sharex=True, sharey=True, squeeze=False
    )
    for ax, (label, ts) in zip(axes.flat, series.items()):
        ax.plot(ts["t"], ts["wheel_left_rad_s"], color=colors[label], lw=1, label="left")
        ax.plot(ts["t"], ts["wheel_right_rad_s"], color=colors[label], lw=1, ls="--", label="right")
        for sign in (-1.0, 1.0):
            ax.axhline(sign * limit, color="0.5", ls=":", lw=0.8)
        ax.set_title(label, fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    for ax in axes.flat[len(series) :]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel("wheel speed (rad/s)")
    for ax in axes[-1, :]:
        ax.set_xlabel("t (s)")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_small_multiples(
    series: Series, colors: Mapping[str, str], robot: Robot, title: str, snapshots: int = 6
) -> Figure:
    """One panel per method: desired and actual end-effector path, base path, and the robot
    (footprint grey, arm black: no method's colour) at ``snapshots`` instants, each labelled
    with its time."""
    from ddwmmr.reports.plots import robot_outline

    rows, columns = _grid_shape(len(series))
    fig, axes = plt.subplots(rows, columns, figsize=(4.4 * columns, 4.2 * rows), squeeze=False)
    for ax, (label, ts) in zip(axes.flat, series.items()):
        # On a closed path the last instant would be drawn over the first: leave it out.
        closed = math.hypot(ts["xE_d"][-1] - ts["xE_d"][0], ts["yE_d"][-1] - ts["yE_d"][0]) < 1e-3
        instants = np.linspace(0, len(ts["t"]) - 1, snapshots + closed)[:snapshots]
        ax.plot(ts["xE_d"], ts["yE_d"], "k--", lw=0.9)
        ax.plot(ts["x"], ts["y"], color="0.6", lw=0.9)
        ax.plot(ts["xE"], ts["yE"], color=colors[label], lw=1.6)
        q = np.column_stack([ts[k] for k in ("x", "y", "phi", "th1", "th2")])
        for k in instants.round().astype(int):
            shape = robot_outline(robot, q[k])
            ax.plot(*shape["footprint"].T, color="0.45", lw=0.8)
            ax.plot(*shape["heading"].T, color="0.45", lw=0.8)
            ax.plot(*shape["arm"].T, color="k", lw=1.3, marker="o", ms=2)
            ax.annotate(
                f"{ts['t'][k]:.3g} s",
                shape["footprint"][0],
                fontsize=6.5,
                color="0.25",
                xytext=(2, 2),
                textcoords="offset points",
            )
        _path_limits(ax, ts, robot.reach + 0.4)
        ax.set_title(label, fontsize=9, color=colors[label])
        ax.tick_params(labelsize=7)
        ax.set_xlabel("x (m)", fontsize=8)
        ax.set_ylabel("y (m)", fontsize=8)
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(series) :]:
        ax.set_visible(False)
    fig.suptitle(
        f"{title}: dashed desired, colour end effector, grey base path; robot (black arm) "
        f"at {snapshots} instants, labelled with t"
    )
    fig.tight_layout()
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
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    first = next(iter(error_curves))
    cmap = plt.get_cmap("viridis")
    taus = sorted(error_curves[first])
    for i, tau in enumerate(taus):
        t, e = error_curves[first][tau]
        ax1.semilogy(t, _floor(e), color=cmap(i / max(len(taus) - 1, 1)), label=f"tau = {tau:g} s")
    ax1.set_xlabel("t (s)")
    ax1.set_ylabel("position error (m, log)")
    ax1.set_title(f"{first}: error vs time")
    ax1.set_ylim(bottom=ERROR_FLOOR / 2)
    ax1.legend(fontsize=8)
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
    ax2.axhline(theory, color="k", ls=":", label=f"first order: {theory:.2f}")
    ax2.set_xscale("log")
    ax2.set_ylim(0.0, 2.0 * theory)
    ax2.set_xlabel("tau (s) (methods offset by a few % to stay visible)")
    ax2.set_ylabel("convergence time / tau")
    ax2.set_title("convergence time is proportional to tau")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return fig


def plot_dt_study(
    drift: Mapping[str, Mapping[str, Mapping[float, float]]], colors: Mapping[str, str]
) -> Figure:
    """Step-size sweep: final position error vs dt (log-log), Euler solid, RK4 dashed.

    Args:
        drift: method -> integrator -> dt (s) -> final position error (m).
    """
    fig, ax = plt.subplots(figsize=(8, 5))
    styles = {"euler": "-", "rk4": "--"}
    for method, by_integrator in drift.items():
        for integrator, values in by_integrator.items():
            xs = sorted(values)
            ax.loglog(
                xs,
                [max(values[x], ERROR_FLOOR) for x in xs],
                styles.get(integrator, "-."),
                marker="o",
                ms=3,
                color=colors[method],
                label=f"{method} ({integrator})",
            )
    ax.set_xlabel("step dt (s)")
    ax.set_ylabel("largest position error (m)")
    ax.set_title("drift vs step size: Euler (solid) is first order, RK4 (dashed) fourth")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=2)
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
    fig, ax = plt.subplots(figsize=(8, 5))
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
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    return fig


def plot_init_study(
    final: Mapping[str, Mapping[float, float]],
    curves: Mapping[float, tuple[np.ndarray, np.ndarray]],
    curve_method: str,
    colors: Mapping[str, str],
) -> Figure:
    """Initial-offset sweep: final error vs initial offset, and one method's error curves.

    Args:
        final: method -> initial offset (m) -> final position error (m).
        curves: initial offset (m) -> (t, position error) for ``curve_method``.
    """
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for method, values in final.items():
        xs = sorted(values)
        errors = [max(values[x], ERROR_FLOOR) for x in xs]
        ax1.plot([1000 * x for x in xs], errors, "o-", color=colors[method], label=method)
    ax1.set_yscale("log")
    ax1.set_xlabel("initial end-effector offset (mm)")
    ax1.set_ylabel("final position error (m, log)")
    ax1.set_title("open loop keeps the offset, closed loop removes it")
    ax1.grid(alpha=0.3, which="both")
    ax1.legend(fontsize=8)
    cmap = plt.get_cmap("viridis")
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
    ax2.legend(fontsize=8)
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
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
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
    ax1.legend(fontsize=8, ncol=3)
    _pi_ticks(ax2)
    ax2.set_ylabel("orientation error (rad, wrapped)")
    ax2.set_xlabel("alpha / (pi/2)")
    fig.tight_layout()
    return fig


def plot_plant_errors(
    kinematic: Series, plant: Series, colors: Mapping[str, str], plant_name: str, title: str
) -> Figure:
    """Position error vs time per method: kinematic plant (dashed) and ``plant`` (solid)."""
    fig, ax = plt.subplots(figsize=(8, 4))
    for label, ts in plant.items():
        base = kinematic[label]
        ax.semilogy(
            base["t"], _floor(base["position_error_m"]), color=colors[label], ls="--", lw=0.8
        )
        ax.semilogy(
            ts["t"], _floor(ts["position_error_m"]), color=colors[label], lw=1.2, label=label
        )
    ax.set_ylabel("position error (m, log)")
    ax.set_xlabel("t (s)")
    ax.set_ylim(bottom=ERROR_FLOOR / 2)
    ax.grid(alpha=0.3, which="major")
    ax.legend(fontsize=8, ncol=3, title=f"solid: {plant_name}, dashed: kinematic", title_fontsize=8)
    ax.set_title(title)
    fig.tight_layout()
    return fig
