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


def _grid_shape(count: int) -> tuple[int, int]:
    columns = min(3, max(count, 1))
    return math.ceil(max(count, 1) / columns), columns


def _path_limits(ax: Axes, ts: Mapping[str, np.ndarray], margin: float) -> None:
    """Frame the desired path plus ``margin`` (m): runs that diverge leave the frame."""
    x, y = ts["xE_d"], ts["yE_d"]
    ax.set_xlim(x.min() - margin, x.max() + margin)
    ax.set_ylim(y.min() - margin, y.max() + margin)
    ax.set_aspect("equal", adjustable="box")


def plot_paths(series: Series, colors: Mapping[str, str], title: str) -> Figure:
    """Overlay of the end-effector paths of every method on the desired path.

    The frame is the desired path plus 0.5 m: a method that drifts far away leaves it.
    """
    fig, ax = plt.subplots(figsize=(7.5, 6))
    reference = next(iter(series.values()))
    ax.plot(reference["xE_d"], reference["yE_d"], "k--", lw=1.2, label="desired", zorder=5)
    for label, ts in series.items():
        ax.plot(ts["xE"], ts["yE"], color=colors[label], lw=1.3, label=label)
        ax.plot(ts["xE"][0], ts["yE"][0], "o", color=colors[label], ms=4)
    _path_limits(ax, reference, 0.5)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    return fig


def plot_errors(series: Series, colors: Mapping[str, str], title: str) -> Figure:
    """Position error (log scale) and orientation error vs time for every method."""
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for label, ts in series.items():
        ax1.semilogy(ts["t"], _floor(ts["position_error_m"]), color=colors[label], label=label)
        ax2.plot(ts["t"], ts["orientation_error_rad"], color=colors[label], lw=1)
    ax1.set_ylabel("position error (m, log)")
    ax1.set_ylim(bottom=ERROR_FLOOR / 2)
    ax1.grid(alpha=0.3, which="major")
    ax1.legend(fontsize=8, ncol=3)
    ax1.set_title(title)
    ax2.set_ylabel("orientation error (rad)")
    ax2.set_xlabel("t (s)")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    return fig


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
    """One panel per method: desired and actual end-effector path, base path and robot poses."""
    from ddwmmr.reports.plots import draw_robot

    rows, columns = _grid_shape(len(series))
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.6 * rows), squeeze=False)
    for ax, (label, ts) in zip(axes.flat, series.items()):
        ax.plot(ts["xE_d"], ts["yE_d"], "k--", lw=0.9)
        ax.plot(ts["x"], ts["y"], color="0.55", lw=0.9)
        ax.plot(ts["xE"], ts["yE"], color=colors[label], lw=1.4)
        q = np.column_stack([ts[k] for k in ("x", "y", "phi", "th1", "th2")])
        for k in np.linspace(0, len(q) - 1, snapshots).astype(int):
            draw_robot(ax, robot, q[k], alpha=0.6)
        _path_limits(ax, ts, robot.reach + 0.4)
        ax.set_title(label, fontsize=9)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(series) :]:
        ax.set_visible(False)
    fig.suptitle(f"{title} (dashed: desired; grey: base; colour: end effector)")
    fig.tight_layout()
    return fig


def plot_tau_study(
    error_curves: Mapping[str, Mapping[float, tuple[np.ndarray, np.ndarray]]],
    convergence: Mapping[str, Mapping[float, float]],
    theory: float,
    colors: Mapping[str, str],
) -> Figure:
    """Time-constant sweep: error vs time per tau (first method) and convergence time vs tau.

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
    for method, values in convergence.items():
        xs = sorted(values)
        ax2.plot(xs, [values[x] for x in xs], "o-", color=colors[method], label=method)
    grid = np.array(taus)
    ax2.plot(grid, theory * grid, "k:", label=f"first order: {theory:.2f} tau")
    ax2.set_xscale("log")
    ax2.set_yscale("log")
    ax2.set_xlabel("tau (s)")
    ax2.set_ylabel("convergence time (s)")
    ax2.set_title("larger tau: slower convergence")
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
        ax2.plot(x, ts["orientation_error_rad"], color=colors[label], lw=1.1)
    for ax in (ax1, ax2):
        for corner in corners:
            ax.axvline(corner / quarter, color="0.4", ls=":", lw=0.9)
        ax.grid(alpha=0.3)
    ax1.set_ylim(bottom=ERROR_FLOOR / 2)
    ax1.set_ylabel("position error (m, log)")
    ax1.set_title("rectangle: errors peak at the corners (dotted, alpha = k pi/2)")
    ax1.legend(fontsize=8, ncol=3)
    ax2.set_yticks([-math.pi, -math.pi / 2, 0, math.pi / 2, math.pi])
    ax2.set_yticklabels(["-pi", "-pi/2", "0", "pi/2", "pi"])
    ax2.set_ylabel("orientation error (rad)")
    ax2.set_xlabel("alpha / (pi/2)")
    fig.tight_layout()
    return fig
