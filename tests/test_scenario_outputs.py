"""What the scenario tool's tables and figures say: a failed scenario has no speed, the
Table 5.2 text has its legend and the stateless controllers' overlap footnote, the study
files say which side is which and count failures out of each side's n, the timeline draws
the controller's thresholds and every waypoint's arrival, the path figures name the
obstacles, the base's enclosing circle and why the scenarios shown were chosen."""

from __future__ import annotations

import csv
import dataclasses
import io
import math

import matplotlib.pyplot as plt
import numpy as np
import pytest

from ddwmmr.cli import scenarios as cli_scenarios
from ddwmmr.scenarios import report, studies
from ddwmmr.scenarios.generator import generate
from ddwmmr.scenarios.protocol import RunConfig, run_scenario
from figure_checks import figure_problems


@pytest.fixture(scope="module")
def base():
    """A real outcome (a 0.3 s timeout) whose metrics the tests vary."""
    return run_scenario(generate(1, 0)[0], RunConfig(time_limit=0.3))


def _outcomes(base, rows):
    """Outcomes of ``base`` with (success, time_s, speed_m_s) replaced, scenarios 1..n."""
    return [
        dataclasses.replace(
            base,
            metrics={
                **base.metrics,
                "scenario": i,
                "success": ok,
                "reason": "ok" if ok else "timeout",
                "time_s": time,
                "speed_m_s": speed,
            },
        )
        for i, (ok, time, speed) in enumerate(rows, start=1)
    ]


@pytest.fixture
def drawn(monkeypatch):
    """The figures the report draws, laid out as when saved (kept open)."""
    figures = []

    def keep(fig, path, rect=None):
        fig.tight_layout(rect=rect)
        figures.append(fig)

    monkeypatch.setattr(report, "_save", keep)
    yield figures
    for fig in figures:
        plt.close(fig)


def test_a_failed_scenario_has_no_speed_and_the_mean_speed_is_over_finished_ones(base):
    # scenario 1 stopped at 60 s having covered part of its 20.7 m route: no speed (the
    # protocol's NaN, tested below), not 0.345 m/s, the whole route over the stop time
    # the whole route over the stop time, no speed it moved at
    outcomes = _outcomes(base, [(False, 60.0, math.nan), (True, 20.0, 0.5), (True, 25.0, 0.7)])
    summary = report.summarize(outcomes, 1.0)
    assert summary["mean_speed_m_s"] == pytest.approx(0.6, abs=1e-12)
    assert summary["sd_speed_m_s"] == pytest.approx(math.sqrt(0.02), abs=1e-12)
    assert summary["speed_scenarios"] == 2
    assert summary["mean_time_s"] == pytest.approx(35.0, abs=1e-12)  # time: all three
    rows = dict(report.table_rows(summary))
    assert rows["Simulation speed (m/s)"] == "0.6 (0.141), over the 2 of 3 that finished"
    speeds = [r["speed_m_s"] for r in csv.DictReader(io.StringIO(report.metrics_csv(outcomes)))]
    assert speeds == ["nan", "0.5", "0.7"]
    none = report.summarize(outcomes[:1], 1.0)
    assert math.isnan(none["mean_speed_m_s"]) and none["speed_scenarios"] == 0
    assert dict(report.table_rows(none))["Simulation speed (m/s)"].startswith("n/a, over the 0")


def test_all_finished_speed_row_is_unchanged(base):
    outcomes = _outcomes(base, [(True, 20.0, 0.5), (True, 25.0, 0.7)])
    rows = dict(report.table_rows(report.summarize(outcomes, 1.0)))
    assert rows["Simulation speed (m/s)"] == "0.6 (0.141)"


def test_table_text_has_its_legend_and_the_stateless_overlap_footnote(base):
    thesis = report.summarize(_outcomes(base, [(True, 20.0, 0.5), (True, 25.0, 0.7)]), 1.0)
    text = report.format_table(thesis, "t")
    assert text.splitlines()[2].startswith("Cells: mean (share of the mean simulation time)")
    assert "*" not in text and "overlap" not in text
    nan = math.nan
    stateless = {"time_manipulability_s": nan, "transitions_manipulability": nan}
    stateless |= {"time_stability_s": nan, "transitions_stability": nan}
    stateless |= {"time_obstacle_s": nan, "transitions_obstacle": nan}
    stateless |= {"time_base_s": 20.0, "time_arm_s": 19.0, "fallback_steps": 0}
    outcomes = [dataclasses.replace(o, metrics={**o.metrics, **stateless}) for o in
                _outcomes(base, [(True, 20.0, 0.5), (True, 20.0, 0.7)])]  # fmt: skip
    qp = report.summarize(outcomes, 1.0)
    rows = dict(report.table_rows(qp))
    assert rows["Time spent moving base (s)"] == "20 (100%)* (0)"
    assert rows["Time spent moving manipulator (s)"] == "19 (95%)* (0)"
    text = report.format_table(qp, "t")
    assert text.splitlines()[2].startswith("Cells: mean")
    assert "\n* This controller has no states" in text and "they overlap" in text
    assert "1 mm/s" in text and "1 mrad/s" in text


