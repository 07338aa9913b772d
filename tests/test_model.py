"""Robot model: kinematics, Jacobian, wheels, manipulability, stability (docs/theory.md)."""

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot
from ddwmmr.model.stability import STABILITY_CAP


def central_difference(f, q, h=1e-6):
    """Jacobian of f at q by central differences (columns = coordinates of q)."""
    columns = []
    for i in range(len(q)):
        step = np.zeros(len(q))
        step[i] = h
        columns.append((f(q + step) - f(q - step)) / (2 * h))
    return np.column_stack(columns)


def test_default_robot_is_the_thesis_robot(robot):
    assert (robot.L1, robot.L2) == (0.35, 0.30)
    assert (robot.base_length, robot.base_width) == (0.45, 0.35)
    assert (robot.track_width, robot.wheel_radius) == (0.35, 0.0975)
    assert (robot.base_mass, robot.base_inertia, robot.link_masses) == (10.0, 0.5, (1.0, 1.0))


def test_fk_closed_form_at_known_pose(robot):
    q = np.array([1.0, 2.0, math.pi / 2, 0.0, 0.0])  # arm straight along +y
    np.testing.assert_allclose(robot.fk(q), [1.0, 2.65, math.pi / 2], atol=1e-12)
    q = np.array([0.0, 0.0, 0.0, math.pi / 2, -math.pi / 2])  # up L1, then along +x
    np.testing.assert_allclose(robot.fk(q), [0.30, 0.35, 0.0], atol=1e-12)


def test_jacobian_matches_central_differences_of_fk(robot, rng):
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, 5)
        numeric = central_difference(robot.fk, q)
        np.testing.assert_allclose(robot.jacobian(q)[:3], numeric, atol=1e-8)


def test_jacobian_last_row_is_the_nonholonomic_constraint(robot):
    q = np.array([0.3, -0.2, 0.7, 0.1, 0.4])
    row = robot.jacobian(q)[3]
    forward = np.array([math.cos(0.7), math.sin(0.7), 0, 0, 0])
    sideways = np.array([-math.sin(0.7), math.cos(0.7), 0, 0, 0])
    assert row @ forward == pytest.approx(0.0, abs=1e-15)
    assert row @ sideways == pytest.approx(1.0)


@pytest.mark.parametrize("aux", ["sum", "shoulder"])
def test_augmented_determinant_is_minus_L1_cos_th1(robot, rng, aux):
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, 5)
        det = np.linalg.det(robot.augmented_jacobian(q, aux))
        assert det == pytest.approx(-robot.L1 * math.cos(q[3]), abs=1e-12)


def test_jacobian_rank_drops_exactly_when_cos_th1_vanishes(robot, rng):
    for th2 in (-2.5, -0.5, 0.0, 0.5, 1.0, math.pi):
        singular = np.array([0.1, 0.2, 0.3, math.pi / 2, th2])
        assert np.linalg.svd(robot.jacobian(singular), compute_uv=False)[-1] < 1e-12
    stretched = np.array([0.0, 0.0, 0.3, 0.0, 0.0])
    assert np.linalg.svd(robot.jacobian(stretched), compute_uv=False)[-1] > 0.1


def test_wheel_speed_round_trip(robot, rng):
    for _ in range(20):
        q = rng.uniform(-3, 3, 5)
        v, w = rng.uniform(-1, 1, 2)
        qdot = np.array([v * math.cos(q[2]), v * math.sin(q[2]), w, 0.3, -0.2])
        wheels = robot.wheel_speeds(q, qdot)
        np.testing.assert_allclose(robot.base_velocity(wheels), [v, w], atol=1e-12)


def test_wheel_speeds_closed_form(robot):
    # Pure translation: both wheels at v/r; pure rotation: opposite at w Lw / (2 r).
    np.testing.assert_allclose(robot.wheel_speeds_from_u(0.39, 0.0), [4.0, 4.0])
    left, right = robot.wheel_speeds_from_u(0.0, 1.0)
    assert right == pytest.approx(0.35 / (2 * 0.0975)) and left == pytest.approx(-right)


def test_manipulability(robot):
    assert robot.manipulability([0, 0, 0, 0.3, math.pi / 2]) == pytest.approx(1.0)
    assert robot.manipulability([0, 0, 0, 0.3, 0.0]) == pytest.approx(0.0)
    assert robot.manipulability([0, 0, 0, 0.3, -0.5]) == pytest.approx(math.sin(0.5))


def test_stability_spec_figures():
    # docs/theory.md, "Tip-over stability": full sideways stretch gives S = 1.0 with 3 kg
    # and S = 1.56 with 1.25 kg.
    sideways = [0, 0, 0, math.pi / 2, 0.0]
    assert Robot().with_payload(3.0).stability(sideways)[2] == pytest.approx(1.0)
    assert Robot().stability(sideways)[2] == pytest.approx(1.559, abs=1e-3)


