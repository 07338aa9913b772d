"""``make gui-check`` (``python -m ddwmmr.gui.check`` under ``xvfb-run``) does what
docs/gui.md says: the real Tk window takes the typed duration and the clicked Run, plays
the run back and is screenshotted. Skipped where ``xvfb-run`` is not installed (CI)."""

from __future__ import annotations

import sys
from pathlib import Path

from xvfb import NEEDS_XVFB, run_under_xvfb

pytestmark = NEEDS_XVFB


def test_the_tk_window_takes_the_typed_duration_and_the_click(tmp_path: Path) -> None:
    """The check types 5.5 into duration as soon as it starts; a canvas Tk has not mapped
    yet (a loaded machine) dropped those key events, and the run lasted the 6 s set up."""
    done = run_under_xvfb([sys.executable, "-m", "ddwmmr.gui.check", str(tmp_path)])
    assert done.returncode == 0, done.stderr
    assert "duration typed and Run clicked via Tk" in done.stdout
    assert "playback of 5.5 s" in done.stdout  # the typed duration, not the 6 s set up
    assert {p.name for p in tmp_path.iterdir()} == {"window_screen.png", "window_figure.png"}
