"""A plug-in controller's constructor, reset() and adopt_*() hooks, a plug-in plant's
constructor and reset(): what they raise is one line naming the plug-in and the call, as
for command() and step() (tests/test_api_inputs.py, tests/test_checked_plant.py)."""

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, make_controller, simulate
from ddwmmr.controllers import StepInfo
from ddwmmr.errors import ParameterError, PluginError
from ddwmmr.plants import KinematicPlant, make_plant
from ddwmmr.registry import CONTROLLERS, PLANTS


class _Plain:
    """A plug-in whose every hook works."""

    def __init__(self, robot):
        self.last = StepInfo()

    def reset(self, trajectory, q0):
        pass

    def command(self, t, q, pose_d, velocity_d):
        return np.zeros(4)


class _InitRaises(_Plain):
    """Its constructor raises."""

    def __init__(self, robot):
        raise KeyError("boom")


class _NoRobot(_Plain):
    """Its constructor forgets the robot."""

    def __init__(self):
        self.last = StepInfo()


class _ResetRaises(_Plain):
    """Its reset raises."""

    def reset(self, trajectory, q0):
        raise KeyError("boom")


class _AdoptRaises(_Plain):
    """Its adopt_control_step raises."""

    def adopt_control_step(self, dt):
        raise ValueError("no such step")


class _InitRefuses(_Plain):
    """Its constructor refuses an option value: bad input, passed as it is."""

    def __init__(self, robot, gain=1.0):
        raise ParameterError(f"gain must be > 0 (got {gain})")


def test_a_raising_constructor_is_one_line_naming_the_plug_in(registered):
    registered(CONTROLLERS, "my-init", _InitRaises)
    with pytest.raises(PluginError) as error:
        make_controller("my-init", Robot())
    assert str(error.value) == (
        "method: my-init: _InitRaises(robot, **options) raised KeyError: \"'boom'\""
    )
    assert isinstance(error.value.__cause__, KeyError)


def test_a_constructor_without_the_robot_says_so(registered):
    registered(CONTROLLERS, "my-norobot", _NoRobot)
    with pytest.raises(PluginError, match=r"^method: my-norobot: _NoRobot\(robot, \*\*options\) "):
        simulate(Robot(), Ellipse(), "my-norobot", duration=0.1)


def test_a_parameter_error_of_a_constructor_passes_as_it_is(registered):
    registered(CONTROLLERS, "my-refuses", _InitRefuses)
    with pytest.raises(ParameterError, match=r"^gain must be > 0 \(got -1\)$"):
        make_controller("my-refuses", Robot(), gain=-1)


@pytest.mark.parametrize(
    ("cls", "message"),
    [
        (_ResetRaises, "method: my-hook.reset() raised KeyError: \"'boom'\" before the first step"),
        (
            _AdoptRaises,
            "method: my-hook.adopt_control_step() raised ValueError: 'no such step' before "
            "the first step",
        ),
    ],
)
def test_a_raising_hook_before_the_first_step_is_one_line(registered, cls, message):
    registered(CONTROLLERS, "my-hook", cls)
    with pytest.raises(PluginError) as error:
        simulate(Robot(), Ellipse(), "my-hook", duration=0.1)
    assert str(error.value) == message
    assert error.value.__cause__ is not None


def test_track_prints_a_raising_reset_in_one_line(tmp_path, capsys, registered):
    from ddwmmr.cli.track import main

    registered(CONTROLLERS, "my-hook", _ResetRaises)
    out = tmp_path / "run"
    argv = ["--method", "my-hook", "--traj", "ellipse", "--duration", "0.1", "--out", str(out)]
    assert main([*argv, "--no-progress"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "error: method: my-hook.reset() raised KeyError: \"'boom'\" before the first step"
    ]
    assert not out.exists()


class _PlantInitRaises(KinematicPlant):
    """A plug-in plant whose constructor raises."""

    def __init__(self, robot):
        raise KeyError("boom")


class _PlantResetRaises(KinematicPlant):
    """A plug-in plant whose reset raises."""

    def reset(self, q0, dt):
        raise KeyError("boom")


def test_a_plug_in_plant_raising_in_its_constructor_is_one_line(registered):
    registered(PLANTS, "my-plant", _PlantInitRaises)
    with pytest.raises(PluginError) as error:
        make_plant("my-plant", Robot())
    assert str(error.value) == (
        "plant: my-plant: _PlantInitRaises(robot, **options) raised KeyError: \"'boom'\""
    )
    assert isinstance(error.value.__cause__, KeyError)


def test_a_plug_in_plant_raising_in_reset_is_one_line(registered):
    registered(PLANTS, "my-plant", _PlantResetRaises)
    with pytest.raises(PluginError) as error:
        simulate(Robot(), Ellipse(), "ats", plant="my-plant", duration=0.1)
    assert str(error.value) == (
        "plant: my-plant.reset() raised KeyError: \"'boom'\" before the first step"
    )
    assert isinstance(error.value.__cause__, KeyError)


class _ArbiterInitRaises:
    """A plug-in arbiter whose constructor raises."""

    def __init__(self, stability=None, manipulability=None):
        raise KeyError("boom")


def test_a_plug_in_arbiter_raising_in_its_constructor_is_one_line(registered):
    from ddwmmr.arbiters import make_arbiter
    from ddwmmr.registry import ARBITERS
    from ddwmmr.scenarios import RunConfig

    registered(ARBITERS, "my-arbiter", _ArbiterInitRaises)
    with pytest.raises(PluginError) as error:
        make_arbiter(RunConfig(arbiter="my-arbiter"))
    assert str(error.value) == (
        "arbiter: my-arbiter: _ArbiterInitRaises(**thresholds) raised KeyError: 'boom'"
    )
    assert isinstance(error.value.__cause__, KeyError)
