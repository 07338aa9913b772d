"""``python -m ddwmmr.scenarios``: smoke runs, outputs, studies and bad input."""

from __future__ import annotations

import csv
import json

import pytest

from ddwmmr.cli.scenarios import main as cli
from ddwmmr.scenarios.protocol import METRICS
from scenarios_cli_helpers import bad_scenarios_main, bad_scenarios_run

SUMMARY_KEYS = {
    "n", "failed", "mean_time_s", "sd_time_s", "mean_speed_m_s", "time_base_s", "time_arm_s",
    "time_manipulability_s", "transitions_manipulability", "time_stability_s",
    "transitions_stability", "min_stability", "wall_time_s",
}  # fmt: skip
FAST = ["--n", "3", "--time-limit", "12", "--jobs", "1", "--no-progress"]


def test_benchmark_writes_csv_summary_table_and_figures(tmp_path, capsys):
    out = tmp_path / "run"
    assert cli([*FAST, "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary) >= SUMMARY_KEYS
    assert summary["n"] == 3
    rows = list(csv.DictReader((out / "scenarios.csv").open()))
    assert [r["scenario"] for r in rows] == ["1", "2", "3"]
    assert set(METRICS) == set(rows[0])
    # Named after what they show, not "thesis_*" whatever the controller.
    figures = {"times", "speed", "stability", "manipulability", "paths", "timeline"}
    assert {p.name for p in out.glob("*.png")} == {f"{name}.png" for name in figures}
    for name in figures:
        assert (out / f"{name}.png").stat().st_size > 1000
    printed = capsys.readouterr().out
    assert "No. of failed scenarios" in printed and "Simulation time (s)" in printed
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no staging left


def test_no_hysteresis_option_sets_exit_to_enter(tmp_path):
    """With the default thresholds, or with EXIT given equal to ENTER (a different EXIT,
    which it would drop, is refused)."""
    out = tmp_path / "run"
    args = [*FAST, "--out", str(out), "--stability", "1.3", "1.3", "--no-hysteresis", "stability"]
    assert cli([*args, "--no-hysteresis", "manipulability"]) == 0
    config = json.loads((out / "summary.json").read_text())["config"]
    assert config["stability"] == [1.3, 1.3]
    assert config["manipulability"] == [0.75, 0.75]


def test_obstacle_study_table(tmp_path, capsys):
    out = tmp_path / "obs"
    args = ["--study", "obstacles", "--time-limit", "6", "--jobs", "1", "--no-progress"]
    assert cli([*args, "--out", str(out)]) == 0
    table = (out / "obstacles.md").read_text()
    assert "scenario 1" in table and "scenario 10" in table
    assert "Time in obstacle state (s)" in table
    assert (out / "obstacle_paths.png").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--n", "0"], "n must be an integer in [1, 100000]"),
        (
            ["--stability", "1.6", "1.2"],
            "stability thresholds: ENTER must be <= EXIT, both in (0, 10] (got 1.6, 1.2)",
        ),
        (
            ["--manipulability", "0.9", "0.8"],
            "manipulability thresholds: ENTER must be <= EXIT, both in (0, 1] (got 0.9, 0.8)",
        ),
        (["--controller", "nope"], "invalid choice"),
        (["--controller", "thesis", "--plant", "kinematic"], "thesis or mujoco"),
        (["--payload", "-1"], "payload must be in [0, "),
        (["--stability", "-5", "-1"], "stability thresholds must be in (0, 10]"),
        (["--stability", "1e300", "1e301"], "stability thresholds must be in (0, 10]"),
        (["--manipulability", "0.5", "1.5"], "manipulability thresholds must be in (0, 1]"),
        (["--qp-stability-min", "1.3"], "qp-stability-min: only used with --controller qp"),
        (["--controller", "mpc", "--qp-max-speed", "1"], "only used with --controller qp"),
        (["--controller", "qp", "--qp-max-speed", "1e300"], "qp-max-speed must be in (0, 10]"),
        (["--controller", "qp", "--qp-stability-min", "10"], "must be in (0, 10)"),
        (["--executor", "dask", "--scheduler", "not an address"], "scheduler: cannot connect"),
        (["--scheduler", "tcp://x:1"], "only used with --executor dask"),
        (["--jobs", "0"], "jobs must be an integer in [1, 256]"),
        (["--study", "thresholds", "--controller", "qp"], "needs --controller thesis"),
        (["--dt", "0"], "dt must be in (0, 0.1] s"),
        (["--dt", "0.2"], "dt must be in (0, 0.1] s"),
        (["--dt", "0.1000000001"], "dt must be in (0, 0.1] s (got 0.1000000001)"),
        (["--dt", "inf"], "dt must be in (0, 0.1] s"),
        (["--time-limit", "nan"], "time-limit must be > 0 s"),
        (["--controller", "qp", "--stability", "1.3", "1.6"], "--stability: only used with"),
        (["--controller", "mpc", "--manipulability", "0.7", "0.9"], "--manipulability: only"),
        (["--controller", "qp", "--no-hysteresis", "stability"], "--no-hysteresis: only used"),
        (
            ["--study", "thresholds", "--stability", "1.3", "1.6"],
            "runs its own thresholds (thesis Table 5.2 and Tables 5.5-5.20); leave it out",
        ),
        (
            ["--no-hysteresis", "stability", "--stability", "1.2", "1.5"],
            "error: no-hysteresis: --no-hysteresis stability leaves the state at ENTER, so "
            "--stability 1.2 1.5 gives an EXIT it would ignore; give EXIT = ENTER "
            "(--stability 1.2 1.2)",
        ),
        (
            ["--no-hysteresis", "manipulability", "--manipulability", "0.7", "0.8"],
            "--manipulability 0.7 0.8 gives an EXIT it would ignore",
        ),
        (["--study", "arbiters", "--no-hysteresis", "stability"], "arbiter study runs its own"),
        (["--controller", "qp", "--arbiter", "state-machine"], "only the thesis controller"),
    ],
)
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, args, message, capsys):
    assert message in bad_scenarios_main(tmp_path, args, capsys)


