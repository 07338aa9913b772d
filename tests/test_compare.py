"""``python -m ddwmmr.compare``: report files, metrics vs ``track``, HTML, jobs, findings."""

import csv
import json
import math
import re
from html.parser import HTMLParser

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.cli import track
from ddwmmr.cli.compare import build_parser, config_from_arguments, main
from ddwmmr.controllers.clrrmc import ConfigurationSpaceController
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
    metrics_csv,
    metrics_rows,
    observed_order,
    plan_runs,
    rank_with_ties,
)

SHORT = ["--duration", "2", "--no-progress"]
L1, L2 = 0.35, 0.30


def read_metrics(path):
    """metrics.csv as {(method, trajectory): row}."""
    with open(path, newline="") as handle:
        return {(r["method"], r["trajectory"]): r for r in csv.DictReader(handle)}


def rms_error_from_configurations(ts, trajectory):
    """RMS end-effector position error (m) recomputed from the recorded configurations with
    the forward kinematics of docs/theory.md and the trajectory's own desired positions."""
    a1 = ts["phi"] + ts["th1"]
    xe = ts["x"] + L1 * np.cos(a1) + L2 * np.cos(a1 + ts["th2"])
    ye = ts["y"] + L1 * np.sin(a1) + L2 * np.sin(a1 + ts["th2"])
    desired = np.array([trajectory.pose(t)[:2] for t in ts["t"]])
    return float(np.sqrt(np.mean((desired[:, 0] - xe) ** 2 + (desired[:, 1] - ye) ** 2)))


def table_after(text, heading, key_column=0):
    """The first Markdown table after ``heading``: (header cells, {key cell: row cells})."""
    lines = text[text.index(heading) :].splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("| "))
    table = []
    for line in lines[first:]:
        if not line.startswith("|"):
            break
        cells = re.split(r"(?<!\\)\|", line.strip()[1:-1])
        table.append([cell.strip() for cell in cells])
    header, rows = table[0], table[2:]
    return header, {row[key_column]: row for row in rows}


