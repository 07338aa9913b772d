"""Summaries, tables (thesis Table 5.2 format), CSV and figures of a scenario batch."""

from __future__ import annotations

import csv
import io
import json
import math
import textwrap
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ddwmmr.arbiters.state_machine import STATES
from ddwmmr.behaviours.obstacle import bubble_gap
from ddwmmr.errors import ParameterError, check_int_at_least, one_line
from ddwmmr.outputs import write_atomic
from ddwmmr.reports import palette
from ddwmmr.scenarios.generator import Scenario
from ddwmmr.scenarios.protocol import (
    FINE_TRACE_DISTANCE,
    METRICS,
    MOVING_RATE,
    MOVING_SPEED,
    NOT_APPLICABLE_AS_NAN,
    TRACE_INTERVAL,
    Outcome,
)
from ddwmmr.sim.result import json_safe

if TYPE_CHECKING:
    import os

    import numpy.typing as npt
    from matplotlib.axes import Axes
    from matplotlib.container import BarContainer
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    #: A figure's output file.
    OutputPath = str | os.PathLike[str]
    #: A scenario's trace: column name -> samples (:attr:`Outcome.trace`).
    Trace = Mapping[str, list[float]]

#: (summary key, metric column) pairs reported as mean and sample standard deviation.
AVERAGED = (
    ("time_s", "time_s"),
    ("speed_m_s", "speed_m_s"),
    ("time_base_s", "time_base_s"),
    ("time_arm_s", "time_arm_s"),
    ("time_manipulability_s", "time_manipulability_s"),
    ("transitions_manipulability", "transitions_manipulability"),
    ("time_stability_s", "time_stability_s"),
    ("transitions_stability", "transitions_stability"),
    ("time_obstacle_s", "time_obstacle_s"),
    ("transitions_obstacle", "transitions_obstacle"),
)


def _column(outcomes: Sequence[Outcome], key: str) -> np.ndarray:
    return np.array([float(o.metrics[key]) for o in outcomes])


def t_quantile_95(dof: int) -> float:
    """Two-sided 95 % quantile (the 0.975 quantile) of Student's t distribution with
    ``dof`` degrees of freedom, an integer >= 1: 12.706 at 1, 2.069 at 23, 1.984 at 99,
    falling to the normal's 1.960 as ``dof`` grows. The mean of n scenarios has n - 1."""
    check_int_at_least("dof", dof, 1)
    # Imported here: scipy.special takes about 0.3 s to import, paid only by a summary
    # of two or more scenarios.
    from scipy.special import stdtrit

    return float(stdtrit(dof, 0.975))


def _mean_sd(values: np.ndarray) -> tuple[float, float]:
    """Mean and sample standard deviation (n - 1) of ``values``: the sd of one value is
    undefined (NaN), and both are NaN without a value that is not NaN."""
    if values.size == 0 or np.all(np.isnan(values)):
        return math.nan, math.nan
    sd = float(np.std(values, ddof=1)) if values.size > 1 else math.nan
    return float(np.mean(values)), sd


#: Relative slack of the check that no scenario beats its ``--bounds`` lower bound (the
#: bound is a solver's result, good to about its tolerance).
LOWER_BOUND_SLACK = 1e-6


def bracket(outcomes: Sequence[Outcome], bounds: dict[int, tuple[float, float]]) -> dict[str, Any]:
    """Each successful scenario's time over both ends of its physical-limit bracket
    (``bounds``: ``{scenario: (lower_bound_s, best_known_s)}``, ``python -m
    ddwmmr.bounds``): the mean ratios to the lower bound and to the best-known time, over
    the scenarios that have the end (NaN if none), and the scenarios faster than their
    lower bound (:func:`below_lower_bound`)."""
    to_lower, to_best = [], []
    for o in outcomes:
        m = o.metrics
        lower, best = bounds.get(m["scenario"], (math.nan, math.nan))
        if m["success"] and math.isfinite(lower) and lower > 0:
            to_lower.append(m["time_s"] / lower)
        if m["success"] and math.isfinite(best) and best > 0:
            to_best.append(m["time_s"] / best)
    return {
        "mean_ratio_to_lower_bound": float(np.mean(to_lower)) if to_lower else math.nan,
        "mean_ratio_to_best_known": float(np.mean(to_best)) if to_best else math.nan,
        "scenarios_with_lower_bound": len(to_lower),
        "scenarios_with_best_known": len(to_best),
        "scenarios_below_lower_bound": [n for n, _, _ in below_lower_bound(outcomes, bounds)],
    }


def below_lower_bound(
    outcomes: Sequence[Outcome], table: dict[int, tuple[float, float]]
) -> list[tuple[int, float, float]]:
    """``(scenario, time_s, lower_bound_s)`` of each successful scenario that reached its
    last waypoint before the bounds file's lower bound (by more than
    :data:`LOWER_BOUND_SLACK`, relative): no run can, so the file is not for this task."""
    beaten = []
    for o in outcomes:
        m = o.metrics
        lower = table.get(m["scenario"], (math.nan, math.nan))[0]
        if m["success"] and m["time_s"] * (1.0 + LOWER_BOUND_SLACK) < lower:
            beaten.append((m["scenario"], m["time_s"], lower))
    return beaten