def test_bad_input_to_the_module_is_one_line_with_status_2(tmp_path):
    """The same check on a real ``python -m ddwmmr.scenarios`` process (its exit status
    and stderr), with an error argparse itself raises."""
    assert "invalid choice" in bad_scenarios_run(tmp_path, ["--controller", "nope"])


def test_refuses_to_replace_a_foreign_folder(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    assert cli([*FAST, "--out", str(out)]) == 2
    assert "holds files no ddwmmr scenarios run wrote" in capsys.readouterr().err
    assert (out / "notes.txt").read_text() == "keep me"


def test_help_explains_protocol(capsys):
    with pytest.raises(SystemExit) as exc:
        cli(["--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    for word in ("--no-hysteresis", "--executor", "--study", "0.01 m", "3.0 kg"):
        assert word in text


def test_threshold_table_states_what_ours_is_against_the_thesis():
    """ "42 / 1" compares failures of the thesis's 100 scenarios with failures of ours:
    the line above the table says how many ours are and how they ran."""
    from ddwmmr.scenarios import RunConfig, studies

    config = RunConfig(arbiter="competitive", arbiter_seed=3, time_limit=4.0)
    context = studies.context_line(2, 0, config)
    assert context == (
        "ours: 2 scenarios (seed 0), thesis controller, thesis plant, payload 3 kg, "
        "competitive (arbiter seed 3) arbiter, 4 s limit; the thesis: 100 scenarios, "
        "1.25 kg payload"
    )
    assert studies.context_line(1, None, RunConfig()).startswith(
        "ours: 1 scenario, thesis controller, thesis plant, payload 3 kg, state-machine "
        "arbiter, 60 s limit;"
    )
    summary = {key: 0 for _, key, _ in studies.THRESHOLD_COLUMNS} | {"n": 2}
    results = [(studies.THRESHOLD_VARIANTS[0], summary)]
    bare = studies.threshold_table(results)
    assert bare.startswith("| variant (thesis table) |")
    assert studies.threshold_table(results, context) == (
        f"{studies.THRESHOLD_HEADING}\n\n{context}\n\n{studies.THRESHOLD_NOTE}\n\n{bare}"
    )


def test_threshold_study_table_has_thesis_and_our_numbers(tmp_path, capsys):
    out = tmp_path / "thr"
    args = ["--study", "thresholds", "--n", "2", "--time-limit", "4", "--jobs", "1"]
    assert cli([*args, "--no-progress", "--out", str(out)]) == 0
    table = (out / "thresholds.md").read_text()
    lines = [line for line in table.splitlines() if line.startswith("| ")]
    assert len(lines) == 1 + 18  # header + every variant of Tables 5.5-5.20
    assert "| Baseline (5.2) | 1.25/1.6 | 0.75/0.9 | 0 of 100 / 2 of 2 | 44.9 / 4 |" in table
    assert "42 of 100 / " in table  # Table 5.12 threshold 5
    assert table.startswith(
        "# Threshold study (thesis Tables 5.5-5.20): cells are thesis / ours\n\n"
        "ours: 2 scenarios (seed 0), thesis controller, thesis plant, payload 3 kg, "
        "state-machine arbiter, 4 s limit; the thesis: 100 scenarios, 1.25 kg payload\n"
    )
    assert "ours: 2 scenarios (seed 0)" in capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary["variants"]) == 18


def test_default_out_is_a_new_timestamped_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli(["--n", "1", "--time-limit", "0.3", "--jobs", "1", "--no-progress"]) == 0
    (folder,) = (tmp_path / "runs").iterdir()
    assert folder.name.startswith("scenarios-") and (folder / "summary.json").is_file()
    assert capsys.readouterr().out.endswith(f"\nwrote runs/{folder.name}/\n")


def test_payload_that_tips_the_start_pose_is_refused_with_the_limit(tmp_path, capsys):
    from ddwmmr.behaviours.objective import default_pose
    from ddwmmr.model import Robot

    assert cli(["--payload", "10", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    limit = float(err.rsplit("at most ", 1)[1].split()[0])
    # Just below the limit the start pose stands (S > 1), just above it tips (S <= 1).
    for payload, stands in ((0.99 * limit, True), (1.01 * limit, False)):
        robot = Robot().with_payload(payload)
        s = robot.stability((0.0, 0.0, 0.0, *default_pose(robot)))[2]
        assert (s > 1.0) is stands
    assert list(tmp_path.iterdir()) == []


def test_mpc_options_are_refused_before_any_scenario_runs(tmp_path, monkeypatch, capsys):
    """A horizon within the control step is refused up front, one line and status 2, with
    no worker started and nothing written (it used to fail inside the run of every
    scenario)."""
    import ddwmmr.cli.scenarios as tool

    def no_scenario(*args, **kwargs):
        raise AssertionError("a scenario ran")

    monkeypatch.setattr(tool, "run_many", no_scenario)
    args = ["--controller", "mpc", "--n", "2", "--dt", "0.05", "--option", "horizon=0.04"]
    assert cli([*args, "--jobs", "1", "--no-progress", "--out", str(tmp_path / "x")]) == 2
    assert capsys.readouterr().err == (
        "error: horizon must be > the control step dt = 0.05 s (got 0.04)\n"
    )
    assert list(tmp_path.iterdir()) == []


def test_mpc_with_the_fewest_intervals_runs_its_scenarios(tmp_path):
    """intervals=2 is in the documented [2, 200]: it used to pass the options' check, fail
    in the OCP ("intervals ... (got 1)") and end every scenario in a controller error."""
    out = tmp_path / "two"
    args = ["--controller", "mpc", "--n", "1", "--time-limit", "1", "--option", "intervals=2"]
    assert cli([*args, "--jobs", "1", "--no-progress", "--out", str(out)]) == 0
    (row,) = csv.DictReader((out / "scenarios.csv").open())
    assert row["reason"] == "timeout" and row["sim_steps"] == "100"
    options = json.loads((out / "summary.json").read_text())["controller_options"]
    assert options["intervals"] == 2


def _bounds_file(folder, header: str, rows: list[str]) -> str:
    """A bounds.csv (with its summary.json: seed 0, the default payload) in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "bounds.csv").write_text("\n".join([header, *rows]) + "\n")
    (folder / "summary.json").write_text(json.dumps({"seed": 0, "payload": 3.0}))
    return str(folder / "bounds.csv")


BOUNDS_HEADER = "scenario,lower_bound_s,best_known_s,replay_ok"


@pytest.mark.parametrize(
    ("header", "rows", "message"),
    [
        (
            BOUNDS_HEADER,
            ["50,10,12,True"],
            "covers none of the run's scenarios 1-2 (it has scenarios 50); "
            "python -m ddwmmr.bounds --scenarios 1-2 makes them",
        ),
        (BOUNDS_HEADER, [], "covers none of the run's scenarios 1-2 (it has no scenario rows)"),
        (
            "scenario,lower,best",
            ["1,10,12"],
            "lacks the columns lower_bound_s, best_known_s, replay_ok (a bounds.csv of ",
        ),
        ("scenario,lower_bound_s,best_known_s", ["1,10,12"], "lacks the column replay_ok ("),
    ],
)
def test_a_bounds_file_that_cannot_serve_the_run_is_refused(
    tmp_path, tmp_path_factory, header, rows, message, capsys
):
    """Audit: a bounds file of other scenarios printed "ratio ... nan"; one with other
    columns "cannot read ... ('replay_ok')" (a raw KeyError)."""
    path = _bounds_file(tmp_path_factory.mktemp("bounds"), header, rows)
    line = bad_scenarios_main(tmp_path, ["--n", "2", "--no-progress", "--bounds", path], capsys)
    assert line.startswith(f"error: bounds: {path} {message}")


@pytest.mark.parametrize(
    ("row", "message"),
    [
        (
            "1,0,12,True",
            "line 2 (scenario 1), column lower_bound_s: must be a time in [1e-06, 1e+09] s, "
            "or nan for none (got 0)",
        ),
        (
            "1,12,10,True",
            "line 2 (scenario 1): best_known_s 10 s is below lower_bound_s 12 s",
        ),
    ],
)
def test_a_bounds_file_with_a_time_no_bracket_has_is_refused(
    tmp_path, tmp_path_factory, row, message, capsys
):
    """A lower bound of 0 was read as none, and the run went on without it."""
    path = _bounds_file(tmp_path_factory.mktemp("bounds"), BOUNDS_HEADER, [row])
    line = bad_scenarios_main(tmp_path, ["--n", "1", "--no-progress", "--bounds", path], capsys)
    assert line.startswith(f"error: bounds: {path} {message}")


def test_the_bounds_ratio_to_the_smallest_time_a_file_may_hold_prints_short(
    tmp_path, tmp_path_factory, capsys
):
    """1e-300 s, refused now, printed a ratio of 300 digits; at the smallest time read
    (1e-6 s) the ratio is the scenario's time in microseconds, in a few digits."""
    path = _bounds_file(tmp_path_factory.mktemp("bounds"), BOUNDS_HEADER, ["1,1e-6,1e-6,True"])
    out = tmp_path / "r"
    assert cli(["--n", "1", "--no-progress", "--out", str(out), "--bounds", path]) == 0
    (line,) = [x for x in capsys.readouterr().out.splitlines() if x.startswith("mean ratio")]
    (row,) = csv.DictReader((out / "scenarios.csv").open())
    ratio = f"{float(row['time_s']) / 1e-6:.3f}"
    assert len(ratio) < 16
    assert line == (
        f"mean ratio to the lower bound {ratio}, to the best-known time {ratio} ({path})"
    )


def test_a_bounds_ratio_without_a_scenario_says_why(tmp_path, tmp_path_factory, capsys):
    """The bounds cover the run's scenario but give it no best-known time (replay failed):
    that ratio is explained, not printed as nan."""
    path = _bounds_file(tmp_path_factory.mktemp("bounds"), BOUNDS_HEADER, ["1,10,12,False"])
    assert cli(["--n", "1", "--no-progress", "--out", str(tmp_path / "r"), "--bounds", path]) == 0
    out = capsys.readouterr().out
    assert "nan" not in out
    why = "to the best-known time none (no successful scenario has a best-known time in the "
    assert why in out
    assert "mean ratio to the lower bound " in out


def test_the_console_counts_why_scenarios_did_not_finish():
    from ddwmmr.cli.scenarios import failure_line

    assert failure_line({"n": 3, "failed": 0, "failures": []}) == ""
    failures = [{"reason": r} for r in ("timeout", "tipped", "timeout", "a", "b")]
    assert failure_line({"n": 9, "failed": 5, "failures": failures}) == (
        "scenarios: 5 of 9 did not finish: 'timeout' x2, 'tipped' x1, 'a' x1 and 1 more "
        "(each in scenarios.csv)"
    )


def test_a_bounds_file_covering_part_of_the_run_says_over_how_many(
    tmp_path, tmp_path_factory, capsys
):
    path = _bounds_file(tmp_path_factory.mktemp("bounds"), BOUNDS_HEADER, ["1,10,12,True"])
    argv = ["--n", "2", "--no-progress", "--out", str(tmp_path / "r"), "--bounds", path]
    assert cli(argv) == 0
    (line,) = [x for x in capsys.readouterr().out.splitlines() if x.startswith("mean ratio")]
    assert line.count("(over 1 of 2)") == 2


@pytest.mark.parametrize(
    ("n", "ran"),
    [("2", "scenario 1"), ("8", "scenarios 1, 3, 7"), ("200", "scenarios 1, 3, 7, 10")],
)
def test_obstacles_says_which_scenarios_run_and_the_table_how_many(tmp_path, capsys, n, ran):
    """--obstacles --n 2 ran thesis scenario 1 alone (of 1, 3, 7, 10, those up to --n),
    and --n 200 four, without a word; the table did not say how many it is over."""
    out = tmp_path / "o"
    args = ["--obstacles", "--n", n, "--time-limit", "0.2", "--jobs", "1", "--no-progress"]
    assert cli([*args, "--out", str(out)]) == 0
    said = capsys.readouterr()
    note = f"note: --obstacles runs the thesis's obstacle scenarios 1, 3, 7, 10 up to --n {n}: "
    assert f"{note}{ran}\n" in said.err
    count = len(ran.split(","))
    row = next(line for line in said.out.splitlines() if line.startswith("No. of scenarios "))
    assert row.split() == ["No.", "of", "scenarios", str(count)]
    assert f"{row}\n" in (out / "table.txt").read_text()
    assert json.loads((out / "summary.json").read_text())["n"] == count
