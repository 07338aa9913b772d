"""Figures of a physics (MuJoCo) run: support loads drawn on the robot, tipping animation.

Works from a recorded run (a :class:`~ddwmmr.sim.SimulationResult` whose time series has
the :class:`~ddwmmr.plants.MujocoPlant` columns ``support_force_<name>_n``,
``physics_stability``, ``base_tilt_rad`` and the kinematic ``stability``). World frame,
metres, newtons. The robot is drawn with :func:`ddwmmr.reports.plots.robot_outline`. The
figures are not pyplot's (:mod:`ddwmmr.reports.canvas`): the matplotlib backend is left alone.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ddwmmr.errors import check_nonnegative
from ddwmmr.reports.canvas import checked_gif_options, new_figure, save_gif
from ddwmmr.reports.plots import robot_outline, run_title

if TYPE_CHECKING:
    from matplotlib.collections import PathCollection
    from matplotlib.lines import Line2D
    from matplotlib.text import Text

    from ddwmmr.model import Robot
    from ddwmmr.sim import SimulationResult


def support_names(timeseries: dict[str, np.ndarray]) -> list[str]:
    """Support names recorded in a physics time series (``support_force_<name>_n``)."""
    prefix, suffix = "support_force_", "_n"
    return [c[len(prefix) : -len(suffix)] for c in timeseries if c.startswith(prefix)]


def support_points_world(q: Sequence[float] | np.ndarray, points: npt.ArrayLike) -> np.ndarray:
    """Base-frame support points (n, 2) placed at configuration q (world frame, m)."""
    x, y, phi = (float(v) for v in q[:3])
    c, s = math.cos(phi), math.sin(phi)
    pts = np.asarray(points, dtype=float)
    return np.column_stack([x + c * pts[:, 0] - s * pts[:, 1], y + s * pts[:, 0] + c * pts[:, 1]])


def draw_supports(
    ax: Axes,
    q: Sequence[float] | np.ndarray,
    points: npt.ArrayLike,
    forces: npt.ArrayLike,
    weight_n: float,
) -> None:
    """Support points at q as discs whose area is proportional to their load; an unloaded
    support is an empty red ring."""
    world = support_points_world(q, points)
    forces = np.asarray(forces, dtype=float)
    loaded = forces > 1e-3 * weight_n
    sizes = 600.0 * forces / weight_n
    # ignore: world (n, 2) unpacks to x and y only, so s is not also given by position
    ax.scatter(*world[loaded].T, s=sizes[loaded], color="tab:blue", alpha=0.6, zorder=3)  # type: ignore[misc]
    ax.scatter(*world[~loaded].T, s=40, facecolors="none", edgecolors="tab:red", zorder=3)  # type: ignore[misc]


def save_physics_animation(
    result: SimulationResult,
    points: npt.ArrayLike,
    weight_n: float,
    path: str | Path,
    frames: int = 60,
    fps: int = 12,
    after_tip_s: float = 1.0,
) -> Path:
    """GIF of a physics run: top view with the support loads, and S / S_phys / tilt in time.

    Args:
        result: the recorded run (time series with the physics columns).
        points: nominal base-frame support points (n, 2), in the order of the columns.
        weight_n: the robot's weight (N), to scale the load discs.
        path: output ``.gif``.
        frames: recorded instants shown (an integer >= 1), ``fps`` per second (in [1,
            100]).
        after_tip_s: a run that tipped (``summary["tip_time_s"]``) is shown only this long
            after it tipped (the top view of a fallen robot means nothing; s, >= 0).

    Bad ``path``, ``frames``, ``fps`` or ``after_tip_s`` is a one-line
    :class:`~ddwmmr.errors.ParameterError` naming it, before anything is drawn.
    """
    path, frames, fps = checked_gif_options(path, frames, fps)
    after_tip_s = check_nonnegative("after_tip_s", after_tip_s)
    robot = result.robot
    tip_time = result.summary.get("tip_time_s")
    ts = _until_after_tip(result.timeseries, tip_time, after_tip_s)
    names = support_names(ts)
    forces = np.column_stack([ts[f"support_force_{n}_n"] for n in names])
    q = np.column_stack([ts[k] for k in ("x", "y", "phi", "th1", "th2")])
    fig = new_figure((9.5, 4.2))
    ax, ax_s = fig.subplots(1, 2, width_ratios=(1, 1.25))
    _top_view_axes(ax, ts, robot.reach + 0.5 * robot.base_length)
    _margins_in_time(ax_s, ts, tip_time)
    cursor = ax_s.axvline(0.0, color="k", lw=0.8)
    (footprint,) = ax.plot([], [], color="0.3")
    (arm,) = ax.plot([], [], color="tab:orange", lw=2, marker="o", ms=3)
    discs = ax.scatter([], [], s=[], color="tab:blue", alpha=0.6, zorder=3)
    indices = np.linspace(0, len(q) - 1, frames).astype(int)
    title = f"{result.summary.get('method', '?')}, payload {robot.payload:g} kg"

    def update(frame: int) -> tuple[Line2D, Line2D, PathCollection, Line2D, Text]:
        k = indices[frame]
        shape = robot_outline(robot, q[k])
        footprint.set_data(*shape["footprint"].T)
        arm.set_data(*shape["arm"].T)
        discs.set_offsets(support_points_world(q[k], points))
        discs.set_sizes(np.maximum(600.0 * forces[k] / weight_n, 4.0))
        discs.set_color(["tab:blue" if f > 1e-3 * weight_n else "tab:red" for f in forces[k]])
        cursor.set_xdata([ts["t"][k], ts["t"][k]])
        fallen = " (tipped)" if tip_time is not None and ts["t"][k] >= tip_time else ""
        heading = ax.set_title(f"{title}: t = {ts['t'][k]:.2f} s{fallen}", fontsize=9)
        return footprint, arm, discs, cursor, heading

    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_gif(fig, update, len(indices), path, fps)


def _until_after_tip(
    ts: dict[str, np.ndarray], tip_time: float | None, after_tip_s: float
) -> dict[str, np.ndarray]:
    """The time series ``ts`` up to ``after_tip_s`` (s) after ``tip_time`` (s); all of
    it when the run did not tip (``tip_time`` None)."""
    if tip_time is None:
        return ts
    keep = ts["t"] <= tip_time + after_tip_s
    return {name: values[keep] for name, values in ts.items()}


def _top_view_axes(ax: Axes, ts: dict[str, np.ndarray], reach: float) -> None:
    """``ax`` as the run's top view (world frame, m, equal aspect): the base path's extent
    plus ``reach`` (m) on every side, and the desired end-effector path dashed if
    recorded."""
    ax.set_xlim(ts["x"].min() - reach, ts["x"].max() + reach)
    ax.set_ylim(ts["y"].min() - reach, ts["y"].max() + reach)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if "xE_d" in ts:
        ax.plot(ts["xE_d"], ts["yE_d"], "k--", lw=0.8)


def _margins_in_time(ax_s: Axes, ts: dict[str, np.ndarray], tip_time: float | None) -> None:
    """``ax_s``: the kinematic S and the physics S_phys over t (s) with the tipping line
    S = 1 and the tip time (s, if any) marked, and the base tilt (deg) on a right axis;
    one legend below the plot."""
    ax_s.plot(ts["t"], ts["stability"], color="tab:brown", label="S (kinematic)")
    ax_s.plot(ts["t"], ts["physics_stability"], color="tab:blue", lw=0.8, label="S_phys")
    ax_s.axhline(1.0, color="tab:red", ls="--", lw=0.8)
    ax_s.set_ylim(0.0, 2.0)
    if tip_time is not None:
        ax_s.axvline(tip_time, color="tab:red", lw=0.8)
        ax_s.annotate(
            "tipped",
            (tip_time, 1.85),
            xytext=(4, 0),
            textcoords="offset points",
            va="center",
            color="tab:red",
            fontsize=8,
        )
    ax_s.set_xlabel("t (s)")
    ax_s.set_ylabel("stability margin")
    tilt_axis = ax_s.twinx()
    (tilt,) = tilt_axis.plot(ts["t"], np.degrees(ts["base_tilt_rad"]), color="0.5", lw=0.8)
    tilt_axis.set_ylabel("base tilt (deg, grey)")
    handles, labels = ax_s.get_legend_handles_labels()
    # Below the plot: the two axes' lines fill it.
    ax_s.legend(
        [*handles, tilt],
        [*labels, "base tilt (right axis)"],
        loc="upper center",
        bbox_to_anchor=(0.5, -0.18),
        ncol=3,
        fontsize=8,
    )


#: File name of the support-load figure a physics ``track`` run writes.
SUPPORT_LOADS_FIGURE = "support_loads.png"
#: An edge counts as unloaded (shaded) below this share of the weight (the plant's).
_UNLOADED_SHARE = 1e-4


def edge_names(normals: npt.ArrayLike) -> list[str]:
    """A name per support-polygon edge from its inward normal (base frame): ``front``,
    ``back``, ``left``, ``right`` for an edge facing that way, else ``edge <i>``."""
    names = []
    for i, (nx, ny) in enumerate(np.asarray(normals, dtype=float), start=1):
        facing = {(-1, 0): "front", (1, 0): "back", (0, -1): "left", (0, 1): "right"}
        key = (round(nx), round(ny)) if max(abs(nx), abs(ny)) > 0.999 else None
        names.append(facing.get(key, f"edge {i}"))  # type: ignore[arg-type]
    return names


def edge_load_series(
    timeseries: dict[str, np.ndarray], robot: Robot
) -> tuple[list[str], np.ndarray]:
    """The measured load (N) on the supports off each edge of the robot's support polygon
    at every sample, (samples, edges), from a physics run's ``support_force_<name>_n``
    columns (in :func:`~ddwmmr.model.support_loads.support_points` order), with the
    edges' names (:func:`edge_names`)."""
    from ddwmmr.model.support_loads import support_points, support_polygon

    forces = np.column_stack(
        [timeseries[f"support_force_{n}_n"] for n in support_names(timeseries)]
    )
    polygon = support_polygon(robot)
    off = polygon.off_edge(support_points(robot)).astype(float)  # (edges, supports)
    return edge_names(polygon.normals), forces @ off.T