def summarize(outcomes: Sequence[Outcome], wall_time_s: float) -> dict[str, Any]:
    """Batch summary: failures, mean and sd of every metric, minimum stability, speed.

    Means are over all scenarios (a failed scenario counts with the time at which it
    stopped), except the speed's: ``mean_speed_m_s`` and ``sd_speed_m_s`` are over the
    ``speed_scenarios`` that finished (``speed_m_s`` of the protocol; NaN if none did); ``sd_*``
    are sample standard deviations (n - 1; NaN for one value).
    ``ci95_time_s`` is the half-width (s) of the mean time's 95 % confidence interval over
    the scenarios, ``t sd / sqrt(n)`` with ``t`` Student's two-sided 95 % quantile for
    n - 1 degrees of freedom (:func:`t_quantile_95`: 4.303 at n = 3, 1.984 at n = 100;
    NaN for one scenario): two runs whose mean times differ by less than that have not
    measured a difference.
    ``fallback_steps`` (and ``fallback_share`` of all steps): the steps whose command was
    the controller's safe fallback after a failed solve; None for the thesis controller.
    """
    if not outcomes:
        raise ParameterError("outcomes: a summary needs at least one scenario's outcome (got 0)")
    failed = [o.metrics for o in outcomes if not o.metrics["success"]]
    summary: dict[str, Any] = {"n": len(outcomes), "failed": len(failed)}
    for key, column in AVERAGED:
        values = _column(outcomes, column)
        if key == "speed_m_s":  # finished scenarios only
            values = values[np.isfinite(values)]
            summary["speed_scenarios"] = int(values.size)
        mean, sd = _mean_sd(values)
        name = "mean_time_s" if key == "time_s" else key
        name = "mean_speed_m_s" if key == "speed_m_s" else name
        summary[name] = mean
        summary["sd_" + key] = sd
    fallbacks = _column(outcomes, "fallback_steps")
    known = bool(np.any(np.isfinite(fallbacks)))
    summary["fallback_steps"] = int(np.nansum(fallbacks)) if known else None
    steps = float(np.sum(_column(outcomes, "sim_steps")))
    summary["fallback_share"] = float(np.nansum(fallbacks)) / steps if known and steps else None
    n = len(outcomes)
    half_width = t_quantile_95(n - 1) * summary["sd_time_s"] / math.sqrt(n) if n > 1 else math.nan
    summary["ci95_time_s"] = half_width
    summary["min_stability"] = float(np.min(_column(outcomes, "min_stability")))
    summary["min_manipulability"] = float(np.min(_column(outcomes, "min_manipulability")))
    unloaded = _column(outcomes, "unloaded_time_s")  # physics plants only (else NaN)
    physics = bool(np.any(np.isfinite(unloaded)))
    summary["tipped_physics"] = (
        sum(o.metrics["reason"] == "tipped (physics)" for o in outcomes) if physics else None
    )
    summary["mean_unloaded_time_s"] = float(np.mean(unloaded)) if physics else None
    sim_time = float(np.sum(_column(outcomes, "time_s")))
    summary["sim_time_s"] = sim_time
    summary["wall_time_s"] = wall_time_s
    summary["sim_seconds_per_wall_second"] = sim_time / wall_time_s if wall_time_s > 0 else None
    summary["failures"] = [
        {
            "scenario": m["scenario"],
            "reason": m["reason"],
            "waypoints_reached": m["waypoints_reached"],
        }
        for m in failed
    ]
    return summary


