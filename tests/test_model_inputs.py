"""Bad input to Robot (constructor, TOML, methods taking q) raises a one-line ParameterError
naming the parameter; valid input keeps its exact results."""

import math

import numpy as np
import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot, kinematics, stability
from ddwmmr.model.robot import CASTER_REACH
from one_line import one_line

ROBOT = Robot()
Q = np.array([0.1, -0.2, 0.3, -0.3, 0.6])


# -- 1. numbers beyond float range -----------------------------------------------------
@pytest.mark.parametrize(
    ("field", "value", "name"),
    [
        ("link_masses", (10**400, 1), r"link_masses\[1\]"),
        ("link_masses", (1, 10**5000), r"link_masses\[2\]"),  # beyond repr's digit limit
        ("home_pose", (10**400, 0), r"home_pose\[1\]"),
        ("joint_torque_limits", (20, 10**400), r"joint_torque_limits\[2\]"),
        ("joint_limits", ((-(10**400), 1), (-1, 1)), r"joint_limits\[1\]"),
        ("caster_positions", [(10**400, 0)], r"caster_positions\[1\]"),
    ],
)
def test_huge_integers_in_pairs_name_the_entry(field, value, name):
    with pytest.raises(ParameterError, match=name) as info:
        Robot(**{field: value})
    assert "finite number" in one_line(info)


def test_huge_integers_through_from_dict_and_toml(tmp_path):
    with pytest.raises(ParameterError, match=r"link_masses\[1\] must be a finite number"):
        Robot.from_dict({"link_masses": [10**400, 1]})
    path = tmp_path / "robot.toml"
    path.write_text("[robot]\nhome_pose = [0.1, 1e400]\n")  # TOML reads 1e400 as inf
    with pytest.raises(ParameterError, match=r"home_pose\[2\] must be a finite number"):
        Robot.from_toml(path)


@pytest.mark.parametrize(
    ("value", "name"),
    [
        (("1.0", 1.0), r"link_masses\[1\]"),
        ((1.0, True), r"link_masses\[2\]"),
        ("ab", "link_masses"),
    ],
)
def test_pairs_refuse_strings_and_booleans(value, name):
    with pytest.raises(ParameterError, match=name):
        Robot(link_masses=value)


# -- 2. home pose and casters ----------------------------------------------------------
@pytest.mark.parametrize(
    ("home", "name"),
    [
        ((1e300, 0.0), r"home_pose\[1\] must be in \[-3.14159, 3.14159\]"),
        ((0.0, 4.0), r"home_pose\[2\]"),
    ],
)
def test_home_pose_must_lie_within_the_joint_limits(home, name):
    with pytest.raises(ParameterError, match=name) as info:
        Robot(home_pose=home)
    assert "joint_limits" in one_line(info)


def test_home_pose_checked_against_custom_limits():
    with pytest.raises(ParameterError, match=r"home_pose\[1\] must be in \[0, 1\]"):
        Robot(joint_limits=((0.0, 1.0), (-1.0, 1.0)))  # default home th1 = -0.3
    robot = Robot(joint_limits=((-1.0, 1.0), (-2.0, 2.0)))
    assert robot.home_pose == (-0.3, 0.6)
    assert Robot(home_pose=(math.pi, -math.pi)).home_pose == (math.pi, -math.pi)  # the edges


@pytest.mark.parametrize(
    "casters", [[(1e300, 0.0)], [(0.3, 0.0), (0.0, -1.0)], [(math.nan, 0.0)], [(0.0, math.inf)]]
)
def test_casters_must_be_finite_and_near_the_base(casters):
    with pytest.raises(ParameterError, match=r"caster_positions\[\d\]") as info:
        Robot(caster_positions=casters)
    one_line(info)


def test_caster_reach_is_twice_the_half_diagonal():
    reach = CASTER_REACH * 0.5 * math.hypot(ROBOT.base_length, ROBOT.base_width)
    assert reach == pytest.approx(0.570088, abs=1e-6)
    assert Robot(caster_positions=[(reach, 0.0), (-reach, 0.0)]).casters[0] == (reach, 0.0)
    with pytest.raises(ParameterError, match=r"caster_positions\[2\] must lie within 0.570088 m"):
        Robot(caster_positions=[(0.3, 0.0), (-reach * 1.0001, 0.0)])
    # scaled with the footprint: a bigger base may have farther casters
    big = Robot(base_length=2.0, base_width=2.0, caster_positions=[(1.5, 1.5), (-1.5, -1.5)])
    assert big.casters == ((1.5, 1.5), (-1.5, -1.5))


