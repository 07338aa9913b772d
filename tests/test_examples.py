"""Every script in examples/ runs, prints something sensible and writes no files."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCRIPTS = sorted(EXAMPLES.glob("*.py"))
#: Text each example must print (scripts not listed must print something).
EXPECTED = {
    "quickstart.py": ("clrrmc-ts on ellipse", "rms_position_error_m", "first command u"),
    "custom_trajectory.py": ("ats", "clrrmc-ts", "final"),
    "compare_aux.py": ("rectangle  sum", "ellipse    shoulder"),
    "own_robot.py": ("default (thesis)", "long arm (TOML)", "would tip over"),
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
    assert {p.name for p in SCRIPTS} >= set(EXPECTED)


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_example_runs(script: Path, tmp_path: Path) -> None:
    done = _run_python([str(script)], tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip()
    for text in EXPECTED.get(script.name, ()):
        assert text in done.stdout
    assert list(tmp_path.iterdir()) == []  # nothing written in the working directory


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


DOCS = Path(__file__).resolve().parents[1] / "docs"
DOC_PAGES = ("api.md", "tutorial_custom_trajectory.md", "theory.md", "thesis.md")
#: Per page: (text its snippets must contain, text they must print).
DOC_EXPECTED = {"thesis.md": (("run_many",), ("ok", "move_arm"))}


def _python_blocks(page: Path) -> str:
    """The page's ```python blocks, concatenated (they run top to bottom in one session)."""
    blocks, inside = [], False
    for line in page.read_text().splitlines():
        if line.strip() == "```python":
            inside = True
        elif line.strip() == "```" and inside:
            inside = False
            blocks.append("")
        elif inside:
            blocks.append(line)
    return "\n".join(blocks)


@pytest.mark.parametrize("page", DOC_PAGES)
def test_doc_snippets_run(page: str, tmp_path: Path) -> None:
    code = _python_blocks(DOCS / page)
    assert code.strip()
    in_code, in_output = DOC_EXPECTED.get(page, ((), ()))
    for text in in_code:
        assert text in code
    done = _run_python(["-c", code], tmp_path)
    assert done.returncode == 0, done.stderr
    for text in in_output:
        assert text in done.stdout