def test_obstacle_batch_table_has_the_obstacle_transitions_row(base):
    metrics = {"time_obstacle_s": 6.0, "transitions_obstacle": 3}
    outcomes = [dataclasses.replace(o, metrics={**o.metrics, **metrics})
                for o in _outcomes(base, [(True, 20.0, 0.5), (True, 25.0, 0.7)])]  # fmt: skip
    rows = dict(report.table_rows(report.summarize(outcomes, 1.0)))
    assert rows["Time in obstacle state (s)"] == "6 (26.7%) (0)"
    assert rows["No. of obstacle state transitions"] == "3 (0)"


def test_threshold_file_has_its_heading_and_counts_failures_out_of_each_n():
    variant = next(v for v in studies.THRESHOLD_VARIANTS if v.key == "stab-nohyst-1.50")
    summary = {key: 0.5 for _, key, _ in studies.THRESHOLD_COLUMNS} | {"failed": 3, "n": 4}
    text = studies.threshold_table([(variant, summary)], "ours: 4 scenarios")
    assert text.startswith(
        "# Threshold study (thesis Tables 5.5-5.20): cells are thesis / ours\n\n"
        "ours: 4 scenarios\n\nfailed: k of each side's n scenarios; speed: mean over the "
        "scenarios that finished;"
    )
    assert "| 1.5/1.5 | 0.75/0.9 | 42 of 100 / 3 of 4 | – / 0.5 |" in text


def test_obstacle_file_has_its_heading_and_no_speed_for_a_failure(base):
    metrics = {**base.metrics, "scenario": 1, "success": False, "reason": "collision"}
    metrics |= {"speed_m_s": math.nan, "time_obstacle_s": 1.0, "transitions_obstacle": 2}
    text = studies.obstacle_table([metrics], "thesis controller, thesis plant")
    assert text.startswith(
        "# Obstacle study (thesis Table 5.21): cells are thesis / ours\n\n"
        "ours: thesis controller, thesis plant\n\n| | scenario 1 |"
    )
    assert "| Simulation speed (m/s) | 0.434 / – |" in text
    assert "| Scenario complete | Yes / No (collision) |" in text


def test_timeline_draws_the_thresholds_and_every_waypoint_arrival(drawn, tmp_path):
    scenario = generate(2, 0)[1]
    outcome = run_scenario(scenario, RunConfig(record=True))
    assert outcome.metrics["success"]
    lines = cli_scenarios.timeline_thresholds(RunConfig())
    report.plot_timeline(outcome, tmp_path / "t.png", "x", scenario, **lines)
    axes = drawn[0].axes
    s_lines = {ln.get_label(): ln.get_ydata()[0] for ln in axes[1].lines[1:]}
    assert s_lines == {
        "S = 1 (tips over)": 1.0,
        "enter stability state, S < 1.25": 1.25,
        "leave it, S >= 1.6": 1.6,
    }
    eta_lines = {ln.get_label(): ln.get_ydata()[0] for ln in axes[2].lines[1:]}
    assert eta_lines == {
        "enter manipulability state, eta < 0.75": 0.75,
        "leave it, eta >= 0.9": 0.9,
    }
    assert [t.get_text() for t in axes[1].get_legend().get_texts()][-1] == "leave it, S >= 1.6"
    marks = [
        ln.get_xdata()[0]
        for ln in axes[3].lines
        if ln.get_linestyle() == ":" and ln.get_color() == report.WAYPOINT_COLOUR
    ]
    assert len(marks) == 5  # all five waypoints, the last at the end of the run
    assert marks[-1] == pytest.approx(outcome.metrics["time_s"], abs=1e-9)
    assert np.all(np.diff(marks) > 0.5)  # five distinct arrivals (6.0 s ... 22.9 s)
    assert figure_problems(drawn[0]) == []


