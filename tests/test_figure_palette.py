"""Track's console names the limits behind saturated steps and the actuator time at its
limit; the scenario figures share one palette (base grey, end effector blue as in track's
path figure, one style per threshold kind, one colour per time share), a stateless
controller's time figure is titled for what it shows, and the arbiter study's figures
name a numbered threshold and the arbiter weight plainly."""

from __future__ import annotations

import dataclasses

import matplotlib.pyplot as plt
import pytest
from matplotlib.colors import to_rgba

from ddwmmr import Robot, simulate
from ddwmmr.cli import scenarios as cli_scenarios
from ddwmmr.cli.track import format_table
from ddwmmr.reports import plots
from ddwmmr.scenarios import arbiter_study, report, studies
from ddwmmr.scenarios.generator import generate
from ddwmmr.scenarios.protocol import RunConfig, run_scenario
from ddwmmr.trajectories import load_trajectory

#: The probe's ats on the rectangle: every saturated step a joint held at a position limit.
ATS_RECTANGLE = {
    "method": "ats",
    "trajectory": "rectangle",
    "plant": "kinematic",
    "saturated_steps": 427,
    "wheel_limit_steps": 0,
    "joint_rate_limit_steps": 0,
    "joint_limit_steps": 427,
    "joint_limit_held": "th2 = -3.142 rad",
}
#: The probe's clrrmc-ts on the thesis plant: a wheel at its 10 N limit for 0.34 s.
THESIS_PLANT = {
    "method": "clrrmc-ts",
    "trajectory": "ellipse",
    "plant": "thesis",
    "saturated_steps": 0,
    "max_wheel_force_n": 10.0,
    "actuator_saturated_time_s": 0.33999999999999275,
}


def test_console_names_the_joint_limit_behind_saturated_steps() -> None:
    lines = format_table(ATS_RECTANGLE).splitlines()
    assert lines[1:] == [
        "  saturated steps (plant clipped)      427",
        "  wheel at speed limit (steps)         0",
        "  joint at rate limit (steps)          0",
        "  joint at position limit (steps)      427",
        "  position limit held (most steps)     th2 = -3.142 rad",
    ]


def test_console_shows_the_time_at_the_actuator_limit() -> None:
    lines = format_table(THESIS_PLANT).splitlines()
    assert lines[-2:] == [
        "  max wheel force (N)                  10",
        "  time with an actuator at limit (s)   0.34",
    ]


@pytest.fixture
def drawn(monkeypatch):
    """The figures the scenario report draws (kept open, not written)."""
    figures = []
    monkeypatch.setattr(report, "_save", lambda fig, path, rect=None: figures.append(fig))
    yield figures
    for fig in figures:
        plt.close(fig)


@pytest.fixture(scope="module")
def runs():
    """Two short recorded scenarios under the thesis controller and under qp."""
    scenarios = generate(2, 0)
    config = RunConfig(time_limit=8.0, record=True)
    qp = dataclasses.replace(config, controller="qp")
    return {
        "thesis": [(s, run_scenario(s, config)) for s in scenarios],
        "qp": [(s, run_scenario(s, qp)) for s in scenarios],
    }


def _line(ax, label: str):
    (line,) = [line for line in ax.get_lines() if line.get_label() == label]
    return line


def _colour(artist) -> tuple[float, ...]:
    return to_rgba(artist.get_color())


def test_scenario_paths_draw_base_and_end_effector_as_track_does(runs, drawn, tmp_path):
    result = simulate(Robot(), load_trajectory("ellipse"), "ats", duration=1.0)
    track = plots.plot_path(result).axes[0]
    report.plot_paths(runs["thesis"][:1], tmp_path / "p.png", "t")
    ax = drawn[0].axes[0]
    base, effector = _line(ax, "base"), _line(ax, "end effector")
    assert _colour(base) == _colour(_line(track, "base (axle midpoint)"))
    assert _colour(effector) == _colour(_line(track, "actual end effector"))
    # each start dot in its path's colour, at that path's first point
    trace = runs["thesis"][0][1].trace
    for name, path, x in (("base", base, "x"), ("end effector", effector, "xe")):
        dot = _line(ax, f"{name} start")
        assert _colour(dot) == _colour(path)
        assert dot.get_xdata()[0] == pytest.approx(trace[x][0], abs=1e-12)
    plt.close(track.figure)


def _threshold(ax, prefix: str):
    (line,) = [line for line in ax.get_lines() if line.get_label().startswith(prefix)]
    return _colour(line), line.get_linestyle()


def test_threshold_lines_mean_the_same_in_timeline_and_weights(runs, drawn, tmp_path):
    scenario, outcome = runs["thesis"][0]
    lines = cli_scenarios.timeline_thresholds(RunConfig())
    report.plot_timeline(outcome, tmp_path / "t.png", "t", scenario, **lines)
    config = RunConfig(time_limit=3.0, stability=(1.5, 1.7))
    arbiter_study.plot_weights(scenario, config, tmp_path / "w.png", "t")
    timeline, weights = drawn
    s_panel, s_weights = timeline.axes[1], weights.axes[2]
    enter, leave = _threshold(s_panel, "enter"), _threshold(s_panel, "leave")
    assert enter == (to_rgba("tab:orange"), ":") and leave == (to_rgba("tab:green"), "-.")
    assert _threshold(s_weights, "enter") == enter
    assert _threshold(s_weights, "leave") == leave
    tip = _threshold(s_panel, "S = 1")
    assert tip == (to_rgba("tab:red"), "--") and tip not in (enter, leave)
    # a behaviour's weight has its quantity's colour in the timeline (stability brown)
    stability = _colour(_line(s_panel, "stability S"))
    assert _colour(_line(weights.axes[0], "stability")) == stability
    assert weights.axes[0].get_ylabel() == "arbiter weight"


