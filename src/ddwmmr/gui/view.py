"""The app's view: the robot on its paths and the time plots, shown at any recorded time.

:class:`RunView` draws one run (or two, overlaid, for the side-by-side mode) into a
path axes and five plot axes. It only reads :class:`ddwmmr.sim.SimulationResult` time
series; the robot's shape comes from :func:`ddwmmr.reports.plots.robot_outline` and
:func:`~ddwmmr.reports.plots.wheel_outlines`. The same class draws the window and the
exported animation (:func:`animation_figure`). World frame, metres, radians, seconds.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Polygon
from matplotlib.ticker import NullFormatter

from ddwmmr.reports.canvas import renderer_of
from ddwmmr.reports.legends import place_legend
from ddwmmr.reports.plots import ERROR_FLOOR, at_least_a_percent, robot_outline, wheel_outlines

if TYPE_CHECKING:
    from ddwmmr.gui.widgets import Rect

#: Plot axes of the view, top to bottom: key -> y-axis label.
PLOTS = {
    "position": "position\nerror (m)",
    "orientation": "orientation\nerror (rad)",
    "wheels": "wheel speed\n(rad/s)",
    "stability": "stability S",
    "manipulability": "manipulability\neta",
}
#: Colours of run A and run B: (end effector and plot lines, arm).
PALETTE = (("tab:blue", "tab:orange"), ("tab:red", "tab:green"))
#: Widths of run A's and run B's lines (end-effector trail, plot lines): B is drawn on
#: top of A, thinner, so that A stays visible where the two coincide.
TRAIL_WIDTHS = (3.0, 1.3)
PLOT_WIDTHS = (2.0, 0.9)
#: Drawing order in the top view: trails (2), the desired path, then the robots.
DESIRED_ZORDER = 2.5
ROBOT_ZORDER = 3.0
#: Font sizes (points) of the tick labels and axis labels of the view: at the window's
#: 100 dpi, 8 pt is 11 px.
TICK_SIZE = 8
LABEL_SIZE = 8
#: Samples of a desired path drawn before any run.
PREVIEW_SAMPLES = 400


@dataclass
class _RunArtists:
    """What is drawn for one run."""

    result: Any
    label: str
    ee_trail: Line2D
    base_trail: Line2D
    footprint: Polygon
    wheels: list[Polygon]
    heading: Line2D
    arm: Line2D
    payload: Line2D
    lines: dict[str, list[Line2D]] = field(default_factory=dict)


class RunView:
    """Robot view and live plots of up to two runs (A and B) on the same trajectory.

    Args:
        path_ax: axes of the top view (equal aspect).
        plot_axes: one axes per key of :data:`PLOTS`.
    """

    def __init__(self, path_ax: Axes, plot_axes: dict[str, Axes]) -> None:
        self.path_ax = path_ax
        self.plot_axes = plot_axes
        self.runs: list[_RunArtists] = []
        self.index = 0
        self.time = 0.0
        self._static: list[Any] = []
        self._cursors = [
            ax.axvline(0.0, color="0.4", lw=0.8, visible=False) for ax in plot_axes.values()
        ]
        (self._period,) = path_ax.plot([], [], color="0.7", lw=0.8, label="desired, one period")
        # Over the end-effector trails (thin, dashed: visible where a run follows it),
        # under the robots.
        (self._desired,) = path_ax.plot(
            [], [], "k--", lw=0.9, label="desired end effector", zorder=DESIRED_ZORDER
        )
        (self._target,) = path_ax.plot([], [], "kx", ms=6, mew=1.2, label="desired now")
        self._style_axes()

    # -- content ------------------------------------------------------------------------
    def preview(self, trajectory: Any, obstacles: Sequence[Any] = ()) -> None:
        """Drop the runs and show the desired path of ``trajectory`` (before a run)."""
        self._clear_runs()
        poses = self._show_period(trajectory)
        self._desired.set_data([], [])
        self._target.set_data([poses[0, 0]], [poses[0, 1]])
        self._draw_obstacles(obstacles)
        self._fit_path(poses[:, 0], poses[:, 1], margin=0.3)
        self.path_ax.set_title("desired path (press Run)", fontsize=9)
        for ax in self.plot_axes.values():
            ax.relim()
        self.time, self.index = 0.0, 0

    def set_runs(
        self, results: Sequence[Any], labels: Sequence[str], obstacles: Sequence[Any] = ()
    ) -> None:
        """Draw ``results`` (A first, B overlaid) and show their start."""
        self._clear_runs()
        first = results[0].timeseries
        period = self._show_period(results[0].trajectory)
        self._desired.set_data(first["xE_d"], first["yE_d"])
        self._draw_obstacles(obstacles)
        for number, (result, label) in enumerate(zip(results, labels)):
            self.runs.append(self._run_artists(number, result, label))
        xs = np.concatenate([np.r_[r.timeseries["x"], r.timeseries["xE"]] for r in results])
        ys = np.concatenate([np.r_[r.timeseries["y"], r.timeseries["yE"]] for r in results])
        robot = results[0].robot
        self._fit_path(np.r_[xs, period[:, 0]], np.r_[ys, period[:, 1]], robot.base_length)
        self._fit_plots(results)
        self.path_ax.legend(
            loc="upper center",
            bbox_to_anchor=(0.5, self._below_x_axis()),
            ncol=3,
            fontsize=7.5,
            frameon=False,
        )
        # The legends go where the whole runs leave room (raising a plot's top if needed),
        # placed once: they do not move during playback.
        self.show_index(self.last_index)
        for key in ("position", "wheels", "stability"):
            ax = self.plot_axes[key]
            place_legend(ax, fontsize=7, ncol=_legend_columns(ax, 7), framealpha=0.8)
        for cursor in self._cursors:
            cursor.set_visible(True)
        self.show(0.0)

    def _below_x_axis(self) -> float:
        """Where the top view's legend starts (axes fraction, negative: under the axes):
        0.07 below, or lower if the tick labels and the x label reach further down (a
        short axes, as in the exported animation), so that the legend never covers them."""
        renderer = renderer_of(self.path_ax.figure)
        # ignore: the x axis is shown, so it has a box
        bottom = self.path_ax.xaxis.get_tightbbox(renderer).y0  # type: ignore[union-attr]
        reached: float = self.path_ax.transAxes.inverted().transform((0.0, bottom))[1]
        return min(-0.07, reached - 0.01)

    def dynamic_artists(self, legends: bool = True) -> list[Any]:
        """The artists :meth:`show_index` changes (for blitting), in drawing order.

        ``legends``: include the legends, so that they stay above the moving lines.
        """
        # The desired path is drawn over the moving trails, so it moves with them.
        artists: list[Any] = [self._desired, self._target, self.path_ax.title, *self._cursors]
        for run in self.runs:
            artists += [run.ee_trail, run.base_trail, run.footprint, *run.wheels]
            artists += [run.heading, run.arm, run.payload]
            artists += [line for lines in run.lines.values() for line in lines]
        if legends:  # on top of the lines, as in a full render
            boxes = [ax.get_legend() for ax in (self.path_ax, *self.plot_axes.values())]
            artists += [box for box in boxes if box is not None]
        return sorted(artists, key=lambda artist: artist.get_zorder())

    @property
    def duration(self) -> float:
        """Recorded time span of the runs (s); 0 without runs."""
        return float(self.runs[0].result.timeseries["t"][-1]) if self.runs else 0.0

    @property
    def last_index(self) -> int:
        """Index of the last recorded instant (0 without runs)."""
        return len(self.runs[0].result.timeseries["t"]) - 1 if self.runs else 0

    def index_at(self, t: float) -> int:
        """Index of the last recorded instant at or before ``t`` (s)."""
        if not self.runs:
            return 0
        times = self.runs[0].result.timeseries["t"]
        return int(np.clip(np.searchsorted(times, t + 1e-9, side="right") - 1, 0, len(times) - 1))

    def show(self, t: float) -> int:
        """Draw the robots at time ``t`` (s), the paths and plots up to it; return the index."""
        return self.show_index(self.index_at(t))

    def show_index(self, k: int) -> int:
        """Draw the recorded instant ``k`` (clipped to the run); return it."""
        if not self.runs:
            return 0
        k = int(np.clip(k, 0, self.last_index))
        self.index = k
        times = self.runs[0].result.timeseries["t"]
        self.time = float(times[k])
        for run in self.runs:
            self._show_run(run, k)
        first = self.runs[0].result.timeseries
        self._target.set_data([first["xE_d"][k]], [first["yE_d"][k]])
        for cursor in self._cursors:
            cursor.set_xdata([self.time, self.time])
        names = " vs ".join(run.label for run in self.runs)
        trajectory = self.runs[0].result.summary.get("trajectory", "?")
        # a file's name is the trajectory's: "$" in it is a dollar sign, not mathtext
        self.path_ax.set_title(
            f"{names} on {trajectory}   t = {self.time:.2f} s", fontsize=9, parse_math=False
        )
        return k

    # -- drawing pieces -----------------------------------------------------------------
    def _show_period(self, trajectory: Any) -> np.ndarray:
        """Draw one period of the desired path (light); return its poses."""
        times = np.linspace(0.0, float(trajectory.duration), PREVIEW_SAMPLES)
        poses = np.array([trajectory.pose(t) for t in times])
        self._period.set_data(poses[:, 0], poses[:, 1])
        return poses

    def _style_axes(self) -> None:
        ax = self.path_ax
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x (m)", fontsize=LABEL_SIZE)
        ax.set_ylabel("y (m)", fontsize=LABEL_SIZE)
        ax.tick_params(labelsize=TICK_SIZE)
        ax.grid(alpha=0.3)
        keys = list(self.plot_axes)
        for key, plot in self.plot_axes.items():
            plot.set_ylabel(PLOTS[key], fontsize=LABEL_SIZE)
            plot.tick_params(labelsize=TICK_SIZE)
            if key != "position":
                plot.ticklabel_format(axis="y", useOffset=False)
            plot.grid(alpha=0.3, which="both")
            if key != keys[-1]:
                plot.tick_params(labelbottom=False)
        self.plot_axes[keys[-1]].set_xlabel("t (s)", fontsize=LABEL_SIZE)
        self.plot_axes["position"].set_yscale("log")
        self.plot_axes["position"].yaxis.set_minor_formatter(NullFormatter())

    def _clear_runs(self) -> None:
        for run in self.runs:
            for artist in (run.ee_trail, run.base_trail, run.footprint, run.heading, run.arm):
                artist.remove()
            run.payload.remove()
            for wheel in run.wheels:
                wheel.remove()
            for lines in run.lines.values():
                for line in lines:
                    line.remove()
        self.runs = []
        for artist in self._static:
            artist.remove()
        self._static = []
        for ax in [self.path_ax, *self.plot_axes.values()]:
            legend = ax.get_legend()
            if legend is not None:
                legend.remove()
        for cursor in self._cursors:
            cursor.set_visible(False)

    def _draw_obstacles(self, obstacles: Sequence[Any]) -> None:
        for number, circle in enumerate(obstacles):
            patch = CirclePatch(
                (circle.x, circle.y),
                circle.radius,
                facecolor="0.75",
                edgecolor="0.3",
                label="obstacle" if number == 0 else None,
            )
            self.path_ax.add_patch(patch)
            self._static.append(patch)

    def _run_artists(self, number: int, result: Any, label: str) -> _RunArtists:
        ax = self.path_ax
        color, arm_color = PALETTE[number]
        robot = result.robot
        (ee_trail,) = ax.plot(
            [], [], color=color, lw=TRAIL_WIDTHS[number], label=f"{label}: end effector"
        )
        (base_trail,) = ax.plot(
            [], [], color=color, lw=0.8, alpha=0.5, ls=":", label=f"{label}: base"
        )
        footprint = Polygon(np.zeros((5, 2)), closed=True, fc=color, ec="0.2", alpha=0.25, lw=0.8)
        ax.add_patch(footprint)
        wheels = [Polygon(np.zeros((5, 2)), closed=True, fc="0.15", ec="0.15") for _ in range(2)]
        for wheel in wheels:
            ax.add_patch(wheel)
        (heading,) = ax.plot([], [], color="0.2", lw=1.2, zorder=ROBOT_ZORDER)
        (arm,) = ax.plot(
            [], [], color=arm_color, lw=2.2, marker="o", ms=3, solid_capstyle="round",
            zorder=ROBOT_ZORDER,
        )  # fmt: skip
        size = 4 + 3 * float(np.sqrt(robot.payload))
        (payload,) = ax.plot(
            [], [], "s", color="0.1", ms=size, mfc=arm_color, alpha=0.9, zorder=ROBOT_ZORDER
        )
        run = _RunArtists(
            result, label, ee_trail, base_trail, footprint, wheels, heading, arm, payload
        )
        style: dict[str, Any] = {"color": color, "lw": PLOT_WIDTHS[number]}
        plot = self.plot_axes
        run.lines["position"] = plot["position"].plot([], [], label=label, **style)
        # Colours name the runs in the position legend; the other plots use the same ones.
        run.lines["orientation"] = plot["orientation"].plot([], [], **style)
        first = number == 0
        run.lines["wheels"] = [
            *plot["wheels"].plot([], [], label="left" if first else None, **style),
            *plot["wheels"].plot([], [], ls="--", label="right" if first else None, **style),
        ]
        run.lines["stability"] = plot["stability"].plot([], [], **style)
        run.lines["manipulability"] = plot["manipulability"].plot([], [], **style)
        floor = result.summary.get("stability_min")
        if floor:
            line = plot["stability"].axhline(
                floor, color=color, ls=":", lw=1, label=f"{label} floor S_min"
            )
            self._static.append(line)
        if number == 0:
            self._static.append(
                plot["stability"].axhline(1.0, color="k", ls="--", lw=0.8, label="tip-over S=1")
            )
            for sign in (-1, 1):
                self._static.append(
                    plot["wheels"].axhline(
                        sign * robot.wheel_speed_limit, color="0.5", ls=":", lw=0.8
                    )
                )
        return run

    def _show_run(self, run: _RunArtists, k: int) -> None:
        ts = run.result.timeseries
        q = np.array([ts[name][k] for name in ("x", "y", "phi", "th1", "th2")])
        shape = robot_outline(run.result.robot, q)
        run.ee_trail.set_data(ts["xE"][: k + 1], ts["yE"][: k + 1])
        run.base_trail.set_data(ts["x"][: k + 1], ts["y"][: k + 1])
        run.footprint.set_xy(shape["footprint"])
        for patch, outline in zip(run.wheels, wheel_outlines(run.result.robot, q)):
            patch.set_xy(outline)
        run.heading.set_data(*shape["heading"].T)
        run.arm.set_data(*shape["arm"].T)
        run.payload.set_data([shape["arm"][-1, 0]], [shape["arm"][-1, 1]])
        t = ts["t"][: k + 1]
        series = plotted_series(ts, k)
        for key, lines in run.lines.items():
            for line, values in zip(lines, series[key]):
                line.set_data(t, values)

    def _fit_path(self, xs: np.ndarray, ys: np.ndarray, margin: float) -> None:
        """Limits holding the points plus ``margin`` (m), widened to the axes' shape so
        that equal scaling needs no change of the axes box."""
        ax = self.path_ax
        x_low, x_high = float(np.min(xs)) - margin, float(np.max(xs)) + margin
        y_low, y_high = float(np.min(ys)) - margin, float(np.max(ys)) + margin
        box = ax.get_position(original=True)
        # ignore: the view's axes sit on a Figure (no SubFigure)
        width_in, height_in = ax.figure.get_size_inches()  # type: ignore[union-attr]
        shape = (box.width * width_in) / (box.height * height_in)  # width / height
        x_span, y_span = x_high - x_low, y_high - y_low
        if x_span / y_span < shape:
            grow = (shape * y_span - x_span) / 2
            x_low, x_high = x_low - grow, x_high + grow
        else:
            grow = (x_span / shape - y_span) / 2
            y_low, y_high = y_low - grow, y_high + grow
        ax.set_xlim(x_low, x_high)
        ax.set_ylim(y_low, y_high)

    def _fit_plots(self, results: Sequence[Any]) -> None:
        """Fixed limits from the whole runs, so the axes do not jump during playback."""
        end = max(float(r.timeseries["t"][-1]) for r in results)
        full = [plotted_series(r.timeseries, len(r.timeseries["t"]) - 1) for r in results]
        for key, ax in self.plot_axes.items():
            ax.set_xlim(0.0, end if end > 0 else 1.0)
            values = np.concatenate([np.ravel(series[key]) for series in full])
            if key == "position":
                low, high = float(values.min()), float(values.max())
                ax.set_ylim(low / 2, max(high * 2, low * 10))
                continue
            extras = {
                "wheels": [results[0].robot.wheel_speed_limit, -results[0].robot.wheel_speed_limit],
                "stability": [1.0]
                + [r.summary["stability_min"] for r in results if r.summary.get("stability_min")],
                "manipulability": [0.0, 1.0],
            }.get(key, [])
            values = np.r_[values, extras]
            low, high = float(values.min()), float(values.max())
            pad = 0.08 * (high - low) if high > low else 0.1 * max(abs(high), 1.0)
            ax.set_ylim(low - pad, high + pad)
            # a near-constant series (an orientation error no controller corrects, tau
            # inf) would be ticked in its last digits, labels running over the top view
            at_least_a_percent(ax, values)


def plotted_series(ts: dict[str, np.ndarray], k: int) -> dict[str, list[np.ndarray]]:
    """The y data of every plot line of one run up to index ``k`` (inclusive).

    Position error is floored at :data:`ddwmmr.reports.plots.ERROR_FLOOR` for the log axis.
    """
    end = k + 1
    return {
        "position": [np.maximum(ts["position_error_m"][:end], ERROR_FLOOR)],
        "orientation": [ts["orientation_error_rad"][:end]],
        "wheels": [ts["wheel_left_rad_s"][:end], ts["wheel_right_rad_s"][:end]],
        "stability": [ts["stability"][:end]],
        "manipulability": [ts["manipulability"][:end]],
    }


def _legend_columns(ax: Axes, fontsize: float) -> int:
    """Columns of ``ax``'s legend: three, or fewer where three make it wider than ``ax``
    (a window whose text is large against its plots, :func:`ddwmmr.gui.layout.text_scale`)."""
    renderer = renderer_of(ax.figure)
    columns = 3
    while columns > 1:
        trial = ax.legend(fontsize=fontsize, ncol=columns)
        wide = trial.get_window_extent(renderer).width > ax.bbox.width
        trial.remove()
        if not wide:
            break
        columns -= 1
    return columns


def add_view_axes(
    figure: Figure, path_rect: Rect, plots_rect: Rect
) -> tuple[Axes, dict[str, Axes]]:
    """Create the path axes and the stacked plot axes in the given figure rectangles.

    Rectangles are ``(left, bottom, width, height)`` in figure fractions. Returns
    ``(path_ax, {key: plot_ax})`` ready for :class:`RunView`.
    """
    path_ax = figure.add_axes(path_rect)
    plot_axes: dict[str, Axes] = {}
    shared = None
    for key, rect in zip(PLOTS, stacked_rects(plots_rect)):
        ax = figure.add_axes(rect, sharex=shared)
        shared = shared or ax
        plot_axes[key] = ax
    return path_ax, plot_axes


def stacked_rects(plots_rect: Rect) -> list[Rect]:
    """The rectangles (figure fractions) of the plot axes stacked in ``plots_rect``, top to
    bottom (one per key of :data:`PLOTS`)."""
    left, bottom, width, height = plots_rect
    gap = 0.012
    each = (height - gap * (len(PLOTS) - 1)) / len(PLOTS)
    tops = [bottom + height - number * (each + gap) for number in range(len(PLOTS))]
    return [(left, top - each, width, each) for top in tops]


def animation_figure(dpi: float = 80.0) -> tuple[Figure, RunView]:
    """A window-independent figure holding only the view (for the exported animation)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    figure = Figure(figsize=(11.0, 5.6), dpi=dpi)
    FigureCanvasAgg(figure)
    # The top view leaves room under it for its x label and its legend (three rows).
    path_ax, plot_axes = add_view_axes(figure, (0.06, 0.2, 0.46, 0.73), (0.62, 0.09, 0.36, 0.86))
    return figure, RunView(path_ax, plot_axes)
