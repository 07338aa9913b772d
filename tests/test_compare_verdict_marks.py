"""The compare report marks and names the runs that did not track (ranking tables, the
advice, including the runs on a ``--plant``), counts the diagnosis's steps as the summary
does, explains and trims the plant table, and says what the advice's step time is."""

import numpy as np
import pytest

from ddwmmr import Ellipse, Rectangle
from ddwmmr.reports.compare import CompareConfig, execute, plan_runs, write_report
from ddwmmr.reports.compare.advice import profiles, recommendations
from ddwmmr.reports.compare.diagnosis import diagnose, saturation_span
from ddwmmr.reports.compare.ranking import NOT_TRACKED_NOTE, build_ranking
from ddwmmr.reports.compare.report import ranking_table

VERDICT = '(docs/cli.md, "Verdict")'


@pytest.fixture(scope="module")
def thesis_report(tmp_path_factory):
    """qp and ats on the ellipse and the rectangle, kinematic and thesis plant: ats does
    not track on the rectangle (either plant), qp tracks on the kinematic plant but not on
    the thesis plant's rectangle (a wheel at its force limit)."""
    config = CompareConfig(
        methods=("qp", "ats"),
        trajectories={"ellipse": Ellipse(), "rectangle": Rectangle()},
        studies=(),
        plants=("thesis",),
    )
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs())
    folder = tmp_path_factory.mktemp("report")
    write_report(config, plan, outputs, folder)
    return config, plan, outputs, (folder / "report.md").read_text()


def _summary(plan, outputs, method, trajectory, plant=None):
    specs = plan.main if plant is None else plan.plants[plant]
    spec = next(s for s in specs if s.method == method and s.trajectory == trajectory)
    return outputs[spec].summary


def _cells(text, start):
    row = next(x for x in text.splitlines() if x.startswith(start))
    return [c.strip() for c in row.strip("|").split("|")]


def test_the_runs_are_as_the_fixture_says(thesis_report):
    _, plan, outputs, _ = thesis_report
    assert _summary(plan, outputs, "ats", "rectangle")["verdict_reasons"]
    assert _summary(plan, outputs, "ats", "ellipse")["verdict_reasons"] == []
    assert _summary(plan, outputs, "qp", "rectangle")["verdict_reasons"] == []
    on_plant = _summary(plan, outputs, "qp", "rectangle", "thesis")
    assert on_plant["verdict_reasons"] == ["rms_error_above_limit"]
    assert 1000 * on_plant["rms_position_error_m"] == pytest.approx(99.25, abs=0.05)


def test_the_ranking_marks_a_score_whose_run_did_not_track(thesis_report):
    config, plan, outputs, text = thesis_report
    ranking = build_ranking(plan, outputs)
    _, rows = ranking_table(ranking, config.shown)
    ats = next(r for r in rows if r[1] == "ats")
    qp = next(r for r in rows if r[1] == "qp")
    rms = 1000 * _summary(plan, outputs, "ats", "rectangle")["rms_position_error_m"]
    assert rms == pytest.approx(134.5, abs=0.5)
    assert ats[3] == f"{rms:.0f}\u2020 (2)"  # the rectangle: did not track
    assert ats[2] == "42.4 (2)"  # the ellipse: tracked, no mark
    assert "\u2020" not in "".join(qp)
    assert "| 2 | ats | 42.4 (2) | 134\u2020 (2) |" in text
    assert f"{NOT_TRACKED_NOTE}." in text
    assert f"\u2020 did not track {VERDICT}" == NOT_TRACKED_NOTE


def test_the_advice_names_where_a_recommended_method_did_not_track(thesis_report):
    _, _, _, text = thesis_report
    lines = [x for x in text.splitlines() if x.startswith("- **")]
    corners = next(x for x in lines if x.startswith("- **Sharp corners"))
    assert corners.startswith("- **Sharp corners (like the rectangle)**: `qp` (42.8 mm RMS, ")
    assert corners.endswith("Did not track: `qp` (see above).")
    best = next(x for x in lines if x.startswith("- **Best tracking"))
    assert best.endswith(f"Did not track {VERDICT}: `qp` on the rectangle (thesis plant).")
    singularity = next(x for x in lines if x.startswith("- **Near the shoulder"))
    assert singularity.endswith(
        f"Did not track {VERDICT}: `ats` on the rectangle (kinematic and thesis plants); "
        "`qp` (see above)."
    )
    blind = next(x for x in lines if x.startswith("- **No pose measurement"))
    assert blind.endswith("Did not track: `ats` (see above).")
    assert (
        'there and on the thesis plant (section "Plant: thesis next to the kinematic plant").'
        in text
    )