#: Size (inches) and resolution (dots per inch) of the support-load figure.
SUPPORT_LOADS_FIGSIZE = (7.5, 5.2)
SUPPORT_LOADS_DPI = 110


def is_physics_run(result: SimulationResult) -> bool:
    """True when ``result`` was recorded on a plant that measures its support forces (the
    ``support_force_<name>_n`` and ``base_tilt_rad`` columns of a physics plant)."""
    ts = result.timeseries
    return bool(support_names(ts)) and "base_tilt_rad" in ts


def plot_support_loads(result: SimulationResult, floor_n: float | None = None) -> Figure:
    """Figure: the load on the supports off each edge of the support polygon (N; the edge
    the base would pivot about when it reaches 0) with the optimisers' floor, and the
    base's tilt (mrad), against time (:func:`draw_support_loads` on a new figure of its
    own, :func:`~ddwmmr.reports.canvas.new_figure`: not pyplot's; to see it in a pyplot
    window, draw into ``plt.figure(figsize=SUPPORT_LOADS_FIGSIZE)`` with
    :func:`draw_support_loads`)."""
    return draw_support_loads(new_figure(SUPPORT_LOADS_FIGSIZE), result, floor_n)


def draw_support_loads(
    fig: Figure, result: SimulationResult, floor_n: float | None = None
) -> Figure:
    """Draw the support-load panel into ``fig`` (empty; any canvas: the track figure and
    the simulator's window both use it): each edge's load (N) with the optimisers' floor
    (dashed) above, the base's tilt (mrad) below, against time; steps with an edge
    unloaded are shaded. The title names the run (:func:`~ddwmmr.reports.plots.run_title`).

    ``result`` is a physics run (:func:`is_physics_run`); ``floor_n`` (N) defaults to the
    run summary's ``min_edge_load_floor_n`` (None: not drawn)."""
    ts, robot = result.timeseries, result.robot
    names, loads = edge_load_series(ts, robot)
    weight = robot.total_mass * 9.81
    if floor_n is None:
        floor_n = result.summary.get("min_edge_load_floor_n")
    t = ts["t"]
    ax_load, ax_tilt = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [2.2, 1]})
    unloaded = np.min(loads, axis=1) < _UNLOADED_SHARE * weight
    for ax in (ax_load, ax_tilt):
        if np.any(unloaded):
            shade = {"color": "tab:red", "alpha": 0.15, "lw": 0, "step": "mid"}
            ax.fill_between(t, 0, 1, where=unloaded, transform=ax.get_xaxis_transform(), **shade)
    for j, name in enumerate(names):
        ax_load.plot(t, loads[:, j], lw=0.8, label=f"{name} edge")
    if floor_n is not None:
        ax_load.axhline(floor_n, color="k", ls="--", lw=0.9, label=f"floor {_newtons(floor_n)} N")
    ax_load.axhline(0.0, color="0.4", lw=0.6)
    top = float(np.max(loads)) if loads.size else 1.0
    ax_load.set_ylim(-0.03 * top, 1.05 * top)
    ax_load.set_ylabel("load on each edge (N)")
    unloaded_s = result.summary.get("unloaded_time_s", 0.0)
    ax_load.set_title(
        run_title(result.summary, f"support loads, unloaded {unloaded_s:.2f} s (shaded)"),
        fontsize=10,
    )
    ax_load.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax_tilt.plot(t, 1e3 * ts["base_tilt_rad"], color="0.3", lw=0.8)
    ax_tilt.set_ylabel("base tilt (mrad)")
    ax_tilt.set_xlabel("t (s)")
    ax_tilt.set_xlim(float(t[0]), float(t[-1]))
    fig.tight_layout()
    return fig


def save_support_loads(
    result: SimulationResult, path: str | Path, floor_n: float | None = None
) -> Path:
    """Write :func:`plot_support_loads` to ``path`` (PNG)."""
    from ddwmmr.reports.plots import PNG_METADATA

    fig = plot_support_loads(result, floor_n)
    fig.savefig(path, dpi=SUPPORT_LOADS_DPI, metadata=PNG_METADATA)
    return Path(path)


def _newtons(value: float) -> str:
    """A force (N) for a legend: one decimal from 0.1 N up (``13.0``), else three
    significant digits, so a small robot's floor is not shown as ``0.0``."""
    return f"{value:.1f}" if abs(value) >= 0.1 else f"{value:.3g}"
