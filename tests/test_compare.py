"""``python -m ddwmmr.compare``: report files, metrics vs ``track``, HTML, jobs, findings."""

import csv
import json
import math
from html.parser import HTMLParser

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory
from ddwmmr.cli import track
from ddwmmr.cli.compare import main
from ddwmmr.reports.compare import (
    CompareConfig,
    Document,
    check_slides,
    convergence_time,
    diagnose,
    drift_kind,
    execute,
    is_timing,
    main_spec,
    observed_order,
    plan_runs,
    rank_with_ties,
)

SHORT = ["--duration", "2", "--no-progress"]


def read_metrics(path):
    """metrics.csv as {(method, trajectory): row}."""
    with open(path, newline="") as handle:
        return {(r["method"], r["trajectory"]): r for r in csv.DictReader(handle)}


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """One short-horizon comparison with every method and every study, 2 jobs."""
    out = tmp_path_factory.mktemp("compare") / "report"
    status = main([*SHORT, "--jobs", "2", "--out", str(out)])
    assert status == 0
    return out


def test_short_report_builds_every_file(report, capsys):
    names = {p.name for p in report.iterdir()}
    assert {"report.md", "report.html", "metrics.csv"} <= names
    for name in ("ellipse", "rectangle"):
        assert {f"paths_{name}.png", f"errors_{name}.png", f"wheels_{name}.png"} <= names
        assert f"methods_{name}.png" in names
    # Corners need t >= T/4 = 10 s: a 2 s run has no corner, so no corner figure.
    assert {"study_tau.png", "study_dt.png", "study_integrator.png", "study_init.png"} <= names
    assert not [n for n in report.parent.iterdir() if n.name.startswith(".")]  # no temp left
    text = (report / "report.md").read_text()
    for heading in ("## Ranking", "## Does the slides' ranking hold?", "## Trajectory: rectangle"):
        assert heading in text
    assert "CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS >= RR-PI" in text
    assert "![" in text and "(paths_ellipse.png)" in text


def test_metrics_has_one_row_per_method_and_trajectory(report):
    from ddwmmr import available_methods

    rows = read_metrics(report / "metrics.csv")
    assert set(rows) == {(m, t) for m in available_methods() for t in ("ellipse", "rectangle")}
    ats = rows[("ats", "ellipse")]
    # Open loop on a 2 s ellipse: the error stays the initial offset hypot(0.03, 0.03) m.
    assert float(ats["final_position_error_m"]) == pytest.approx(math.hypot(0.03, 0.03), rel=1e-6)
    assert float(ats["steps"]) == 100 and float(ats["dt"]) == 0.02


@pytest.mark.parametrize(("method", "trajectory"), [("clrrmc-cs", "rectangle"), ("qp", "ellipse")])
def test_metrics_equal_the_track_summary(report, tmp_path, method, trajectory):
    out = tmp_path / "track"
    status = track.main(
        ["--method", method, "--traj", trajectory, *SHORT, "--no-plots", "--out", str(out)]
    )
    assert status == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary.pop("run")["method"] == method  # the run record: not a metric
    row = read_metrics(report / "metrics.csv")[(method, trajectory)]
    assert set(summary) <= set(row)
    for key, value in summary.items():
        if is_timing(key):
            assert float(row[key]) > 0  # a timing: present, not reproducible
        elif value is None:
            assert row[key] == ""
        elif isinstance(value, str):
            assert row[key] == value, key
        else:
            assert float(row[key]) == value, key  # exact: floats are written by repr


