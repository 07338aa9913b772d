"""A name typed in the wrong case (``l1`` for the robot's ``L1``, ``C1`` for the thesis
plant's ``c1``) got no suggestion: difflib's similarity of two-letter names differing in
one letter's case is 0.5, below its 0.6 cut-off."""

from __future__ import annotations

import pytest

from ddwmmr import Robot
from ddwmmr.errors import ParameterError, did_you_mean


def test_a_name_differing_in_case_alone_is_suggested():
    assert did_you_mean("l1", ["L1", "L2", "payload"]) == " (did you mean L1?)"
    assert did_you_mean("TAU", ["tau", "aux"]) == " (did you mean tau?)"
    assert did_you_mean("METHOD", ["method", "methods"], "--") == " (did you mean --method?)"
    assert did_you_mean("paylod", ["L1", "payload"]) == " (did you mean payload?)"
    assert did_you_mean("zzz", ["L1", "payload"]) == ""


def test_a_robot_field_in_the_wrong_case_is_named():
    with pytest.raises(
        ParameterError, match=r"^robot: unknown parameter 'l1' \(did you mean L1\?\)"
    ):
        Robot.from_dict({"l1": 0.35})


def test_a_plant_option_in_the_wrong_case_is_named(capsys):
    from ddwmmr.cli.track import main as track

    argv = ["--method", "ats", "--traj", "ellipse", "--plant", "thesis"]
    assert track([*argv, "--plant-option", "C1=3"]) == 2
    assert "has no option 'C1' (did you mean c1?)" in capsys.readouterr().err
