"""Robot files in millimetres or degrees: warned about, taken as given; and the start-pose
refusal names the arm's geometry when lightening the payload could not help."""

import math
import warnings

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.cli.track import main as track
from ddwmmr.model.stability import stability_terms, tips_in_every_pose
from ddwmmr.sim.simulate import tipping_message


def _load(tmp_path, text):
    path = tmp_path / "robot.toml"
    path.write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = Robot.from_toml(path)
    return robot, [str(w.message) for w in caught if w.category is UserWarning], path


def test_lengths_in_millimetres_are_warned_about_and_taken_as_given(tmp_path):
    robot, messages, path = _load(tmp_path, "[robot]\nL2 = 350\n")
    assert robot.L2 == 350.0
    assert messages == [
        f"robot: {path}: L2 = 350 m is above 10 m, implausible for a mobile manipulator: "
        "lengths are in metres (given in millimetres?); taken as given"
    ]
    text = "wheel_radius = 100\ntrack_width = 500\nbase_length = 550\nbase_width = 400\n"
    _, messages, _ = _load(tmp_path, text)
    assert len(messages) == 1 and "\n" not in messages[0]
    assert (
        "wheel_radius = 100 m, track_width = 500 m, base_length = 550 m, base_width = 400 m "
        "are above 10 m" in messages[0]
    )


def test_angles_in_degrees_are_warned_about(tmp_path):
    text = "[robot]\nhome_pose = [90, 45]\njoint_limits = [[-180,180],[-180,180]]\n"
    robot, messages, _ = _load(tmp_path, text)
    assert robot.joint_limits == ((-180.0, 180.0), (-180.0, 180.0))
    assert len(messages) == 1
    assert (
        "joint_limits = [[-180, 180], [-180, 180]] rad, home_pose = [90, 45] rad go beyond "
        "2 pi rad (one turn) in magnitude: angles are in radians (given in degrees?)"
    ) in messages[0]


def test_a_wheel_in_other_units_than_the_base_is_warned_about():
    with pytest.warns(UserWarning, match=r"^robot: wheel_radius = 9\.75 m is above base_length"):
        Robot.from_dict({"wheel_radius": 9.75})


@pytest.mark.parametrize(
    "fields",
    [
        {},
        {"L1": 0.45, "L2": 0.35, "payload": 2.0, "base_length": 0.55, "base_width": 0.40},
        {"wheel_radius": 0.3, "joint_limits": [[-6.28, 6.28], [-1, 1]], "home_pose": [0, 0]},
        {"L1": 10.0, "base_length": 10.0, "wheel_radius": 10.0},
    ],
)
def test_plausible_robots_load_without_a_warning(fields):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Robot.from_dict(fields)


def test_tips_in_every_pose_is_never_wrong():
    """Where it says no pose stands, none of a grid of poses has S > 1."""
    grid = np.linspace(-math.pi, math.pi, 73)
    for robot in (Robot(L2=350.0), Robot(L2=12.0, payload=0.2), Robot(L2=8.0, payload=0.0)):
        k = robot.com_coefficients
        assert tips_in_every_pose(k)
        assert max(stability_terms(k, a, b)[2] for a in grid for b in grid) <= 1.0
    assert not tips_in_every_pose(Robot().com_coefficients)
    assert not tips_in_every_pose(Robot(L1=0.6, L2=0.6, link_masses=(4, 4)).com_coefficients)


def test_the_track_tool_names_the_arm_not_the_payload_of_a_robot_in_millimetres(tmp_path, capsys):
    robot = tmp_path / "r4.toml"
    robot.write_text("[robot]\nL2 = 350\n")
    argv = ["--method", "pi", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    code = track([*argv, "--robot", str(robot), "--out", str(tmp_path / "out")])
    assert code == 2
    warning, err = capsys.readouterr().err.split("\n", 1)  # the tool's one-line warning
    assert warning.startswith("warning: robot: ") and "L2 = 350 m is above 10 m" in warning
    assert err.count("\n") == 1 and "lighten the payload" not in err
    assert err.startswith(
        "error: robot: the robot tips over in this run's start pose (S = 0.00509 <= 1), even "
        "without its 1.25 kg payload: its arm (reach L1 + L2 = 350.35 m) puts the centre of "
        "mass 46.3 m from the base centre, outside the 0.45 m x 0.35 m base in every arm "
        "pose; change the robot; its lengths may be in millimetres (L2 = 350 m)\n"
    )


def test_a_heavy_arm_that_some_pose_might_hold_keeps_the_start_advice():
    robot = Robot(L1=0.6, L2=0.6, link_masses=(4.0, 4.0), payload=0.5)
    message = tipping_message(robot, [0.0, 0.0, 0.0, 0.0, 0.0], start="--offset")
    assert message == (
        "robot: the robot tips over in this run's start pose (S = 0.771 <= 1), even without "
        "its 0.5 kg payload: its arm (reach L1 + L2 = 1.2 m) puts the centre of mass 0.292 m "
        "from the base centre, outside the 0.45 m x 0.35 m base; change the robot or --offset"
    )
    unloaded = tipping_message(robot.with_payload(0.0), [0.0] * 5, start=None)
    assert unloaded is not None and "(S = 0.844 <= 1), unloaded: " in unloaded
    assert unloaded.endswith("; change the robot")


def test_a_payload_alone_keeps_its_message():
    message = tipping_message(Robot(payload=30.0), [0.0] * 5, start="--offset")
    assert message == (
        "payload: a 30 kg payload tips the robot over in this run's start pose "
        "(S = 0.468 <= 1), which holds at most 4.764 kg; lighten the payload or change --offset"
    )