def number(cell):
    """The leading number of a table cell such as ``3.42 (1)``."""
    return float(cell.split()[0])


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
        elif isinstance(value, bool):  # e.g. start_tipped
            assert row[key] == str(value), key
        elif isinstance(value, list):  # the verdict's reason codes
            assert row[key].split() == value, key
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
    """The fixture's main runs (2 worker processes) again in this process, one by one,
    from the same command line's configuration, written by the same metrics.csv code
    (the figures and the HTML, which jobs do not reach, are not drawn again)."""
    config = config_from_arguments(build_parser().parse_args([*SHORT, "--study", "none"]), [])
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs(), jobs=1)
    out = tmp_path / "metrics.csv"
    out.write_text(metrics_csv(metrics_rows(plan, outputs, config.shown)))
    one, two = read_metrics(out), read_metrics(report / "metrics.csv")
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
    # The verdict must agree with the scores recomputed here: CLRRMC-TS >= RR-ATS where the
    # RMS error of clrrmc-ts is at most 5 % (or 0.1 mm) above that of ats.
    holds = all(
        float(rows[("clrrmc-ts", t)]["rms_position_error_m"])
        <= 1.05 * float(rows[("ats", t)]["rms_position_error_m"]) + 1e-4
        for t in ("ellipse", "rectangle", "figure8")
    )
    assert holds  # the closed loop removes the 42.4 mm offset, the open loop keeps it
    assert ("holds on every trajectory" in printed) == holds
    assert str(out / "report.html") in printed
    assert not (out / "study_tau.png").exists()
    # Running again replaces the earlier report in place (--methods adds pi to the two;
    # --only keeps one trajectory: the rows of the first run's other two are gone).
    assert main([*argv, "--methods", "pi", "--only", "figure8", "--out", str(out)]) == 0
    rows = read_metrics(out / "metrics.csv")
    assert set(rows) == {(m, "figure8") for m in ("ats", "clrrmc-ts", "pi")}


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
    """20 s runs: ap reaches cos(th1) = 0 at 5.4 s, pi at 12.6 s; ats keeps its offset."""
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
    for method in ("ap", "pi"):
        ts = outputs[main_spec(config, method, "ellipse")].timeseries
        onset = float(ts["t"][np.argmax(np.abs(np.cos(ts["th1"])) < 0.05)])
        text = [
            f.text for f in diagnose(config, plan, outputs, main_spec(config, method, "ellipse"))
        ]
        # The onset the sentence states is the first sample with |cos th1| < 0.05.
        stated = float(re.search(r"cos\(th1\) = 0 at t = ([0-9.]+) s", text[0]).group(1))
        assert stated == pytest.approx(onset, abs=0.05)
    reason = " ".join(check.reasons[("ellipse", "ap")])
    assert "With K3 = 0" in reason
    pi = [f.text for f in diagnose(config, plan, outputs, main_spec(config, "pi", "ellipse"))]
    assert "splits the yaw rate equally" in pi[0]
    ts = outputs[main_spec(config, "pi", "ellipse")].timeseries
    # The minimum-norm split: w = th1dot (identical columns of J), so th1 - phi is constant
    # to the integration error.
    np.testing.assert_allclose(ts["w"], ts["th1dot"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(ts["th1"] - ts["phi"], ts["th1"][0] - ts["phi"][0], atol=1e-9)
    ats_spec = main_spec(config, "ats", "ellipse")
    ats = [f.text for f in diagnose(config, plan, outputs, ats_spec)]
    assert len(ats) == 1 and ats[0].startswith("it is open loop: it keeps the initial")
    stated = float(re.search(r"offset \(([0-9.]+) mm\)", ats[0]).group(1))
    assert stated == pytest.approx(1000 * math.hypot(0.03, 0.03), abs=0.05)
    error = outputs[ats_spec].timeseries["position_error_m"]
    np.testing.assert_allclose(error, math.hypot(0.03, 0.03), rtol=0, atol=1e-9)


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


def test_report_ranks_both_presets_with_independently_checked_scores(report):
    text = (report / "report.md").read_text()
    assert "## The slides' settings and ours" in text
    for preset, options in (("slides", {"preset": "slides"}), ("default", {})):
        header, rows = table_after(text, f"(preset `{preset}`)", key_column=1)
        for name in ("ellipse", "rectangle"):
            trajectory = load_trajectory(name)
            ts = simulate(Robot(), trajectory, "clrrmc-ts", duration=2.0, **options).timeseries
            expected = 1000 * rms_error_from_configurations(ts, trajectory)
            cell = rows["clrrmc-ts"][header.index(f"{name} RMS (mm)")]
            assert number(cell) == pytest.approx(expected, rel=5e-3)
    # The settings that differ, stated from the slides: the row [0 0 0 1 1] for ats and both
    # closed-loop methods, and no orientation feedback for clrrmc-ts.
    header, rows = table_after(text, "Settings that differ")
    body = text[text.index("Settings that differ") :].split("\n\n")[1]
    assert body.count("| ats |") == 1 and body.count("| clrrmc-cs |") == 1
    assert body.count("| clrrmc-ts |") == 2
    assert rows["ats"][2].startswith("sum [0 0 0 1 1]")
    assert "no orientation feedback" in body and "| ap |" not in body


def test_which_method_section_follows_the_metrics(report):
    text = (report / "report.md").read_text()
    assert "## Which method should I use?" in text
    metrics = read_metrics(report / "metrics.csv")
    methods = {m for m, _ in metrics}
    overall = {
        m: math.exp(
            np.mean(
                [
                    math.log(float(metrics[(m, t)]["rms_position_error_m"]))
                    for t in ("ellipse", "rectangle")
                ]
            )
        )
        for m in methods
    }
    header, rows = table_after(text, "## Which method should I use?")
    assert set(rows) == methods
    for m in methods:
        steps = [float(metrics[(m, t)]["median_step_us"]) for t in ("ellipse", "rectangle")]
        assert number(rows[m][header.index("step (us)")]) == pytest.approx(
            np.median(steps), rel=5e-3
        )
    best_line = next(line for line in text.splitlines() if "**Best tracking over all" in line)
    named = re.findall(r"`([a-z0-9-]+)` \(", best_line)
    best = min(overall.values())
    # Every method the line names is tied with the best (5 %), and every tied one is named.
    assert set(named) == {m for m in methods if overall[m] <= 1.05 * best + 1e-4}
    guarantee = next(line for line in text.splitlines() if "**Tip-over stability" in line)
    floor = float(metrics[("qp", "ellipse")]["stability_min"])
    assert f"`qp` (S >= {floor:g})" in guarantee


def test_slow_methods_can_be_left_out_of_the_studies(monkeypatch):
    monkeypatch.setattr(ConfigurationSpaceController, "in_studies", False, raising=False)
    trajectories = {"ellipse": load_trajectory("ellipse")}
    config = CompareConfig(methods=("ats", "clrrmc-cs"), trajectories=trajectories)
    assert config.study_methods == ("ats",)
    named = CompareConfig(
        methods=("ats", "clrrmc-cs"), trajectories=trajectories, study_methods=("clrrmc-cs",)
    )
    assert named.study_methods == ("clrrmc-cs",)
    specs = plan_runs(config).studies["init"]
    assert {s.method for s in specs} == {"ats"}


def test_metrics_csv_names_each_trajectory_as_the_report_does(tmp_path, capsys):
    """Two files of one stem are ``loop`` and ``loop-2`` in the report and its figures;
    metrics.csv gave both rows the trajectory's own name, ``loop``. A name the report
    makes safe for file names (``my loop``) keeps its own name there and in the report;
    only its figure files take the safe one (``my_loop``)."""
    files = []
    for folder, name, samples in (("a", "loop", 2000), ("b", "loop", 1000), ("c", "my loop", 500)):
        (tmp_path / folder).mkdir()
        files.append(tmp_path / folder / f"{name}.toml")
        files[-1].write_text(f'[trajectory]\nshape = "ellipse"\nT = 40.0\nN = {samples}\n')
    out = tmp_path / "report"
    only = ["--only", "ellipse", *map(str, files)]
    argv = ["--methods", "ats", "--study", "none", "--duration", "0.2", "--jobs", "1"]
    assert main([*argv, *only, "--no-progress", "--out", str(out)]) == 0, capsys.readouterr()
    with (out / "metrics.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    names = ["ellipse", "loop", "loop-2", "my loop"]
    stems = ["ellipse", "loop", "loop-2", "my_loop"]
    assert [r["trajectory"] for r in rows] == names
    # each row is its own file's run: the default step is T / N of that file
    assert [float(r["dt"]) for r in rows] == [0.02, 0.02, 0.04, 0.08]
    record = json.loads((out / "run.json").read_text())
    assert list(record["trajectories"]) == stems
    assert record["trajectories"]["loop-2"]["file"] == str(files[1])
    text = (out / "report.md").read_text()
    for name, stem in zip(names, stems):
        assert (out / f"errors_{stem}.png").exists()
        assert f"{name} RMS (mm)" in text