def test_the_advice_without_plant_runs_names_the_kinematic_failures(thesis_report):
    config, plan, outputs, _ = thesis_report
    items = profiles(config, outputs, build_ranking(plan, outputs))
    singularity = next(x for x in recommendations(items) if x.startswith("**Near the shoulder"))
    assert singularity.endswith(f"Did not track {VERDICT}: `ats` on the rectangle.")
    corners = next(x for x in recommendations(items) if x.startswith("**Sharp corners"))
    assert "Did not track" not in corners


def test_the_diagnosis_counts_joint_limit_steps_as_the_summary(thesis_report):
    config, plan, outputs, text = thesis_report
    summary = _summary(plan, outputs, "ats", "rectangle")
    steps = summary["joint_limit_steps"]
    assert steps == pytest.approx(427, abs=3)
    ts = outputs[plan.main[3]].timeseries
    assert plan.main[3].method == "ats" and plan.main[3].trajectory == "rectangle"
    # the last sample sits at the limit too: its command is never applied
    assert ts["th2"][-1] <= -np.pi + 1e-6
    findings = diagnose(config, plan, outputs, plan.main[3])
    assert any(f"and stayed there for {steps} steps;" in f.text for f in findings)
    assert f"stayed there for {steps} steps;" in text


def test_saturation_span_counts_commanded_steps_only():
    ts = {"t": np.array([0.0, 0.1, 0.2, 0.3]), "saturated": np.array([0, 1, 0, 1])}
    assert saturation_span(ts) == (1, pytest.approx(0.1), pytest.approx(0.1))
    exclude = np.array([False, True, False, False])
    assert saturation_span(ts, exclude)[0] == 0


def test_the_plant_table_names_its_ratio_and_drops_empty_columns(thesis_report):
    _, plan, outputs, text = thesis_report
    header = _cells(text, "| trajectory | method | RMS kin")
    assert header[4] == "RMS ratio to kinematic"
    for gone in ("x", "min physics stability", "tipped", "slip (mm/s)"):
        assert gone not in header
    assert "lag (mm/s)" in header and "actuator-limited" in header
    row = _cells(text, "| rectangle | qp |")
    on_plant = _summary(plan, outputs, "qp", "rectangle", "thesis")["rms_position_error_m"]
    kinematic = _summary(plan, outputs, "qp", "rectangle")["rms_position_error_m"]
    assert float(row[4]) == pytest.approx(on_plant / kinematic, rel=5e-3)
    assert float(row[4]) == pytest.approx(2.32, abs=0.01)
    assert len(row) == len(header)
    assert (
        "(the command is the motion). The RMS ratio to kinematic is the RMS error on the "
        "thesis plant over the RMS error of the same run on the kinematic plant; lag " in text
    )
    assert "slip the peak speed" not in text


def test_the_step_time_says_it_is_a_median_over_the_trajectories(thesis_report):
    config, plan, outputs, _ = thesis_report
    items = profiles(config, outputs, build_ranking(plan, outputs))
    qp = next(p for p in items if p.method == "qp")
    steps = [_summary(plan, outputs, "qp", n)["median_step_us"] for n in ("ellipse", "rectangle")]
    assert qp.step_us == pytest.approx(float(np.median(steps)), rel=1e-12)
    line = next(x for x in recommendations(items) if x.startswith("**Tightest"))
    assert " us per step, median over both trajectories, on this machine;" in line


def test_the_mark_prints_on_a_console_that_cannot_show_it():
    """A latin-1 or ASCII stdout ended compare with a UnicodeEncodeError after the runs."""
    from types import SimpleNamespace

    from ddwmmr.cli.common import console_text

    text = "134\u2020 (2)\n\u2020 did not track; 5 \u00b5m"
    assert console_text(text, SimpleNamespace(encoding="utf-8")) == text
    assert console_text(text, SimpleNamespace(encoding="latin-1")) == (
        "134+ (2)\n+ did not track; 5 \u00b5m"
    )
    assert console_text(text, SimpleNamespace(encoding="ascii")) == (
        "134+ (2)\n+ did not track; 5 ?m"
    )


def test_a_caveat_names_the_settings_and_groups_plants_by_trajectory():
    """The slides line's failures are of the slides-preset runs (the default clrrmc-ts
    tracks the rectangle); one trajectory's kinematic and plant runs read as one place."""
    from ddwmmr.reports.compare import advice

    slides = advice._did_not_track([("clrrmc-ts", [("rectangle", None)])], str, " under x")
    assert slides == f" Did not track under x {VERDICT}: `clrrmc-ts` on the rectangle."
    runs = [("rectangle", None), ("ellipse", "mujoco"), ("rectangle", "thesis")]
    assert advice._did_not_track([("ats", runs)], str) == (
        f" Did not track {VERDICT}: `ats` on the rectangle (kinematic and thesis plants) "
        "and the ellipse (mujoco plant)."
    )
    assert advice._did_not_track([("ats", [])], str) == ""
