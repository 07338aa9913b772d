"""Every script in examples/ runs, prints something sensible and writes no files; edited
with a value the library refuses, it ends as the tools do (one line on stderr, status 2,
no traceback, through ddwmmr.cli.common.run_script); the quickstart prints the run's
verdict as `python -m ddwmmr.track` does."""

from __future__ import annotations

import importlib.util
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot
from ddwmmr.resolution.reference import (
    DEFAULT_INITIAL_OFFSET,
    offset_configuration,
    start_configuration,
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: The example scripts.
SCRIPTS = sorted(EXAMPLES.glob("*.py"))
#: Text each example must print (scripts not listed must print something).
EXPECTED = {
    "quickstart.py": (
        "clrrmc-ts on ellipse",
        "rms_position_error_m",
        "\nverdict: tracked\n",
        "first command u",
    ),
    "custom_trajectory.py": ("ats", "clrrmc-ts", "final"),
    "compare_aux.py": ("rectangle  sum", "ellipse    shoulder"),
    "own_robot.py": ("default (thesis)", "long arm (TOML)", "would tip over"),
    "physics_tipping.py": ("static floor only", "TIPPED", "every edge loaded (default)"),
}


def _run_python(arguments: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """Run Python with ``arguments`` in ``cwd`` (headless matplotlib), capturing output."""
    return subprocess.run(
        [sys.executable, *arguments],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )


def test_examples_exist() -> None:
    assert {p.name for p in SCRIPTS} >= set(EXPECTED) | set(NUMBER_CHECKS)


def run_example(script: Path, folder: Path) -> str:
    """The standard output of ``script`` run as a user runs it, in the empty ``folder``;
    it must end with status 0 and write nothing there."""
    done = _run_python([str(script)], folder)
    assert done.returncode == 0, done.stderr
    assert list(folder.iterdir()) == []  # nothing written in the working directory
    return done.stdout


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_example_runs(script: Path, tmp_path: Path) -> None:
    """Each example runs once, in a test of its own, and its output is checked here: the
    texts of EXPECTED and the numbers of its checks in NUMBER_CHECKS."""
    printed = run_example(script, tmp_path)
    assert printed.strip()
    for text in EXPECTED.get(script.name, ()):
        assert text in printed
    for check in NUMBER_CHECKS.get(script.name, ()):
        check(printed)


# -- the examples' numbers against independent expectations --------------------------------
#: Initial end-effector offset of every example run (simulate's default, |(-30, -30)| mm).
E0 = math.hypot(0.03, -0.03)


def closed_loop_rms(samples: int, dt: float, tau: float = 0.5) -> float:
    """RMS over samples + 1 recorded instants of e0 exp(-t / tau), the exact closed-loop
    decay of CLRRMC-TS's position error (K = 1/tau on x and y): a geometric series."""
    ratio = math.exp(-2.0 * dt / tau)
    return E0 * math.sqrt((1.0 - ratio ** (samples + 1)) / ((samples + 1) * (1.0 - ratio)))


def _numbers(line: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+\.?\d*(?:e-?\d+)?", line)]


def check_quickstart_numbers(printed: str) -> None:
    """The quickstart's summary against the exact closed-loop decay."""
    values = {}
    for line in printed.splitlines()[1:]:
        key, _, value = line.strip().partition(" ")
        values[key] = value.strip()
    # One 40 s period of the default ellipse in 2000 RK4 steps of 0.02 s.
    assert int(values["steps"]) == 2000
    assert float(values["max_position_error_m"]) == pytest.approx(E0, rel=1e-5)
    assert float(values["rms_position_error_m"]) == pytest.approx(
        closed_loop_rms(2000, 0.02), rel=1e-4
    )
    assert float(values["final_position_error_m"]) < E0 * math.exp(-40.0 / 0.5) + 1e-9
    assert int(values["singular_steps"]) == 0


def check_quickstart_first_command_tracks_with_the_feedback(printed: str) -> None:
    """u makes the end effector move at Xd_dot + K (Xd - X) (checked by finite differences
    of the forward kinematics), and the shoulder row of the ATS keeps th1dot = 0."""
    line = next(x for x in printed.splitlines() if "first command u" in x)
    v, w, th1dot, th2dot = _numbers(line.split("=")[1])
    assert th1dot == 0.0
    robot, trajectory = Robot(), Ellipse()
    q = offset_configuration(robot, start_configuration(robot, trajectory), DEFAULT_INITIAL_OFFSET)
    qdot = np.array([v * math.cos(q[2]), v * math.sin(q[2]), w, th1dot, th2dot])
    h = 1e-6
    moved = (robot.fk(q + h * qdot) - robot.fk(q - h * qdot)) / (2 * h)
    wanted = trajectory.velocity(0.0) + 2.0 * (trajectory.pose(0.0) - robot.fk(q))
    np.testing.assert_allclose(moved[:2], wanted[:2], atol=2e-4)  # u printed to 4 decimals


def check_custom_trajectory_numbers(printed: str) -> None:
    """Open loop keeps the offset, closed loop decays it as exp(-t / 0.5 s)."""
    lines = {x.split()[0]: _numbers(x) for x in printed.splitlines()}
    rms, final, singular = lines["ats"]
    # Open loop: the offset is kept (exact velocity feed-forward, RK4 drift far below 1 um).
    assert rms == pytest.approx(1000 * E0, abs=0.01) and final == pytest.approx(1000 * E0, abs=0.01)
    rms, final, singular = lines["clrrmc-ts"]
    # 30 s, 1500 samples: dt = 0.02 s; the error decays as exp(-t / 0.5 s).
    assert rms == pytest.approx(1000 * closed_loop_rms(1500, 0.02), abs=0.01)
    assert final == 0.0 and singular == 0


def check_compare_aux_numbers(printed: str) -> None:
    """aux = sum is singular on the rectangle, aux = shoulder is not."""
    rows = {}
    for line in printed.splitlines()[1:]:
        name, aux, *numbers = line.split()
        rows[(name, aux)] = [float(x) for x in numbers]
    for aux in ("shoulder", "sum"):  # on the ellipse, open loop keeps the offset exactly
        rms, worst, singular, saturated = rows[("ellipse", aux)]
        assert rms == pytest.approx(E0, abs=1e-4) and worst == pytest.approx(E0, abs=1e-4)
        assert singular == 0 and saturated == 0
    # On the rectangle, aux = sum drives the arm into cos(th1) = 0: damped steps, larger error.
    assert rows[("rectangle", "sum")][2] > 0 == rows[("rectangle", "shoulder")][2]
    assert rows[("rectangle", "sum")][0] > 10 * rows[("rectangle", "shoulder")][0]


def check_own_robot_numbers(printed: str) -> None:
    """Reach, payload, closed-loop RMS and stability of each robot of the example."""
    lines = printed.splitlines()
    found = {line[:22].strip(): _numbers(line[22:]) for line in lines}
    for label, L1, L2, payload in (
        ("default (thesis)", 0.35, 0.30, 1.25),
        ("default, 3 kg payload", 0.35, 0.30, 3.0),
        ("long arm (TOML)", 0.45, 0.35, 2.0),
        ("long arm, 6 kg payload", 0.45, 0.35, 6.0),
    ):
        got_reach, got_payload, _, rms = found[label][:4]
        assert got_reach == pytest.approx(L1 + L2, abs=0.005)
        assert got_payload == pytest.approx(payload, abs=0.005)
        # Closed loop on the default ellipse: the same decay for any robot (no saturation),
        # from its own default offset, the default's times its length unit L1 / 0.35 m.
        unit = L1 / 0.35
        assert rms == pytest.approx(1000 * unit * closed_loop_rms(2000, 0.02), abs=0.005)
    stability = {label: numbers[2] for label, numbers in found.items()}
    # More payload at the end effector moves the centre of mass out: less stable.
    assert stability["default, 3 kg payload"] < stability["default (thesis)"]
    assert stability["long arm, 6 kg payload"] <= 1.0 < stability["long arm (TOML)"]
    assert "would tip over" in lines[3] and "would tip over" not in "".join(lines[:3])


def check_physics_tipping_numbers(printed: str) -> None:
    """The static floor alone tips within the first second although its static S stays
    above 1.2; with the arm's lag and the braking step the run finishes but an edge is
    unloaded longer than with the edge-load rows too (the default)."""
    row = re.compile(
        r"(TIPPED|ok)\s+at\s+([\d.]+) s, waypoints (\d)/5, static S >= ([\d.]+), "
        r"an edge unloaded ([\d.]+) s"
    )
    rows = [row.search(line) for line in printed.splitlines()[1:]]
    (static, lagged, default) = [
        (m[1], float(m[2]), int(m[3]), float(m[4]), float(m[5])) for m in rows
    ]
    assert static[0] == "TIPPED" and static[1] < 1.0 and static[2] == 0 and static[3] > 1.2
    assert lagged[:1] == default[:1] == ("ok",) and lagged[2] == default[2] == 5
    # the edge-load rows keep the wheels loaded (0.24 s unloaded against 2.27 s)
    assert default[4] < 0.6 * lagged[4]


#: Per example: the checks of its printed numbers (test_example_runs runs each).
NUMBER_CHECKS = {
    "quickstart.py": (
        check_quickstart_numbers,
        check_quickstart_first_command_tracks_with_the_feedback,
    ),
    "custom_trajectory.py": (check_custom_trajectory_numbers,),
    "compare_aux.py": (check_compare_aux_numbers,),
    "own_robot.py": (check_own_robot_numbers,),
    "physics_tipping.py": (check_physics_tipping_numbers,),
}


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_custom_trajectory_velocity_is_the_pose_derivative() -> None:
    wave = _load("custom_trajectory").SineWave()
    h = 1e-5
    for t in np.linspace(0.5, 29.5, 13):
        numeric = (wave.pose(t + h) - wave.pose(t - h)) / (2 * h)
        np.testing.assert_allclose(wave.velocity(t), numeric, atol=1e-7)


def test_custom_trajectory_sample_gives_pose_and_velocity() -> None:
    wave = _load("custom_trajectory").SineWave()
    times = np.linspace(0.0, 30.0, 301)
    poses, velocities = wave.sample(times)
    np.testing.assert_allclose(poses, [wave.pose(t) for t in times], rtol=0, atol=1e-15)
    np.testing.assert_allclose(velocities, [wave.velocity(t) for t in times], rtol=0, atol=1e-15)


ROOT = Path(__file__).resolve().parents[1]
#: Every page with Python snippets: README.md and docs/*.md, found automatically (a page a
#: helper adds is tested as soon as it has a ```python block). Blocks not meant to run use
#: another fence (```text, ```sh, ```toml).
DOC_PAGES = [
    p.relative_to(ROOT).as_posix()
    for p in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    if "```python" in p.read_text()
]
#: Per page: (text its snippets must contain, text they must print).
DOC_EXPECTED = {
    "docs/thesis.md": (("run_many",), ("ok", "move_arm")),
    "README.md": (("make_controller", "simulate"), ("u = [",)),
    # The Results section's run is on the default ellipse (0.042 m RMS): a snippet that
    # rebinds a name the later ones use (the 8x scaled ellipse) shows here as metres.
    "docs/api.md": (("ellipse_x8",), ("'steps': 2000, 'rms_position_error_m': 0.04",)),
}


def python_blocks(page: Path) -> str:
    """The page's ```python blocks, concatenated (they run top to bottom in one session)."""
    blocks, inside = [], False
    for line in page.read_text().splitlines():
        if line.strip() == "```python":
            inside = True
        elif line.strip().startswith("```") and inside:
            inside = False
            blocks.append("")
        elif inside:
            blocks.append(line)
    return "\n".join(blocks)


def test_snippet_pages_are_found() -> None:
    assert {"README.md", "docs/api.md", "docs/qp.md", "docs/thesis.md"} <= set(DOC_PAGES)


@pytest.mark.parametrize("page", DOC_PAGES)
def test_doc_snippets_run(page: str, tmp_path: Path) -> None:
    code = python_blocks(ROOT / page)
    assert code.strip()
    in_code, in_output = DOC_EXPECTED.get(page, ((), ()))
    for text in in_code:
        assert text in code
    done = _run_python(["-c", code], tmp_path)  # in an empty folder, as a new user would
    assert done.returncode == 0, done.stderr
    for text in in_output:
        assert text in done.stdout


# -- a user's edits, and the quickstart's verdict ---------------------------------------
def edited_copy(tmp_path: Path, name: str, old: str, new: str) -> Path:
    """``examples/<name>`` with ``old`` replaced by ``new``, alone in a folder of its own
    (as a user's copy of an example may be)."""
    folder = tmp_path / "examples"
    folder.mkdir()
    text = (EXAMPLES / name).read_text()
    assert old in text
    script = folder / name
    script.write_text(text.replace(old, new))
    return script


def assert_one_line_refusal(done: subprocess.CompletedProcess, wanted: str) -> None:
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("error: ")
    assert wanted in done.stderr


def test_physics_tipping_with_the_qp_refuses_the_mpc_option_in_one_line(tmp_path) -> None:
    script = edited_copy(tmp_path, "physics_tipping.py", 'controller="mpc"', 'controller="qp"')
    done = _run_python([str(script)], tmp_path)
    assert_one_line_refusal(done, "error: method qp: unknown option 'arm_time_constant'")


def test_compare_aux_with_an_unknown_method_refuses_it_in_one_line(tmp_path) -> None:
    script = edited_copy(tmp_path, "compare_aux.py", '"ats", aux=aux', '"atz", aux=aux')
    done = _run_python([str(script)], tmp_path)
    assert_one_line_refusal(done, "error: method: unknown method 'atz'")


def test_quickstart_refuses_an_unknown_method_in_one_line(tmp_path) -> None:
    done = _run_python([str(EXAMPLES / "quickstart.py"), "bogus"], tmp_path)
    assert_one_line_refusal(done, "error: method: unknown method 'bogus'")
    assert done.stdout == ""


def test_quickstart_refuses_a_second_method_in_one_line(tmp_path) -> None:
    """`quickstart.py ats pi` ran ats alone, the pi silently dropped."""
    done = _run_python([str(EXAMPLES / "quickstart.py"), "ats", "pi"], tmp_path)
    assert_one_line_refusal(done, "error: method: one METHOD per run (got 2: ats pi)")
    assert done.stdout == ""


@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_quickstart_help_prints_its_usage_not_an_unknown_method(tmp_path, flag) -> None:
    """A newcomer's first try, `quickstart.py --help`, is the usage, not a refusal."""
    done = _run_python([str(EXAMPLES / "quickstart.py"), flag], tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert done.stdout.startswith("usage: python examples/quickstart.py [METHOD]")
    assert "clrrmc-ts" in done.stdout and "mpc" in done.stdout


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_every_example_ends_through_the_shared_runner(script: Path) -> None:
    """One pattern, not a copy per script: each __main__ block hands main to run_script."""
    main_block = script.read_text().split('if __name__ == "__main__":', 1)[1]
    assert "from ddwmmr.cli.common import run_script" in script.read_text()
    assert re.search(r"^    run_script\(main\b", main_block, re.MULTILINE)
    assert "except" not in main_block


@pytest.mark.parametrize(
    ("method", "singular", "final_mm", "rms_mm"),
    [("pi", 1183, 3027, 1870), ("ap", 1187, 3638, 2711)],
)
def test_quickstart_says_when_a_method_did_not_track(
    capsys, method, singular, final_mm, rms_mm
) -> None:
    """pi and ap end metres off the ellipse: the verdict says so, with the numbers the
    summary above it prints (in mm) and the singularity as the likely cause. The script's
    main is called in-process: the method argument reaching main from the command line is
    test_quickstart_refuses_an_unknown_method_in_one_line's."""
    _load("quickstart").main(method)
    lines = capsys.readouterr().out.splitlines()
    values = {line.split()[0]: float(line.split()[1]) for line in lines[1:10]}
    verdict = " ".join(line.strip() for line in lines[10:-1])
    assert lines[10].startswith("verdict: did not track: singular (damped) ")
    assert lines[-1].startswith("  first command u =")
    found = re.search(
        r"singular \(damped\) (\d+) of (\d+) steps, "
        r"settled-end RMS position error (\d+) mm \(limit ([\d.]+) mm\), RMS error (\d+) mm",
        verdict,
    )
    assert found, verdict
    assert int(found[1]) == singular == values["singular_steps"]
    assert int(found[2]) == 2000
    assert int(found[3]) == pytest.approx(1000 * values["final_position_error_m"], abs=1)
    assert int(found[3]) == pytest.approx(final_mm, abs=2)
    assert int(found[5]) == pytest.approx(1000 * values["rms_position_error_m"], abs=1)
    assert int(found[5]) == pytest.approx(rms_mm, abs=2)
    # the limit: twice the initial offset |(-30, -30)| mm
    assert float(found[4]) == pytest.approx(2 * 1000 * 0.03 * 2**0.5, abs=0.01)
    assert "likely cause: the resolution drives the shoulder into its singularity" in verdict


def test_run_script_exits_0_whatever_main_returns(tmp_path) -> None:
    script = tmp_path / "returns.py"
    script.write_text(
        "from ddwmmr.cli.common import run_script\n"
        "run_script(lambda: {'rms': 1.0})\n"  # a truthy return value is no exit status
    )
    done = _run_python([str(script)], tmp_path)
    assert done.returncode == 0 and done.stdout == "" and done.stderr == ""
