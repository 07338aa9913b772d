"""Bad input to every tool (track, compare, scenarios, bench): one line, exit 2, nothing
written.

A table of the cases a bad-input review found (absurd sizes, broken files, FIFOs, output paths,
trajectory names with ``..``, wrong TOML types) plus property tests over invalid numbers.
Tools run in-process through their ``main(argv)``; the working folder is a fresh
temporary folder whose content must not change. (A read-only output folder: see
tests/test_outputs.py, which also covers running as root, who may write there.)
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ddwmmr.cli.bench import build_parser as bench_parser
from ddwmmr.cli.bench import main as bench_main
from ddwmmr.cli.compare import build_parser as compare_parser
from ddwmmr.cli.compare import main as compare_main
from ddwmmr.cli.scenarios import build_parser as scenarios_parser
from ddwmmr.cli.scenarios import main as scenarios_main
from ddwmmr.cli.track import build_parser as track_parser
from ddwmmr.cli.track import main as track_main
from ddwmmr.errors import MAX_SCENARIOS, MAX_STEPS
from in_process import call_main

MAINS = {
    "track": track_main,
    "compare": compare_main,
    "scenarios": scenarios_main,
    "bench": bench_main,
}
#: Arguments that make each tool's run small (the cases add the bad part).
BASE = {
    "track": ["--method", "ats", "--traj", "ellipse", "--duration", "0.2", "--no-plots"],
    "compare": ["--methods", "pi", "--only", "ellipse", "--study", "none", "--jobs", "1"],
    "scenarios": ["--n", "1", "--time-limit", "0.2", "--jobs", "1"],
    "bench": ["--repeats", "1", "--calls", "1", "--duration", "0.1", "--method", "pi"],
}

#: Input files the cases refer to as {name}; written into inputs/ before the snapshot.
FILES = {
    "robot_latin1.toml": b"L1 = 0.4  # \xe9paule\n",
    "robot_array.toml": b"[[robot]]\nL1 = 0.4\n",
    "robot_L1_string.toml": b'L1 = "0.3"\n',
    "robot_L1_bool.toml": b"L1 = true\n",
    "robot_tiny_wheel.toml": b"wheel_radius = 1e-320\n",
    "robot_huge_L1.toml": b"L1 = 1e300\n",
    "robot_masses_number.toml": b"link_masses = 1.0\n",
    "robot_masses_text.toml": b'link_masses = [1.0, "a"]\n',
    "robot_payload_nan.toml": b"payload = nan\n",
    "robot_unknown.toml": b"arm_length = 0.3\n",
    "robot_caster_out.toml": b"caster_positions = [[0.1, 0.5]]\n",
    "robot_bad.toml": b"L1 = = 0.3\n",
    "traj_N_string.toml": b'shape = "ellipse"\nN = "2000"\n',
    "traj_a_string.toml": b'shape = "ellipse"\na = "2.0"\n',
    "traj_N_1e9.toml": b'shape = "ellipse"\nN = 1e9\n',
    "traj_N_1e30.toml": b'shape = "ellipse"\nN = 1e30\n',
    "traj_a_1e300.toml": b'shape = "ellipse"\na = 1e300\n',
    "traj_T_inf.toml": b'shape = "ellipse"\nT = inf\n',
    "traj_array.toml": b'[[trajectory]]\nshape = "ellipse"\n',
    "traj_unknown_key.toml": b'shape = "ellipse"\nradius = 2.0\n',
    "traj_no_shape.toml": b"a = 2.0\n",
    "traj_latin1.toml": b'shape = "ellipse"  # \xe9\n',
    "traj_latin1.csv": b"t,x,y\n0,0,0\n1,1,0\n2,2,\xff\n",
    "traj_text.csv": b"t,x,y\n0,0,0\n1,a,0\n2,2,0\n",
    "traj_short_row.csv": b"t,x,y\n0,0,0\n1,1\n2,2,0\n",
    "traj_huge.csv": b"t,x,y\n0,0,0\n1,1e300,0\n2,2,0\n",
    "traj_short.csv": b"t,x,y\n0,0,0\n",
    "traj_long_row.csv": b"t,x,y\n0,0,0\n1,1,0,5\n2,2,0\n",
    "traj_repeated_column.csv": b"t,x,y,t\n0,0,0,0\n1,1,0,1\n2,2,0,2\n",
    "traj_blank_columns.csv": b"garbage,,\n1,2,3\n",
    # columns that were silently ignored (the run was that of t,x,y), numbers misread
    "traj_Phi.csv": b"t,x,y,Phi\n0,2,0,0\n1,2,1,0\n2,2,2,0\n",
    "traj_theta.csv": b"t,x,y,theta\n0,2,0,0\n1,2,1,0\n2,2,2,0\n",
    "traj_underscore.csv": b"t,x,y\n0,2,0\n1_0,2,1\n20,2,2\n",
    "traj_arabic_digit.csv": "t,x,y\n0,2,0\n\u0661,2,1\n2,2,2\n".encode(),
    "traj_hash_header.csv": b"# t,x,y\n0,2,0\n1,2,1\n2,2,2\n",
    # 10 MB strings: each echoed whole in the one line before
    "traj_huge_orientation.toml": b'shape = "ellipse"\norientation = "' + b"x" * 10**7 + b'"\n',
    "traj_huge_key.toml": b'shape = "ellipse"\n' + b"k" * 10**7 + b" = 1\n",
    "robot_huge_string.toml": b'L1 = "' + b"x" * 10**7 + b'"\n',
    "obstacle_at_start.toml": b"[[obstacle]]\nx = 2.0\ny = 0.0\nradius = 0.5\n",
    "obstacle_far.toml": b"[[obstacle]]\nx = 1e9\ny = 0.0\nradius = 0.3\n",
    "obstacle_huge.toml": b"[[obstacle]]\nx = 5.0\ny = 0.0\nradius = 5000.0\n",
    "obstacles_text.toml": b'[[obstacle]]\nx = "1"\ny = 0.0\nradius = 0.3\n',
    "a_file.txt": b"not a folder\n",
    # 10 kB of nested arrays, inline tables nested 500 deep: the parser recurses per level
    "robot_deep_array.toml": b"L1 = " + b"[" * 5000 + b"]" * 5000 + b"\n",
    "robot_deep_tables.toml": b"L1 = " + b"{a = " * 500 + b"1" + b"}" * 500 + b"\n",
    "robot_deep_parsed.toml": b"L1 = " + b"[" * 100 + b"]" * 100 + b"\n",  # parses, too deep
    "traj_deep.toml": b'shape = "ellipse"\na = ' + b"[" * 5000 + b"]" * 5000 + b"\n",
    "obstacles_deep.toml": b"[[obstacle]]\nx = 1.0\ny = 0.0\nradius = "
    + b"{r = " * 500
    + b"0.3"
    + b"}" * 500
    + b"\n",
}
TOO_DEEP = "nests arrays or tables more than 32 levels deep"

# (tool, arguments, text the one line must contain)
ROBOT_CASES = [
    (["--robot", "{robot_latin1.toml}"], "not UTF-8 text (byte 0xe9"),
    (["--robot", "{robot_array.toml}"], "[[robot]]"),
    (["--robot", "{robot_L1_string.toml}"], "L1 must be a number"),
    (["--robot", "{robot_L1_bool.toml}"], "L1 must be a number"),
    (["--robot", "{robot_tiny_wheel.toml}"], "wheel_radius must be in [1e-06, 1000] m"),
    (["--robot", "{robot_huge_L1.toml}"], "L1 must be in"),
    (["--robot", "{robot_masses_number.toml}"], "link_masses must be a pair of numbers"),
    (["--robot", "{robot_masses_text.toml}"], "link_masses[2] must be a number (got 'a')"),
    (["--robot", "{robot_payload_nan.toml}"], "payload must be a finite number"),
    (["--robot", "{robot_unknown.toml}"], "unknown parameter 'arm_length'"),
    (  # MuJoCo's own refusal, named by the file before the run
        ["--robot", "{robot_caster_out.toml}", "--plant", "mujoco"],
        "robot: {robot_caster_out.toml}: caster_positions: the base centre must lie strictly",
    ),
    (["--robot", "{robot_bad.toml}"], "is not valid TOML"),
    (["--robot", "{robot_deep_array.toml}"], TOO_DEEP),
    (["--robot", "{robot_deep_tables.toml}"], TOO_DEEP),
    (["--robot", "{robot_deep_parsed.toml}"], TOO_DEEP),
    (["--robot", "{fifo}"], "is not a regular file"),
    (["--robot", "{inputs}"], "is not a regular file"),
    (["--robot", "missing.toml"], "cannot read missing.toml"),
    (["--payload", "1e300"], "payload must be in [0, 100000] kg"),
    (["--payload", "-1"], "payload must be in [0, 100000] kg (got -1)"),
    (["--payload", "nan"], "payload must be a finite number"),
]
TRAJ_CASES = [
    ("{traj_N_string.toml}", "N must be a number (got '2000')"),
    ("{traj_a_string.toml}", "a must be a number (got '2.0')"),
    ("{traj_N_1e9.toml}", "N must be an integer in [2, 1000000]"),
    ("{traj_N_1e30.toml}", "N must be an integer in [2, 1000000]"),
    ("{traj_a_1e300.toml}", "a must be in [1e-06, 1000] m"),
    ("{traj_T_inf.toml}", "T must be a finite number"),
    ("{traj_array.toml}", "[trajectory] must be one table"),
    ("{traj_unknown_key.toml}", "unknown key 'radius'"),
    ("{traj_no_shape.toml}", "needs shape = one of ellipse, rectangle"),
    ("{traj_latin1.toml}", "not UTF-8 text"),
    ("{traj_latin1.csv}", "not UTF-8 text (byte 0xff"),
    ("{traj_text.csv}", "data row 2, column x: 'a' is not a number"),
    ("{traj_short_row.csv}", "data row 2 has no value in column y"),
    ("{traj_huge.csv}", "must be <= 1e+06"),
    ("{traj_short.csv}", "need at least 3 rows"),
    ("{fifo_csv}", "is not a regular file"),
    ("../trajectories/ellipse", "neither a trajectory name"),
    ("../../etc/passwd", "neither a trajectory name"),
    ("..", "neither a trajectory name"),
    ("sub/figure8", "neither a trajectory name"),
    ("nowhere", "unknown trajectory 'nowhere'"),
    ("missing.csv", "no such file missing.csv"),
    ("{traj_deep.toml}", TOO_DEEP),
]
OUT_CASES = [
    ("{a_file.txt}/out", "is not a folder"),
    ("{a_file.txt}", "exists and is not a folder"),
    ("x" * 300, "is too long (300 bytes, at most 255)"),
    (".", "is the current folder"),
    ("", "out: give an output folder (got an empty path)"),
    ("..", "is the current folder or one of its parents"),
    ("{link_to_dir}", "is a symbolic link"),
    ("{dangling_link}", "is a symbolic link"),
    ("{dangling_link}/out", "is a dangling symbolic link"),
]

CASES: list[tuple[str, list[str], str]] = []
for tool in ("track", "compare"):
    CASES += [(tool, args, text) for args, text in ROBOT_CASES]
CASES += [("track", ["--traj", traj], text) for traj, text in TRAJ_CASES]
CASES += [
    ("track", ["--traj", "{traj_long_row.csv}"], "data row 2 has more values than the header"),
    ("track", ["--traj", "{traj_repeated_column.csv}"], "repeats column(s) t; needs a header"),
    (
        "track",
        ["--traj", "{traj_blank_columns.csv}"],
        "has a blank column name over values (column 2)",
    ),
    ("track", ["--traj", "{traj_Phi.csv}"], "unknown column(s) 'Phi' (accepted: t, x, y, phi"),
    ("track", ["--traj", "{traj_theta.csv}"], "unknown column(s) 'theta' (accepted: t, x, y"),
    ("track", ["--traj", "{traj_underscore.csv}"], "column t: '1_0' is not a number"),
    ("track", ["--traj", "{traj_arabic_digit.csv}"], "data row 2, column t: '\u0661' is not a"),
    ("track", ["--traj", "{traj_hash_header.csv}"], "has no header line (its first line that"),
    ("compare", ["--only", "{traj_Phi.csv}"], "unknown column(s) 'Phi'"),
    ("track", ["--traj", "{traj_huge_orientation.toml}"], "(got 'xxxxxxxxxxxxxxxxxxxxxxx"),
    ("track", ["--traj", "{traj_huge_key.toml}"], "unknown key 'kkkkkkkkkkkkkkkkkkkkkkkk"),
    (
        "track",
        ["--robot", "{robot_huge_string.toml}"],
        "L1 must be a number in [1e-06, 1000] m (got 'xxxxxxx",
    ),
    # a payload that tips the robot in the start pose: refused by every tool, as by track
    ("track", ["--payload", "20"], "a 20 kg payload tips the robot over in this run's start"),
    ("compare", ["--payload", "50"], "a 50 kg payload tips the robot over in this run's start"),
    ("track", ["--method", "qp", "--obstacles", "{obstacle_at_start.toml}"], "overlaps the rob"),
    ("track", ["--method", "qp", "--obstacles", "{obstacle_far.toml}"], "obstacle x must be in"),
    ("track", ["--method", "qp", "--obstacles", "{obstacle_huge.toml}"], "radius must be in"),
    ("track", ["--method", "qp", "--obstacles", "{obstacles_deep.toml}"], TOO_DEEP),
]
CASES += [("compare", ["--only", traj], text) for traj, text in TRAJ_CASES[:4] + TRAJ_CASES[15:]]
CASES += [("compare", ["--traj", traj], text) for traj, text in TRAJ_CASES[10:13]]
for tool in ("track", "compare", "scenarios"):  # tools writing a folder
    CASES += [(tool, ["--out", out], text) for out, text in OUT_CASES]
#: bench writes one file: the same path checks, with a file's wording.
BENCH_OUT_CASES = [
    ("{a_file.txt}/out", "is not a folder"),
    ("{a_file.txt}", "exists and is not a ddwmmr.bench report"),
    ("{inputs}", "is a folder; give a file name"),
    ("x" * 300, "is too long (300 bytes, at most 255)"),
    (".", "is the current folder"),
    ("..", "is the current folder or one of its parents"),
    ("{link_to_dir}", "is a symbolic link"),
    ("{dangling_link}", "is a symbolic link"),
    ("{dangling_link}/out", "is a dangling symbolic link"),
]
CASES += [("bench", ["--out", out], text) for out, text in BENCH_OUT_CASES]
CASES += [
    ("track", ["--duration", "1e9"], f"duration / dt must be <= {MAX_STEPS} steps"),
    ("track", ["--duration", "inf"], "duration must be a finite number"),
    ("track", ["--duration", "1e12"], "duration / dt must be <="),
    ("track", ["--duration", "-5"], "duration must be > 0 (got -5)"),
    ("track", ["--duration", "nan"], "duration must be a finite number"),
    ("track", ["--duration", "0"], "duration must be > 0"),
    ("track", ["--dt", "1e-7"], "duration / dt must be <="),
    ("track", ["--dt", "1e-300"], "duration / dt must be <="),
    ("track", ["--dt", "0"], "dt must be > 0"),
    ("track", ["--dt", "-0.1"], "dt must be > 0"),
    ("track", ["--dt", "nan"], "dt must be a finite number"),
    ("track", ["--dt", "1"], "dt must be <= duration (0.2 s)"),
    ("track", ["--dt", "abc"], "argument --dt: must be a number > 0 s (got 'abc')"),
    ("track", ["--method", "clrrmc-ts", "--tau", "-2"], "tau must be > 0"),
    ("track", ["--method", "clrrmc-ts", "--tau", "1e-300"], "(at least 0.0001 s)"),
    ("track", ["--method", "qp", "--manipulability-weight", "1e300"], "in [0, 1e+06]"),
    ("track", ["--method", "clrrmc-ts", "--tau", "1", "2"], "tau must be one value or 3"),
    # a method option's text that is no number: the method's range, as for nan (an audit's)
    ("track", ["--option", "damping=abc"], "damping must be a finite number in [1e-06, 1000] ("),
    ("track", ["--method", "clrrmc-ts", "--option", "tau=fast"], "tau must be > 0 s (at least"),
    ("compare", ["--option", "damping=1e"], "damping must be a finite number in [1e-06, 1000]"),
    ("scenarios", ["--option", "adjust=far"], "adjust must be a finite number in [0.01, 5] m"),
    ("track", ["--method", "pi", "--aux", "sum"], "aux: --aux is taken only by --method"),
    ("track", ["--tau", "1"], "tau: --tau is taken only by --method"),
    ("track", ["--method", "nope"], "invalid choice: 'nope'"),
    ("track", ["--offset", "nan", "0"], "offset must be a finite number"),
    ("track", ["--offset", "1e300", "0"], "offset must be in [-0.65, 0.65] m"),
    ("track", ["--rerun", "{traj_N_string.toml}"], "is not valid JSON"),
    ("track", ["--rerun", "{fifo}"], "is not a regular file"),
    ("track", ["--rerun", ""], "rerun: give the path of a summary.json"),
    (
        "track",
        ["--method", "qp", "--obstacles", "{obstacles_text.toml}"],
        "x must be a number in m (got '1')",
    ),
    ("track", ["--method", "qp", "--obstacles", "../x"], "cannot read ../x"),
    ("track", ["--method", "qp", "--obstacles", "nope"], "unknown obstacle file 'nope'"),
    ("compare", ["--duration", "1e9"], "duration / dt must be <="),
    ("compare", ["--duration", "inf"], "duration must be a finite number"),
    ("compare", ["--duration", "-5"], "duration must be > 0 (got -5)"),
    ("compare", ["--duration", "nan"], "duration must be a finite number"),
    ("compare", ["--jobs", "0"], "jobs must be an integer in [1, 256]"),
    ("compare", ["--jobs", "100000"], "jobs must be an integer in [1, 256]"),
    ("compare", ["--jobs", "1e9"], "argument --jobs: must be an integer in [1, 256] (got '1e9')"),
    ("compare", ["--methods", "nope"], "unknown method 'nope'"),
    ("compare", ["--study", "nope"], "unknown study 'nope'"),
    ("compare", ["--plant", "thesis,nope"], "plant: unknown plant 'nope' (one of thesis"),
    ("compare", ["--plant", "kinematic"], "the kinematic plant always runs"),
    ("compare", ["--plant", ","], "plant: no name given"),
    ("compare", ["--study", "tau"], "study: 'none' cannot be combined with other studies"),
    ("compare", ["--study-methods", "qp"], "study-methods: only used with a study"),
    ("compare", ["--methods", ""], "methods: no name given"),
    ("compare", ["--methods", ",,,"], "methods: no name given"),
    ("compare", ["--study", ""], "study: no name given"),
    ("compare", ["--only", ","], "only: no name given"),
    ("compare", ["--traj", ""], "traj: no name given"),
    ("scenarios", ["--n", "1000000000"], f"n must be an integer in [1, {MAX_SCENARIOS}]"),
    ("scenarios", ["--n", "0"], "n must be an integer in [1,"),
    ("scenarios", ["--dt", "1e-7"], "time-limit / dt must be <="),
    ("scenarios", ["--dt", "1e-300"], "time-limit / dt must be <="),
    ("scenarios", ["--dt", "nan"], "dt must be in (0, 0.1] s (got nan)"),
    ("scenarios", ["--time-limit", "1e12"], "time-limit / dt must be <="),
    ("scenarios", ["--time-limit", "inf"], "time-limit must be > 0"),
    ("scenarios", ["--payload", "10"], "10 kg tips the robot over in the start pose"),
    ("scenarios", ["--payload", "1e300"], "payload must be in [0, 100000] kg"),
    ("scenarios", ["--seed", "-1"], "seed must be an integer >= 0 (got -1)"),
    ("scenarios", ["--stability", "nan", "1"], "stability thresholds must be in (0, 10]"),
    ("scenarios", ["--jobs", "0"], "jobs must be an integer in [1, 256]"),
    ("bench", ["--repeats", "0"], "--repeats: must be an integer in [1, 1000] (got '0')"),
    ("bench", ["--repeats", "abc"], "--repeats: must be an integer in [1, 1000]"),
    ("bench", ["--calls", "-1"], "--calls: must be an integer in [1, 10000]"),
    ("bench", ["--duration", "nan"], "--duration: must be a number in [0.02, 20000] s"),
    ("bench", ["--duration", "inf"], "--duration: must be a number in [0.02, 20000] s"),
    ("bench", ["--method", "nope"], "unknown method 'nope'"),
]

#: Dask scheduler options (the addresses of servers the tests start: see below).
DASK = ["--executor", "dask", "--connect-timeout", "1", "--scheduler"]
CASES += [
    ("scenarios", ["--connect-timeout", "5"], "connect-timeout: only used with --scheduler"),
    ("scenarios", [*DASK[:2], "--connect-timeout", "0", "--scheduler", "tcp://127.0.0.1:1"],
     "connect-timeout must be in (0, 600] s"),
    ("scenarios", [*DASK[:2], "--connect-timeout", "nan", "--scheduler", "tcp://127.0.0.1:1"],
     "argument --connect-timeout: must be a number in (0, 600] s (got 'nan')"),
    ("scenarios", [*DASK[:2], "--connect-timeout", "1e9", "--scheduler", "tcp://127.0.0.1:1"],
     "connect-timeout must be in (0, 600] s"),
    ("scenarios", [*DASK, "tcp://127.0.0.1:1"], "no Dask scheduler answered"),
]  # fmt: skip


@pytest.fixture(scope="module")
def written_files(tmp_path_factory) -> Path:
    """A folder holding FILES, written once per module (three of them are 10 MB)."""
    folder = tmp_path_factory.mktemp("fuzz_files")
    for name, data in FILES.items():
        (folder / name).write_bytes(data)
    return folder


@pytest.fixture
def workdir(tmp_path, monkeypatch, written_files) -> dict[str, str]:
    """A fresh working folder with the input files; returns the {name} substitutions.
    The files are hard links to ``written_files``: regular files with FILES' bytes at
    the same paths, without writing 30 MB per case."""
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    for name in FILES:
        os.link(written_files / name, inputs / name)
    os.mkfifo(inputs / "fifo.toml")
    os.mkfifo(inputs / "fifo.csv")
    (inputs / "a_dir").mkdir()
    os.symlink(inputs / "a_dir", inputs / "link_to_dir")
    os.symlink(inputs / "gone", inputs / "dangling_link")
    monkeypatch.chdir(tmp_path)
    names = {name: str(inputs / name) for name in FILES}
    names.update(
        fifo=str(inputs / "fifo.toml"),
        fifo_csv=str(inputs / "fifo.csv"),
        inputs=str(inputs),
        link_to_dir=str(inputs / "link_to_dir"),
        dangling_link=str(inputs / "dangling_link"),
    )
    return names


def tree(folder: Path) -> list[tuple[str, float]]:
    """Every path below ``folder`` with its modification time."""
    return sorted((str(p), os.lstat(p).st_mtime) for p in folder.rglob("*"))


def expand(args: list[str], names: dict[str, str]) -> list[str]:
    out = []
    for arg in args:
        for name, value in names.items():
            arg = arg.replace("{" + name + "}", value)
        out.append(arg)
    return out


def with_base(tool: str, args: list[str]) -> list[str]:
    """BASE[tool] without the options that take one value and ``args`` gives itself: the
    tools refuse such an option given twice."""
    parser = {
        "track": track_parser,
        "compare": compare_parser,
        "scenarios": scenarios_parser,
        "bench": bench_parser,
    }[tool]()
    given = {arg.split("=")[0] for arg in args if arg.startswith("--")}
    base, kept, i = BASE[tool], [], 0
    while i < len(base):
        action = parser._option_string_actions[base[i]]
        width = 1 + (action.nargs != 0)  # BASE gives one value per option (or none)
        scheduled = base[i] == "--jobs" and "--scheduler" in given  # refused together
        if not scheduled and not (base[i] in given and type(action).__name__ == "_StoreOnce"):
            kept += base[i : i + width]
        i += width
    return kept


def run_bad(tool: str, args: list[str], capsys) -> tuple[int, str]:
    """Run ``tool`` with BASE + args (+ --out out unless given); status and stderr."""
    extra = [] if "--out" in args else ["--out", "out"]
    base = [] if "--rerun" in args else with_base(tool, args)  # a rerun takes no options
    status, out, err = call_main(MAINS[tool], [*base, *args, *extra], capsys)
    assert out == ""
    return status, err


@pytest.mark.parametrize(
    ("tool", "args", "text"), CASES, ids=[f"{t}:{' '.join(a)[:60]}" for t, a, _ in CASES]
)
def test_bad_input_one_line_exit_2_nothing_written(workdir, tool, args, text, capsys):
    cwd = Path.cwd()
    before = tree(cwd)
    status, err = run_bad(tool, expand(args, workdir), capsys)
    lines = err.strip().splitlines()
    assert status == 2, err
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert expand([text], workdir)[0] in lines[0]
    assert len(lines[0]) < 2000  # echoed values are cut (a 10 MB string came out whole)
    assert tree(cwd) == before


def test_duration_message_names_duration_not_dt(workdir, capsys):
    status, err = run_bad("track", ["--duration", "-5"], capsys)
    assert status == 2 and "duration" in err and "dt" not in err


# -- properties: any number outside the documented domain is refused ------------------------
INVALID_STEP = st.one_of(
    st.floats(max_value=0.0),
    st.sampled_from([math.inf, -math.inf, math.nan]),
    st.floats(min_value=1e-320, max_value=0.2 / (MAX_STEPS + 1), exclude_min=False),
)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(dt=INVALID_STEP)
def test_any_invalid_step_is_refused(workdir, capsys, dt):
    status, err = run_bad("track", ["--dt", repr(dt)], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "dt" in err
    assert not Path("out").exists()


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    duration=st.one_of(
        st.floats(max_value=0.0),
        st.sampled_from([math.inf, math.nan]),
        st.floats(min_value=0.02 * (MAX_STEPS + 1), allow_infinity=False),
    )
)
def test_any_invalid_duration_is_refused(workdir, capsys, duration):
    for tool in ("track", "compare"):
        status, err = run_bad(tool, ["--duration", repr(duration)], capsys)
        assert status == 2 and len(err.strip().splitlines()) == 1 and "duration" in err
    assert not Path("out").exists()


@settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(n=st.one_of(st.integers(max_value=0), st.integers(min_value=MAX_SCENARIOS + 1)))
def test_any_invalid_scenario_count_is_refused(workdir, capsys, n):
    status, err = run_bad("scenarios", ["--n", str(n)], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "n must be" in err


@settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    key=st.sampled_from(["L1", "L2", "wheel_radius", "track_width", "base_length"]),
    value=st.one_of(
        st.text(max_size=5).map(lambda s: f'"{s}"'),
        st.booleans().map(lambda b: str(b).lower()),
        st.sampled_from(["1e300", "1e-320", "-1.0", "nan", "inf", "[1.0]", "{x = 1}"]),
    ),
)
def test_any_mistyped_or_absurd_robot_value_is_refused(workdir, capsys, key, value):
    path = Path(workdir["inputs"]) / "robot_fuzz.toml"
    path.write_text(f"{key} = {value}\n")
    status, err = run_bad("track", ["--robot", str(path)], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1
    assert key in err or "not valid TOML" in err


# -- as a user runs them: python -m, FIFOs (which would block if opened) ---------------------
# One case per tool as a real process (exit status, no traceback on a real stderr); each is
# in the tables above too, run in-process.
@pytest.mark.parametrize(
    ("tool", "args"),
    [
        ("track", ["--robot", "{fifo}"]),
        ("compare", ["--robot", "{fifo}"]),
        ("scenarios", ["--payload", "10"]),
    ],
)
def test_as_a_module_one_line_and_no_traceback(workdir, tool, args):
    done = subprocess.run(
        [sys.executable, "-m", f"ddwmmr.{tool}", *with_base(tool, args), *expand(args, workdir)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    assert not Path("runs").exists()


# -- Dask scheduler addresses: servers on 127.0.0.1 that are not Dask schedulers ------------
class _Listeners:
    """TCP servers on 127.0.0.1 (ephemeral ports): one that accepts and never answers, an
    HTTP server, and two that answer garbage (a huge frame length, a bad header)."""

    def __init__(self) -> None:
        import http.server
        import socket
        import threading

        self._sockets: list[socket.socket] = []
        self._held: list[socket.socket] = []
        self.silent = self._serve(lambda conn: self._held.append(conn))
        self.ascii = self._serve(lambda conn: conn.sendall(b"1" * 4096))  # 3.07 EiB frame
        self.binary = self._serve(lambda conn: conn.sendall(b"\xff" * 64 + b"garbage" * 64))

        class Quiet(http.server.SimpleHTTPRequestHandler):
            def log_message(self, *args) -> None:  # the tool's stderr is under test
                pass

        self._http = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Quiet)
        threading.Thread(target=self._http.serve_forever, daemon=True).start()
        self.http = self._http.server_address[1]

    def _serve(self, answer) -> int:
        import socket
        import threading

        server = socket.create_server(("127.0.0.1", 0))
        self._sockets.append(server)

        def accept() -> None:
            while True:
                try:
                    conn, _ = server.accept()
                    answer(conn)
                except OSError:
                    return

        threading.Thread(target=accept, daemon=True).start()
        return server.getsockname()[1]

    def close(self) -> None:
        self._http.shutdown()
        self._http.server_close()
        for sock in self._sockets + self._held:
            sock.close()


@pytest.fixture(scope="module")
def listeners():
    servers = _Listeners()
    yield servers
    servers.close()


#: --connect-timeout of the cases that must time out (1 s: the test stays short), and of
#: those that must fail at once: a garbage answer or an unusable scheme is "cannot
#: connect", and the generous timeout keeps a stalled, loaded machine from turning it into
#: "no Dask scheduler answered".
TIMES_OUT, FAILS_FAST = "1", "10"
SCHEDULER_CASES = [
    ("tcp://127.0.0.1:{silent}", TIMES_OUT, "no Dask scheduler answered at 'tcp://127.0.0.1:"),
    ("tcp://127.0.0.1:{http}", TIMES_OUT, "no Dask scheduler answered"),
    ("tcp://127.0.0.1:{ascii}", FAILS_FAST, "cannot connect to 'tcp://127.0.0.1:"),
    ("tcp://127.0.0.1:{binary}", FAILS_FAST, "cannot connect to 'tcp://127.0.0.1:"),
    ("tls://127.0.0.1:{silent}", FAILS_FAST, "cannot connect to 'tls://127.0.0.1:"),
    ("ucx://127.0.0.1:{silent}", FAILS_FAST, "cannot connect to 'ucx://127.0.0.1:"),
    ("http://127.0.0.1:{http}", FAILS_FAST, "unknown address scheme 'http'"),
    ("127.0.0.1", FAILS_FAST, "missing port number"),
]


@pytest.mark.parametrize(
    ("address", "timeout", "text"), SCHEDULER_CASES, ids=[a for a, _, _ in SCHEDULER_CASES]
)
def test_a_scheduler_address_that_is_not_a_scheduler(
    workdir, listeners, capsys, address, timeout, text
):
    """Checked before the output exists, within --connect-timeout: one line, exit 2."""
    cwd = Path.cwd()
    before = tree(cwd)
    ports = {"silent": listeners.silent, "http": listeners.http,
             "ascii": listeners.ascii, "binary": listeners.binary}  # fmt: skip
    options = [*DASK[:2], "--connect-timeout", timeout, "--scheduler", address.format(**ports)]
    status, err = run_bad("scenarios", options, capsys)
    assert status == 2, err
    assert len(err.strip().splitlines()) == 1 and text in err, err
    assert tree(cwd) == before


# -- tampered --rerun records: a rerun passes the checks of a fresh run --------------------
@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> dict:
    """A valid track summary.json of a qp run (cases change one field of a copy)."""
    import json

    out = tmp_path_factory.mktemp("recorded") / "run"
    args = ["--method", "qp", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    assert track_main([*args, "--no-progress", "--out", str(out)]) == 0
    return json.loads((out / "summary.json").read_text())


RERUN_CASES = [
    # (field of the run record, value, text of the one line)
    ("dt", 10**400, "dt must be a finite number > 0 (got an integer of about 1e400)"),
    ("duration", 10**400, "duration must be a finite number > 0 (got an integer of about 1e400)"),
    ("dt", -0.1, "dt must be > 0"),
    # a dt that is no number: the one line of --dt's check, naming the range (an audit's)
    ("dt", 0, "dt must be > 0 (got 0)"),
    ("dt", "abc", "dt must be a finite number > 0 (got 'abc')"),
    ("dt", None, "dt must be a finite number > 0 (got None)"),
    ("duration", 1e12, "duration / dt must be <="),
    ("robot.payload", 20, "a 20 kg payload tips the robot over in this run's start pose"),
    ("options.obstacles", [[2.0, 0.0, 0.5]], "overlaps the robot's start pose by 0.104 m"),
    ("options.obstacles", [[1e9, 0.0, 0.3]], "obstacle x must be in [-1e+06, 1e+06] m"),
    ("options.obstacles", [[5.0, 0.0, 5000.0]], "obstacle radius must be in"),
    ("initial_offset", [5.0, 0.0], "offset must be in [-0.65, 0.65] m"),
    ("initial_offset", [0.0, 0.0, 0.0], "offset must be two numbers"),
    ("integrator", "bogus", "integrator must be one of euler, rk4 (got 'bogus')"),
    ("trajectory.parameters.a", 1e300, "a must be in [1e-06, 1000] m"),
]


@pytest.mark.parametrize(
    ("field", "value", "text"), RERUN_CASES, ids=[f"{f}={str(v)[:20]}" for f, v, _ in RERUN_CASES]
)
def test_a_tampered_rerun_record_is_refused_as_a_fresh_run(
    workdir, recorded, capsys, field, value, text
):
    import json

    tampered = json.loads(json.dumps(recorded))
    *sections, key = field.split(".")
    holder = tampered["run"]
    for section in sections:
        holder = holder[section]
    holder[key] = value
    path = Path(workdir["inputs"]) / "summary.json"
    path.write_text(json.dumps(tampered))
    before = tree(Path.cwd())
    status, err = run_bad("track", ["--rerun", str(path)], capsys)
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: rerun: {path}: "), err
    assert text in lines[0], err
    assert tree(Path.cwd()) == before
