"""``python -m ddwmmr.track``: outputs, summary keys, bad input (exit 2, nothing left)."""

import csv
import dataclasses
import hashlib
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ddwmmr
from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.cli.track import main as run
from ddwmmr.resolution.reference import DEFAULT_INITIAL_OFFSET
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
        (
            ["--method", "ats", "--traj", "ellipse", "--payload", "-1"],
            "payload must be in [0, 100000] kg (got -1)",
        ),
        (["--method", "ats", "--traj", "ellipse", "--payload", "nan"], "payload must be a finite"),
        (["--method", "clrrmc-ts", "--traj", "ellipse", "--tau", "-2"], "tau must be > 0"),
        (
            ["--method", "pi", "--traj", "ellipse", "--aux", "sum"],
            "error: aux: --aux is taken only by --method ats, clrrmc-ts or clrrmc-cs "
            "(got --method pi)\n",
        ),
        (["--method", "ats", "--traj", "missing.toml"], "no such file"),
        ([], "error: method: --method and --traj are required, e.g. --method ats --traj ellipse"),
        (["--method", "pi"], "error: traj: --traj is required, e.g. --method ats --traj ellipse"),
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


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["--method", "mpc", "--qp-mode", "weighted"],
            "qp-mode: --qp-mode is taken only by --method qp (got --method mpc)",
        ),
        (
            ["--method", "pi", "--stability-min", "1.5"],
            "stability-min: --stability-min is taken only by --method qp or mpc (got --method pi)",
        ),
        (
            ["--method", "ats", "--obstacles", "ellipse_post"],
            "obstacles: --obstacles is taken only by --method qp or mpc (got --method ats)",
        ),
        (
            ["--method", "pi", "--tau", "0.3"],
            "tau: --tau is taken only by --method clrrmc-ts, clrrmc-cs or qp (got --method pi)",
        ),
    ],
)
def test_an_option_the_method_does_not_take_names_the_flag(tmp_path, capsys, args, message):
    out = tmp_path / "run"
    assert run([*args, "--traj", "ellipse", "--duration", "0.1", "--out", str(out)]) == 2
    assert capsys.readouterr().err == f"error: {message}\n"
    assert not out.exists()


def test_a_duration_shorter_than_the_default_step_names_it(tmp_path, capsys):
    args = ["--method", "pi", "--traj", "ellipse", "--duration", "0.01"]
    assert run([*args, "--out", str(tmp_path / "run")]) == 2
    assert capsys.readouterr().err == (
        "error: duration must be >= one step, 0.02 s (the trajectory's T/N; or give a "
        "smaller --dt) (got 0.01)\n"
    )
    assert list(tmp_path.iterdir()) == []


