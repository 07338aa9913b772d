"""Non-finite inputs to ``Controller.command`` raise a one-line error naming the argument
(issue 8, 4b), the same for every method."""

import math

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, make_controller
from ddwmmr.controllers.inputs import MAX_INPUT_MAGNITUDE, check_inputs
from ddwmmr.resolution.reference import start_configuration

METHODS = ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs", "qp"]
BAD = [math.nan, math.inf, -math.inf]


def finite_arguments():
    trajectory = Ellipse()
    q = start_configuration(Robot(), trajectory)
    return {
        "t": 0.5,
        "q": q,
        "pose_d": trajectory.pose(0.5),
        "velocity_d": trajectory.velocity(0.5),
    }


def ready(method):
    controller = make_controller(method, Robot())
    controller.reset(Ellipse(), finite_arguments()["q"])
    return controller


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("argument", ["t", "q", "pose_d", "velocity_d"])
@pytest.mark.parametrize("bad", BAD)
def test_non_finite_input_is_refused_naming_the_argument(method, argument, bad):
    arguments = finite_arguments()
    if argument == "t":
        arguments["t"] = bad
    else:
        value = np.array(arguments[argument], dtype=float)
        value[1] = bad
        arguments[argument] = value
    controller = ready(method)
    with pytest.raises(ParameterError) as info:
        controller.command(**arguments)
    message = str(info.value)
    assert message.startswith(f"{argument} must be")
    assert "\n" not in message
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("method", METHODS)
def test_finite_input_gives_a_finite_command(method):
    u = ready(method).command(**finite_arguments())
    assert u.shape == (4,) and np.all(np.isfinite(u))


def test_wrong_sizes_and_types_are_named():
    arguments = finite_arguments()
    with pytest.raises(ParameterError, match=r"^q must be 5 finite numbers .*shape \(4,\)"):
        check_inputs(
            arguments["t"], arguments["q"][:4], arguments["pose_d"], arguments["velocity_d"]
        )
    with pytest.raises(ParameterError, match=r"^velocity_d must be 3 finite numbers"):
        check_inputs(arguments["t"], arguments["q"], arguments["pose_d"], ["a", 0, 0])
    with pytest.raises(ParameterError, match=r"^t must be a finite time"):
        check_inputs(None, arguments["q"], arguments["pose_d"], arguments["velocity_d"])


def test_values_up_to_the_documented_magnitude_are_accepted():
    big = MAX_INPUT_MAGNITUDE
    q = np.array([big, -big, big, 0.1, -big])
    assert check_inputs(0.0, q, np.array([big, big, -big]), np.full(3, big))[0] == q.tolist()
    check_inputs(0.0, list(q), [0.0, 0.0, 0.0], (0.0, 0.0, 0.0))  # plain sequences too


@pytest.mark.parametrize("argument", ["q", "pose_d", "velocity_d"])
@pytest.mark.parametrize("value", [1.7e308, -1e308, 1.0000001e9])
def test_finite_values_beyond_the_documented_magnitude_are_named(argument, value):
    # q = [1.7e308, 0, 0.3, -0.3, 0.6] made clrrmc-ts command [-inf, inf, 0, -inf]
    arguments = {"q": [0.0, 0.0, 0.3, -0.3, 0.6], "pose_d": [0.0] * 3, "velocity_d": [0.0] * 3}
    arguments[argument] = [value, *arguments[argument][1:]]
    with pytest.raises(ParameterError, match=rf"^{argument} must be .* magnitude at most 1e\+09"):
        check_inputs(0.0, *(np.array(arguments[k]) for k in ("q", "pose_d", "velocity_d")))
