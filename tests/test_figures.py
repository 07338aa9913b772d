"""Track and scenario figures: obstacles drawn, no false wrap jumps,
labelled timeline axes; the scenario table never divides by zero."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
import pytest

from ddwmmr import load_trajectory, simulate
from ddwmmr.reports.plots import break_wraps, plot_errors, plot_path
from ddwmmr.scenarios import report
from ddwmmr.scenarios.generator import generate
from ddwmmr.scenarios.protocol import RunConfig, run_scenario


def test_break_wraps_cuts_only_the_wrap():
    t = np.arange(6.0)
    angle = np.array([3.0, 3.1, -3.1, -3.0, -2.9, 0.1])  # wraps once, then a real step
    tb, ab = break_wraps(t, angle)
    assert np.isnan(ab).sum() == 1 and np.isnan(ab[2]) and np.isnan(tb[2])
    np.testing.assert_array_equal(ab[~np.isnan(ab)], angle)
    # Between any two consecutive drawn points the line moves less than pi.
    pieces = np.split(ab, np.flatnonzero(np.isnan(ab)))
    assert all(np.all(np.abs(np.diff(p[~np.isnan(p)])) < math.pi) for p in pieces)


@pytest.fixture(scope="module")
def rectangle_run():
    """clrrmc-cs on the rectangle: its wrapped orientation error crosses +-pi."""
    return simulate(None, load_trajectory("rectangle"), "clrrmc-cs")


def test_orientation_error_line_has_no_vertical_wrap_stroke(rectangle_run):
    error = rectangle_run.timeseries["orientation_error_rad"]
    wraps = int(np.sum(np.abs(np.diff(error)) > math.pi))
    assert wraps >= 1  # the case the figure must handle
    fig = plot_errors(rectangle_run)
    line = fig.axes[1].lines[0]
    y = np.asarray(line.get_ydata(), dtype=float)
    assert np.isnan(y).sum() == wraps
    drawn = [seg[~np.isnan(seg)] for seg in np.split(y, np.flatnonzero(np.isnan(y)))]
    assert max(np.max(np.abs(np.diff(s)), initial=0.0) for s in drawn) < math.pi
    assert "orientation error (rad)" in fig.axes[1].get_ylabel()
    plt.close(fig)


def test_obstacles_are_drawn_in_the_path_plot(rectangle_run):
    circles = [(0.5, 1.0, 0.3), (-1.0, -0.5, 0.2)]
    fig = plot_path(rectangle_run, obstacles=circles)
    discs = [p for p in fig.axes[0].patches if isinstance(p, plt.Circle)]
    assert sorted((d.center[0], d.center[1], d.radius) for d in discs) == sorted(circles)
    assert "obstacle" in [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    plt.close(fig)


def test_timeline_axes_are_labelled_and_waypoints_marked(tmp_path, monkeypatch):
    scenario = generate(1, 0)[0]
    outcome = run_scenario(scenario, RunConfig(time_limit=15.0, record=True))
    reached = outcome.metrics["waypoints_reached"]
    assert reached >= 2
    figures = []
    monkeypatch.setattr(report, "_save", lambda fig, path: figures.append(fig))
    report.plot_timeline(outcome, tmp_path / "t.png", "thesis", scenario)
    labels = [ax.get_ylabel() for ax in figures[0].axes]
    assert labels[0] == "state" and "stability S" in labels[1]
    assert "manipulability" in labels[2] and "waypoint (m)" in labels[3]
    assert figures[0].axes[3].get_xlabel().startswith("time (s)")
    marks = [line for line in figures[0].axes[3].lines if line.get_linestyle() == ":"]
    assert len(marks) == reached  # one per waypoint reached while the trace ran
    plt.close(figures[0])


def tipping_config(**fields) -> RunConfig:
    """A configuration whose 10 kg payload tips the start pose over (S <= 1), so that every
    run ends at t = 0 as "tipped". RunConfig refuses that payload (as the command line
    does); the run's own handling of such a start is what these tests draw, so the field is
    set past the check."""
    config = RunConfig(**fields)
    object.__setattr__(config, "payload", 10.0)  # a frozen dataclass: past __post_init__
    return config


def test_table_rows_without_time_do_not_divide_by_zero():
    outcome = run_scenario(generate(1, 0)[0], tipping_config(time_limit=1.0))
    assert outcome.metrics["time_s"] == 0.0 and outcome.metrics["reason"] == "tipped"
    rows = dict(report.table_rows(report.summarize([outcome, outcome], 0.0)))
    assert rows["Time spent moving base (s)"] == "0 (n/a) (0)"


def test_the_mean_time_has_its_95_percent_confidence_interval():
    """ci95_time_s = t sd / sqrt(n) over the scenarios' times, t Student's 95 % quantile
    for n - 1 degrees of freedom (3.182 for 4 scenarios), printed with the table; none for
    a single scenario."""
    import dataclasses
    import statistics

    base = run_scenario(generate(1, 0)[0], RunConfig(time_limit=0.3))
    times = [3.0, 5.0, 4.0, 8.0]
    outcomes = [dataclasses.replace(base, metrics={**base.metrics, "time_s": t}) for t in times]
    summary = report.summarize(outcomes, 1.0)
    expected = 3.182446 * statistics.stdev(times) / math.sqrt(len(times))
    assert summary["ci95_time_s"] == pytest.approx(expected, rel=1e-6)  # 3.44 s
    assert "Mean time, 95 % CI (s)" in report.format_table(summary, "t")
    assert "5 +- 3.44" in report.format_table(summary, "t")
    single = report.summarize(outcomes[:1], 1.0)
    assert math.isnan(single["ci95_time_s"]) and "95 % CI" not in report.format_table(single, "t")


def test_figures_of_runs_over_at_t0_draw_without_warnings(tmp_path, monkeypatch):
    """Every scenario tipping at its first instant (a payload the start cannot hold) leaves
    empty traces: the figures say so instead of warning about singular axis limits."""
    import warnings

    scenarios = generate(2, 0)
    config = tipping_config(time_limit=1.0, record=True)
    outcomes = [run_scenario(s, config) for s in scenarios]
    assert [o.metrics["time_s"] for o in outcomes] == [0.0, 0.0]
    figures = []
    monkeypatch.setattr(report, "_save", lambda fig, path: figures.append(fig))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        report.plot_timeline(outcomes[0], tmp_path / "t.png", "thesis", scenarios[0])
        report.plot_state_times(outcomes, tmp_path / "s.png", "thesis")
        for fig in figures:  # the warnings come when the figure is laid out
            fig.tight_layout()
            fig.canvas.draw()
    low, high = figures[0].axes[3].get_xlim()
    assert high - low == pytest.approx(1.0)
    texts = [t.get_text() for fig in figures for ax in fig.axes for t in ax.texts]
    assert texts == ["the run ended at t = 0 s", "every scenario ended at t = 0"]
    for fig in figures:
        plt.close(fig)


def test_a_summary_of_no_scenarios_is_refused_in_one_line():
    """summarize([]) raised numpy's 'zero-size array to reduction operation minimum'."""
    from ddwmmr.errors import ParameterError

    with pytest.raises(ParameterError, match=r"^outcomes: a summary needs at least one"):
        report.summarize([], 1.0)