def _fmt(value: float) -> str:
    """Three significant figures, as the thesis reports (thesis 5.1)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return f"{value:.3g}"


def _stateless(summary: dict[str, Any]) -> bool:
    """True for a controller without states: no time in the stability state (NaN)."""
    value = summary["time_stability_s"]
    return isinstance(value, float) and math.isnan(value)


#: What a Table 5.2 cell holds (thesis Table 5.2's own layout), and the rows that hold
#: something else than a mean over the scenarios.
TABLE_LEGEND = (
    "Cells: mean (share of the mean simulation time) (sample standard deviation) over the "
    "scenarios; a failed scenario counts up to the instant it stopped, except in the speed, "
    "which is over the finished scenarios only (the route's straight-line length over the "
    "time to its last waypoint). Not means: the numbers of failed and tipped scenarios "
    "(counts), the minimum stability S (the lowest of all the scenarios' runs) and the steps "
    "with a fallback command (the total over the scenarios, and its share of all their "
    "steps); the time with an edge unloaded is a mean without its deviation."
)
#: Footnote of a controller without states, whose base and arm times overlap.
OVERLAP_NOTE = (
    "* This controller has no states: base and arm times are the times with the base moving "
    f"(|v| > {MOVING_SPEED * 1e3:g} mm/s or |w| > {MOVING_RATE * 1e3:g} mrad/s) and with a "
    f"joint moving (> {MOVING_RATE * 1e3:g} mrad/s); they overlap, so their shares need not "
    "add to 100 %, and a base creeping at the end of an approach counts as moving."
)


def table_rows(summary: dict[str, Any]) -> list[tuple[str, str]]:
    """Rows of thesis Table 5.2: label and "mean (share of time) (sd)" text
    (:data:`TABLE_LEGEND`). The base and arm shares of a controller without states are
    starred (:data:`OVERLAP_NOTE`); the speed of a batch with failures says over how many
    finished scenarios it is."""
    total = summary["mean_time_s"]
    star = "*" if _stateless(summary) else ""

    def with_share(key: str, mark: str = "") -> str:
        mean, sd = summary[key], summary["sd_" + key]
        if isinstance(mean, float) and math.isnan(mean):
            return "n/a"
        # Every scenario may stop at t = 0 (a payload that tips the start pose): no share.
        share = _fmt(100.0 * mean / total) + "%" if total and total > 0 else "n/a"
        return f"{_fmt(mean)} ({share}){mark} ({_fmt(sd)})"

    def plain(mean_key: str, sd_key: str) -> str:
        if isinstance(summary[mean_key], float) and math.isnan(summary[mean_key]):
            return "n/a"
        return f"{_fmt(summary[mean_key])} ({_fmt(summary[sd_key])})"

    speed = plain("mean_speed_m_s", "sd_speed_m_s")
    if summary["failed"]:
        speed += f", over the {summary['speed_scenarios']} of {summary['n']} that finished"
    rows = [
        ("No. of failed scenarios", str(summary["failed"])),
        ("Simulation time (s)", plain("mean_time_s", "sd_time_s")),
        ("Simulation speed (m/s)", speed),
        ("Time spent moving base (s)", with_share("time_base_s", star)),
        ("Time spent moving manipulator (s)", with_share("time_arm_s", star)),
        ("Time in manipulability state (s)", with_share("time_manipulability_s")),
        (
            "No. of manipulability state transitions",
            plain("transitions_manipulability", "sd_transitions_manipulability"),
        ),
        ("Time in stability state (s)", with_share("time_stability_s")),
        (
            "No. of stability state transitions",
            plain("transitions_stability", "sd_transitions_stability"),
        ),
    ]
    if summary.get("time_obstacle_s", 0.0) and not math.isnan(summary["time_obstacle_s"]):
        rows.append(("Time in obstacle state (s)", with_share("time_obstacle_s")))
        rows.append(
            (
                "No. of obstacle state transitions",
                plain("transitions_obstacle", "sd_transitions_obstacle"),
            )
        )
    return rows


def format_table(summary: dict[str, Any], title: str) -> str:
    """Plain-text table in the format of thesis Table 5.2: ``title``, the cells' legend
    (:data:`TABLE_LEGEND`), the number of scenarios the means are over, the rows, and for
    a controller without states the footnote on its overlapping base and arm times
    (:data:`OVERLAP_NOTE`)."""
    rows = table_rows(summary)
    width = max(len(label) for label, _ in rows)
    lines = [title, "-" * len(title), *textwrap.wrap(TABLE_LEGEND, width=88)]
    lines.append(f"{'No. of scenarios':<{width}}  {summary['n']}")
    lines += [f"{label:<{width}}  {value}" for label, value in rows]
    label = "Minimum stability S (lowest run)"
    lines.append(f"{label:<{width}}  {_fmt(summary['min_stability'])}")
    if summary.get("fallback_steps") is not None:
        label = "Steps with a fallback command (total)"
        share = summary["fallback_share"] or 0.0
        lines.append(f"{label:<{width}}  {summary['fallback_steps']} ({_fmt(100 * share)} %)")
    ci = summary.get("ci95_time_s")
    if ci is not None and math.isfinite(ci):
        label = "Mean time, 95 % CI (s)"
        lines.append(f"{label:<{width}}  {_fmt(summary['mean_time_s'])} +- {_fmt(ci)}")
    if summary.get("tipped_physics") is not None:
        label = "Tipped over (physics) (count)"
        lines.append(f"{label:<{width}}  {summary['tipped_physics']}")
        label = "Mean time with an edge unloaded (s)"
        lines.append(f"{label:<{width}}  {_fmt(summary['mean_unloaded_time_s'])}")
    if _stateless(summary):
        lines += textwrap.wrap(OVERLAP_NOTE, width=88)
    return "\n".join(lines) + "\n"


def summary_json(summary: dict[str, Any]) -> str:
    """The text of a scenarios or bounds run's summary.json: ``summary`` as indented
    standard JSON in which every undefined number (NaN, or a non-finite float: the mean of
    a metric the controller has not, the sd and CI of one scenario, a ratio over no
    scenario) is null, as the fields that do not apply already are (``fallback_steps``...). Strings,
    such as the run record's ``"inf"`` (:mod:`ddwmmr.provenance`), are kept as they are."""
    return json.dumps(json_safe(summary, undefined_as_null=True), indent=2, allow_nan=False) + "\n"


