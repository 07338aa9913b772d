"""The thesis plant with robots other than the thesis's: the wheels' lever, the joint
limits, the reported wheel speeds and the start pose follow the robot's parameters."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.commands import WheelForces
from ddwmmr.errors import ParameterError
from ddwmmr.model import symbolic as sym
from ddwmmr.plants.thesis import ThesisPlant, ThesisState
from ddwmmr.thesis_controller import ThesisController

POSE = (-0.3, 0.6)
#: The thesis robot's joint ranges narrowed (rad): the thesis's default pose has th2 = pi/2.
TIGHT = Robot(joint_limits=((-1.0, 0.5), (0.2, 1.5)), home_pose=POSE)


@pytest.mark.parametrize("track", [0.35, 0.15, 0.5])
def test_yaw_response_uses_the_track_width_as_the_wheels_lever(track):
    """Opposite forces +-5 N for 1 s from rest, arm held: the torque is ``T = b (F_r -
    F_l)`` with ``b = track_width / 2`` (not the footprint's ``base_width / 2``), so
    ``w(t) = (T / c2) (1 - exp(-c2 t / I))`` and ``phi(t) = (T / c2) (t - I/c2 (1 -
    exp(-c2 t / I)))``."""
    robot = Robot(track_width=track)  # base_width stays 0.35 m
    plant = ThesisPlant(robot)
    plant.reset(np.array([0.0, 0.0, 0.0, *POSE]), 0.01)
    for k in range(100):
        plant.step(k * 0.01, WheelForces(-5.0, 5.0, *POSE), 0.01)
    b, c2 = track / 2.0, 4.0
    inertia = plant.inertia(*POSE)
    w_ss, tau = 10.0 * b / c2, inertia / c2
    assert plant.wheel_lever == b
    assert plant.state.w == pytest.approx(w_ss * (1.0 - math.exp(-1.0 / tau)), rel=1e-9)
    assert plant.state.phi == pytest.approx(w_ss * (1.0 - tau * (1.0 - math.exp(-1.0 / tau))))
    # the force-level model the MPC and the bounds use: the same lever and yaw acceleration
    model = sym.ThesisDynamics.from_robot(robot)
    assert model.half_width == b
    x, u = ca.DM([0.0, 0.0, 0.0, *POSE, 0.0, 0.0]), ca.DM([-5.0, 5.0, 0.0, 0.0])
    rate = np.array(model.rhs(x, u)).ravel()
    assert float(rate[6]) == pytest.approx(10.0 * b / model.inertia(POSE[1]), rel=1e-12)
    assert model.top_yaw_rate == pytest.approx(2.0 * 10.0 * b / c2, rel=1e-12)
    assert plant.velocity_envelope() == pytest.approx(model.velocity_envelope())


def test_velocity_servo_turns_at_the_commanded_rate_with_a_narrow_track():
    """The servo's force split uses the same lever as the dynamics: steady state is exact."""
    plant = ThesisPlant(Robot(track_width=0.15))
    plant.reset(np.array([0.0, 0.0, 0.0, *POSE]), 0.01)
    for k in range(1000):
        plant.step(k * 0.01, np.array([0.0, 0.2, 0.0, 0.0]), 0.01)
    assert plant.state.w == pytest.approx(0.2, rel=1e-9)
    left, right = plant.extra_values()
    assert right - left == pytest.approx(4.0 * 0.2 / 0.075, rel=1e-9)  # c2 w / b


def test_velocity_commands_stop_the_joints_at_their_limits():
    """Rates pushing past the limits for 2 s: each joint stops exactly at its limit."""
    plant = ThesisPlant(TIGHT)
    plant.reset(np.array([0.0, 0.0, 0.0, 0.3, 1.2]), 0.01)
    for k in range(200):
        plant.step(k * 0.01, np.array([0.0, 0.0, 1.5, 1.5]), 0.01)
    assert plant.state.th1 == 0.5 and plant.state.th2 == 1.5
    for k in range(200, 500):
        plant.step(k * 0.01, np.array([0.0, 0.0, -1.5, -1.5]), 0.01)
    assert plant.state.th1 == -1.0 and plant.state.th2 == 0.2


def test_tracking_on_the_thesis_plant_keeps_the_joints_within_their_limits():
    """``pi`` on the ellipse drives th1 past 0.5 rad and th2 below 0.2 rad; the plant stops
    them at the limits, the steps pushing at a limit count as saturated (as on the
    kinematic plant) and the run does not read as tracked."""
    (low1, high1), (low2, high2) = TIGHT.joint_limits
    result = simulate(TIGHT, Ellipse(), "pi", plant="thesis", duration=12.0)
    ts = result.timeseries
    assert np.all((low1 <= ts["th1"]) & (ts["th1"] <= high1))
    assert np.all((low2 <= ts["th2"]) & (ts["th2"] <= high2))
    assert ts["th1"].max() == high1 and ts["th2"].min() == low2  # it did reach the limits
    assert result.summary["saturated_steps"] > 0
    assert result.summary["verdict"] != "tracked"


def wheel_speeds(robot: Robot, v: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The faster wheel's speed (rad/s) at base speeds v (m/s), w (rad/s)."""
    r, lw = robot.wheel_radius, robot.track_width
    return np.maximum(np.abs((2 * v - lw * w) / (2 * r)), np.abs((2 * v + lw * w) / (2 * r)))


def test_wheel_speeds_on_the_thesis_plant_are_the_measured_ones():
    """A fast ellipse: the commanded yaw rate is far above what the force-limited base
    reaches; the wheel columns and ``max_wheel_speed_rad_s`` are the base's actual wheel
    speeds, from the measured (v, w), not from the command."""
    robot = Robot()
    trajectory = Ellipse(a=2.0, b=1.5, T=8.0, N=400)
    result = simulate(robot, trajectory, "clrrmc-ts", plant="thesis", duration=4.0)
    ts, summary = result.timeseries, result.summary
    r, lw = robot.wheel_radius, robot.track_width
    vm, wm = ts["v_measured"], ts["w_measured"]
    np.testing.assert_allclose(ts["wheel_left_rad_s"], (2 * vm - lw * wm) / (2 * r), rtol=1e-15)
    np.testing.assert_allclose(ts["wheel_right_rad_s"], (2 * vm + lw * wm) / (2 * r), rtol=1e-15)
    measured = float(np.max(wheel_speeds(robot, vm, wm)))
    assert summary["max_wheel_speed_rad_s"] == pytest.approx(measured, rel=1e-12)
    commanded = float(np.max(wheel_speeds(robot, ts["v"], ts["w"])))
    assert commanded > 2.0 * robot.wheel_speed_limit > 2.0 * measured  # the gap it closes


def test_wheel_speeds_on_the_kinematic_plant_are_the_applied_command():
    robot = Robot()
    result = simulate(robot, Ellipse(), "clrrmc-ts", plant="kinematic", duration=2.0)
    ts = result.timeseries
    r, lw = robot.wheel_radius, robot.track_width
    assert np.array_equal(ts["wheel_left_rad_s"], (2.0 * ts["v"] - lw * ts["w"]) / (2.0 * r))
    assert np.array_equal(ts["wheel_right_rad_s"], (2.0 * ts["v"] + lw * ts["w"]) / (2.0 * r))


def test_default_pose_lies_within_the_joint_limits():
    """The thesis's pose ``(-atan2(L2, L1), pi/2)`` as the arm holds it: clipped to the
    limits (the arm mover's targets), unchanged for the thesis robot."""
    default = Robot()
    assert ThesisController(default).default_pose == (
        -math.atan2(default.L2, default.L1),
        0.5 * math.pi,
    )
    pose = ThesisController(TIGHT).default_pose
    assert pose == (-math.atan2(TIGHT.L2, TIGHT.L1), 1.5)
    assert TIGHT.joints_outside((0.0, 0.0, 0.0, *pose)) is None
    plant = ThesisPlant(TIGHT)
    plant.reset([0.0, 0.0, 0.0, *pose], 0.01)  # accepted
    assert plant.observe().values == (0.0, 0.0, 0.0, *pose)


@pytest.mark.parametrize(
    ("q0", "message"),
    [
        ((0.0, 0.0, 0.0, -0.7, 0.5 * math.pi), "q0: joint th2 = 1.5708 rad is outside"),
        ((0.0, 0.0, 0.0, 0.6, 1.0), "q0: joint th1 = 0.6 rad is outside joint_limits[1]"),
    ],
)
def test_reset_refuses_a_start_outside_the_joint_limits(q0, message):
    plant = ThesisPlant(TIGHT)
    plant.reset([1.0, 2.0, 0.3, *POSE], 0.01)
    before = plant.state.copy()
    with pytest.raises(ParameterError) as error:
        plant.reset(q0, 0.01)
    assert message in str(error.value)
    assert "\n" not in str(error.value)
    assert plant.state == before  # nothing changed
    assert isinstance(before, ThesisState)