def test_help_states_the_controller_option_defaults(capsys):
    with pytest.raises(SystemExit):
        run(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    for words in (
        "hard floor on the tip-over stability margin S (S <= 1 tips over), in (0, 10) "
        "(default 1.25) [qp, mpc]",
        "weight of the manipulability reward (default 0.5) [qp, mpc]",
        "drawn in path.png (default none) [qp, mpc]",
        "(default daqp for qp, rti for mpc) [qp, mpc]",
        "priority handling (default weighted) [qp]",
        # not "(default None)": the mpc's horizons (GRID_DEFAULTS), as docs/cli.md says
        "prediction horizon in s (docs/mpc.md, Options) (default 1 s for tracking, 5 s for "
        "waypoints) [mpc]",
    ):
        assert words in text, words


def test_the_horizon_help_states_is_the_one_a_run_takes(tmp_path):
    """--help's and docs/cli.md's 1 s is the horizon a track run without --horizon
    plans with (the table said 2.0, --help "None")."""
    out = tmp_path / "run"
    args = ["--method", "mpc", "--traj", "ellipse", "--duration", "0.1", "--no-plots"]
    assert run([*args, "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["mpc_horizon_s"] == 1.0 and summary["mpc_options"]["horizon"] == 1.0
    table = (Path(__file__).resolve().parents[1] / "docs" / "cli.md").read_text()
    row = next(line for line in table.splitlines() if line.startswith("| `--horizon S` |"))
    assert row.rsplit("|", 2)[1].strip().startswith("1 s (the tracking default")


@pytest.mark.parametrize("option", ["position_weight=0", "orientation_weight=0"])
def test_a_zero_cost_weight_runs(tmp_path, capsys, option):
    """Documented >= 0; a zero weight used to end in a LinAlgError traceback from the
    terminal cost's LQR design (control.dlqr)."""
    out = tmp_path / "run"
    args = ["--method", "mpc", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    assert run([*args, "--option", option, "--out", str(out)]) == 0, capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    name = option.split("=")[0]
    assert summary["mpc_options"][name] == 0.0
    assert summary["steps"] == 10 and summary["mpc_fallbacks"] == 0


def test_help_explains_methods():
    process = subprocess.run(
        [sys.executable, "-m", "ddwmmr.track", "--help"], capture_output=True, text=True
    )
    assert process.returncode == 0
    for word in ("--method", "--traj", "--tau", "clrrmc-ts", "pseudoinverse", "--animate"):
        assert word in process.stdout


# -- reproducibility: summary.json records the run, --rerun repeats it ----------------------
def _rows_without_timing(path):
    """timeseries.csv with the wall-clock column (step_us) removed, as text rows."""
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    keep = [i for i, name in enumerate(header) if not name.endswith("_us")]
    assert len(keep) == len(header) - 1  # exactly one timing column
    return [[row.split(",")[i] for i in keep] for row in lines]


@pytest.mark.parametrize(
    "args",
    [
        ["--method", "clrrmc-ts", "--traj", "rectangle", "--tau", "0.3", "0.3", "inf",
         "--duration", "3", "--integrator", "euler", "--offset", "-0.04", "0.02"],
        ["--method", "ap", "--traj", "figure8", "--duration", "2", "--dt", "0.03",
         "--payload", "2.5"],
        ["--method", "qp", "--traj", "ellipse", "--obstacles", "ellipse_post",
         "--stability-min", "1.3", "--duration", "1"],
    ],
    ids=["clrrmc-ts-inf-tau", "ap-csv", "qp-obstacles"],
)  # fmt: skip
def test_rerun_reproduces_the_run_bit_for_bit(tmp_path, args, capsys):
    robot_file = tmp_path / "robot.toml"
    robot_file.write_text("L2 = 0.32\nlink_masses = [1.2, 0.8]\n")
    first, second = tmp_path / "first", tmp_path / "second"
    assert run([*args, "--robot", str(robot_file), "--no-plots", "--out", str(first)]) == 0
    robot_file.unlink()  # the record must not need the robot file any more
    assert run(["--rerun", str(first / "summary.json"), "--no-plots", "--out", str(second)]) == 0
    assert _rows_without_timing(first / "timeseries.csv") == _rows_without_timing(
        second / "timeseries.csv"
    )
    one, two = (json.loads((f / "summary.json").read_text()) for f in (first, second))
    record, again = one.pop("run"), two.pop("run")
    for key in one:
        if not key.endswith("_us"):
            assert one[key] == two[key], key
    for key in ("method", "options", "robot", "trajectory", "dt", "duration", "integrator"):
        assert record[key] == again[key], key
    assert again["rerun_of"] == str((first / "summary.json").resolve())


def test_run_record_holds_everything_to_rerun(tmp_path):
    out = tmp_path / "run"
    argv = ["--method", "ats", "--traj", "figure8", "--duration", "1", "--no-plots"]
    assert run([*argv, "--out", str(out)]) == 0
    record = json.loads((out / "summary.json").read_text())["run"]
    assert record["tool"] == "track" and record["version"] == ddwmmr.__version__
    assert record["argv"] == [*argv, "--out", str(out)]
    assert record["command"].startswith("python -m ddwmmr.track --method ats")
    # Every option with its default filled in; the robot with all its fields.
    # the damping options None: derived from the robot (0.05 each on this one)
    assert record["options"] == {"aux": "shoulder", "singularity_threshold": None, "damping": None}
    assert set(record["robot"]) == {f.name for f in dataclasses.fields(Robot) if f.init}
    assert record["robot"]["payload"] == 1.25
    # A sampled trajectory: its file and hash (computed here independently).
    trajectory = record["trajectory"]
    assert trajectory["type"] == "samples" and trajectory["name"] == "figure8"
    data = Path(trajectory["file"]).read_bytes()
    assert trajectory["sha256"] == hashlib.sha256(data).hexdigest()
    # the rows are 0.25 s apart: the default step is no coarser than 0.02 s
    assert record["dt"] == 60.0 / 3000 and record["duration"] == 1.0
    assert record["integrator"] == "rk4" and record["initial_offset"] == list(
        DEFAULT_INITIAL_OFFSET
    )
    assert record["plant"] == {"name": "kinematic"} and record["seed"] is None
    git = record["git"]
    assert git is None or len(git["commit"]) == 40


def test_rerun_refuses_a_changed_trajectory_file_and_extra_options(tmp_path, capsys):
    traj = tmp_path / "line.csv"
    traj.write_text("t,x,y\n0,0,0\n1,0.1,0\n2,0.2,0\n3,0.3,0\n")
    out = tmp_path / "run"
    args = ["--method", "pi", "--traj", str(traj), "--offset", "0", "0", "--no-plots"]
    assert run([*args, "--out", str(out)]) == 0
    summary = str(out / "summary.json")
    assert run(["--rerun", summary, "--dt", "0.1", "--out", str(tmp_path / "b")]) == 2
    assert "--dt cannot be combined with --rerun" in capsys.readouterr().err
    traj.write_text("t,x,y\n0,0,0\n1,0.2,0\n2,0.4,0\n3,0.6,0\n")
    assert run(["--rerun", summary, "--out", str(tmp_path / "c")]) == 2
    assert "changed since the run" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["line.csv", "run"]


@pytest.mark.parametrize("after", ["deleted", "edited", "a folder"])
def test_rerun_of_a_toml_trajectory_needs_only_the_record(tmp_path, after):
    traj = tmp_path / "mine.toml"
    traj.write_text('shape = "ellipse"\na = 1.0\nb = 0.6\n')
    first, second = tmp_path / "first", tmp_path / "second"
    args = ["--method", "ats", "--traj", str(traj), "--duration", "0.4", "--no-plots"]
    assert run([*args, "--out", str(first)]) == 0
    traj.unlink()
    if after == "edited":
        traj.write_text('shape = "ellipse"\na = 2.0\nb = 0.6\n')
    elif after == "a folder":
        traj.mkdir()
    assert run(["--rerun", str(first / "summary.json"), "--out", str(second)]) == 0
    assert _rows_without_timing(first / "timeseries.csv") == _rows_without_timing(
        second / "timeseries.csv"
    )
    one, two = (json.loads((f / "summary.json").read_text())["run"] for f in (first, second))
    # the file as the first run read it: the new record does not hash what is there now
    assert two["trajectory"] == one["trajectory"]
    assert len(one["trajectory"]["sha256"]) == 64 and one["trajectory"]["type"] == "ellipse"


def test_rerun_of_a_toml_trajectory_record_without_its_digest_is_refused(tmp_path, capsys):
    traj = tmp_path / "mine.toml"
    traj.write_text('shape = "ellipse"\na = 1.0\nb = 0.6\n')
    first = tmp_path / "first"
    args = ["--method", "ats", "--traj", str(traj), "--duration", "0.2", "--no-plots"]
    assert run([*args, "--out", str(first)]) == 0
    summary = json.loads((first / "summary.json").read_text())
    damaged = tmp_path / "damaged.json"
    for digest in (None, "z" * 64, "A" * 64):  # missing, not hex, not as hashlib spells it
        trajectory = summary["run"]["trajectory"]
        trajectory.pop("sha256", None)
        if digest is not None:
            trajectory["sha256"] = digest
        damaged.write_text(json.dumps(summary))
        capsys.readouterr()
        assert run(["--rerun", str(damaged), "--out", str(tmp_path / "b")]) == 2
        err = capsys.readouterr().err.strip()
        if digest is None:
            expected = "is not a complete run record (field run.trajectory.sha256 is missing)"
            assert err == f"error: rerun: {damaged} {expected}"
        else:
            assert err.startswith(
                f"error: rerun: {damaged}: trajectory.sha256 must be a string of 64 hex digits "
                f"(0-9, a-f) (got '{digest[:8]}"
            )
            assert "\n" not in err


@pytest.fixture(scope="module")
def recorded_run(tmp_path_factory) -> dict:
    """A valid track summary.json (tests change one field of a copy)."""
    out = tmp_path_factory.mktemp("recorded") / "run"
    args = ["--method", "pi", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    assert run([*args, "--no-progress", "--out", str(out)]) == 0
    return json.loads((out / "summary.json").read_text())


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("dt", "abc", "dt must be a finite number > 0 (got 'abc')"),
        ("dt", True, "dt must be a finite number > 0 (got True)"),
        ("duration", "1s", "duration must be a finite number > 0 (got '1s')"),
        ("method", ["pi"], "method name must be a str"),
        ("options", [1], "options must be a dict"),
        ("options", "x", "options must be a dict"),
        ("integrator", None, "integrator name must be a str"),
        ("robot", {}, "summary.json: the robot record lacks L1"),
        ("plant", {"name": "foo"}, "summary.json: plant 'foo' is not supported by this"),
        ("record_version", 99, "summary.json holds a run record of version 99; this version"),
        ("record_version", "1", "summary.json holds a run record of version '1'; this"),
        ("initial_offset", 3, "offset must be a list"),
    ],
)
def test_rerun_of_a_damaged_record_is_one_line(
    recorded_run, tmp_path, capsys, field, value, message
):
    damaged = json.loads(json.dumps(recorded_run))
    damaged["run"][field] = value
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(damaged))
    assert run(["--rerun", str(path), "--no-progress", "--out", str(tmp_path / "o")]) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and message in error[0], error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


@pytest.mark.parametrize(
    ("parameters", "message"),
    [
        ("x", "trajectory.parameters must be a table of the ellipse's parameters (x0, y0, "),
        ([1, 2], "trajectory.parameters must be a table of the ellipse's parameters (x0, y0, "),
        ({"zz": 1}, "trajectory.parameters: unknown key 'zz' (known: x0, y0, a, b, "),
    ],
)
def test_rerun_of_bad_trajectory_parameters_names_them(
    recorded_run, tmp_path, capsys, parameters, message
):
    """They were the class's TypeError ("Ellipse() argument after ** must be a mapping",
    "got an unexpected keyword argument 'zz'") in the line."""
    damaged = json.loads(json.dumps(recorded_run))
    trajectory = damaged["run"]["trajectory"]
    if isinstance(parameters, dict):
        trajectory["parameters"].update(parameters)
    else:
        trajectory["parameters"] = parameters
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(damaged))
    assert run(["--rerun", str(path), "--no-progress", "--out", str(tmp_path / "o")]) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and error[0].startswith(f"error: rerun: {path}: {message}"), error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("method", "nope", "method: unknown method 'nope' (tracking: pi, ats, ap, "),
        ("options", {"aux": "sum"}, "method pi: unknown option 'aux' (accepted: "),
    ],
)
def test_rerun_of_a_record_with_a_bad_method_or_option_names_the_file(
    recorded_run, tmp_path, capsys, field, value, message
):
    """The recorded method and options were checked only when the controller was built,
    outside the record's check: the refusal did not say it came from the file."""
    damaged = json.loads(json.dumps(recorded_run))
    damaged["run"][field] = value
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(damaged))
    out = tmp_path / "o"
    assert run(["--rerun", str(path), "--no-progress", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: rerun: {path}: {message}") and err.count("\n") == 1
    assert not out.exists()


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (-0.01, "dt must be > 0 (got -0.01)"),
        (0, "dt must be > 0 (got 0)"),
        (math.nan, "dt must be a finite number > 0 (got nan)"),
        (math.inf, "dt must be a finite number > 0 (got inf)"),
        ("abc", "dt must be a finite number > 0 (got 'abc')"),
        ("0.02", "dt must be a finite number > 0 (got '0.02')"),
        (True, "dt must be a finite number > 0 (got True)"),
        (None, "dt must be a finite number > 0 (got None)"),
    ],
)
def test_rerun_of_a_record_with_a_bad_dt_names_its_range(
    recorded_run, tmp_path, capsys, value, message
):
    """Audit: a summary.json whose dt was nan said "dt must be a finite number (got nan)",
    one whose dt was text "lacks a complete run record (dt must be a number in s, got
    'abc')": neither named the range. The recorded dt now passes the check --dt passes."""
    damaged = json.loads(json.dumps(recorded_run))
    damaged["run"]["dt"] = value
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(damaged))  # nan and inf as JSON's NaN and Infinity
    out = tmp_path / "o"
    assert run(["--rerun", str(path), "--no-progress", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == f"error: rerun: {path}: {message}\n" and not out.exists()
    if isinstance(value, float | int) and not isinstance(value, bool):  # --dt takes it
        argv = ["--method", "pi", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
        assert run([*argv, f"--dt={value!r}", "--out", str(out)]) == 2
        assert capsys.readouterr().err == f"error: {message}\n"  # the same words


def test_rerun_of_a_record_with_an_integer_duration_records_a_float(recorded_run, tmp_path):
    """JSON's 1 for a duration reruns, and the rerun's record says 1.0 as a fresh run does
    (the checked float, not the file's integer)."""
    record = json.loads(json.dumps(recorded_run))
    record["run"]["duration"] = 1
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(record))
    out = tmp_path / "o"
    assert run(["--rerun", str(path), "--no-progress", "--no-plots", "--out", str(out)]) == 0
    rerun = json.loads((out / "summary.json").read_text())["run"]
    assert rerun["duration"] == 1.0 and isinstance(rerun["duration"], float)
    assert isinstance(rerun["dt"], float)


def test_rerun_of_a_record_with_a_bad_dt_as_a_module_is_one_line(recorded_run, tmp_path):
    damaged = json.loads(json.dumps(recorded_run))
    damaged["run"]["dt"] = "abc"
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(damaged))
    out = tmp_path / "o"
    done = subprocess.run(
        [sys.executable, "-m", "ddwmmr.track", "--rerun", str(path), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2 and "Traceback" not in done.stderr and not out.exists()
    assert done.stderr == f"error: rerun: {path}: dt must be a finite number > 0 (got 'abc')\n"


#: Fields of a run record (``section.field`` inside a section) a --rerun cannot do without.
NEEDED_FIELDS = ("trajectory", "method", "dt", "plant", "initial_offset")
NEEDED_FIELDS += ("trajectory.parameters", "plant.name")


@pytest.mark.parametrize("field", NEEDED_FIELDS)
def test_rerun_of_a_record_missing_a_field_names_it(recorded_run, tmp_path, capsys, field):
    damaged = json.loads(json.dumps(recorded_run))
    section, _, key = field.rpartition(".")
    del (damaged["run"][section] if section else damaged["run"])[key]
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(damaged))
    assert run(["--rerun", str(path), "--no-progress", "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err == (
        f"error: rerun: {path} is not a complete run record (field run.{field} is missing)\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


def test_rerun_of_a_deeply_nested_file_is_one_line(tmp_path, capsys):
    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    assert run(["--rerun", str(path), "--out", str(tmp_path / "o")]) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and "nested too deeply" in error[0], error


def test_errors_are_printed_in_mm(tmp_path, capsys):
    out = tmp_path / "run"
    assert run(["--method", "pi", "--traj", "ellipse", "--duration", "1", "--no-plots",
                "--out", str(out)]) == 0  # fmt: skip
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    line = next(x for x in printed.splitlines() if "RMS position error (mm)" in x)
    assert float(line.split()[-1]) == pytest.approx(
        1000 * summary["rms_position_error_m"], rel=1e-5
    )
    assert "(m)" not in printed


def test_package_main_lists_the_tools():
    done = subprocess.run([sys.executable, "-m", "ddwmmr"], capture_output=True, text=True)
    assert done.returncode == 0
    lines = done.stdout.splitlines()
    for tool in ("track", "compare", "scenarios", "bench"):
        assert sum(f"python -m ddwmmr.{tool} " in line for line in lines) == 1
        assert any(f"ddwmmr-{tool}" in line for line in lines)
    done = subprocess.run([sys.executable, "-m", "ddwmmr", "nope"], capture_output=True, text=True)
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1


def test_progress_off_a_terminal_is_one_line_per_phase(tmp_path, capsys):
    out = tmp_path / "run"
    assert run(["--method", "pi", "--traj", "ellipse", "--duration", "2", "--out", str(out)]) == 0
    err = capsys.readouterr().err.splitlines()  # captured: not a terminal
    assert err[0].startswith("track: steps: 100/100 done in ")
    assert all(line.startswith("track: ") for line in err)
    assert run(["--method", "pi", "--traj", "ellipse", "--duration", "2", "--no-progress",
                "--out", str(out)]) == 0  # fmt: skip
    assert capsys.readouterr().err == ""


def test_plant_option_runs_the_physics_plant_and_reruns_it(tmp_path, capsys):
    """--plant mujoco: the physics keys reach summary.json and the table; the record names
    the plant, so --rerun repeats the (deterministic) physics run bit for bit."""
    first, second = tmp_path / "first", tmp_path / "second"
    args = ["--method", "clrrmc-ts", "--traj", "ellipse", "--duration", "2", "--no-plots"]
    assert run([*args, "--plant", "mujoco", "--out", str(first)]) == 0
    printed = capsys.readouterr().out
    assert "(mujoco plant)" in printed and "tipped over (physics)" in printed
    summary = json.loads((first / "summary.json").read_text())
    assert summary["plant"] == "mujoco" and summary["tipped"] is False
    assert summary["integrator"] is None and summary["run"]["plant"] == {"name": "mujoco"}
    assert run(["--rerun", str(first / "summary.json"), "--no-plots", "--out", str(second)]) == 0
    assert _rows_without_timing(first / "timeseries.csv") == _rows_without_timing(
        second / "timeseries.csv"
    )


def test_integrator_needs_the_kinematic_plant(tmp_path, capsys):
    out = tmp_path / "x"
    args = ["--method", "ats", "--traj", "ellipse", "--plant", "thesis", "--integrator", "euler"]
    assert run([*args, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "only the kinematic plant" in err[0]
    assert not out.exists()


def test_default_step_on_the_physics_plant_is_a_whole_engine_multiple(tmp_path):
    # The README's command runs at a whole multiple of MuJoCo's 0.002 s step, as simulate()
    # rounds it (sideways_reach's rows are 0.02 s apart).
    out = tmp_path / "run"
    args = ["--method", "qp", "--traj", "sideways_reach", "--payload", "3", "--plant", "mujoco"]
    assert run([*args, "--duration", "0.2", "--no-plots", "--no-progress", "--out", str(out)]) == 0
    record = json.loads((out / "summary.json").read_text())
    assert record["dt"] == pytest.approx(0.02, abs=1e-15)
    assert record["run"]["dt"] == record["dt"]


def test_track_says_when_the_steps_do_not_fill_the_duration(tmp_path, capsys):
    argv = ["--method", "pi", "--traj", "ellipse", "--no-plots", "--no-progress"]
    assert run([*argv, "--dt", "0.3", "--duration", "1", "--out", str(tmp_path / "a")]) == 0
    err = capsys.readouterr().err
    note = "note: duration 1 s is not a whole number of steps of dt 0.3 s"
    assert any(line.startswith(note) for line in err.splitlines()), err
    assert "the run lasts 3 steps, 0.9 s" in err
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert summary["duration"] == pytest.approx(0.9, rel=1e-12)
    assert run([*argv, "--dt", "0.25", "--duration", "1", "--out", str(tmp_path / "b")]) == 0
    assert "note" not in capsys.readouterr().err


def test_track_refuses_a_payload_that_tips_the_robot_at_the_start(tmp_path, capsys):
    """The kinematic plant would run it (S < 1 from the first step); the run is refused
    instead, as the scenarios tool refuses it, naming the payload and the margin."""
    argv = ["--method", "pi", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    out = tmp_path / "out"
    assert run([*argv, "--payload", "50", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and not out.exists()
    assert "payload: a 50 kg payload tips the robot over in this run's start pose (S = 0.45" in err
    assert run([*argv, "--no-progress", "--payload", "3", "--out", str(out)]) == 0
    tilted = [*argv, "--payload", "5", "--offset", "-0.6", "-0.4", "--out", str(tmp_path / "b")]
    assert run(tilted) == 2  # 5 kg holds with the default offset, not this one
    assert capsys.readouterr().err.endswith("lighten the payload or change --offset\n")


def test_track_refuses_an_obstacle_over_the_start_pose(tmp_path, capsys):
    obstacles = tmp_path / "onstart.toml"
    obstacles.write_text("[[obstacle]]\nx = 1.8\ny = -0.6\nradius = 0.5\n")
    argv = ["--method", "qp", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    out = tmp_path / "out"
    assert run([*argv, "--obstacles", str(obstacles), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and not out.exists()
    assert "obstacles: obstacle 1 (x 1.8 m, y -0.6 m, radius 0.5 m) overlaps the robot's" in err


def test_a_physics_run_draws_its_support_loads(tmp_path):
    """--plant mujoco writes support_loads.png beside the other figures (not on other
    plants); the edges' loads it draws are the plant's: their least is min_edge_load_n."""
    from ddwmmr.reports.physics_plots import SUPPORT_LOADS_FIGURE, edge_load_series

    out = tmp_path / "run"
    args = ["--method", "qp", "--traj", "sideways_reach", "--payload", "3", "--duration", "1"]
    assert run([*args, "--plant", "mujoco", "--no-progress", "--out", str(out)]) == 0
    assert (out / SUPPORT_LOADS_FIGURE).stat().st_size > 10_000
    summary = json.loads((out / "summary.json").read_text())
    assert summary["min_edge_load_floor_n"] == pytest.approx(0.1 * 15.0 * 9.81)
    with open(out / "timeseries.csv") as handle:
        rows = list(csv.DictReader(handle))
    series = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    names, loads = edge_load_series(series, Robot().with_payload(3.0))
    assert sorted(names) == ["back", "front", "left", "right"]
    assert loads.min(axis=1) == pytest.approx(series["min_edge_load_n"], abs=1e-9)
    kinematic = tmp_path / "kinematic"
    assert run([*args, "--no-progress", "--out", str(kinematic)]) == 0
    assert not (kinematic / SUPPORT_LOADS_FIGURE).exists()


def test_a_start_outside_the_robots_joint_limits_is_one_line(tmp_path, capsys):
    robot = tmp_path / "narrow.toml"
    robot.write_text("joint_limits = [[-0.31, -0.29], [0.59, 0.61]]\n")
    out = tmp_path / "run"
    argv = ["--method", "ats", "--traj", "ellipse", "--robot", str(robot), "--out", str(out)]
    assert run(argv) == 2
    assert capsys.readouterr().err == (
        "error: the start pose: joint th1 = -0.437856 rad is outside joint_limits[1] = "
        "[-0.31, -0.29] rad; change the robot's joint_limits or the default --offset\n"
    )
    assert not out.exists()
    assert run([*argv, "--offset", "0", "0", "--duration", "0.2", "--no-plots"]) == 0


def test_an_unreachable_default_offset_is_not_blamed_on_an_offset_never_given(tmp_path, capsys):
    """Without --offset the robot's default (0.03 of its length unit each way) is used; a
    robot whose arm cannot make it reads "the default --offset", not "--offset"."""
    robot = tmp_path / "lopsided.toml"
    robot.write_text("L1 = 3.5\nL2 = 0.01\n")
    out = tmp_path / "run"
    argv = ["--method", "ats", "--traj", "ellipse", "--robot", str(robot), "--out", str(out)]
    assert run(argv) == 2
    assert capsys.readouterr().err == (
        "error: the default --offset (-0.3, -0.3) m (end-effector frame) cannot be reached "
        "with the arm alone; along that direction it reaches (-0.075, -0.075) m\n"
    )
    assert run([*argv, "--offset", "-0.3", "-0.3"]) == 2
    assert capsys.readouterr().err.startswith("error: --offset (-0.3, -0.3) m")
    assert not out.exists()


def test_qp_mode_is_the_qps_even_where_a_plug_in_has_a_mode(tmp_path, capsys, registered):
    from ddwmmr.registry import CONTROLLERS

    class Moded:
        """A plug-in controller with an option of its own called mode."""

        def __init__(self, robot, mode="shape"):
            self.robot, self.mode = robot, mode

        def reset(self, trajectory, q0):
            pass

        def command(self, t, q, pose_d, velocity_d):
            return np.zeros(4)

    registered(CONTROLLERS, "moded", Moded, tasks=("tracking",))
    out = str(tmp_path / "o")
    argv = ["--method", "moded", "--traj", "ellipse", "--qp-mode", "hierarchical", "--out", out]
    assert run(argv) == 2
    assert capsys.readouterr().err == (
        "error: qp-mode: --qp-mode is taken only by --method qp (got --method moded)\n"
    )
    with pytest.raises(SystemExit):
        run(["--help"])
    assert "priority handling (default weighted) [qp]\n" in capsys.readouterr().out


def test_the_table_shows_the_mpcs_fallbacks():
    """An mpc run whose every step fell back to its qp read 'tracked' with no line saying
    so: the table had the qp's fallbacks only."""
    from ddwmmr.cli.track import format_table

    run = {"method": "mpc", "trajectory": "ellipse", "steps": 100}
    lines = format_table({**run, "mpc_fallbacks": 100}).splitlines()
    assert "  MPC fallbacks (its qp commanded)     100" in lines
    assert not any("MPC fallbacks" in line for line in format_table(run).splitlines())
