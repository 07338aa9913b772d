"""Non-finite inputs to ``Controller.command`` raise a one-line error naming the argument,
the same for every method."""

import math

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, make_controller
from ddwmmr.controllers.inputs import check_inputs
from ddwmmr.resolution.reference import start_configuration
from one_line import one_line

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


def test_huge_finite_values_are_accepted():
    # Their sum overflows to inf; the element-wise check clears them.
    q = np.array([1e308, 1e308, 0.0, 0.1, 0.2])
    check_inputs(0.0, q, np.array([1e308, 1e308, 0.0]), np.zeros(3))
    check_inputs(0.0, list(q), [0.0, 0.0, 0.0], (0.0, 0.0, 0.0))  # plain sequences too


@pytest.mark.parametrize("method", [*METHODS, "mpc"])
@pytest.mark.parametrize("bad", ["0", b"0", True, np.True_])
def test_text_or_boolean_time_is_refused(method, bad):
    # float() takes "0" and True, but neither is a time: clrrmc-cs and mpc failed on a
    # text t with a TypeError, the other methods ran it as 0 s (or 1 s).
    with pytest.raises(ParameterError) as info:
        ready(method).command(bad, **{k: v for k, v in finite_arguments().items() if k != "t"})
    assert one_line(info) == f"t must be a finite time in s (got {bad!r})"


@pytest.mark.parametrize("t", [np.float64(0.5), 0, np.int64(0)])
def test_numpy_and_integer_times_are_times(t):
    arguments = finite_arguments()
    del arguments["t"]
    expected = ready("clrrmc-cs").command(float(t), **arguments)
    np.testing.assert_array_equal(ready("clrrmc-cs").command(t, **arguments), expected)
