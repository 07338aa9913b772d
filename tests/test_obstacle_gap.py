"""The obstacle gap: one measure for the scenario protocol's collision check and the path
figures' "closest gap"."""

from __future__ import annotations

import math

import pytest

from ddwmmr.behaviours.obstacle import base_bubble, bubble_gap
from ddwmmr.model import Robot
from ddwmmr.scenarios import RunConfig, generate
from ddwmmr.scenarios.protocol import _Tally


def test_gap_is_the_distance_between_the_circles():
    # 3-4-5 triangle: centres 5 m apart, radii 1 and 1.5 m
    assert bubble_gap(3.0, 4.0, (0.0, 0.0, 1.0), 1.5) == pytest.approx(2.5, abs=1e-15)
    assert bubble_gap(0.5, 0.0, (0.0, 0.0, 1.0), 1.5) == pytest.approx(-2.0, abs=1e-15)


@pytest.mark.parametrize("offset", [-1e-9, 0.0, 1e-9])
def test_the_protocol_collides_exactly_where_the_gap_is_negative(offset):
    robot = Robot()
    bubble = base_bubble(robot)
    scenario = generate(1, 0)[0]
    # an obstacle straight ahead of a base at the origin, its edge at the bubble +- offset
    radius = 0.3
    centre = bubble + radius + offset
    scenario = type(scenario)(**{**scenario.__dict__, "obstacles": ((centre, 0.0, radius),)})
    tally = _Tally(robot, scenario, RunConfig())
    q = [0.0, 0.0, 0.0, robot.home_pose[0], robot.home_pose[1]]
    gap = bubble_gap(0.0, 0.0, scenario.obstacles[0], bubble)
    assert math.copysign(1.0, gap) == math.copysign(1.0, offset) or gap == 0.0
    collided = tally.check(q) and tally.reason == "collision"
    assert collided == (gap < 0.0)
