"""The thesis plant: base dynamics (closed forms), force limit, inertia, arm servo."""

from __future__ import annotations

import math

import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.plants.thesis import ThesisPlant, ThesisState, arm_step

ROBOT = Robot().with_payload(3.0)
POSE = (-0.7, 1.5)


def run(plant: ThesisPlant, f_left: float, f_right: float, seconds: float, dt: float = 0.01):
    state = ThesisState(0.0, 0.0, 0.0, *POSE)
    for _ in range(round(seconds / dt)):
        plant.advance(state, f_left, f_right, POSE, dt)
    return state


def test_total_mass_includes_arm_and_payload():
    assert ThesisPlant(ROBOT).mass == pytest.approx(10.0 + 1.0 + 1.0 + 3.0)


def test_constant_force_reaches_terminal_velocity_f_over_c1():
    plant = ThesisPlant(ROBOT)
    state = run(plant, 4.0, 4.0, 30.0)  # 30 s >> m/c1 = 1 s
    assert state.v == pytest.approx(8.0 / 15.0, rel=1e-9)
    assert state.w == pytest.approx(0.0, abs=1e-12)
    assert state.y == pytest.approx(0.0, abs=1e-12)


def test_velocity_after_one_time_constant_and_distance_closed_form():
    plant = ThesisPlant(ROBOT)
    tau = plant.mass / 15.0  # m / c1 (s)
    state = run(plant, 5.0, 5.0, tau, dt=tau / 100)
    v_ss = 10.0 / 15.0
    assert state.v == pytest.approx(v_ss * (1.0 - math.exp(-1.0)), rel=1e-9)
    # x(t) = v_ss (t - tau (1 - e^{-t/tau})), integrated by hand
    assert state.x == pytest.approx(v_ss * (tau - tau * (1.0 - math.exp(-1.0))), rel=1e-9)


def test_exact_step_matches_fine_explicit_integration():
    """Independent check: 1 ms Euler integration of m v' = F - c1 v vs the 0.02 s plant."""
    plant = ThesisPlant(ROBOT)
    state = run(plant, 3.0, 7.0, 2.0, dt=0.02)
    v = w = x = y = phi = 0.0
    h = 1e-4
    inertia = plant.inertia(*POSE)
    for _ in range(20000):
        x += h * v * math.cos(phi)
        y += h * v * math.sin(phi)
        phi += h * w
        v += h * (10.0 - 15.0 * v) / plant.mass
        w += h * ((7.0 - 3.0) * 0.175 - 4.0 * w) / inertia
    assert state.v == pytest.approx(v, rel=1e-3)
    assert state.w == pytest.approx(w, rel=1e-3)
    assert state.phi == pytest.approx(phi, rel=1e-3)
    assert (state.x, state.y) == pytest.approx((x, y), abs=2e-3)


def test_force_limit_10_newton_per_wheel():
    plant = ThesisPlant(ROBOT)
    limited = run(plant, 100.0, 100.0, 5.0)
    at_limit = run(plant, 10.0, 10.0, 5.0)
    assert limited.v == pytest.approx(at_limit.v, rel=1e-12)
    assert limited.v < 20.0 / 15.0


def test_turning_torque_and_terminal_yaw_rate():
    plant = ThesisPlant(ROBOT)
    state = run(plant, -2.0, 2.0, 20.0)
    torque = (2.0 - -2.0) * ROBOT.track_width / 2.0  # T = (F2 - F1) b, b = track_width / 2
    assert state.w == pytest.approx(torque / 4.0, rel=1e-9)
    assert state.v == pytest.approx(0.0, abs=1e-12)
    assert math.hypot(state.x, state.y) < 1e-12


def test_inertia_against_discretised_links():
    """Pose-dependent yaw inertia vs 2000 point masses along the links plus the payload."""
    plant = ThesisPlant(ROBOT)
    th1, th2 = 0.4, -1.1
    n = 2000
    total = ROBOT.base_inertia
    for length, mass, start, angle in (
        (ROBOT.L1, 1.0, (0.0, 0.0), th1),
        (ROBOT.L2, 1.0, (ROBOT.L1 * math.cos(th1), ROBOT.L1 * math.sin(th1)), th1 + th2),
    ):
        for i in range(n):
            s = (i + 0.5) / n * length
            px, py = start[0] + s * math.cos(angle), start[1] + s * math.sin(angle)
            total += mass / n * (px * px + py * py)
    xe = ROBOT.L1 * math.cos(th1) + ROBOT.L2 * math.cos(th1 + th2)
    ye = ROBOT.L1 * math.sin(th1) + ROBOT.L2 * math.sin(th1 + th2)
    total += 3.0 * (xe * xe + ye * ye)
    assert plant.inertia(th1, th2) == pytest.approx(total, rel=1e-6)
    assert plant.inertia(0.0, 0.0) > plant.inertia(0.0, 2.5)  # stretched arm: more inertia


