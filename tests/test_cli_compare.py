"""``python -m ddwmmr.compare`` options of issue 8: --only, and the install split."""

from __future__ import annotations

import csv
import re
import subprocess
from pathlib import Path

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
