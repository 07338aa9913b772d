"""The compare report and console judge the runs on ``--plant`` plants too, and the
advice on a hard stability floor names a compared method that broke its floor."""

import pytest

from ddwmmr import Ellipse, Rectangle, Robot, simulate
from ddwmmr.cli.compare import not_tracked
from ddwmmr.reports.compare import CompareConfig, execute, mm, plan_runs, write_report
from ddwmmr.reports.compare.advice import (
    ADVICE_HEADERS,
    advice_rows,
    profiles,
    recommendations,
)
from ddwmmr.reports.compare.ranking import build_ranking


@pytest.fixture(scope="module")
def thesis_rectangle(tmp_path_factory):
    """qp on the rectangle, kinematic and thesis plant: it tracks on the kinematic plant
    and not on the thesis plant (a wheel at its force limit, docs/cli.md "Verdict")."""
    config = CompareConfig(
        methods=("qp",), trajectories={"rectangle": Rectangle()}, studies=(), plants=("thesis",)
    )
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs())
    folder = tmp_path_factory.mktemp("report")
    write_report(config, plan, outputs, folder)
    return plan, outputs, (folder / "report.md").read_text()


def test_the_console_names_a_plant_run_that_did_not_track(thesis_rectangle):
    plan, outputs, _ = thesis_rectangle
    expected = simulate(Robot(), Rectangle(), "qp", plant="thesis").summary
    assert expected["verdict_reasons"] == ["rms_error_above_limit"]
    lines = not_tracked(plan, outputs)
    assert lines[0].startswith("Did not track (1 of 2 runs")
    rms = 1000 * expected["rms_position_error_m"]
    assert rms == pytest.approx(99.25, abs=0.05)
    assert lines[1] == f"  qp on rectangle (thesis plant): RMS error {rms:.2f} mm (limit 84.85 mm)"
    assert lines[2].startswith("  likely cause (qp on the thesis plant): the robot ran at a limit")
    assert len(lines) == 3


def test_the_plant_table_has_a_tracked_column_and_the_verdicts(thesis_rectangle):
    _, _, text = thesis_rectangle
    header = next(x for x in text.splitlines() if x.startswith("| trajectory | method | RMS kin"))
    assert header.rstrip(" |").endswith("tracked? (docs/cli.md, Verdict)")
    row = next(x for x in text.splitlines() if x.startswith("| rectangle | qp |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert float(cells[3]) == pytest.approx(99.3, abs=0.05)
    assert cells[-1] == "no: rms_error_above_limit"
    assert 'Did not track on the thesis plant (1 of 1 runs; docs/cli.md, "Verdict"):' in text
    assert "- **qp on rectangle**: RMS error 99.25 mm (limit 84.85 mm); likely cause: " in text


def test_advice_names_a_compared_method_that_broke_its_floor():
    config = CompareConfig(
        methods=("qp",),
        trajectories={"ellipse": Ellipse()},
        duration=1.0,
        studies=(),
        options={"qp": {"stability_min": 2.5}},
    )
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs())
    items = profiles(config, outputs, build_ranking(plan, outputs))
    summary = outputs[plan.main[0]].summary
    assert summary["start_stability"] == pytest.approx(2.18, abs=0.005)
    steps = summary["stability_violations"]
    assert 0 < steps < summary["steps"]
    line = next(x for x in recommendations(items) if "Tip-over stability" in x)
    assert line == (
        "**Tip-over stability as a hard guarantee**: `qp` (S >= 2.50, "
        f"{steps} steps below it; it started below it, at S = 2.18) enforces a floor but "
        "did not keep it in these runs; no other compared method constrains S."
    )
    cell = advice_rows(items)[0][ADVICE_HEADERS.index("tip-over stability")]
    assert cell == (
        f"hard constraint S >= 2.50 ({steps} steps below it; started below it, at S = 2.18)"
    )


def test_advice_keeps_its_line_when_every_floor_held():
    config = CompareConfig(
        methods=("qp", "ats"), trajectories={"ellipse": Ellipse()}, duration=1.0, studies=()
    )
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs())
    items = profiles(config, outputs, build_ranking(plan, outputs))
    line = next(x for x in recommendations(items) if "Tip-over stability" in x)
    assert line == (
        "**Tip-over stability as a hard guarantee**: `qp` (S >= 1.25); no other compared "
        "method constrains S."
    )


def test_the_setup_names_the_obstacles_and_who_takes_them(tmp_path):
    config = CompareConfig(
        methods=("qp", "ats"),
        trajectories={"ellipse": Ellipse()},
        duration=0.5,
        studies=(),
        options={"qp": {"obstacles": ((-0.2, 1.05, 0.3),)}},
    )
    plan = plan_runs(config)
    write_report(config, plan, execute(config, plan.all_specs()), tmp_path)
    text = (tmp_path / "report.md").read_text()
    assert (
        "- obstacles (world frame, m): circle at (-0.2, 1.05) of radius 0.3, given to `qp`; "
        "`ats` ignores them\n" in text
    )


def test_a_short_run_claims_no_corner_winner_and_no_return_of_the_drift(tmp_path):
    config = CompareConfig(
        methods=("ats", "clrrmc-ts"),
        trajectories={"ellipse": Ellipse(), "rectangle": Rectangle()},
        duration=3.0,
        studies=("integrator",),
    )
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs())
    write_report(config, plan, outputs, tmp_path)
    text = (tmp_path / "report.md").read_text()
    assert Rectangle().corner_times(40.0)[0] == pytest.approx(10.0)  # after the 3 s run
    assert (
        "- **Sharp corners (like the rectangle)**: not judged: the runs end before the "
        "rectangle's first corner.\n" in text
    )
    euler = next(s for s in plan.all_specs() if s.method == "ats" and s.integrator == "euler")
    error = outputs[euler].timeseries["position_error_m"]
    assert error[-1] == pytest.approx(error.max(), rel=1e-9)  # the worst drift is at the end
    assert f"mm half way, {mm(error[-1])} mm at the end), while" in text
    assert "brings part of it back" not in text