def test_stability_matches_moment_ratio_from_first_principles(rng):
    robot = Robot().with_payload(2.0)
    for _ in range(20):
        q = np.r_[0, 0, 0, rng.uniform(-math.pi, math.pi, 2)]
        th1, th2 = q[3], q[4]
        points = [  # base-frame centres of mass of link 1, link 2, payload
            (0.175 * math.cos(th1), 0.175 * math.sin(th1)),
            (
                0.35 * math.cos(th1) + 0.15 * math.cos(th1 + th2),
                0.35 * math.sin(th1) + 0.15 * math.sin(th1 + th2),
            ),
            (
                0.35 * math.cos(th1) + 0.30 * math.cos(th1 + th2),
                0.35 * math.sin(th1) + 0.30 * math.sin(th1 + th2),
            ),
        ]
        masses = (1.0, 1.0, 2.0)
        total = 10.0 + sum(masses)
        # Counter moment M g (half extent) vs tipping moment g sum m_i p_i about the edge.
        moment_x = sum(m * p[0] for m, p in zip(masses, points))
        moment_y = sum(m * p[1] for m, p in zip(masses, points))
        expected_lon = min(STABILITY_CAP, total * 0.225 / abs(moment_x))
        expected_lat = min(STABILITY_CAP, total * 0.175 / abs(moment_y))
        s_lon, s_lat, s = robot.stability(q)
        assert s_lon == pytest.approx(expected_lon, rel=1e-12)
        assert s_lat == pytest.approx(expected_lat, rel=1e-12)
        assert s == pytest.approx(min(expected_lon, expected_lat), rel=1e-12)


def test_stability_gradient_matches_central_differences(rng):
    robot = Robot().with_payload(3.0)
    checked = 0
    while checked < 20:
        q = np.r_[0, 0, 0, rng.uniform(-math.pi, math.pi, 2)]
        s_lon, s_lat, s = robot.stability(q)
        if s >= STABILITY_CAP or abs(s_lon - s_lat) < 1e-3:
            continue  # capped, or at the kink of the min: no derivative there
        numeric = central_difference(lambda x: np.array([robot.stability(x)[2]]), q)[0]
        np.testing.assert_allclose(robot.stability_gradient(q), numeric, rtol=1e-5, atol=1e-7)
        checked += 1


def test_arm_ik_round_trip(robot, rng):
    for _ in range(20):
        th1, th2 = rng.uniform(-3, 3), rng.uniform(0.1, 3)
        tip = robot.fk([0, 0, 0, th1, th2])[:2]
        solution = robot.arm_ik(*tip, elbow=1)
        assert solution is not None
        np.testing.assert_allclose(robot.fk([0, 0, 0, *solution])[:2], tip, atol=1e-9)
    assert robot.arm_ik(1.0, 0.0) is None  # beyond the 0.65 m reach


def test_robot_from_toml(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text("[robot]\nL1 = 0.5\npayload = 2.0\nlink_masses = [1.5, 0.5]\n")
    robot = Robot.from_toml(path)
    assert (robot.L1, robot.L2, robot.payload, robot.link_masses) == (0.5, 0.30, 2.0, (1.5, 0.5))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"L1": -1.0}, "L1 must be in [1e-06, 1000] m (got -1)"),
        ({"payload": float("nan")}, "payload must be a finite number in [0, 100000] kg (got nan)"),
        ({"payload": -0.1}, "payload must be in [0, 100000] kg (got -0.1)"),
        ({"base_mass": 0.0}, "base_mass must be in (0, 100000] kg (got 0)"),
        ({"link_masses": (1.0, -1.0)}, "link_masses[2] must be in [0, 100000] kg (got -1)"),
        ({"joint_limits": ((1.0, -1.0), (-1.0, 1.0))}, "joint_limits[1] must satisfy min < max"),
        ({"wheel_speed_limit": 0.0}, "wheel_speed_limit must be in [1e-06, 1e+06] rad/s (got 0)"),
    ],
)
def test_invalid_robot_parameters_name_the_parameter(kwargs, message):
    with pytest.raises(ParameterError) as info:
        Robot(**kwargs)
    assert message in str(info.value)
    assert "\n" not in str(info.value)


def test_robot_toml_errors(tmp_path):
    with pytest.raises(ParameterError, match="cannot read"):
        Robot.from_toml(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("L3 = 1.0\n")
    with pytest.raises(ParameterError, match="unknown parameter 'L3'"):
        Robot.from_toml(bad)


def test_own_mass_is_the_robot_without_its_payload():
    """``own_mass`` (what the thesis plant's damping and the MuJoCo tyres scale with) is the
    total mass less the payload, at any payload."""
    for payload in (0.0, 1.25, 3.0):
        robot = Robot().with_payload(payload)
        assert robot.own_mass == pytest.approx(robot.total_mass - payload, abs=1e-12)
        assert robot.own_mass == Robot().own_mass