def metrics_csv(outcomes: Sequence[Outcome]) -> str:
    """One CSV row per scenario with every metric of :data:`METRICS`, floats by ``repr``
    (they read back exactly). A metric that does not apply (None, or NaN in a column of
    :data:`NOT_APPLICABLE_AS_NAN`) is an empty cell, as in compare's metrics.csv, and
    null in summary.json; the speed of a scenario that did not finish is an undefined
    number, "nan" (``speed_m_s`` of :mod:`ddwmmr.scenarios.protocol`)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(METRICS)
    for o in outcomes:
        writer.writerow([_cell(o.metrics[k], k in NOT_APPLICABLE_AS_NAN) for k in METRICS])
    return buffer.getvalue()


def _cell(value: Any, nan_not_applicable: bool = False) -> str:
    """The CSV text of one metric (see :func:`metrics_csv`)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and math.isnan(value):
        return "" if nan_not_applicable else "nan"
    return repr(value) if isinstance(value, float) else str(value)


# -- figures ------------------------------------------------------------------------------
# One palette for the scenario figures (paths, timeline, times, arbiter weights): a colour
# or line style means the same thing in each of them, and the base and the end effector
# are drawn as in track's path figure (ddwmmr.reports.plots: end effector blue, base grey).
BASE_COLOUR = palette.BASE
EFFECTOR_COLOUR = palette.END_EFFECTOR
STABILITY_COLOUR = "tab:brown"
MANIPULABILITY_COLOUR = "tab:purple"
OBSTACLE_COLOUR = "tab:olive"
OBJECTIVE_COLOUR = "tab:pink"
WAYPOINT_COLOUR = "k"
#: (colour, line style) of each kind of threshold line: tip-over (S = 1), a fix state's
#: enter threshold (also a controller's floor, ``S_min``) and its leave threshold.
TIP_OVER_LINE = ("tab:red", "--")
ENTER_LINE = ("tab:orange", ":")
LEAVE_LINE = ("tab:green", "-.")
#: Colour of each arbiter's traces where both are drawn (the arbiter study's figures).
ARBITER_COLOURS = {"competitive": "k", "state-machine": "tab:cyan"}
#: Colour of each time share (a metric column) in the per-scenario time bars.
TIME_COLOURS = {
    "time_s": "0.8",
    "time_base_s": BASE_COLOUR,
    "time_arm_s": EFFECTOR_COLOUR,
    "time_manipulability_s": MANIPULABILITY_COLOUR,
    "time_stability_s": STABILITY_COLOUR,
    "time_obstacle_s": OBSTACLE_COLOUR,
}
#: Colour of each behaviour's weight (the competitive arbiter's behaviours).
BEHAVIOUR_COLOURS = {
    "objective": OBJECTIVE_COLOUR,
    "stability": STABILITY_COLOUR,
    "manipulability": MANIPULABILITY_COLOUR,
    "obstacle": OBSTACLE_COLOUR,
}


def _figure(rows: int = 1, cols: int = 1, height: float = 3.2) -> tuple[Figure, np.ndarray]:
    """A figure 10 in wide, ``height`` in per row, and its ``rows`` x ``cols`` axes (a 2-D
    array). Not pyplot's (:func:`~ddwmmr.reports.canvas.new_figure`): the report leaves the
    caller's matplotlib backend alone and opens no window."""
    from ddwmmr.reports.canvas import new_figure

    fig = new_figure((10, height * rows))
    return fig, fig.subplots(rows, cols, squeeze=False)


def _save(
    fig: Figure, path: OutputPath, rect: tuple[float, float, float, float] | None = None
) -> None:
    """Lay out ``fig`` (its axes within ``rect``, figure fractions; None: all of it) and
    write it to ``path`` as PNG (a figure of :func:`_figure`: nothing to close)."""
    buffer = io.BytesIO()
    fig.tight_layout(rect=rect)
    fig.savefig(buffer, format="png", dpi=110)
    write_atomic(path, buffer.getvalue())


#: Hatch and legend label of the bars of scenarios that did not finish (a timeout, a tip,
#: a collision...): their times are the instant the run stopped, not a finished scenario's.
FAILED_HATCH = "///"
FAILED_LABEL = "did not finish"
#: Up to this many scenarios, every scenario number is a tick; beyond, integer ticks only.
MAX_LABELLED_SCENARIOS = 25


def _failed(outcomes: Sequence[Outcome]) -> np.ndarray:
    return np.array([not o.metrics["success"] for o in outcomes], dtype=bool)


def _bars(
    ax: Axes, index: npt.ArrayLike, values: npt.ArrayLike, failed: np.ndarray, **kwargs: Any
) -> BarContainer:
    """``ax.bar`` with the bars of failed scenarios hatched (dark hatch, no outline)."""
    bars = ax.bar(index, values, **kwargs)
    for patch, hatched in zip(bars.patches, failed):
        if hatched:
            patch.set_hatch(FAILED_HATCH)
            patch.set_edgecolor("0.1")
            patch.set_linewidth(0.0)
    return bars


def _failed_handle() -> Patch:
    import matplotlib.patches as patches

    return patches.Patch(facecolor="white", edgecolor="0.1", hatch=FAILED_HATCH, label=FAILED_LABEL)


