"""Bad input an API fuzz found, each one line naming what is wrong.

``Plant.limit`` of the library plants checks ``q`` and ``u`` (a NaN q passed silently, a
NaN u was a FloatingPointError, a short u a ValueError from unpacking); ``step`` refuses a
``policy`` that is not callable and the constructors a ``robot`` that is no Robot. What a
custom trajectory's ``pose``, ``velocity`` or ``sample`` raise is a one-line PluginError
naming the trajectory, the method and t, as for a controller or a plant. The result writers
refuse a folder that takes no files and a summary value JSON cannot hold. A trajectory's
``samples`` must be an integer, a trajectory's ``name`` a non-empty string. The
unknown-option message has one home.
"""

from __future__ import annotations

import math
import os
import re
import warnings

import numpy as np
import pytest

from ddwmmr import Robot, simulate
from ddwmmr.controllers.base import check_known_options, make_controller
from ddwmmr.errors import ParameterError, PluginError
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.plants.thesis import ThesisPlant
from ddwmmr.trajectories import Ellipse, Rectangle
from ddwmmr.trajectories.base import resolution_step
from ddwmmr.trajectories.sampled import SampledTrajectory

ROBOT = Robot()
Q = np.array([0.0, 0.0, 0.0, 0.3, 1.2])
U = np.array([0.1, 0.2, 0.3, 0.4])
Q_MESSAGE = "q must be 5 finite numbers [x, y, phi, th1, th2] (m, rad) (got "
U_MESSAGE = "u must be 4 finite numbers u = [v, w, th1dot, th2dot] (m/s, rad/s, rad/s, rad/s) (got "


def _plants():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return [KinematicPlant(ROBOT), ThesisPlant(ROBOT)]


def _message(call, kind=ParameterError) -> str:
    with pytest.raises(kind) as error:
        call()
    text = str(error.value)
    assert "\n" not in text
    return text


# -- 1. Plant.limit, Plant.step's policy, the plants' robot ------------------------------
@pytest.mark.parametrize(
    ("q", "u", "start"),
    [
        ([math.nan] * 5, U, Q_MESSAGE + "[nan, nan, nan, nan, nan])"),
        (np.zeros(3), U, Q_MESSAGE + "array([0., 0., 0.]))"),
        (None, U, Q_MESSAGE + "None)"),
        (Q, np.array([math.nan, 0.0, 0.0, 0.0]), U_MESSAGE + "array([nan, 0., 0., 0.]))"),
        (Q, np.array([0.0, 0.0, 0.0, math.inf]), U_MESSAGE + "array([ 0., 0., 0., inf]))"),
        (Q, [1, 2, 3], U_MESSAGE + "[1, 2, 3])"),
        (Q, "abcd", U_MESSAGE + "'abcd')"),
    ],
)
def test_limit_refuses_a_bad_q_or_u_naming_it(q, u, start):
    for plant in _plants():
        assert _message(lambda p=plant: p.limit(q, u)) == start, type(plant).__name__


def test_limit_gives_the_same_numbers_for_any_sequence():
    """Lists and arrays alike; clipped at the wheel and joint-rate limits as before."""
    u = [5.0, 1.0, 3.0, -0.5]  # far beyond the wheels' speed and the joint-rate limit
    for plant in _plants():
        from_arrays = plant.limit(Q, np.array(u))
        from_lists = plant.limit(Q.tolist(), u)
        assert from_arrays[0].tolist() == from_lists[0].tolist()
        assert from_arrays[1] is from_lists[1] is True
        assert from_arrays[0][2] == pytest.approx(ROBOT.joint_speed_limit, abs=1e-12)
        assert from_arrays[0][3] == pytest.approx(-0.5, abs=1e-12)
    applied, _ = KinematicPlant(ROBOT).limit(Q, np.array(u))
    wheels = abs(applied[0]) / ROBOT.wheel_radius + abs(applied[1]) * ROBOT.track_width / (
        2.0 * ROBOT.wheel_radius
    )
    assert wheels == pytest.approx(ROBOT.wheel_speed_limit, rel=1e-12)
    assert applied[1] / applied[0] == pytest.approx(1.0 / 5.0, rel=1e-12)  # curvature kept


def test_step_refuses_a_policy_that_is_not_callable_before_the_state_changes():
    for plant in _plants():
        plant.reset(Q, 0.01)
        before = plant.observe().values
        text = _message(lambda p=plant: p.step(0.0, U, 0.01, policy="bogus"))
        assert text == "policy must be None or a callable (t, q) -> u (got 'bogus')"
        assert plant.observe().values == before
        plant.step(0.0, U, 0.01, policy=None)  # None: the command is held
        assert plant.observe().values != before


@pytest.mark.parametrize("kind", [KinematicPlant, ThesisPlant])
@pytest.mark.parametrize("robot", [None, "thesis", 3.0])
def test_a_plant_refuses_a_robot_that_is_no_robot(kind, robot):
    text = _message(lambda: kind(robot))
    assert text.startswith("robot must be a Robot (got ")


# -- 2. a custom trajectory that raises ----------------------------------------------------
class _PoseRaises(Ellipse):
    def pose(self, t):
        if t > 0.5:
            return 1 / 0
        return super().pose(t)


class _VelocityRaises(Ellipse):
    def velocity(self, t):
        if t > 0.5:
            raise KeyError("no such time")
        return super().velocity(t)


class _SampleRaises(Ellipse):
    def sample(self, times):
        raise RuntimeError("sampling\nbroke")


class _PoseRefuses(Ellipse):
    def pose(self, t):
        raise ParameterError("pose: my own words")


PATTERN = r"trajectory: ellipse\.{method}\(\) raised {kind}: {text} at t = ([0-9.e+-]+) s"