def test_arm_servo_eq_4_10_synchronised_and_limited():
    # errors 1.0 and -0.5 rad: largest moves at 2 rad/s, the other at 1 rad/s
    th1, th2 = arm_step(0.0, 0.0, 1.0, -0.5, 2.0, 0.1)
    assert (th1, th2) == pytest.approx((0.2, -0.1))
    steps = 0
    while (th1, th2) != (1.0, -0.5):
        th1, th2 = arm_step(th1, th2, 1.0, -0.5, 2.0, 0.1)
        steps += 1
        assert abs(th1) <= 1.0 and abs(th2) <= 0.5  # never overshoots
    assert steps == 4  # 1 rad at 2 rad/s = 0.5 s = 5 steps in all, both arrive together


def test_arm_servo_inside_plant_and_no_motion_at_target():
    plant = ThesisPlant(ROBOT)
    state = ThesisState(0.0, 0.0, 0.0, 0.0, 1.0)
    plant.advance(state, 0.0, 0.0, (0.3, 1.0), 0.01)
    assert (state.th1, state.th2) == pytest.approx((0.02, 1.0))
    assert arm_step(0.3, 1.0, 0.3, 1.0, 2.0, 0.01) == (0.3, 1.0)


@pytest.mark.parametrize("bad", [math.nan, math.inf])
@pytest.mark.parametrize("index", [0, 1, 2, 3])
def test_limit_refuses_a_non_finite_command_as_the_kinematic_plant_does(bad, index):
    """Clipping max(-limit, nan) gave -limit: a NaN joint rate became a full-speed one."""
    import numpy as np

    from ddwmmr.plants.kinematic import KinematicPlant

    q = np.array([0.0, 0.0, 0.0, *POSE])
    u = np.array([0.1, 0.2, 0.3, 0.4])
    u[index] = bad
    for plant in (ThesisPlant(ROBOT), KinematicPlant(ROBOT)):
        with pytest.raises(ParameterError, match=r"^u must be 4 finite numbers"):
            plant.limit(q, u)
    huge = np.array([1e308, 1e308, 3.0, -3.0])  # finite, though their sum is not
    applied, clipped = ThesisPlant(ROBOT).limit(q, huge)
    assert clipped and applied.tolist() == [1e308, 1e308, 2.0, -2.0]


def test_arm_targets_are_clipped_to_the_joint_limits():
    """A target beyond a limit stops the joint at the limit, as the servo reaches it."""
    from ddwmmr.commands import WheelForces

    robot = Robot(joint_limits=((-1.0, 0.5), (0.2, 1.5)), home_pose=(0.0, 1.0))
    plant = ThesisPlant(robot)
    plant.reset([0.0, 0.0, 0.0, 0.4, 1.4], 0.01)
    for k in range(100):  # 1 s at 2 rad/s: far enough to pass both limits unclipped
        plant.step(k * 0.01, WheelForces(0.0, 0.0, 3.0, -3.0), 0.01)
    assert (plant.state.th1, plant.state.th2) == (0.5, 0.2)
    assert plant.clip_targets(-7.0, 9.0) == (-1.0, 1.5)
    assert plant.clip_targets(0.1, 0.9) == (0.1, 0.9)  # inside: unchanged


def test_limit_stops_a_joint_at_its_limit_and_reports_it_as_the_kinematic_plant():
    import numpy as np

    from ddwmmr.plants.kinematic import KinematicPlant

    robot = Robot(joint_limits=((-1.0, 0.5), (0.2, 1.5)), home_pose=(0.0, 1.0))
    u = np.array([0.1, 0.2, 0.7, -0.3])
    for q, expected, clipped in (
        ((0.0, 0.0, 0.0, 0.5, 0.2), [0.1, 0.2, 0.0, 0.0], True),  # both pushing outward
        ((0.0, 0.0, 0.0, 0.5, 1.5), [0.1, 0.2, 0.0, -0.3], True),  # th1 at its max
        ((0.0, 0.0, 0.0, -1.0, 0.2), [0.1, 0.2, 0.7, 0.0], True),  # th2 at its min
        ((0.0, 0.0, 0.0, 0.0, 1.0), [0.1, 0.2, 0.7, -0.3], False),  # inside
    ):
        q = np.array(q)
        for plant in (ThesisPlant(robot), KinematicPlant(robot)):
            applied, saturated = plant.limit(q, u)
            assert applied.tolist() == expected and saturated is clipped, type(plant).__name__
