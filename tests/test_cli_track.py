"""``python -m ddwmmr.track``: outputs, summary keys, bad input (exit 2, nothing left)."""

import json
import subprocess
import sys

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.cli.track import main as run
from expected import REQUIRED_SUMMARY_KEYS


def test_track_writes_csv_summary_and_figures(tmp_path, capsys):
    out = tmp_path / "run"
    status = run(["--method", "ats", "--traj", "ellipse", "--duration", "2", "--out", str(out)])
    assert status == 0
    names = {p.name for p in out.iterdir()}
    assert {"timeseries.csv", "summary.json", "path.png", "errors.png", "rates.png"} <= names
    assert "metrics.png" in names
    summary = json.loads((out / "summary.json").read_text())
    for key in REQUIRED_SUMMARY_KEYS:
        assert key in summary
    assert summary["steps"] == 100
    # The CSV holds the same run: its last position error is the summary's final one.
    data = np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True)
    assert data["position_error_m"][-1] == pytest.approx(summary["final_position_error_m"])
    printed = capsys.readouterr().out
    assert "RMS position error" in printed and str(out) in printed


def test_summary_equals_the_api_result(tmp_path):
    out = tmp_path / "run"
    run(
        [
            "--method",
            "clrrmc-cs",
            "--traj",
            "rectangle",
            "--duration",
            "3",
            "--tau",
            "0.3",
            "--out",
            str(out),
            "--no-plots",
        ]
    )
    summary = json.loads((out / "summary.json").read_text())
    api = simulate(Robot(), load_trajectory("rectangle"), "clrrmc-cs", duration=3.0, tau=0.3)
    for key, value in api.summary.items():
        if key != "median_step_us":
            assert summary[key] == pytest.approx(value), key


def test_payload_robot_file_and_animation(tmp_path):
    robot_file = tmp_path / "robot.toml"
    robot_file.write_text("L1 = 0.4\n")
    out = tmp_path / "run"
    status = run(
        [
            "--method",
            "clrrmc-ts",
            "--traj",
            "ellipse",
            "--duration",
            "1",
            "--robot",
            str(robot_file),
            "--payload",
            "3",
            "--animate",
            "--no-plots",
            "--out",
            str(out),
        ]
    )
    assert status == 0
    assert (out / "animation.gif").read_bytes()[:6] == b"GIF89a"
    summary = json.loads((out / "summary.json").read_text())
    expected = Robot(L1=0.4, payload=3.0)
    q0 = simulate(
        expected, load_trajectory("ellipse"), "clrrmc-ts", duration=0.02
    ).configurations()[0]
    assert summary["min_stability"] <= expected.stability(q0)[2] + 1e-12


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--method", "nope", "--traj", "ellipse"], "invalid choice: 'nope'"),
        (["--method", "ats", "--traj", "nowhere"], "unknown trajectory 'nowhere'"),
        (["--method", "ats", "--traj", "ellipse", "--dt", "0"], "dt must be > 0"),
        (["--method", "ats", "--traj", "ellipse", "--dt", "-0.1"], "dt must be > 0"),
        (["--method", "ats", "--traj", "ellipse", "--payload", "-1"], "payload must be >= 0"),
        (["--method", "ats", "--traj", "ellipse", "--payload", "nan"], "payload must be a finite"),
        (["--method", "clrrmc-ts", "--traj", "ellipse", "--tau", "-2"], "tau must be > 0"),
        (["--method", "pi", "--traj", "ellipse", "--aux", "sum"], "unknown option 'aux'"),
        (["--method", "ats", "--traj", "missing.toml"], "no such file"),
        (["--method", "ats", "--traj", "ellipse", "--robot", "missing.toml"], "cannot read"),
    ],
)
def test_bad_input_exits_2_with_one_line_and_no_output(tmp_path, args, message):
    out = tmp_path / "run"
    process = subprocess.run(
        [sys.executable, "-m", "ddwmmr.track", *args, "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert process.returncode == 2
    assert message in process.stderr
    assert "Traceback" not in process.stderr
    assert len(process.stderr.strip().splitlines()) == 1
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == []  # no staging folder left either


def test_refuses_to_overwrite_a_foreign_folder(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    assert run(["--method", "ats", "--traj", "ellipse", "--duration", "1", "--out", str(out)]) == 2
    assert (out / "notes.txt").read_text() == "keep me"


def test_help_explains_methods():
    process = subprocess.run(
        [sys.executable, "-m", "ddwmmr.track", "--help"], capture_output=True, text=True
    )
    assert process.returncode == 0
    for word in ("--method", "--traj", "--tau", "clrrmc-ts", "pseudoinverse", "--animate"):
        assert word in process.stdout