class _Collector(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags, self.links = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.links += [(tag, k, v) for k, v in attrs if k in ("src", "href", "data")]


def test_html_is_self_contained(report):
    text = (report / "report.html").read_text()
    parser = _Collector()
    parser.feed(text)
    parser.close()
    figures = [p for p in report.iterdir() if p.suffix == ".png"]
    images = [v for tag, k, v in parser.links if tag == "img"]
    assert len(images) == len(figures) >= 12
    assert all(v.startswith("data:image/png;base64,") for v in images)
    assert [link for link in parser.links if not link[2].startswith("data:")] == []
    assert "http:" not in text and "https:" not in text
    assert "script" not in parser.tags and "link" not in parser.tags
    assert parser.tags.count("table") >= 4


def test_jobs_do_not_change_the_metrics(report, tmp_path):
    out = tmp_path / "one-job"
    assert main([*SHORT, "--jobs", "1", "--study", "none", "--out", str(out)]) == 0
    one, two = read_metrics(out / "metrics.csv"), read_metrics(report / "metrics.csv")
    assert one.keys() == two.keys()
    for key, row in one.items():
        for column, value in row.items():
            if not is_timing(column):
                assert value == two[key][column], (key, column)


def test_extra_trajectory_and_method_selection(tmp_path, capsys):
    out = tmp_path / "sel"
    argv = ["--methods", "ats,clrrmc-ts", "--traj", "figure8", "--study", "none", *SHORT]
    assert main([*argv, "--out", str(out)]) == 0
    rows = read_metrics(out / "metrics.csv")
    assert set(rows) == {
        (m, t) for m in ("ats", "clrrmc-ts") for t in ("ellipse", "rectangle", "figure8")
    }
    printed = capsys.readouterr().out
    # Closed loop removes the 42.4 mm offset, open loop keeps it: CLRRMC-TS >= RR-ATS holds.
    assert "CLRRMC-TS >= RR-ATS holds on every trajectory" in printed
    assert str(out / "report.html") in printed
    assert not (out / "study_tau.png").exists()
    # Running again replaces the earlier report in place.
    assert main([*argv, "--methods", "pi", "--out", str(out)]) == 0
    assert ("pi", "figure8") in read_metrics(out / "metrics.csv")


def test_jobs_do_not_change_any_time_series():
    config = CompareConfig(
        methods=("ats", "clrrmc-cs"),
        trajectories={"ellipse": load_trajectory("ellipse")},
        duration=1.0,
        studies=("init",),
    )
    specs = plan_runs(config).all_specs()
    serial, parallel = execute(config, specs, jobs=1), execute(config, specs, jobs=2)
    assert list(serial) == list(parallel) == specs
    for spec in specs:
        for column, values in serial[spec].timeseries.items():
            if column != "step_us":
                np.testing.assert_array_equal(values, parallel[spec].timeseries[column])


@pytest.mark.parametrize(
    "argv",
    [
        ["--methods", "nope"],
        ["--traj", "no-such-trajectory"],
        ["--study", "everything"],
        ["--jobs", "0"],
        ["--duration", "-1"],
        ["--duration", "0.001"],  # shorter than the 0.02 s step
        ["--payload", "-3"],
        ["--robot", "missing.toml"],
        ["--jobs", "two"],
    ],
)
def test_bad_input_is_one_line_exit_2_and_no_folder(tmp_path, capsys, argv):
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as info:
        raise SystemExit(main([*argv, "--out", str(out)]))
    assert info.value.code == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert len(captured.err.strip().splitlines()) == 1 and "Traceback" not in captured.err
    assert list(tmp_path.iterdir()) == []


def test_an_unrelated_folder_is_never_replaced(tmp_path, capsys):
    (tmp_path / "keep.txt").write_text("mine")
    assert main(["--study", "none", *SHORT, "--out", str(tmp_path)]) == 2
    assert "holds files no ddwmmr compare run wrote" in capsys.readouterr().err
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_slides_ranking_check_explains_ap_and_pi():
    """20 s runs: ap hits cos(th1) = 0 at 4.5 s, pi at 12 s; ats keeps its offset."""
    config = CompareConfig(
        methods=("pi", "ats", "ap"),
        trajectories={"ellipse": load_trajectory("ellipse")},
        duration=20.0,
        studies=(),
    )
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs())
    from ddwmmr.reports.compare import build_ranking

    check = check_slides(config, plan, outputs, build_ranking(plan, outputs))
    assert not check.holds["ellipse"]
    pairs = {(v.expected_better, v.expected_worse) for v in check.violations}
    assert pairs == {("ap", "ats"), ("ap", "pi")}
    reason = " ".join(check.reasons[("ellipse", "ap")])
    assert "cos(th1) = 0" in reason and "With K3 = 0" in reason
    pi = [f.text for f in diagnose(config, plan, outputs, main_spec(config, "pi", "ellipse"))]
    assert "splits the yaw rate equally" in pi[0]
    ts = outputs[main_spec(config, "pi", "ellipse")].timeseries
    k = int(np.argmax(np.abs(np.cos(ts["th1"])) < 0.05))
    # The minimum-norm split: th1 turns with the base heading, to within 1 %.
    assert ts["th1"][k] - ts["th1"][0] == pytest.approx(ts["phi"][k] - ts["phi"][0], rel=0.01)
    ats = [f.text for f in diagnose(config, plan, outputs, main_spec(config, "ats", "ellipse"))]
    assert ats == [
        "it is open loop: it keeps the initial end-effector offset (42.4 mm) for the whole run"
    ]


def test_convergence_time_is_three_tau_for_clrrmc_ts():
    config = CompareConfig(
        methods=("clrrmc-ts",),
        trajectories={"ellipse": load_trajectory("ellipse")},
        robot=Robot(),
        duration=3.0,
        studies=(),
    )
    spec = main_spec(config, "clrrmc-ts", "ellipse", options=(("tau", 0.3),))
    ts = execute(config, [spec])[spec].timeseries
    # e(t) = e0 exp(-t/tau) falls below 5 % after -ln(0.05) tau = 0.899 s (step 0.02 s).
    assert convergence_time(ts["t"], ts["position_error_m"]) == pytest.approx(0.9, abs=0.021)


def test_convergence_time_and_observed_order_on_synthetic_data():
    t = np.linspace(0.0, 5.0, 501)
    assert convergence_time(t, 0.04 * np.exp(-t / 0.5)) == pytest.approx(1.5, abs=0.01)
    assert math.isnan(convergence_time(t, np.full_like(t, 0.04)))
    assert convergence_time(t, np.zeros_like(t)) == 0.0
    steps = (0.01, 0.02, 0.04)
    assert observed_order({dt: 3.0 * dt**4 for dt in steps}) == pytest.approx(4.0)
    assert math.isnan(observed_order({dt: 1e-15 for dt in steps}))  # round-off only
    assert drift_kind({dt: 0.5 * dt for dt in steps}) == "scales"
    assert drift_kind({dt: 3.0 for dt in steps}) == "failure"
    assert drift_kind({dt: 2.4e-4 for dt in steps}) == "bias"


def test_ranks_share_ties_within_five_percent():
    ranks = rank_with_ties({"a": 0.0100, "b": 0.0104, "c": 0.020, "d": 3.0, "e": 0.0201})
    assert ranks == {"a": 1, "b": 1, "c": 3, "e": 3, "d": 5}


def test_document_escapes_html_and_renders_markup(tmp_path):
    doc = Document("T <1>")
    doc.paragraph("**bold** and `code` <script>")
    doc.table(["a", "b"], [["x|", "1"]])
    page = doc.to_html(tmp_path)
    assert "<strong>bold</strong>" in page and "<code>code</code>" in page
    assert "&lt;script&gt;" in page and "<script>" not in page
    markdown = doc.to_markdown()
    assert markdown.startswith("# T <1>\n") and "| x\\| | 1 |" in markdown
