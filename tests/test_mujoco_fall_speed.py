"""MujocoPlant's divergence bounds have a gravity floor: a robot with slow motors falls as
fast as any, and its fall is a tip, not a blow-up."""

import math

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.plants.mujoco import MujocoPlant
from ddwmmr.plants.mujoco.plant import SPEED_BOUND_FACTOR

G = 9.81
#: Facing sideways with a 6 kg payload at the arm's end: S 0.69, it tips at once.
SIDEWAYS = np.array([0.0, 0.0, 0.0, math.pi / 2, 0.0])


@pytest.mark.parametrize("wheel_speed_limit", [1.0, 0.1, 0.02])
def test_a_slow_wheeled_robot_falling_over_tips_and_does_not_diverge(wheel_speed_limit):
    """The motors' bounds alone (10 x 0.0975 m/s at 1 rad/s) read this fall as a blow-up:
    at 1 rad/s in step 30, at 0.1 in step 2 before the tip was seen, at 0.02 in step 1."""
    robot = Robot(wheel_speed_limit=wheel_speed_limit).with_payload(6.0)
    summary = simulate(
        robot,
        load_trajectory("ellipse"),
        "clrrmc-ts",
        plant="mujoco",
        duration=0.7,
        dt=0.02,
        q0=SIDEWAYS,
        tipped_start="allow",
    ).summary
    assert "diverged" not in summary and "diverged_at_step" not in summary
    assert summary["tipped"] and summary["tip_time_s"] == pytest.approx(0.08, abs=0.021)
    assert summary["steps"] == 35
    assert summary["max_base_tilt_rad"] > 1.5  # on its side


def test_the_fall_scales_are_gravitys():
    plant = MujocoPlant(Robot())
    fall_speed, fall_rate = plant._fall_scales()
    assert fall_speed == pytest.approx(math.sqrt(2 * G * 0.35), rel=1e-12)  # the arm's plane
    assert fall_rate == pytest.approx(math.sqrt(2 * G / 0.1951), rel=1e-3)  # h_c 0.195 m
    # the default robot's bounds are the fall's: 26.2 m/s and 100 rad/s (the motors': 14.6
    # m/s, 84 rad/s for the base, 20 rad/s for the joints)
    bounds = np.maximum(plant._motor_bounds, plant._fall_bounds)
    assert bounds[0:3] == pytest.approx([SPEED_BOUND_FACTOR * fall_speed] * 3)
    assert bounds[3:6] == pytest.approx([SPEED_BOUND_FACTOR * fall_rate] * 3)
    assert bounds[0] == pytest.approx(26.2, abs=0.05) and bounds[3] == pytest.approx(100.3, abs=0.1)
    # a slow robot keeps the same floor
    slow = MujocoPlant(Robot(wheel_speed_limit=0.02))
    assert slow._bounds[0] == pytest.approx(SPEED_BOUND_FACTOR * fall_speed)


def test_a_blow_up_passes_both_bounds_in_its_step_and_the_message_names_both():
    """A 50 g base with 1 g links on the default robot's tyres (a stiffness for 12 kg)
    blows up in step 11 at 35.8 m/s: beyond the fall's 26.2 m/s as well as the motors'
    14.6 m/s, so the floor catches it as early."""
    tiny = Robot(base_mass=0.05, wheel_mass=0.01, base_inertia=0.001, link_masses=(0.001, 0.001))
    summary = simulate(
        tiny.with_payload(0.0),
        load_trajectory("ellipse"),
        "clrrmc-ts",
        plant="mujoco",
        plant_options={"tyre_stiffness": 5e4},
        duration=0.1,
        dt=0.002,
    ).summary
    assert summary["diverged_at_step"] == 11
    assert summary["diverged"].startswith(
        "MuJoCo state diverged in control step 11 (t = 0.02 to 0.022 s): base speed 35.8 m/s, "
        "beyond 10 times the fastest the motors drive it (14.6 m/s) and a fall moves it "
        "(26.2 m/s) ("
    )
