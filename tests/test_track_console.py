"""Track's console names the settled-end RMS apart from the error at the last sample and
shows the limits a method holds itself beside the steps the plant clipped; its path figure
has no empty bands around the equal-scale axes."""

from __future__ import annotations

import matplotlib.pyplot as plt
import pytest

from ddwmmr import Robot, simulate
from ddwmmr.cli.track import format_table
from ddwmmr.reports import plots
from ddwmmr.trajectories import load_trajectory

#: The probe's qp on the rectangle: the joint rate held at +2 rad/s on 145 steps.
SUMMARY = {
    "method": "qp",
    "trajectory": "rectangle",
    "plant": "kinematic",
    "final_position_error_m": 2.727953425720948e-06,
    "end_position_error_m": 0.0031360737972504042,
    "saturated_steps": 0,
    "wheel_limit_steps": 0,
    "joint_rate_limit_steps": 145,
}


def test_console_names_the_settled_end_and_the_held_limits() -> None:
    lines = format_table(SUMMARY).splitlines()
    assert lines[1:] == [
        "  settled-end RMS position error (mm)  0.00272795",
        "  position error at the end (mm)       3.13607",
        "  saturated steps (plant clipped)      0",
        "  wheel at speed limit (steps)         0",
        "  joint at rate limit (steps)          145",
    ]


@pytest.mark.parametrize(
    ("traj", "duration", "heights"),
    [("rectangle", 40.0, (4.0, 5.6)), ("ellipse", 10.0, (5.6, 9.0))],  # wide; a tall arc
)
def test_the_path_axes_fill_the_space_beside_the_legend(
    traj: str, duration: float, heights: tuple[float, float]
) -> None:
    result = simulate(Robot(), load_trajectory(traj), "ats", duration=duration)
    fig = plots.plot_path(result)
    fig.canvas.draw()
    ax = fig.axes[0]
    box, frame = ax.get_position(), fig.subplotpars
    # equal scale: the box shrinks to the data's shape; it now meets all four margins
    assert box.x0 == pytest.approx(frame.left, abs=0.01)
    assert box.x1 == pytest.approx(frame.right, abs=0.01)
    assert box.y0 == pytest.approx(frame.bottom, abs=0.01)
    assert box.y1 == pytest.approx(frame.top, abs=0.01)
    width, height = fig.get_size_inches()
    assert width == pytest.approx(8.6) and heights[0] <= height <= heights[1]
    plt.close(fig)
