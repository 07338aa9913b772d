"""Running a program in the real Tk window on a virtual X display (``xvfb-run``), for the
tests that need one; they skip with :data:`NEEDS_XVFB` where it is not installed (CI)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

#: Skip marker of a test module whose programs need ``xvfb-run``.
NEEDS_XVFB = pytest.mark.skipif(
    shutil.which("xvfb-run") is None,
    reason="xvfb-run is not installed: the real Tk window needs a display (make gui-check)",
)


def run_under_xvfb(command: list[str], timeout: float = 300) -> subprocess.CompletedProcess:
    """``command`` on a fresh 1920 x 1080 virtual screen, with no DISPLAY or MPLBACKEND
    of the test's own (the program chooses Tk) and this folder first on its PYTHONPATH
    (a script imports the tests' helpers: :mod:`tk_steps`, :mod:`figure_checks`); its
    output captured as text."""
    environment = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "MPLBACKEND")}
    path = [str(Path(__file__).resolve().parent), environment.get("PYTHONPATH", "")]
    environment["PYTHONPATH"] = os.pathsep.join(p for p in path if p)
    return subprocess.run(
        ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", *command],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=environment,
    )
