"""A tool's Ctrl-C guard is installed by ``import ddwmmr`` before any module Python has
not loaded at start-up already: ``typing`` (a few ms of import) comes after it."""

from __future__ import annotations

import subprocess
import sys


def imported_in_order(*arguments: str) -> list[str]:
    """The modules a fresh ``python -X importtime ARGUMENTS`` imports, in order."""
    out = subprocess.run(
        [sys.executable, "-X", "importtime", *arguments],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    lines = [line for line in out.stderr.splitlines() if line.startswith("import time:")]
    return [line.split("|")[2].strip() for line in lines[1:]]  # [0]: the column titles


def test_the_guard_comes_before_typing_in_a_tool(tmp_path):
    names = imported_in_order("-m", "ddwmmr.track", "--help")
    assert "ddwmmr.cli.signals" in names and "typing" in names
    assert names.index("ddwmmr.cli.signals") < names.index("typing")
    # nor before the guard's first import: Python's start-up and runpy do not load it
    assert "typing" not in names[: names.index("ddwmmr.__main__")]


def test_a_library_import_installs_no_guard_and_keeps_its_exports():
    code = "import ddwmmr, sys; print('ddwmmr.cli.signals' in sys.modules, ddwmmr.__version__)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    guarded, version = out.stdout.split()
    assert guarded == "False" and version.count(".") >= 1