def _bar_axes(
    ax: Axes,
    index: Sequence[float] | np.ndarray,
    failed: np.ndarray,
    entries: bool = False,
    empty: str = "0 in every scenario",
) -> None:
    """Scenario-number ticks, a y-axis from 0 and a legend beside the axes (never on
    the tallest bars) naming the series (``entries``) and, if any are drawn, the hatched
    bars. Without a bar above 0 the axis is 0..1 and says ``empty``."""
    from matplotlib.ticker import MaxNLocator

    from ddwmmr.reports.legends import legend_beside

    if len(index) <= MAX_LABELLED_SCENARIOS:
        ax.set_xticks(np.asarray(index, dtype=float), [str(int(i)) for i in index])
    else:
        ax.xaxis.set_major_locator(MaxNLocator(integer=True, steps=[1, 2, 5, 10]))
    # ignore: the axes' patches are its bars, Rectangles (Patch has no y or height)
    heights = [p.get_y() + p.get_height() for p in ax.patches]  # type: ignore[attr-defined]
    top = np.nanmax(heights) if heights and np.any(np.isfinite(heights)) else 0.0
    if top > 0:
        ax.set_ylim(bottom=0.0)
    else:  # nothing to scale to: a unit axis from 0 rather than -0.04..0.04
        ax.set_ylim(0.0, 1.0)
        ax.text(0.5, 0.5, empty, transform=ax.transAxes, ha="center", va="center")
    handles, labels = ax.get_legend_handles_labels() if entries else ([], [])
    if failed.any() and top > 0:  # hatched bars to name
        handles, labels = [*handles, _failed_handle()], [*labels, FAILED_LABEL]
    if handles:
        legend_beside(ax, handles=handles, labels=labels, fontsize=8)


#: What :func:`plot_state_times` shows, after its subject in the title: the time in each
#: state, or for a controller without states the total time and the (overlapping) times
#: with the base and with the arm moving.
STATE_TIMES_HEADING = "time per state"
MOVING_TIMES_HEADING = "total time; time moving: base / arm"


def plot_state_times(outcomes: Sequence[Outcome], path: OutputPath, title: str) -> None:
    """Stacked per-scenario time in each state (thesis Figs 5.3, 5.10, 5.11), titled
    ``"<title>: time per state"`` (``title``: the figure's subject, e.g. the controller
    and plant).

    Controllers without states move base and arm together, so their times overlap: they
    are drawn as grouped bars (total, moving base, moving arm) instead of stacked, titled
    ``"<title>: total time; time moving: base / arm"``. Each time share has its colour
    (:data:`TIME_COLOURS`); bars of scenarios that did not finish are hatched
    (:data:`FAILED_HATCH`); the legend sits beside the axes.
    """
    fig, ax = _figure()
    ax = ax[0, 0]
    index = np.array([o.metrics["scenario"] for o in outcomes])
    failed = _failed(outcomes)
    ax.set(xlabel="scenario", ylabel="time (s)")
    if np.all(np.isnan(_column(outcomes, "time_stability_s"))):
        ax.set_title(f"{title}: {MOVING_TIMES_HEADING}")
        for shift, key, label in (
            (-0.3, "time_s", "total"),
            (0.0, "time_base_s", "moving base"),
            (0.3, "time_arm_s", "moving arm"),
        ):
            values = _column(outcomes, key)
            _bars(
                ax, index + shift, values, failed, width=0.3, label=label, color=TIME_COLOURS[key]
            )
        _bar_axes(ax, index, failed, entries=True)
        _save(fig, path)
        return
    ax.set_title(f"{title}: {STATE_TIMES_HEADING}")
    bottom = np.zeros(len(outcomes))
    for key, label in (
        ("time_base_s", "moving base"),
        ("time_arm_s", "moving arm"),
        ("time_manipulability_s", "manipulability"),
        ("time_stability_s", "stability"),
        ("time_obstacle_s", "obstacle"),
    ):
        values = np.nan_to_num(_column(outcomes, key))
        if np.any(values):
            colour = TIME_COLOURS[key]
            _bars(ax, index, values, failed, bottom=bottom, label=label, width=0.85, color=colour)
            bottom += values
    _bar_axes(ax, index, failed, entries=True, empty="every scenario ended at t = 0")
    _save(fig, path)


#: Legend label of the marks of scenarios that did not finish in the speed figure.
NO_SPEED_LABEL = "did not finish: no speed"