def _bar_colours(ax) -> dict[str, tuple[float, ...]]:
    return {c.get_label(): to_rgba(c.patches[0].get_facecolor()) for c in ax.containers}


def test_time_shares_keep_their_colour_and_a_stateless_title(runs, drawn, tmp_path):
    report.plot_state_times([o for _, o in runs["thesis"]], tmp_path / "a.png", "thesis")
    report.plot_state_times([o for _, o in runs["qp"]], tmp_path / "b.png", "qp")
    thesis, qp = (fig.axes[0] for fig in drawn)
    assert thesis.get_title() == "thesis: time per state"
    assert qp.get_title() == "qp: total time; time moving: base / arm"
    colours, stateless = _bar_colours(thesis), _bar_colours(qp)
    assert colours["moving base"] == stateless["moving base"] == to_rgba(report.BASE_COLOUR)
    assert colours["moving arm"] == stateless["moving arm"] == to_rgba(report.EFFECTOR_COLOUR)
    assert stateless["total"] not in (colours["moving base"], colours["moving arm"])


def test_batch_time_figure_is_titled_by_the_report(tmp_path, monkeypatch):
    seen = {}
    monkeypatch.setattr(report, "plot_state_times", lambda o, p, title: seen.update(t=title))
    for name in ("plot_speeds", "plot_fix_state", "plot_paths", "plot_timeline"):
        monkeypatch.setattr(report, name, lambda *a, **k: None)
    args = ["--n", "1", "--time-limit", "2", "--jobs", "1", "--no-progress"]
    assert cli_scenarios.main([*args, "--controller", "qp", "--out", str(tmp_path / "r")]) == 0
    assert seen["t"] == "qp controller, thesis plant"  # the report adds what it shows


def test_paths_title_counts_the_scenarios_run(runs):
    outcomes = [o for _, o in runs["thesis"]]
    title = cli_scenarios.paths_title("t", outcomes, [0, 1], 0)
    assert title.endswith(" of 2 scenarios run")
    assert cli_scenarios.paths_title("t", outcomes[:1], [0], 0).endswith(" of 1 scenario run")


def test_numbered_thresholds_are_written_out_in_the_labels():
    """The thesis numbers its no-hysteresis thresholds 1 to 5: a label says which is the
    number and which the threshold (it read "threshold 5 (1.50)")."""
    by_key = {v.key: v for v in studies.THRESHOLD_VARIANTS}
    assert by_key["stab-nohyst-1.50"].label == (
        "No stab. hysteresis, thesis threshold no. 5: S = 1.50"
    )
    assert by_key["manip-nohyst-0.60"].label == (
        "No manip. hysteresis, thesis threshold no. 1: eta = 0.60"
    )
    assert by_key["stab-1.50-1.70"].label == "Stability 1.50 with hysteresis 1.70"


def test_the_study_titles_its_weight_figures_with_the_written_out_label(tmp_path, monkeypatch):
    titles = []
    monkeypatch.setattr(arbiter_study, "plot_weights", lambda s, c, p, title: titles.append(title))
    monkeypatch.setattr(arbiter_study, "weight_statistics", lambda *a: [{"switches": 0.0}])
    for table in ("claims_table", "table_52", "variants_table"):
        monkeypatch.setattr(arbiter_study, table, lambda rows: "")
    monkeypatch.setattr(arbiter_study, "compare_variants", _fake_results)
    arbiter_study.write_study(tmp_path, generate(1, 0), RunConfig(), None, noise=False)
    assert titles[2] == "No stab. hysteresis, thesis threshold no. 5: S = 1.50"


def _fake_results(scenarios, config, run):
    """Every study variant with one short outcome per arbiter and no summary numbers."""
    outcome = run_scenario(scenarios[0], dataclasses.replace(config, time_limit=0.5))
    summaries = {a: {} for a, _ in arbiter_study.ARBITER_COLUMNS}
    outcomes = {a: [outcome] for a, _ in arbiter_study.ARBITER_COLUMNS}
    return [arbiter_study.VariantResult(v, summaries, outcomes) for v in arbiter_study.variants()]


def test_fix_state_bars_have_the_state_colour_of_the_time_figure(runs, drawn, tmp_path):
    outcomes = [o for _, o in runs["thesis"]]
    report.plot_fix_state(outcomes, "stability", tmp_path / "s.png", "t")
    times, counts = drawn[0].axes
    for ax in (times, counts):
        assert {to_rgba(p.get_facecolor()) for p in ax.patches} == {
            to_rgba(report.STABILITY_COLOUR)
        }


def test_a_long_paths_title_is_set_smaller_to_fit_its_figure(runs, drawn, tmp_path):
    """The default batch's title (125 characters) was cut at both edges of the figure."""
    title = (
        "thesis controller, thesis plant: paths of scenarios 1, 2 (the first two) and 31 "
        "(the most fix-state entries) of 100 scenarios run"
    )
    report.plot_paths(runs["thesis"][:1], tmp_path / "p.png", title)
    fig = drawn[0]
    fig.canvas.draw()
    shown = fig._suptitle
    assert shown.get_text() == title and shown.get_fontsize() < 12.0
    box = shown.get_window_extent(fig.canvas.get_renderer())
    assert box.x0 >= 0.0 and box.x1 <= fig.bbox.width
    report.plot_paths(runs["thesis"][:1], tmp_path / "q.png", "t: a short title")
    assert drawn[1]._suptitle.get_fontsize() == 12.0