@pytest.mark.parametrize("method", ["ats", "qp", "mpc"])
@pytest.mark.parametrize(
    ("trajectory", "call", "kind", "text", "cause"),
    [
        (_PoseRaises, "pose", "ZeroDivisionError", "'division by zero'", ZeroDivisionError),
        (_VelocityRaises, "velocity", "KeyError", "\"'no such time'\"", KeyError),
    ],
)
def test_a_raising_trajectory_is_one_plugin_error_naming_it_the_method_and_t(
    method, trajectory, call, kind, text, cause
):
    with pytest.raises(PluginError) as error:
        simulate(Robot(), trajectory(), method, duration=1.0)
    message = str(error.value)
    found = re.fullmatch(PATTERN.format(method=call, kind=kind, text=re.escape(text)), message)
    assert found, message
    assert 0.5 < float(found.group(1)) <= 1.0 + 1e-9
    assert isinstance(error.value.__cause__, cause)


def test_a_raising_sample_is_one_plugin_error_naming_the_times():
    with pytest.raises(PluginError) as error:
        simulate(Robot(), _SampleRaises(), "ats", duration=1.0)
    found = re.fullmatch(
        r"trajectory: ellipse\.sample\(\) raised RuntimeError: 'sampling broke' at t = 0 to "
        r"([0-9.]+) s",
        str(error.value),
    )
    assert found, str(error.value)
    assert 1.0 <= float(found.group(1)) < 1.1  # the block: the run's samples and stages
    assert isinstance(error.value.__cause__, RuntimeError)


def test_a_trajectory_s_own_parameter_error_passes_as_it_is():
    assert _message(lambda: simulate(Robot(), _PoseRefuses(), "ats", duration=1.0)) == (
        "pose: my own words"
    )


# -- 3. the result writers -----------------------------------------------------------------
@pytest.fixture(scope="module")
def result():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(Robot(), Ellipse(), "ats", duration=0.1)


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs /proc")
@pytest.mark.parametrize("writer", ["write_csv", "write_summary"])
def test_a_folder_that_takes_no_files_is_one_line_naming_it(result, writer):
    text = _message(lambda: getattr(result, writer)("/proc/ddwmmr-missing/run.out"))
    assert text == (
        "path: cannot make the folder /proc/ddwmmr-missing: /proc takes no new files or "
        "folders; choose a folder elsewhere"
    )
    text = _message(lambda: getattr(result, writer)("/proc/run.out"))
    assert text == (
        "path: cannot write in /proc: /proc takes no new files or folders; choose a folder "
        "elsewhere"
    )


@pytest.mark.parametrize(
    ("value", "shown"),
    [(object, "<class 'object'>"), ({"a": {1, 2}}, "{'a': {1, 2}}"), ({(1, 2): 3}, "{(1, 2): 3}")],
)
def test_a_summary_value_json_cannot_hold_is_named_before_anything_is_written(
    result, tmp_path, value, shown
):
    target = tmp_path / "summary.json"
    text = _message(lambda: result.write_summary(target, run=1, foo=value))
    assert text == (
        "summary: foo must be JSON data (numbers, text, true/false, None, lists and dicts of "
        f"them) (got {shown})"
    )
    assert os.listdir(tmp_path) == []
    result.write_summary(target, run={"a": [1, 2.5, None]})  # JSON data: written
    assert '"run": {' in target.read_text()


# -- 4. samples and name -------------------------------------------------------------------
class _Custom:
    duration = 1.0

    def __init__(self, samples):
        self.samples = samples

    def pose(self, t):
        return np.array([1.0 + 0.1 * t, 0.0, 0.0])

    def velocity(self, t):
        return np.array([0.1, 0.0, 0.0])


@pytest.mark.parametrize("samples", [1.5, 0.5, 0, True, "10", math.nan])
def test_a_trajectory_s_samples_must_be_an_integer(samples):
    text = _message(lambda: simulate(Robot(), _Custom(samples), "ats"))
    assert text.startswith("trajectory: samples (its resolution N) must be an integer >= 1 (got ")


def test_an_integral_samples_gives_its_step():
    assert resolution_step(_Custom(4)) == 0.25
    assert resolution_step(_Custom(2.0)) == 0.5
    assert resolution_step(_Custom(np.int64(8))) == 0.125


@pytest.mark.parametrize("name", [1, None, "", b"x"])
def test_a_trajectory_name_must_be_a_non_empty_string(name):
    for shape in (Ellipse, Rectangle):
        text = _message(lambda s=shape: s(name=name))
        assert text.startswith("name must be a string, not empty (got ")
    text = _message(lambda: SampledTrajectory([0, 1, 2], [[0, 0], [1, 0], [2, 0]], name=name))
    assert text.startswith("trajectory samples: name must be a string, not empty (got ")
    assert Ellipse(name="mine").name == "mine"


# -- 5. the unknown-option message -----------------------------------------------------------
def test_the_unknown_option_message_has_one_home():
    with pytest.raises(ParameterError) as helper:
        check_known_options("mine", {"zeta", "beta"}, ["alpha"])
    assert str(helper.value) == "method mine: unknown option 'beta' (accepted: alpha)"
    from ddwmmr.mpc.controller import MPCController

    direct = _message(lambda: MPCController(Robot(), horizon_s=2.0))
    built = _message(lambda: make_controller("mpc", Robot(), horizon_s=2.0))
    assert direct == built
    assert direct.startswith("method mpc: unknown option 'horizon_s' (accepted: ")
    assert _message(lambda: make_controller("ats", Robot(), bogus=1)).startswith(
        "method ats: unknown option 'bogus' (accepted: "
    )
