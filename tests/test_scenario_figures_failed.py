"""Scenario figures tell a failed scenario from a finished one: the timeline's title
states the outcome and marks the stop, failed bars are hatched and named in a legend
beside the axes; bar axes have scenario-number ticks and start at 0."""

from __future__ import annotations

import dataclasses

import matplotlib.pyplot as plt
import numpy as np
import pytest

from ddwmmr.scenarios import report
from ddwmmr.scenarios.generator import generate
from ddwmmr.scenarios.protocol import RunConfig, run_scenario
from figure_checks import figure_problems

#: No stability hysteresis at 1.5: scenarios 1 and 3 chatter into the 60 s timeout,
#: scenario 2 finishes (27.4 s).
CHATTER = RunConfig(stability=(1.5, 1.5))


@pytest.fixture(scope="module")
def mixed():
    outcomes = [run_scenario(s, CHATTER) for s in generate(3, 0)]
    assert [o.metrics["success"] for o in outcomes] == [False, True, False]
    assert [o.metrics["reason"] for o in outcomes] == ["timeout", "ok", "timeout"]
    return outcomes


@pytest.fixture
def drawn(monkeypatch):
    """The figures the report draws, laid out as when saved (kept open)."""
    figures = []

    def keep(fig, path):
        fig.tight_layout()
        figures.append(fig)

    monkeypatch.setattr(report, "_save", keep)
    yield figures
    for fig in figures:
        plt.close(fig)


def _hatches(ax) -> list[str | None]:
    return [patch.get_hatch() for patch in ax.patches]


def _legend_beside(ax) -> bool:
    renderer = ax.figure.canvas.get_renderer()
    legend = ax.get_legend().get_window_extent(renderer)
    return legend.x0 >= ax.get_window_extent(renderer).x1


def test_failed_bars_are_hatched_and_named_beside_the_axes(mixed, drawn, tmp_path):
    report.plot_state_times(mixed, tmp_path / "t.png", "thesis")
    report.plot_speeds(mixed, tmp_path / "s.png", "thesis")
    report.plot_fix_state(mixed, "stability", tmp_path / "f.png", "thesis")
    times, speeds, fix = drawn
    stacked = times.axes[0]
    # moving base, moving arm, stability: one bar per scenario each; 1 and 3 hatched
    assert _hatches(stacked) == ["///", None, "///"] * 3
    assert [t.get_text() for t in stacked.get_legend().get_texts()] == [
        "moving base",
        "moving arm",
        "stability",
        "did not finish",
    ]
    assert _hatches(fix.axes[0]) == _hatches(fix.axes[1]) == ["///", None, "///"]
    assert [t.get_text() for t in fix.axes[0].get_legend().get_texts()] == ["did not finish"]
    for ax in speeds.axes:  # a scenario that did not finish has no speed: a cross, no bar
        assert _hatches(ax) == [None, None, None]
        assert [t.get_text() for t in ax.get_legend().get_texts()] == [report.NO_SPEED_LABEL]
    for fig in drawn:  # the legends sit beside the 60 s bars, not on them
        assert _legend_beside(fig.axes[0])
        assert figure_problems(fig) == []
        for ax in fig.axes:
            assert list(ax.get_xticks()) == [1.0, 2.0, 3.0]
            assert ax.get_ylim()[0] == 0.0


def test_all_finished_bars_have_no_hatch_and_no_failure_entry(mixed, drawn, tmp_path):
    report.plot_speeds(mixed[1:2], tmp_path / "s.png", "thesis")
    (fig,) = drawn
    assert _hatches(fig.axes[0]) == [None]
    assert fig.axes[0].get_legend() is None


def test_non_consecutive_scenarios_get_their_numbers_as_ticks(mixed, drawn, tmp_path):
    """The obstacle study draws scenarios 1, 3, 7, 10: no 0.5 or 2 ticks between them."""
    outcomes = [
        dataclasses.replace(o, metrics={**o.metrics, "scenario": number})
        for o, number in zip(mixed * 2, (1, 3, 7, 10))
    ]
    report.plot_state_times(outcomes, tmp_path / "t.png", "thesis")
    assert [t.get_text() for t in drawn[0].axes[0].get_xticklabels()] == ["1", "3", "7", "10"]


def test_an_all_zero_panel_starts_at_zero_and_says_so(mixed, drawn, tmp_path):
    """No manipulability state in any scenario: a 0..1 axis, not -0.04..0.04."""
    assert all(o.metrics["time_manipulability_s"] == 0.0 for o in mixed)
    report.plot_fix_state(mixed, "manipulability", tmp_path / "m.png", "thesis")
    for ax in drawn[0].axes:
        assert ax.get_ylim() == (0.0, 1.0)
        assert [t.get_text() for t in ax.texts] == ["0 in every scenario"]
        assert ax.get_legend() is None  # no visible bar to call failed


def test_failed_timeline_states_reason_and_time_and_marks_the_stop(drawn, tmp_path):
    scenario = generate(1, 0)[0]
    outcome = run_scenario(scenario, dataclasses.replace(CHATTER, record=True))
    assert outcome.metrics["reason"] == "timeout" and outcome.metrics["time_s"] == 60.0
    report.plot_timeline(outcome, tmp_path / "t.png", "thesis / thesis", scenario)
    axes = drawn[0].axes
    assert axes[0].get_title() == (
        "thesis / thesis: scenario 1 controller state; timeout at 60.0 s, 2 of 5 waypoints reached"
    )
    for ax in axes[:4]:
        stops = [
            line for line in ax.lines if line.get_color() == "tab:red" and line.get_ls() == "-"
        ]
        assert len(stops) == 1 and np.allclose(stops[0].get_xdata(), 60.0)
    names = [t.get_text() for t in axes[3].get_legend().get_texts()]
    assert names[-1] == "stopped: timeout"


def test_finished_timeline_states_the_time_and_has_no_stop_mark(drawn, tmp_path):
    scenario = generate(2, 0)[1]
    outcome = run_scenario(scenario, dataclasses.replace(CHATTER, record=True))
    assert outcome.metrics["success"]
    report.plot_timeline(outcome, tmp_path / "t.png", "thesis", scenario)
    axes = drawn[0].axes
    time = outcome.metrics["time_s"]
    assert axes[0].get_title() == (
        f"thesis: scenario 2 controller state; reached all 5 waypoints in {time:.1f} s"
    )
    assert "stopped" not in " ".join(t.get_text() for t in axes[3].get_legend().get_texts())


def test_outcome_text_cuts_a_long_controller_error():
    metrics = {
        "success": False,
        "reason": "controller error: SolverError: " + "x" * 100,
        "time_s": 1.25,
        "waypoints_reached": 0,
    }
    text = report.outcome_text(metrics, 5)
    assert text.startswith("controller error: SolverError: xxx") and "...  at" not in text
    assert text.endswith("... at 1.2 s, 0 of 5 waypoints reached")
    assert len(text) == 60 + len(" at 1.2 s, 0 of 5 waypoints reached")