def test_timeline_thresholds_of_each_controller():
    assert cli_scenarios.timeline_thresholds(RunConfig(controller="qp", plant="kinematic")) == {
        "stability_lines": [(1.25, "floor S_min = 1.25")]
    }
    flat = cli_scenarios.timeline_thresholds(RunConfig(stability=(1.5, 1.5)))
    assert flat["stability_lines"] == [(1.5, "stability state below, left above S = 1.5")]


def test_obstacle_paths_name_the_obstacles_and_draw_the_base_circle(drawn, tmp_path):
    scenario = studies.obstacle_scenarios(generate(1, 0))[0]
    outcome = run_scenario(scenario, RunConfig(record=True))
    assert outcome.metrics["success"]
    report.plot_paths([(scenario, outcome)], tmp_path / "p.png", "obstacles", clearance=0.285)
    fig = drawn[0]
    names = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "obstacle (r 0.3 m)" in names
    assert "base's enclosing circle (r 0.285 m) where closest to an obstacle" in names
    ax = fig.axes[0]
    (circle,) = [p for p in ax.patches if not p.get_fill()]
    assert circle.get_radius() == pytest.approx(0.285)
    gap = float(ax.get_title().rsplit("closest gap ", 1)[1].split()[0])
    to_disc = min(
        math.hypot(circle.center[0] - ox, circle.center[1] - oy) - r
        for ox, oy, r in scenario.obstacles
    )
    assert gap == pytest.approx(to_disc - 0.285, abs=0.005)
    assert 0.0 < gap < 0.3  # a success never touches; it passes close
    assert ax.get_legend() is None  # one legend below the panels, none on the paths
    assert figure_problems(fig) == []


def test_paths_title_says_which_scenarios_and_why(base):
    outcomes = _outcomes(base, [(False, 60.0, math.nan), (True, 20.0, 0.5), (True, 25.0, 0.7)])
    title = cli_scenarios.paths_title("qp controller, thesis plant", outcomes, [0, 1], 0)
    assert title == (
        "qp controller, thesis plant: paths of scenarios 1, 2 (the first two; 1: the first "
        "failure) of 3 scenarios run"
    )
    six = _outcomes(base, [(True, 20.0, 0.5)] * 4 + [(False, 60.0, math.nan), (True, 20.0, 0.5)])
    assert cli_scenarios.paths_title("t", six, [0, 1, 4], 4) == (
        "t: paths of scenarios 1, 2 (the first two) and 5 (the first failure) of 6 scenarios run"
    )


def test_batch_figures_are_titled_with_controller_and_plant(tmp_path, monkeypatch):
    seen = {}

    def timeline(outcome, path, title, scenario, **lines):
        seen["timeline"] = (title, lines)

    def paths(items, path, title, clearance=None):
        seen["paths"] = title

    monkeypatch.setattr(report, "plot_timeline", timeline)
    monkeypatch.setattr(report, "plot_paths", paths)
    args = ["--n", "2", "--time-limit", "3", "--jobs", "1", "--no-progress"]
    assert cli_scenarios.main([*args, "--out", str(tmp_path / "run")]) == 0
    title, lines = seen["timeline"]
    assert title == "thesis controller, thesis plant"
    assert lines == cli_scenarios.timeline_thresholds(RunConfig())
    assert seen["paths"] == (
        "thesis controller, thesis plant: paths of scenarios 1, 2 (the first two; 1: the "
        "first failure) of 2 scenarios run"
    )


def test_the_protocol_gives_a_failed_scenario_no_speed():
    from ddwmmr.scenarios import RunConfig, generate, run_scenario

    scenario = generate(1, 0)[0]
    failed = run_scenario(scenario, RunConfig(time_limit=2.0))  # far from its last waypoint
    assert not failed.metrics["success"] and math.isnan(failed.metrics["speed_m_s"])
    assert failed.metrics["path_length_m"] == pytest.approx(scenario.path_length())


def test_the_timeline_draws_each_arbiters_own_thresholds():
    from ddwmmr.cli.scenarios import timeline_thresholds
    from ddwmmr.scenarios import RunConfig

    machine = timeline_thresholds(RunConfig())
    assert machine["stability_lines"] == [
        (1.25, "enter stability state, S < 1.25"),
        (1.6, "leave it, S >= 1.6"),
    ]
    # the competitive arbiter grades stability in below its enter threshold: no exit switch
    competitive = timeline_thresholds(RunConfig(arbiter="competitive"))
    assert competitive["stability_lines"] == [(1.25, "stability weighs in below S = 1.25 (graded)")]
    assert competitive["manipulability_lines"] == machine["manipulability_lines"]
