"""Records that hold up outside the checkout: bench.json names the code it measured as run
records do, a shipped CSV trajectory reruns from another install path, and the docs say
what a record's ``command`` is."""

import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ddwmmr
from ddwmmr import provenance
from ddwmmr.bench.report import format_comparison, format_source, read_report
from ddwmmr.cli.track import main as track
from ddwmmr.errors import ParameterError
from ddwmmr.trajectories import load_trajectory
from ddwmmr.trajectories.files import file_sha256, package_folder

ROOT = Path(__file__).resolve().parents[1]
GONE = "/nowhere/venv/lib/python3.11/site-packages/ddwmmr/trajectories/data/figure8.csv"


# -- bench.json: the code measured -----------------------------------------------------------
@pytest.mark.skipif(shutil.which("git") is None, reason="needs git")
def test_an_installed_bench_inside_a_users_repository_records_no_commit(tmp_path):
    """The package copied into site-packages of a venv inside the user's own git project:
    the report's config has the package version and no commit (not the user's)."""
    project = tmp_path / "project"
    site = project / "venv" / "lib" / "python3.11" / "site-packages"
    shutil.copytree(
        ROOT / "src" / "ddwmmr", site / "ddwmmr", ignore=shutil.ignore_patterns("__pycache__")
    )
    git = ["git", "-C", str(project), "-c", "user.email=u@x", "-c", "user.name=u"]
    subprocess.run([*git, "init", "-q"], check=True)
    subprocess.run([*git, "commit", "-q", "--allow-empty", "-m", "user"], check=True)
    user_commit = subprocess.run(
        [*git, "rev-parse", "HEAD"], capture_output=True, text=True, check=True
    ).stdout.strip()
    code = (
        "import json, ddwmmr.bench.run as r; from ddwmmr.trajectories import Ellipse; "
        "print(json.dumps([r.__file__, r._config(1, 1, Ellipse(), 1.0, 0.0)]))"
    )
    env = {**os.environ, "PYTHONPATH": str(site)}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    where, config = json.loads(done.stdout)
    assert where.startswith(str(site))  # the copy ran, not the checkout
    assert user_commit[:7] not in done.stdout
    assert "git_commit" not in config
    assert config["git"] is None and config["git_note"] == provenance.NOT_A_CHECKOUT
    assert config["package_version"] == ddwmmr.__version__
    assert format_source(config) == f"ddwmmr {ddwmmr.__version__}, no commit"


def test_the_checkouts_bench_config_is_the_run_records_git_record():
    from ddwmmr.bench.run import _config
    from ddwmmr.trajectories import Ellipse

    config = _config(1, 1, Ellipse(), 1.0, 0.0)
    assert config["package_version"] == ddwmmr.__version__
    assert config["git"] == provenance.git_record()["git"]


def test_the_source_line_of_each_report_layout():
    assert format_source({"git_commit": "b697be4"}) == "commit b697be4"
    assert format_source({}) == "commit ?"
    new = {"package_version": "0.1.0", "git": {"commit": "0123456789abcdef" * 2, "dirty": True}}
    assert format_source(new) == "ddwmmr 0.1.0, commit 0123456789ab, dirty"
    new["git"]["dirty"] = False
    assert format_source(new) == "ddwmmr 0.1.0, commit 0123456789ab"


def test_a_layout_2_report_is_still_compared():
    """A bench.json of layout 2 (``git_commit``, no ``git``), the report the docs quoted
    until 2026-12-07, kept as it was written."""
    previous = read_report(ROOT / "tests" / "golden" / "bench_layout2.json")
    text = format_comparison({"rows": [{"label": "pi", "step_us": 1.42}]}, previous)
    first, pi = text.splitlines()[:2]
    assert first == "against 2026-12-01T11:19:05+00:00 (commit b697be4): median step new / old"
    assert pi.split() == ["pi", "2.84", "->", "1.42", "us", "(0.50x)"]


