"""Your own robot: from a TOML file, or a modified copy of the default one.

Writes a TOML file into a temporary directory only, then prints the tip-over stability and
tracking of the default robot, a heavier payload and a longer-armed robot. Prints only.
"""

from __future__ import annotations

import tempfile
from dataclasses import replace
from pathlib import Path

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.cli.common import run_script  # bad input: one line, status 2

ROBOT_TOML = """\
# Field names of ddwmmr.Robot; missing fields keep their defaults (SI units).
[robot]
L1 = 0.45            # m
L2 = 0.35            # m
payload = 2.0        # kg
base_length = 0.55   # m
base_width = 0.40    # m
"""


def report(label: str, robot: Robot) -> None:
    """Print reach, worst-case stability along a clrrmc-ts run, and tracking error."""
    # A start that tips the robot over is what this study looks for: run it without the
    # warning simulate gives by default, and say it here (summary["start_tipped"]).
    summary = simulate(robot, Ellipse(), "clrrmc-ts", tipped_start="allow").summary
    print(
        f"{label:<22} reach {robot.reach:.2f} m  payload {robot.payload:.2f} kg  "
        f"min S {summary['min_stability']:.2f}  "
        f"rms error {summary['rms_position_error_m'] * 1000:.2f} mm"
        + ("  (S <= 1: would tip over)" if summary["min_stability"] <= 1.0 else "")
    )


def main() -> None:
    """Build three robots and compare them on the default ellipse."""
    report("default (thesis)", Robot())
    report("default, 3 kg payload", Robot().with_payload(3.0))
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "long_arm.toml"
        path.write_text(ROBOT_TOML)
        long_arm = Robot.from_toml(path)
    report("long arm (TOML)", long_arm)
    report("long arm, 6 kg payload", replace(long_arm, payload=6.0))


if __name__ == "__main__":
    run_script(main)