def plot_speeds(outcomes: Sequence[Outcome], path: OutputPath, title: str) -> None:
    """Per-scenario speed (Fig 5.4) and speed over base-moving time only (Fig 5.5) of the
    scenarios that finished (``speed_m_s`` of :mod:`ddwmmr.scenarios.protocol`); a
    scenario that did not finish has no bar but a red cross on the axis, named in the
    legend (:data:`NO_SPEED_LABEL`)."""
    fig, axes = _figure(2, 1)
    index = np.array([o.metrics["scenario"] for o in outcomes])
    failed = _failed(outcomes)
    length = np.where(failed, np.nan, _column(outcomes, "path_length_m"))
    base = _column(outcomes, "time_base_s")
    with np.errstate(divide="ignore", invalid="ignore"):
        over_base = np.where(base > 0, length / base, np.nan)
    panels = (
        (_column(outcomes, "speed_m_s"), f"{title}: waypoint route length / total time"),
        (over_base, "waypoint route length / base-moving time"),
    )
    for ax, (values, heading) in zip(axes[:, 0], panels):
        _bars(ax, index, values, np.zeros_like(failed), width=0.85)
        if failed.any():  # a cross just above the axis (axes fraction 0.04), never cut
            ax.plot(index[failed], np.full(int(failed.sum()), 0.04), "x", color="tab:red",
                    transform=ax.get_xaxis_transform(), label=NO_SPEED_LABEL)  # fmt: skip
        ax.set(ylabel="speed (m/s)", title=heading)
        _bar_axes(ax, index, np.zeros_like(failed), entries=True, empty="no scenario finished")
    axes[1, 0].set(xlabel="scenario")
    _save(fig, path)


def plot_fix_state(outcomes: Sequence[Outcome], key: str, path: OutputPath, title: str) -> None:
    """Per-scenario time in and transitions into one fix state (Figs 5.7, 5.9), in the
    state's colour (:data:`TIME_COLOURS`); bars of scenarios that did not finish are
    hatched."""
    from matplotlib.ticker import MaxNLocator

    fig, axes = _figure(2, 1)
    index = [o.metrics["scenario"] for o in outcomes]
    failed = _failed(outcomes)
    colour = TIME_COLOURS[f"time_{key}_s"]  # the state's colour in every time figure
    times = np.nan_to_num(_column(outcomes, f"time_{key}_s"))
    _bars(axes[0, 0], index, times, failed, width=0.85, color=colour)
    axes[0, 0].set(ylabel="time (s)", title=f"{title}: time in {key} state")
    counts = np.nan_to_num(_column(outcomes, f"transitions_{key}"))
    _bars(axes[1, 0], index, counts, failed, width=0.85, color=colour)
    axes[1, 0].set(xlabel="scenario", ylabel="transitions", title=f"transitions into {key}")
    _bar_axes(axes[0, 0], index, failed)
    _bar_axes(axes[1, 0], index, np.zeros_like(failed))
    axes[1, 0].yaxis.set_major_locator(MaxNLocator(integer=True))  # a count
    _save(fig, path)


