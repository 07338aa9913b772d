"""A start far from the origin (coordinates up to the documented 1e6 m) is placed with
its initial offset to the same relative accuracy as one near it, never refused for
float spacing."""

import math

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.resolution.reference import (
    DEFAULT_INITIAL_OFFSET,
    OFFSET_TOLERANCE_M,
    offset_configuration,
    start_configuration,
)

# Starts where an absolute 1e-12 m (below one float spacing there) was refused.
FAR_STARTS = [
    (1e4, -1e4, 0.3, DEFAULT_INITIAL_OFFSET),
    (1e5, -1e5, 0.3, DEFAULT_INITIAL_OFFSET),
    (1e5, -1e5, 1.2, (0.02, 0.03)),
    (316227.7660168379, -316227.7660168379, 1.2, DEFAULT_INITIAL_OFFSET),
    (1e6, -1e6, 1.2, DEFAULT_INITIAL_OFFSET),
    (1e6, -1e6, 3.0, (-0.1, 0.05)),
]


def _placement_error(robot: Robot, q0: np.ndarray, q: np.ndarray, offset) -> tuple[float, float]:
    """Distance (m) of the placed end effector from ``offset`` in q0's end-effector frame,
    and the target's largest coordinate (m)."""
    x, y, phi = robot.fk(q0)
    c, s = math.cos(phi), math.sin(phi)
    target = np.array([x + c * offset[0] - s * offset[1], y + s * offset[0] + c * offset[1]])
    return float(np.hypot(*(target - robot.fk(q)[:2]))), float(np.max(np.abs(target)))


@pytest.mark.parametrize(("x0", "y0", "beta", "offset"), FAR_STARTS)
def test_far_offset_is_placed_to_relative_accuracy(x0, y0, beta, offset) -> None:
    robot = Robot()
    q0 = start_configuration(robot, Ellipse(x0=x0, y0=y0, beta=beta))
    q = offset_configuration(robot, q0, offset)
    error, scale = _placement_error(robot, q0, q, offset)
    assert error <= 1e-14 * scale
    np.testing.assert_array_equal(q[:3], q0[:3])  # the base does not move


def test_near_start_keeps_the_absolute_tolerance() -> None:
    robot = Robot()
    q0 = start_configuration(robot, Ellipse())
    q = offset_configuration(robot, q0, DEFAULT_INITIAL_OFFSET)
    error, _ = _placement_error(robot, q0, q, DEFAULT_INITIAL_OFFSET)
    assert error < OFFSET_TOLERANCE_M


def test_far_run_starts_and_tracks() -> None:
    summary = simulate(Robot(), Ellipse(x0=1e4, y0=-1e4, beta=0.3), "ats", duration=0.5).summary
    assert math.isclose(summary["max_position_error_m"], math.hypot(0.03, 0.03), rel_tol=1e-6)