def test_default_and_custom_casters_still_work():
    assert ROBOT.caster_positions is None and len(ROBOT.casters) == 4
    assert Robot(caster_positions=[(0.3, 0.0), (-0.3, 0.0)]).casters == ((0.3, 0.0), (-0.3, 0.0))


# -- 3. robot TOML tables ------------------------------------------------------------------
@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[robot]\nL1 = 0.3\n[other]\nx = 1", r"unknown table \[other\]"),
        ("[robot]\nL1 = 0.3\n[[runs]]\nx = 1", r"unknown table \[runs\]"),
        ("L2 = 0.2\n[robot]\nL1 = 0.3", "unknown key 'L2'"),
        ("L1 = 0.3\n[other]\nx = 1", "unknown parameter 'other'"),
    ],
)
def test_robot_toml_refuses_unknown_tables(tmp_path, text, message):
    path = tmp_path / "robot.toml"
    path.write_text(text + "\n")
    with pytest.raises(ParameterError, match=message) as info:
        Robot.from_toml(path)
    assert str(path) in one_line(info)


def test_robot_toml_layouts_still_load(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text("[robot]\nL1 = 0.3\n")
    assert Robot.from_toml(path).L1 == 0.3
    path.write_text("L1 = 0.3\nhome_pose = [0.1, 0.2]\n")
    assert Robot.from_toml(path).home_pose == (0.1, 0.2)


# -- 5. methods taking q -------------------------------------------------------------------
METHODS = {
    "fk": lambda q: ROBOT.fk(q),
    "jacobian": lambda q: ROBOT.jacobian(q),
    "augmented_jacobian": lambda q: ROBOT.augmented_jacobian(q, "sum"),
    "manipulability": lambda q: ROBOT.manipulability(q),
    "stability": lambda q: ROBOT.stability(q),
    "stability_gradient": lambda q: ROBOT.stability_gradient(q),
    "centre_of_mass": lambda q: ROBOT.centre_of_mass(q),
    "wheel_speeds": lambda q: ROBOT.wheel_speeds(q, np.zeros(5)),
}
BAD_Q = {
    "short": np.zeros(4),
    "long": [0.0] * 6,
    "2-D": np.zeros((5, 1)),
    "inf": [0, 0, 0, 0, math.inf],
    "nan": np.array([0, 0, math.nan, 0, 0]),
    "-inf list": [0.0, -math.inf, 0.0, 0.0, 0.0],
    "strings": ["0", "0", "0", "0", "0"],
    "a string": "01234",
    "None": None,
    "scalar": 0.0,
    "huge int": [0, 0, 0, 0, 10**400],
    "ragged": [0, 0, 0, 0, [1, 2]],
}


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("q", BAD_Q.values(), ids=list(BAD_Q))
def test_methods_refuse_a_bad_configuration(method, q):
    with pytest.raises(
        ParameterError, match=r"^q must be 5 finite numbers \[x, y, phi, th1, th2\]"
    ) as info:
        METHODS[method](q)
    one_line(info)


def test_wheel_speeds_checks_qdot():
    with pytest.raises(ParameterError, match=r"^qdot must be 5 finite numbers"):
        ROBOT.wheel_speeds(Q, [0.0, 0.0, math.nan, 0.0, 0.0])
    with pytest.raises(ParameterError, match=r"^qdot must be 5 finite numbers"):
        ROBOT.wheel_speeds(Q, np.zeros(3))


def test_sums_that_overflow_are_not_mistaken_for_infinities():
    q = [1e308, 1e308, 0.0, 0.3, 0.6]  # finite entries whose sum is inf
    x, _, _ = ROBOT.fk(q)
    assert x == 1e308 + ROBOT.L1 * math.cos(0.3) + ROBOT.L2 * math.cos(0.9)
    assert ROBOT.stability(q) == ROBOT.stability([0, 0, 0, 0.3, 0.6])


@pytest.mark.parametrize(
    "q", [Q, Q.tolist(), tuple(Q.tolist()), Q.astype(np.float32), np.arange(5), [0, 0, 0, 1, 2]]
)
def test_valid_configurations_give_the_kinematics_results_bit_for_bit(q):
    L1, L2, k = ROBOT.L1, ROBOT.L2, ROBOT.com_coefficients
    floats = [float(v) for v in q]
    assert ROBOT.fk(q).tolist() == list(kinematics.forward_kinematics(L1, L2, floats))
    assert ROBOT.jacobian(q).tobytes() == kinematics.jacobian(L1, L2, floats).tobytes()
    expected = kinematics.augmented_jacobian(L1, L2, floats, "shoulder")
    assert ROBOT.augmented_jacobian(q, "shoulder").tobytes() == expected.tobytes()
    assert ROBOT.stability(q) == stability.stability_terms(k, floats[3], floats[4])
    assert ROBOT.manipulability(q) == abs(math.sin(floats[4]))
    gradient = stability.stability_gradient(k, floats[3], floats[4])
    assert ROBOT.stability_gradient(q).tolist() == [0.0, 0.0, 0.0, *gradient[1:]]
    com = stability.centre_of_mass(k, floats[3], floats[4])
    assert ROBOT.centre_of_mass(q).tolist() == list(com)


def test_other_methods_check_their_numbers():
    with pytest.raises(ParameterError, match=r"^v must be a finite number"):
        ROBOT.wheel_speeds_from_u(math.nan, 0.0)
    with pytest.raises(ParameterError, match=r"^w must be a finite number \(got '1'\)"):
        ROBOT.wheel_speeds_from_u(0.0, "1")
    with pytest.raises(ParameterError, match=r"^wheel_speeds\[2\] must be a finite number"):
        ROBOT.base_velocity([1.0, math.inf])
    with pytest.raises(ParameterError, match=r"^wheel_speeds must be a pair"):
        ROBOT.base_velocity([1.0, 2.0, 3.0])
    with pytest.raises(ParameterError, match=r"^pose_e must be 3 numbers \[xE, yE, phiE\]"):
        ROBOT.base_for_end_effector([0.0, 0.0], 0.1, 0.2)
    with pytest.raises(ParameterError, match=r"^pose_e\[3\] must be a finite number"):
        ROBOT.base_for_end_effector([0.0, 0.0, math.nan], 0.1, 0.2)
    with pytest.raises(ParameterError, match=r"^th2 must be a finite number"):
        ROBOT.base_for_end_effector([0.0, 0.0, 0.0], 0.1, math.inf)
    with pytest.raises(ParameterError, match=r"^dx must be a finite number"):
        ROBOT.arm_ik(math.nan, 0.0)
    with pytest.raises(ParameterError, match=r"^dy must be a finite number"):
        ROBOT.arm_ik(0.1, math.inf)
    with pytest.raises(ParameterError, match=r"^elbow must be"):
        ROBOT.arm_ik(0.3, 0.2, elbow=0)
    with pytest.raises(ParameterError, match=r"^aux must be one of"):
        ROBOT.augmented_jacobian(Q, ["sum"])


def test_other_methods_keep_their_results():
    r, lw = ROBOT.wheel_radius, ROBOT.track_width
    assert ROBOT.wheel_speeds_from_u(0.3, 0.7) == (
        (0.6 - lw * 0.7) / (2 * r),
        (0.6 + lw * 0.7) / (2 * r),
    )
    assert ROBOT.wheel_speeds_from_u(np.float64(0.3), 1) == ROBOT.wheel_speeds_from_u(0.3, 1.0)
    assert ROBOT.base_velocity([1.0, 2.0]).tolist() == [r * 1.5, r * 1.0 / lw]
    q = ROBOT.base_for_end_effector([1.0, 2.0, 0.5], 0.3, -0.4)
    np.testing.assert_allclose(ROBOT.fk(q), [1.0, 2.0, 0.5], atol=1e-15)
    assert ROBOT.arm_ik(0.3, 0.2, elbow=-1) == ROBOT.arm_ik(0.3, 0.2, elbow=-1.0)
    assert ROBOT.arm_ik(2.0, 0.0) is None
    assert ROBOT.arm_ik(1e200, 0.0) is None  # finite but far: out of reach, not an error
