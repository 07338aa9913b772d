"""Running a program in the real Tk window on a virtual X display (``xvfb-run``), for the
tests that need one; they skip with :data:`NEEDS_XVFB` where it is not installed (CI)."""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest

#: Skip marker of a test module whose programs need ``xvfb-run``.
NEEDS_XVFB = pytest.mark.skipif(
    shutil.which("xvfb-run") is None,
    reason="xvfb-run is not installed: the real Tk window needs a display (make gui-check)",
)


def run_under_xvfb(command: list[str], timeout: float = 300) -> subprocess.CompletedProcess:
    """``command`` on a fresh 1920 x 1080 virtual screen, with no DISPLAY or MPLBACKEND
    of the test's own (the program chooses Tk); its output captured as text."""
    environment = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "MPLBACKEND")}
    return subprocess.run(
        ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", *command],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=environment,
    )
