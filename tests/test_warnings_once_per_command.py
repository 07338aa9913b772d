"""A library warning that every run repeats is said once per command: the tools' one-line
display shows each line once, and pool workers do not repeat the lines their parent showed
(the thesis plant's derived constants for a robot other than the thesis robot)."""

from __future__ import annotations

import subprocess
import sys
import warnings

import pytest

from ddwmmr.cli.common import one_line_warnings
from ddwmmr.model import Robot
from ddwmmr.plants import ThesisPlant

HEAVY = "[robot]\nbase_mass = 60.0\nbase_inertia = 3.0\nwheel_mass = 2.0\n"


def test_the_one_line_display_shows_a_repeated_warning_once(capsys):
    robot = Robot(base_mass=60.0, base_inertia=3.0, wheel_mass=2.0)
    with one_line_warnings(), warnings.catch_warnings():
        warnings.simplefilter("always")  # Python's filter would show each build's
        for _ in range(3):
            ThesisPlant(robot)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: thesis plant: c1 = 77.5 N s/m")


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_compare_on_the_thesis_plant_warns_about_the_robot_once(tmp_path, jobs):
    """Two runs (two methods on the ellipse), each building a thesis plant for the robot:
    in the parent one after the other, or one in each of two pool workers."""
    robot = tmp_path / "heavy.toml"
    robot.write_text(HEAVY)
    done = subprocess.run(
        [sys.executable, "-m", "ddwmmr.compare", "--robot", str(robot), "--plant", "thesis",
         "--methods", "pi,ats", "--only", "ellipse", "--study", "none", "--duration", "1",
         "--jobs", jobs,
         "--out", str(tmp_path / "out"), "--no-progress"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("warning: thesis plant: c1 = 77.5 N s/m") == 1, done.stderr