def plot_paths(
    items: Sequence[tuple[Scenario, Outcome]],
    path: OutputPath,
    title: str,
    clearance: float | None = None,
) -> None:
    """Base and end-effector paths with waypoints (and obstacles, grey discs) of chosen
    scenarios, under the figure title ``title``. With ``clearance`` (m, the radius of the
    base's enclosing circle, which the protocol keeps off the obstacles), that circle is
    drawn where the base came closest to an obstacle and each panel's title gives that
    gap. One legend below the panels names every kind of line, mark and disc."""
    import matplotlib.patches as patches

    cols = min(len(items), 2)
    rows = math.ceil(len(items) / cols)
    fig, axes = _figure(rows, cols, height=4.6)
    for ax, (scenario, outcome) in zip(axes.flat, items):
        tr = outcome.trace or {}
        # as track's path figure: the end effector wide, the base thin over it
        _draw_path(ax, tr, "xe", "ye", EFFECTOR_COLOUR, "end effector", lw=2.0, alpha=0.8)
        _draw_path(ax, tr, "x", "y", BASE_COLOUR, "base", lw=1.0)
        wx, wy = zip(*scenario.waypoints)
        ax.plot(wx, wy, "x", color=WAYPOINT_COLOUR, ms=8, label="waypoints")
        for i, (x, y) in enumerate(scenario.waypoints, start=1):
            ax.annotate(str(i), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
        for i, (ox, oy, radius) in enumerate(scenario.obstacles):
            label = f"obstacle (r {radius:g} m)" if i == 0 else None
            ax.add_patch(patches.Circle((ox, oy), radius, color="0.5", alpha=0.6, label=label))
        m = outcome.metrics
        heading = f"scenario {m['scenario']}: {m['reason']}, {m['time_s']:.1f} s"
        if clearance is not None and scenario.obstacles:
            heading += (
                f", closest gap {_closest_approach(ax, tr, scenario.obstacles, clearance):.2f} m"
            )
        ax.set(aspect="equal", title=heading, xlabel="x (m)", ylabel="y (m)")
    for ax in list(axes.flat)[len(items) :]:
        ax.axis("off")
    fig.suptitle(title, fontsize=_fitting_size(title, fig))
    named: dict[str, Any] = {}
    for ax in axes.flat:  # each kind once, in drawing order
        for handle, label in zip(*ax.get_legend_handles_labels()):
            named.setdefault(label, handle)
    fig.legend(list(named.values()), list(named), loc="lower center", ncol=4, fontsize=8)
    legend_rows = math.ceil(len(named) / 4)
    _save(fig, path, rect=(0.0, 0.25 * legend_rows / fig.get_figheight(), 1.0, 1.0))


def _draw_path(
    ax: Axes,
    trace: Trace,
    x: str,
    y: str,
    colour: str,
    name: str,
    lw: float,
    alpha: float = 1.0,
) -> None:
    """The trace's ``x``/``y`` path in ``colour`` (line width ``lw``, points), labelled
    ``name``, with a dot of the same colour where it starts, labelled ``"<name> start"``."""
    xs, ys = trace.get(x, []), trace.get(y, [])
    ax.plot(xs, ys, color=colour, lw=lw, alpha=alpha, label=name)
    if len(xs):
        ax.plot(xs[:1], ys[:1], "o", color=colour, ms=5, label=f"{name} start")


#: A threshold line of a timeline panel: value and legend label.
Threshold = tuple[float, str]
#: (colour, line style) of a panel's thresholds, in order (an enter and an exit threshold).
THRESHOLD_STYLES = (ENTER_LINE, LEAVE_LINE)


def _closest_approach(
    ax: Axes, trace: Trace, obstacles: Sequence[tuple[float, float, float]], clearance: float
) -> float:
    """Draw the base's enclosing circle (radius ``clearance``, m) at the trace sample where
    it came closest to an obstacle and return that gap (m; negative: overlapping; NaN
    without a trace)."""
    import matplotlib.patches as patches

    x = np.asarray(trace.get("x", []), dtype=float)
    y = np.asarray(trace.get("y", []), dtype=float)
    if not len(obstacles) or not len(x):
        return math.nan
    # the protocol's own collision measure, sample by sample (a trace holds few samples)
    gaps = np.array([[bubble_gap(xi, yi, o, clearance) for o in obstacles] for xi, yi in zip(x, y)])
    k = int(np.argmin(np.min(gaps, axis=1)))
    label = f"base's enclosing circle (r {clearance:.3g} m) where closest to an obstacle"
    circle = patches.Circle((x[k], y[k]), clearance, fill=False, ec="tab:red", ls="--", lw=0.9)
    circle.set_label(label)
    ax.add_patch(circle)
    return float(np.min(gaps[k]))


#: Largest and smallest font size (pt) of a figure title; an average character is about
#: 0.6 of the font size wide.
_TITLE_POINTS = (12.0, 8.0)


def _fitting_size(title: str, fig: Any) -> float:
    """The font size (pt) at which ``title`` fits on one line across ``fig``: the default
    12 pt where it fits, smaller down to 8 pt for a long one (a suptitle wider than its
    figure is cut at both edges; wrapping it instead would shrink the panels under it)."""
    largest, smallest = _TITLE_POINTS
    fitting = fig.get_figwidth() * 72.0 / (0.6 * max(len(title), 1))
    size: float = max(smallest, min(largest, fitting))
    return size


def plot_timeline(
    outcome: Outcome,
    path: OutputPath,
    title: str,
    scenario: Scenario | None = None,
    stability_lines: Sequence[Threshold] = (),
    manipulability_lines: Sequence[Threshold] = (),
) -> None:
    """Controller state, stability, manipulability and the distance to the current waypoint
    over time for one scenario (thesis Fig 5.17); with ``scenario``, the instants at which
    each waypoint was reached are marked, the last one's included. ``stability_lines`` and
    ``manipulability_lines`` (up to two each, ``(value, label)``) are the thresholds the
    controller acts on, drawn with their labels in the S and eta panels beside S = 1.

    The top title states the outcome (:func:`outcome_text`); a scenario that did not
    finish has the instant it stopped marked by a red vertical in every panel."""
    from ddwmmr.reports.legends import legend_beside

    tr = outcome.trace or {}
    t = tr.get("t", [])
    fig, axes = _figure(4, 1, height=2.2)
    ax = axes[0, 0]
    ax.step(t, tr.get("state", []), where="post", color="k")
    number = outcome.metrics["scenario"]
    if isinstance(outcome.metrics["transitions_stability"], float) and math.isnan(
        outcome.metrics["transitions_stability"]
    ):  # no arbiter: the trace only tells whether the base moves
        ax.set_yticks([0, 1], ["base moving", "base at rest"])
        ax.set(ylabel="base")
        shown_as = "base motion"
    else:
        ax.set_yticks(range(len(STATES)), [s.replace("_", " ") for s in STATES])
        ax.set(ylabel="state")
        shown_as = "controller state"
    total = len(scenario.waypoints) if scenario is not None else None
    outcome_title = outcome_text(outcome.metrics, total)
    ax.set_title(f"{title}: scenario {number} {shown_as}; {outcome_title}")
    ax2 = axes[1, 0]
    ax2.plot(t, tr.get("s", []), color=STABILITY_COLOUR, label="stability S")
    tip_colour, tip_style = TIP_OVER_LINE
    ax2.axhline(1.0, color=tip_colour, lw=0.8, ls=tip_style, label="S = 1 (tips over)")
    top = max(3.0, 1.05 * max(tr.get("s", [0.0]), default=0.0))
    ax2.set(ylim=(0.0, top), ylabel="stability S (-)")
    ax3 = axes[2, 0]
    eta_label = "manipulability eta = |sin th2|"
    ax3.plot(t, tr.get("eta", []), color=MANIPULABILITY_COLOUR, label=eta_label)
    ax3.set(ylim=(0.0, 1.05), ylabel="manipulability\neta (-)")
    for axis, lines in ((ax2, stability_lines), (ax3, manipulability_lines)):
        for (value, label), (color, style) in zip(lines, THRESHOLD_STYLES):
            axis.axhline(value, color=color, lw=0.9, ls=style, label=label)
    ax4 = axes[3, 0]
    # The log scale and its range before the data: a one-instant trace cannot autoscale.
    ax4.set(yscale="log", ylim=(1e-4, 30.0))
    distance = np.maximum(tr.get("distance", []), 1e-4)
    ax4.plot(t, distance, color=EFFECTOR_COLOUR, label="distance")
    ax4.axhline(0.01, color=WAYPOINT_COLOUR, lw=0.6, ls="--", label="tolerance 0.01 m")
    if scenario is not None:
        _mark_waypoints(ax4, tr, scenario, outcome.metrics)
    sampling = (
        f" (trace: every {TRACE_INTERVAL:g} s, every step within {FINE_TRACE_DISTANCE:g} m "
        "of a waypoint)"
        if len(t) > 1
        else ""
    )
    ax4.set(xlabel=f"time (s){sampling}", ylabel="end effector to\nwaypoint (m)")
    if not len(t) or t[-1] == t[0]:  # a run over at its first instant: give the axes a width
        start = t[0] if len(t) else 0.0
        ax4.set_xlim(start - 0.5, start + 0.5)
        ax.set_ylim(-0.5, len(ax.get_yticks()) - 0.5)
        ax.text(
            0.5,
            0.5,
            f"the run ended at t = {start:g} s",
            transform=ax.transAxes,
            ha="center",
            va="center",
        )
    for axis in (ax, ax2, ax3):
        axis.sharex(ax4)
        axis.grid(alpha=0.3)
    ax4.grid(alpha=0.3)
    if not outcome.metrics["success"] and len(t) > 1:
        stopped = f"stopped: {one_line(str(outcome.metrics['reason']), 30)}"
        for axis in (ax, ax2, ax3, ax4):
            stop_label = stopped if axis is ax4 else None
            axis.axvline(outcome.metrics["time_s"], color="tab:red", lw=1.2, label=stop_label)
    # Beside the panels: the waypoint marks span the whole height of the last one.
    for axis in (ax2, ax3, ax4):
        legend_beside(axis, fontsize=8)
    _save(fig, path)


def outcome_text(metrics: dict[str, Any], waypoints: int | None = None) -> str:
    """How a scenario ended, for a title: "reached all 5 waypoints in 24.2 s", or for
    one that did not finish "tipped (physics) at 10.3 s, 3 of 5 waypoints reached"
    (``waypoints``: the scenario's count; None: not stated). A long reason (a
    controller's error message) is cut to 60 characters."""
    reached, time = metrics["waypoints_reached"], metrics["time_s"]
    if metrics["success"]:
        count = f"all {waypoints}" if waypoints is not None else f"all {reached}"
        return f"reached {count} waypoints in {time:.1f} s"
    of = f" of {waypoints}" if waypoints is not None else ""
    reason = one_line(str(metrics["reason"]), 60)
    return f"{reason} at {time:.1f} s, {reached}{of} waypoints reached"


def _mark_waypoints(ax: Axes, trace: Trace, scenario: Scenario, metrics: dict[str, Any]) -> None:
    """Dotted verticals at the first trace sample after each waypoint was reached, and
    for a finished scenario (``metrics``' ``success``) at its end, ``time_s``: the run
    stops on reaching the last waypoint, so no sample follows that one.

    The trace records the distance to the *current* waypoint; the waypoint it refers to is
    the one at exactly that distance from the end effector, so a change of that index is
    a waypoint reached (not merely the distance growing as the arm moves).
    """
    t = np.asarray(trace.get("t", []), dtype=float)
    xe = np.asarray(trace.get("xe", []), dtype=float)
    ye = np.asarray(trace.get("ye", []), dtype=float)
    distance = np.asarray(trace.get("distance", []), dtype=float)
    if len(t) < 2:
        return
    points = np.asarray(scenario.waypoints, dtype=float)  # (5, 2)
    to_each = np.hypot(xe[:, None] - points[None, :, 0], ye[:, None] - points[None, :, 1])
    current = np.maximum.accumulate(np.argmin(np.abs(to_each - distance[:, None]), axis=1))
    done = distance == 0.0  # after the last waypoint
    current[done] = len(points)
    reached = list(t[np.flatnonzero(np.diff(current) > 0) + 1])
    if metrics["success"] and len(reached) < len(points):
        reached.append(float(metrics["time_s"]))
    for i, instant in enumerate(reached):
        label = "waypoint reached" if i == 0 else None
        ax.axvline(instant, color=WAYPOINT_COLOUR, lw=0.6, ls=":", label=label)
