"""``python -m ddwmmr.compare`` options: --only, and the install split."""

from __future__ import annotations

import csv
import json
import re
import subprocess
from pathlib import Path

import pytest

from ddwmmr.cli.compare import main

ROOT = Path(__file__).resolve().parents[1]
QUICK = ["--methods", "pi", "ats", "--study", "none", "--duration", "0.5", "--jobs", "1"]


def _trajectories(folder: Path) -> set[str]:
    with (folder / "metrics.csv").open() as handle:
        return {row["trajectory"] for row in csv.DictReader(handle)}


def test_only_replaces_the_default_trajectories(tmp_path, capsys):
    out = tmp_path / "only"
    assert main([*QUICK, "--only", "figure8", "--no-progress", "--out", str(out)]) == 0
    assert _trajectories(out) == {"figure8"}
    assert "on figure8:" in capsys.readouterr().out


def test_traj_adds_to_the_defaults_and_progress_lines_off_a_terminal(tmp_path, capsys):
    out = tmp_path / "extra"
    assert main([*QUICK, "--traj", "figure8", "--out", str(out)]) == 0
    assert _trajectories(out) == {"ellipse", "rectangle", "figure8"}
    err = capsys.readouterr().err.splitlines()  # stderr is not a terminal here
    # One line per finished phase: every run of the plan done (both presets, variants).
    assert re.match(r"compare: runs: (\d+)/\1 done in ", err[0]), err[0]
    assert int(err[0].split("/")[1].split()[0]) >= 6  # 2 methods x 3 trajectories at least


def test_make_demo_installs_only_the_runtime_dependencies():
    demo = subprocess.run(["make", "-n", "-B", "demo"], cwd=ROOT, capture_output=True, text=True)
    test = subprocess.run(["make", "-n", "-B", "test"], cwd=ROOT, capture_output=True, text=True)
    assert demo.returncode == 0 and test.returncode == 0
    assert "pip install --quiet -e .\n" in demo.stdout and "[test]" not in demo.stdout
    assert 'pip install --quiet -e ".[test]"' in test.stdout


def test_run_record_holds_the_preset_its_options_and_the_plants():
    """run.json says what ran: the preset, each method's options under it, every plant."""
    from ddwmmr.cli.compare import run_record
    from ddwmmr.reports.compare.plan import CompareConfig
    from ddwmmr.trajectories import Ellipse

    trajectories = {"ellipse": Ellipse()}
    slides = CompareConfig(("ats", "pi"), trajectories, preset="slides", plants=("mujoco",))
    record = run_record(slides, {}, [], jobs=1)
    assert record["preset"] == "slides"
    assert record["options"]["ats"]["aux"] == "sum"  # the slides' row, not the default
    assert record["plants"] == ["kinematic", "mujoco"]
    default = run_record(CompareConfig(("ats",), trajectories), {}, [], jobs=1)
    assert default["preset"] == "default" and default["options"]["ats"]["aux"] == "shoulder"
    assert default["plants"] == ["kinematic"]


def test_a_zero_cost_weight_of_the_mpc_runs(tmp_path, capsys):
    """position_weight=0 (documented >= 0) used to end every mpc run in a LinAlgError from
    the terminal cost's LQR design; the run now completes (without a position cost the
    mpc does not track: it ends further off than its 42 mm start, and compare says so)."""
    out = tmp_path / "zero"
    args = ["--methods", "mpc", "--only", "ellipse", "--study", "none", "--duration", "0.2"]
    argv = [*args, "--jobs", "1", "--option", "mpc:position_weight=0", "--no-progress"]
    assert main([*argv, "--out", str(out)]) == 0, capsys.readouterr().err
    with (out / "metrics.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["method"], r["steps"], r["mpc_fallbacks"]) for r in rows] == [("mpc", "10", "0")]
    assert float(rows[0]["end_position_error_m"]) > float(rows[0]["initial_offset_m"])
    assert "mpc on ellipse" in capsys.readouterr().out  # listed among the untracked


def test_a_requested_study_that_cannot_run_is_named_on_stderr(tmp_path, capsys):
    """Audit: --study corners --only ellipse exited 0 with "studies: none" and no word."""
    out = tmp_path / "report"
    argv = ["--methods", "ats", "--study", "corners", "--only", "ellipse", "--duration", "0.5"]
    assert main([*argv, "--jobs", "1", "--no-progress", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert (
        "note: study corners skipped: it needs the rectangle trajectory, which is not compared "
        "(trajectories: ellipse)\n" in err
    )


def test_an_option_named_like_a_simulate_keyword_reaches_the_controller(
    tmp_path, capsys, monkeypatch
):
    """Audit: --option qp:dt=... (the qp's look-ahead step) ended every run in a TypeError,
    simulate() got the option and its own dt both; the option now reaches the controller,
    as in track: the controller that ran holds it, and the run equals the API's."""
    from ddwmmr import Robot, simulate
    from ddwmmr.controllers.base import make_controller
    from ddwmmr.reports.compare import plan
    from ddwmmr.trajectories import Ellipse

    built = []

    def recording(name, robot=None, **options):
        built.append(make_controller(name, robot, **options))
        return built[-1]

    monkeypatch.setattr(plan, "make_controller", recording)  # --jobs 1: in this process
    out = tmp_path / "qp"
    args = ["--methods", "qp", "--only", "ellipse", "--study", "none", "--duration", "0.2"]
    argv = [*args, "--jobs", "1", "--option", "qp:dt=0.05", "--no-progress"]
    assert main([*argv, "--out", str(out)]) == 0, capsys.readouterr().err
    with (out / "metrics.csv").open() as handle:
        (row,) = list(csv.DictReader(handle))
    record = json.loads((out / "run.json").read_text())
    assert record["options"]["qp"]["dt"] == 0.05
    assert built[-1]._dt_option == 0.05  # the run's controller, built last (run_one)
    robot = Robot()
    expected = simulate(robot, Ellipse(), make_controller("qp", robot, dt=0.05), duration=0.2)
    error = float(row["end_position_error_m"])
    assert error == pytest.approx(expected.summary["end_position_error_m"], rel=1e-6, abs=1e-12)


def test_default_out_is_a_new_timestamped_folder_each_run(tmp_path, monkeypatch, capsys):
    """Without --out, compare wrote to runs/compare and a second run replaced the first
    report; each run now gets its own runs/compare-<time>/ (as track and scenarios)."""
    monkeypatch.chdir(tmp_path)
    quick = ["--only", "ellipse", "--study", "none", "--duration", "0.2", "--jobs", "1"]
    for method in ("ats", "pi"):
        assert main(["--methods", method, *quick, "--no-progress"]) == 0
    first, second = sorted((tmp_path / "runs").iterdir())  # same second: second is first-2
    assert re.fullmatch(r"compare-\d{8}-\d{6}", first.name), first.name
    assert re.fullmatch(rf"compare-\d{{8}}-\d{{6}}|{first.name}-2", second.name), second.name
    with (first / "metrics.csv").open() as a, (second / "metrics.csv").open() as b:
        assert [r["method"] for r in csv.DictReader(a)] == ["ats"]
        assert [r["method"] for r in csv.DictReader(b)] == ["pi"]
    assert f"Report: runs/{second.name}/report.html" in capsys.readouterr().out
