"""Which of the thesis plant's constants come from the robot: the arm servo's speed is the
robot's ``joint_speed_limit``; the force limit and the damping c1, c2 are the thesis's for
the thesis robot and derived from them for another, with one warning line when they differ
(docs/thesis.md, "What is simulated"; tests/test_thesis_plant_scaling.py)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.commands import WheelForces
from ddwmmr.plants import make_plant
from ddwmmr.plants.thesis import ThesisPlant
from scaled_robots import TEN_TIMES

START = np.array([0.0, 0.0, 0.0, -0.3, 0.6])
DT = 0.1
#: The probe's heavy robot: 30 N m motors on 0.2 m wheels, 150 N per wheel.
BIG = Robot(wheel_radius=0.2, wheel_torque_limit=30.0)


def _built(build):
    """``build()``'s result and the warnings it raised, under Python's default filter."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        result = build()
    return result, [str(w.message) for w in caught]


@pytest.mark.parametrize("speed", [4.0, 0.5])
def test_arm_servo_moves_at_the_robots_joint_speed_limit(speed):
    """Joint targets 1 rad away: in 0.1 s the leading joint moves speed * 0.1 rad (the
    robot's limit, not the thesis's 2 rad/s), the other in proportion (0.5 of it)."""
    plant = ThesisPlant(Robot(joint_speed_limit=speed))
    plant.reset(START, DT)
    plant.step(0.0, WheelForces(0.0, 0.0, -0.3 + 1.0, 0.6 - 0.5), DT)
    assert plant.joint_speed == speed
    assert plant.state.th1 == pytest.approx(-0.3 + speed * DT, abs=1e-12)
    assert plant.state.th2 == pytest.approx(0.6 - 0.5 * speed * DT, abs=1e-12)


def test_velocity_command_joint_rate_above_two_is_followed():
    """A 3 rad/s joint rate on a 4 rad/s robot: ``limit`` passes it and the arm follows it
    (0.3 rad in 0.1 s), instead of creeping at 2 rad/s (0.2 rad)."""
    plant = ThesisPlant(Robot(joint_speed_limit=4.0))
    plant.reset(START, DT)
    u = np.array([0.0, 0.0, 3.0, 0.0])
    assert plant.limit(START, u)[1] is False
    plant.step(0.0, u, DT)
    assert plant.state.th1 == pytest.approx(-0.3 + 0.3, abs=1e-12)


def test_default_robot_keeps_the_thesis_constants_silently():
    """The thesis robot (any payload): 10 N, c1 = 15, c2 = 4, 2 rad/s, no warning."""
    for robot in (Robot(), Robot().with_payload(3.0)):
        plant, messages = _built(lambda r=robot: make_plant("thesis", r))
        assert messages == []
        assert (plant.force_limit, plant.c1, plant.c2, plant.joint_speed) == (10.0, 15, 4, 2)


def test_other_wheel_drive_warns_once_naming_the_derived_constants():
    """A robot with other wheel motors (150 N) gets the thesis's share of them, 10 N of
    20.5 N: 73.125 N, and is told so in one line, once for two plants."""
    plants, messages = _built(lambda: [ThesisPlant(BIG) for _ in range(2)])
    assert len(messages) == 1 and "\n" not in messages[0]
    assert messages[0] == (
        "thesis plant: force_limit = 73.13 N (the thesis's 10 N scaled by its motors' force, "
        "150 / 20.51 N) derived for this robot (ThesisPlant(robot, force_limit=...) sets it; "
        "track: --plant-option force_limit=...)"
    )  # c1, c2 derived too, but the thesis's own 15 and 4: not named
    assert plants[0].force_limit == pytest.approx(10.0 * 150.0 / (2.0 / 0.0975), rel=1e-12)


def test_given_force_limit_is_used_without_warning():
    """``force_limit`` given (the robot's own 150 N): used, and nothing to warn about."""
    plant, messages = _built(lambda: ThesisPlant(BIG, force_limit=150.0))
    assert messages == []
    assert plant.force_limit == 150.0
    assert plant.velocity_envelope(1.0)["max_base_speed"] == pytest.approx(300.0 / 15.0)


def test_given_damping_is_not_named_as_derived():
    """c1, c2 given: only the force limit is derived and named."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plant = ThesisPlant(BIG, c1=5.0, c2=1.0)
    (message,) = [str(w.message) for w in caught]
    assert message.startswith("thesis plant: force_limit = 73.13 N (the thesis's 10 N")
    assert "c1" not in message and "c2" not in message
    assert message.endswith("sets it; track: --plant-option force_limit=...)")
    assert (plant.c1, plant.c2) == (5.0, 1.0)


def test_given_force_limit_names_only_the_derived_damping():
    """``force_limit`` given to the ten-times robot: the line names c1 and c2, each with the
    thesis's value and what it scales with, and suggests setting exactly those; not the
    force limit the user set, nor the thesis's 10 N."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plant = ThesisPlant(TEN_TIMES, force_limit=500.0)
    (message,) = [str(w.message) for w in caught]
    assert "\n" not in message
    assert message.startswith(
        "thesis plant: c1 = 1.5e+04 N s/m (the thesis's 15 N s/m scaled by its own mass, "
        "1.2e+04 / 12 kg), c2 = 4e+05 N m s/rad (the thesis's 4 N m s/rad scaled by its own "
        "yaw inertia, 7.983e+04 / 0.7983 kg m^2) derived for this robot"
    )
    assert message.endswith(
        "(ThesisPlant(robot, c1=..., c2=...) sets them; track: --plant-option c1=... "
        "--plant-option c2=...)"
    )
    assert "force_limit" not in message and "10 N" not in message and "motors" not in message
    assert (plant.force_limit, plant.c1, plant.c2) == pytest.approx((500.0, 1.5e4, 4e5))
