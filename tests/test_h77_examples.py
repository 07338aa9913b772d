"""The examples, edited by a user with a value the library refuses, end as the tools do
(one line on stderr, status 2, no traceback), all through ddwmmr.cli.common.run_script; the
quickstart prints the run's verdict as `python -m ddwmmr.track` does."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCRIPTS = sorted(p for p in EXAMPLES.glob("*.py") if not p.name.startswith("_"))


def run_python(arguments: list[str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, *arguments],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )


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
    done = run_python([str(script)], tmp_path)
    assert_one_line_refusal(done, "error: method qp: unknown option 'arm_time_constant'")


def test_compare_aux_with_an_unknown_method_refuses_it_in_one_line(tmp_path) -> None:
    script = edited_copy(tmp_path, "compare_aux.py", '"ats", aux=aux', '"atz", aux=aux')
    done = run_python([str(script)], tmp_path)
    assert_one_line_refusal(done, "error: method: unknown method 'atz'")


def test_quickstart_refuses_an_unknown_method_in_one_line(tmp_path) -> None:
    done = run_python([str(EXAMPLES / "quickstart.py"), "bogus"], tmp_path)
    assert_one_line_refusal(done, "error: method: unknown method 'bogus'")
    assert done.stdout == ""


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
    tmp_path, method, singular, final_mm, rms_mm
) -> None:
    """pi and ap end metres off the ellipse: the verdict says so, with the numbers the
    summary above it prints (in mm) and the singularity as the likely cause."""
    done = run_python([str(EXAMPLES / "quickstart.py"), method], tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    values = {line.split()[0]: float(line.split()[1]) for line in lines[1:10]}
    verdict = " ".join(line.strip() for line in lines[10:-1])
    assert lines[10].startswith("verdict: did not track: singular (damped) ")
    assert lines[-1].startswith("  first command u =")
    found = re.search(
        r"singular \(damped\) (\d+) of (\d+) steps, final error (\d+) mm \(limit ([\d.]+) mm\), "
        r"RMS error (\d+) mm",
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
    done = run_python([str(script)], tmp_path)
    assert done.returncode == 0 and done.stdout == "" and done.stderr == ""