# -- a shipped trajectory from another install path -----------------------------------------
def _figure8_record() -> dict:
    shipped = package_folder() / "figure8.csv"
    record = provenance.trajectory_record(load_trajectory("figure8"), shipped)
    return {**record, "file": GONE}


def test_a_gone_shipped_file_is_read_from_the_package_with_a_note():
    trajectory, file, note = provenance.read_trajectory_record(_figure8_record())
    shipped = package_folder() / "figure8.csv"
    assert file == shipped
    assert note == (
        f"the trajectory file {GONE} is gone; read the one this package ships, {shipped}, "
        "which has the recorded SHA-256"
    )
    original = load_trajectory("figure8")
    for t in (0.0, 0.37, 5.0, 11.9):
        np.testing.assert_allclose(trajectory.pose(t), original.pose(t), rtol=0, atol=0)
    with pytest.warns(UserWarning, match="read the one this package ships"):
        provenance.trajectory_from_record(_figure8_record())


def test_a_gone_file_of_another_sha256_or_name_stays_refused():
    record = {**_figure8_record(), "sha256": "0" * 64}
    with pytest.raises(ParameterError, match=r"is gone \(the package's own figure8.csv has"):
        provenance.read_trajectory_record(record)
    for name, file in (("mine", "/nowhere/mine.csv"), ("../data/figure8", "/x/../y.csv")):
        record = {**_figure8_record(), "name": name, "file": file}
        with pytest.raises(ParameterError, match=r"is gone$"):
            provenance.read_trajectory_record(record)


def _columns_but_step_us(path: Path) -> list[list[str]]:
    with path.open(newline="") as handle:
        rows = list(csv.reader(handle))
    keep = [i for i, name in enumerate(rows[0]) if name != "step_us"]
    return [[row[i] for i in keep] for row in rows]


def test_track_reruns_a_figure8_record_written_at_another_install_path(tmp_path, capsys):
    first, second = tmp_path / "a", tmp_path / "b"
    args = ["--method", "clrrmc-ts", "--traj", "figure8", "--duration", "0.4", "--no-plots"]
    assert track([*args, "--no-progress", "--out", str(first)]) == 0
    summary = json.loads((first / "summary.json").read_text())
    summary["run"]["trajectory"]["file"] = GONE  # as another venv recorded it
    moved = tmp_path / "moved.json"
    moved.write_text(json.dumps(summary))
    capsys.readouterr()
    assert track(["--rerun", str(moved), "--no-plots", "--no-progress", "--out", str(second)]) == 0
    err = capsys.readouterr().err
    # one line in the form of the package's warnings and errors (no tool prefix)
    note = f"note: the trajectory file {GONE} is gone; read the one"
    assert any(line.startswith(note) for line in err.splitlines()), err
    assert _columns_but_step_us(second / "timeseries.csv") == _columns_but_step_us(
        first / "timeseries.csv"
    )
    again = json.loads((second / "summary.json").read_text())["run"]["trajectory"]
    shipped = package_folder() / "figure8.csv"
    assert again["file"] == str(shipped.resolve()) and again["sha256"] == file_sha256(shipped)


# -- the command field -----------------------------------------------------------------------
def test_the_docs_say_what_the_recorded_command_is(tmp_path):
    out = tmp_path / "r"
    argv = [
        "--method",
        "pi",
        "--traj",
        "ellipse",
        "--duration",
        "0.1",
        "--no-plots",
        "--no-progress",
    ]
    assert track([*argv, "--out", str(out)]) == 0
    record = json.loads((out / "summary.json").read_text())["run"]
    assert record["command"].startswith("python -m ddwmmr.track --method pi ")
    assert record["argv"] == [*argv, "--out", str(out)]
    text = " ".join((ROOT / "docs" / "cli.md").read_text().split())
    assert "the exact command line (`command`" not in text
    assert (
        "a command that repeats the run (`command`: `python -m ddwmmr.track` and the "
        "arguments, also when the run was started as `ddwmmr-track`)" in text
    )
