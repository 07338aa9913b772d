"""A home pose refused by the joint limits says when it was most likely written in degrees
(beyond one turn, the rule of the unit warnings), and only then."""

from __future__ import annotations

import pytest

from ddwmmr import Robot
from ddwmmr.cli.track import main as track
from ddwmmr.errors import ParameterError
from ddwmmr.model.robot import PLAUSIBLE_ANGLE_RAD, plausibly_degrees


def refusal(**fields) -> str:
    with pytest.raises(ParameterError) as refused:
        Robot(**fields)
    return str(refused.value)


def test_a_home_pose_in_degrees_is_refused_with_the_radians_it_would_be() -> None:
    assert refusal(home_pose=(-17.0, 34.0)) == (
        "home_pose[1] must be in [-3.14159, 3.14159] rad (joint_limits[1]) (got -17); "
        "angles are in radians (given in degrees? -17 deg = -0.296706 rad)"
    )
    assert refusal(home_pose=(-0.3, 90.0)).endswith("(given in degrees? 90 deg = 1.5708 rad)")


def test_a_home_pose_just_past_its_limit_gets_no_degrees_hint() -> None:
    assert refusal(home_pose=(4.0, 0.6)) == (
        "home_pose[1] must be in [-3.14159, 3.14159] rad (joint_limits[1]) (got 4)"
    )
    narrow = ((-1.0, 1.0), (-1.0, 1.0))
    assert "degrees" not in refusal(joint_limits=narrow, home_pose=(-0.3, 6.0))


def test_the_hint_uses_the_one_rule_of_the_unit_warnings() -> None:
    assert not plausibly_degrees(PLAUSIBLE_ANGLE_RAD)
    assert plausibly_degrees(-6.3) and not plausibly_degrees(6.28)


def test_the_track_tool_refuses_such_a_robot_file_in_one_line(tmp_path, capsys) -> None:
    path = tmp_path / "robot.toml"
    path.write_text("[robot]\nhome_pose = [-17, 34]\n")
    argv = [
        "--method",
        "pi",
        "--traj",
        "ellipse",
        "--robot",
        str(path),
        "--out",
        str(tmp_path / "o"),
    ]
    assert track(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "home_pose[1] must be in [-3.14159, 3.14159] rad" in err
    assert "(given in degrees? -17 deg = -0.296706 rad)" in err
    assert not (tmp_path / "o").exists()
