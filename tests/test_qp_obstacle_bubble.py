"""The qp in the scenario protocol keeps clear what the protocol judges: the base's
enclosing circle (``base_bubble``), not only its footprint rectangle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.behaviours.obstacle import base_bubble
from ddwmmr.commands import PlantTraits
from ddwmmr.controllers.base import WaypointRun
from ddwmmr.qp.controller import QPController
from ddwmmr.qp.limits import Circle
from ddwmmr.qp.limits.obstacles import clearance_and_rate
from ddwmmr.scenarios import RunConfig, run_scenario
from ddwmmr.scenarios.generator import Scenario, generate, place_obstacles

ROBOT = Robot()
KINEMATIC = PlantTraits(interfaces=("velocity",), judges_tipping=False, joint_time_constant=None)


def _options(scenario: Scenario) -> dict:
    config = RunConfig(controller="qp", plant="kinematic")
    return QPController.waypoint_options(
        WaypointRun(scenario, config, KINEMATIC, ROBOT.with_payload(config.payload))
    )


def test_the_circles_grow_by_the_bubble_less_the_half_width():
    """0.3 m grows to 0.3 + 0.2850 - 0.175 m (the footprint is 0.45 m x 0.35 m)."""
    options = _options(Scenario(0, ((5.0, 0.0),), ((2.0, 0.5, 0.3), (-1.0, 3.0, 0.1))))
    grow = math.hypot(0.225, 0.175) - 0.175
    assert grow == pytest.approx(0.110044, abs=1e-6)
    assert options["obstacles"] == [
        pytest.approx((2.0, 0.5, 0.3 + grow)),
        pytest.approx((-1.0, 3.0, 0.1 + grow)),
    ]


def test_a_footprint_clear_of_the_grown_circle_keeps_the_bubble_clear():
    """Wherever the footprint touches the grown circle, the enclosing circle is clear of
    the real one; level with a long side they touch exactly."""
    radius = 0.3
    ((x, y, grown),) = _options(Scenario(0, ((5.0, 0.0),), ((0.0, 0.0, radius),)))["obstacles"]
    bubble = base_bubble(ROBOT)
    closest = math.inf
    for heading in np.linspace(-math.pi, math.pi, 13):
        for bearing in np.linspace(-math.pi, math.pi, 25):
            # the centre distance at which the footprint touches the grown circle
            low, high = 0.0, 5.0
            for _ in range(60):
                mid = 0.5 * (low + high)
                bx, by = -mid * math.cos(bearing), -mid * math.sin(bearing)
                d = clearance_and_rate(0.225, 0.175, bx, by, heading, Circle(x, y, grown))[0]
                low, high = (mid, high) if d < 0.0 else (low, mid)
            closest = min(closest, high)
    assert closest >= radius + bubble - 1e-9
    assert closest == pytest.approx(radius + bubble, abs=1e-9)  # beside a long side


@pytest.mark.parametrize(("number", "seconds"), [(1, 36.14), (3, 39.04)])
def test_the_obstacle_scenarios_complete_on_the_physics_plant(number, seconds):
    """Scenarios 1 and 3 of ``--obstacles --n 3`` on MuJoCo ended in 'collision' with the
    footprint 84 and 94 mm clear (the enclosing circle inside a post's radius + 0.285 m);
    now both complete."""
    scenario = place_obstacles(generate(3, seed=0)[number - 1])
    outcome = run_scenario(scenario, RunConfig(controller="qp", plant="mujoco"))
    assert outcome.metrics["reason"] == "ok"
    assert outcome.metrics["time_s"] == pytest.approx(seconds, abs=0.5)
