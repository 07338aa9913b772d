"""What docs/thesis.md and docs/cli.md say of the scaled robots' runs, the weak-arm robot and
the gain-step warning holds: the twentieth robot's rectangle, the sign of the offsets the
measurements come with, the wheel motors of the weak arm, and the help texts and docs that
name the warning and the thesis plant's derived constants."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from ddwmmr import Ellipse, Rectangle, Robot, simulate
from ddwmmr.cli.track import build_parser
from ddwmmr.gains import GAIN_STEP_MARGIN
from scaled_robots import TWENTIETH
from test_verdict_force_cause import WEAK_ARM

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _joined(name: str) -> str:
    return re.sub(r"\s*\n\s*", " ", (DOCS / name).read_text(encoding="utf-8"))


def _help(option: str) -> str:
    action = next(a for a in build_parser()._actions if option in a.option_strings)
    return " ".join(action.help.split())


def _thesis_run(robot: Robot, trajectory, method: str, offset: tuple[float, float]) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the thesis plant's constants derived from the robot
        return simulate(robot, trajectory, method, plant="thesis", initial_offset=offset).summary


@pytest.mark.parametrize(
    ("method", "tracked", "rms_mm", "final_mm"),
    [("qp", True, 2.08, 0.305), ("ats", False, 9.18, 20.25)],
)
def test_the_twentieth_robot_s_rectangle_tracks_with_qp_and_folds_with_ats(
    method, tracked, rms_mm, final_mm
):
    rectangle = Rectangle(a=0.1, b=0.075, T=40.0, N=2000)
    summary = _thesis_run(TWENTIETH, rectangle, method, (0.0015, 0.0015))
    assert (summary["verdict"] == "tracked") is tracked
    assert summary["rms_position_error_m"] * 1e3 == pytest.approx(rms_mm, abs=0.01)
    assert summary["final_position_error_m"] * 1e3 == pytest.approx(final_mm, abs=0.005)
    if not tracked:
        assert summary["min_manipulability"] < 1e-6  # the arm folded
    text = _joined("thesis.md")
    assert (
        "the twentieth robot's `qp` tracks (RMS 2.08 mm, 0.305 mm at the end, no wheel at its "
        "force limit) and its `ats` does not (arm folded, 20.25 mm at the end)"
    ) in text


@pytest.mark.parametrize(("offset", "final_mm"), [(0.03, 31.0), (-0.03, 62.2)])
def test_the_thesis_table_s_ats_number_needs_the_positive_offset(offset, final_mm):
    ellipse = Ellipse(a=2.0, b=1.5, T=40.0, N=2000)
    summary = _thesis_run(Robot(), ellipse, "ats", (offset, offset))
    assert summary["final_position_error_m"] * 1e3 == pytest.approx(final_mm, abs=0.05)
    text = _joined("thesis.md")
    assert "start offset `+0.03 s` m each way, e.g. `--offset 0.03 0.03`" in text
    assert "the CLI's default offset, -0.03 m each way, gives the thesis robot's `ats` 62.2 mm" in (
        text
    )


def test_the_ten_times_paragraph_names_the_offset_its_numbers_come_with():
    """Its numbers are test_verdict_force_cause's, run from (0.3, 0.3)."""
    text = _joined("cli.md")
    start = text.index("The ten-times robot of tests/scaled_robots.py")
    paragraph = text[start : text.index('hence "may"', start)]
    assert "866 of 2000 steps" in paragraph and "0.269" in paragraph
    assert "from `--offset 0.3 0.3` (the numbers below come with this offset" in paragraph


def test_the_weak_arm_example_names_all_its_motors():
    arm = " and ".join(f"{t:g}" for t in WEAK_ARM.joint_torque_limits)
    described = (
        f"a robot with {arm} N m arm motors and {WEAK_ARM.wheel_torque_limit:g} N m wheel motors "
        f"({WEAK_ARM.payload:g} kg payload)"
    )
    assert described in _joined("cli.md")


@pytest.mark.parametrize("option", ["--tau", "--dt"])
def test_tau_and_dt_help_name_the_gain_step_warning(option):
    text = _help(option)
    assert f"reaches {GAIN_STEP_MARGIN:g} of its loop's stability limit" in text
    assert '(docs/theory.md, "Error dynamics and python-control")' in text


def test_the_dt_row_of_cli_md_names_the_gain_step_warning():
    row = next(line for line in (DOCS / "cli.md").open() if line.startswith("| `--dt S`"))
    assert (
        f"reaches {GAIN_STEP_MARGIN:g} of its loop's stability limit gets a one-line warning"
        in (row)
    )
    assert '[theory.md](theory.md), "Error dynamics and python-control", section 6' in row


def test_plant_option_help_names_the_derived_constants():
    assert (
        "for a robot other than the thesis robot the thesis plant's c1, c2 and force_limit "
        "default to values derived from its motors, mass and yaw inertia"
    ) in _help("--plant-option")


def test_compare_section_says_its_plants_run_on_their_defaults():
    text = _joined("cli.md")
    section = text[text.index("## `python -m ddwmmr.compare`") :]
    assert (
        "`compare --plant` runs each plant on its default options and refuses `--plant-option`: "
        "a `--robot` other than the thesis robot runs the thesis plant on the c1, c2 and "
        "force_limit derived from its motors"
    ) in section
    assert "`track --plant-option NAME=VALUE` sets them for one run" in section
