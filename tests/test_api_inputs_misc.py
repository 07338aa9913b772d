"""Bad input to more of the documented API, each one ParameterError line naming the
parameter and its allowed range: the trajectories' sample times, the verdict's summary,
plug-in names, the GUI's geometry values and the python-control error loops. Valid input
keeps its numbers (checked against the scalar calls and the closed forms)."""

import math

import numpy as np
import pytest

from ddwmmr.controllers.base import register
from ddwmmr.errors import ParameterError
from ddwmmr.registry import ARBITERS, CONTROLLERS, PLANTS, Registry
from ddwmmr.sim import error_dynamics
from ddwmmr.sim.verdict import error_limit, explain, short_verdict, verdict
from ddwmmr.trajectories import Ellipse, Rectangle, SampledTrajectory
from ddwmmr.trajectories.parametric import check_geometry_value
from one_line import one_line

NAN, INF = math.nan, math.inf
TRAJECTORIES = {
    "ellipse": Ellipse(),
    "rectangle": Rectangle(),
    "sampled": SampledTrajectory([0.0, 1.0, 2.0, 3.0], [[0, 0], [1, 0.2], [2, 0], [3, -0.2]]),
}


# -- trajectories: the times of sample, pose and velocity -----------------------------------


@pytest.mark.parametrize("name", list(TRAJECTORIES))
@pytest.mark.parametrize(
    ("times", "got"),
    [
        ([NAN], "got nan as times[1]"),
        ([0.0, INF], "got inf as times[2]"),
        (np.array([1.0, -INF]), "got -inf as times[2]"),
        (NAN, "got nan"),
        ("abc", "got 'abc'"),
        (None, "got None"),
        ([True, False], "got [True, False]"),
        (["1.0"], "got ['1.0']"),
        ([[0.0, 1.0]], "got an array of shape (1, 2)"),
        ([0, 10**400], "got a value beyond float range"),
    ],
)
def test_sample_refuses_times_that_are_not_finite_numbers(name, times, got):
    with pytest.raises(ParameterError) as info:
        TRAJECTORIES[name].sample(times)
    assert one_line(info) == (
        f"times must be a finite number or a 1-D sequence of finite numbers (s) ({got})"
    )


@pytest.mark.parametrize("name", list(TRAJECTORIES))
@pytest.mark.parametrize("method", ["pose", "velocity"])
@pytest.mark.parametrize("t", [NAN, INF, -INF, "1.0", None])
def test_pose_and_velocity_refuse_a_time_that_is_not_finite(name, method, t):
    with pytest.raises(ParameterError, match=r"^t must be a finite number \(got ") as info:
        getattr(TRAJECTORIES[name], method)(t)
    one_line(info)


@pytest.mark.parametrize("name", list(TRAJECTORIES))
def test_sample_of_valid_times_gives_the_scalar_calls_numbers(name):
    trajectory = TRAJECTORIES[name]
    times = [0.0, 0.7, 1.5, 2.25, -1.0, 9.0]  # any order, before and after the samples
    poses, velocities = trajectory.sample(times)
    assert poses.shape == velocities.shape == (len(times), 3)
    for row, t in enumerate(times):
        np.testing.assert_allclose(poses[row], trajectory.pose(t), rtol=0, atol=1e-12)
        np.testing.assert_allclose(velocities[row], trajectory.velocity(t), rtol=0, atol=1e-12)
    one_pose, one_velocity = trajectory.sample(0.7)  # one number: one row
    assert np.array_equal(one_pose, poses[1:2]) and np.array_equal(one_velocity, velocities[1:2])
    empty, _ = trajectory.sample([])
    assert empty.shape == (0, 3)


# -- the verdict's summary ------------------------------------------------------------------


@pytest.mark.parametrize("function", [verdict, short_verdict, explain, error_limit])
@pytest.mark.parametrize("summary", [None, [("steps", 10)], "tracked", 3.0])
def test_verdict_refuses_anything_but_a_mapping(function, summary):
    with pytest.raises(ParameterError, match=r"^summary must be a mapping ") as info:
        function(summary)
    assert "(got " in one_line(info)


def test_verdict_of_a_mapping_is_unchanged():
    assert verdict({}) == {"verdict": "tracked", "verdict_reasons": []}
    failed = verdict({"steps": 10, "diverged": True})
    assert failed["verdict_reasons"] == ["diverged"]
    assert short_verdict({"verdict_reasons": []}) == "tracked"


# -- plug-in names ----------------------------------------------------------------------------

BAD_NAMES = ["a b", "a,b", "a:b", "a=b", "-x", ".hidden", "", "a\tb", "é", "x" * 65, None, 3]


@pytest.mark.parametrize("name", BAD_NAMES)
def test_register_refuses_a_name_the_command_line_cannot_address(name):
    before = CONTROLLERS.names()
    with pytest.raises(ParameterError, match=r"^register_controller: name must be 1 to 64 "):
        register(name)
    with pytest.raises(ParameterError) as info:
        Registry("widget", "widget", {}, "widget must be one of {known} (got {name})").register(
            name
        )
    assert one_line(info).startswith(
        "register_widget: name must be 1 to 64 ASCII letters, digits, '_', '-' or '.', "
        "not starting with '-' or '.', so that the command line can address it (got "
    )
    assert CONTROLLERS.names() == before


def test_every_registered_and_documented_name_is_allowed():
    names = [*CONTROLLERS.names(), *PLANTS.names(), *ARBITERS.names()]
    names += ["p-only", "ideal", "objective-only", "my_method.v2", "x" * 64, "2stage"]
    for name in names:
        assert CONTROLLERS.check_name(name) == name
    registry = Registry("widget", "widget", {}, "widget must be one of {known} (got {name})")

    @registry.register("my_widget-1.0")
    class Widget:
        """A widget."""

    assert Widget.name == "my_widget-1.0"
    assert registry.entry("my_widget-1.0").cls is Widget


# -- the GUI's geometry values (the check, without a display) ----------------------------------

RANGES = {
    "x0": "in [-1e+06, 1e+06] m",
    "y0": "in [-1e+06, 1e+06] m",
    "beta": "in [-1e+06, 1e+06] rad",
    "phi": "in [-1e+06, 1e+06] rad",
    "a": "in [1e-06, 1000] m",
    "b": "in [1e-06, 1000] m",
    "T": "in [1e-06, 1e+09] s",
}


@pytest.mark.parametrize("name", list(RANGES))
@pytest.mark.parametrize("value", ["abc", "", NAN, INF, None])
def test_every_bad_geometry_text_names_the_field_and_its_range(name, value):
    from ddwmmr.gui.settings import check_geometry

    for check in (check_geometry_value, check_geometry):
        with pytest.raises(ParameterError) as info:
            check(name, value)
        got = repr(value) if isinstance(value, str) else f"{value}"
        assert one_line(info) == f"{name} must be a finite number {RANGES[name]} (got {got})"


def test_valid_geometry_values_pass_unchanged():
    assert check_geometry_value("x0", -2) == -2.0 and check_geometry_value("beta", 0.3) == 0.3
    assert check_geometry_value("a", 2.5) == 2.5 and check_geometry_value("T", 40) == 40.0
    with pytest.raises(ParameterError, match=r"^x0 must be in \[-1e\+06, 1e\+06\] m"):
        check_geometry_value("x0", 1e300)


# -- python-control error loops (docs/api.md, "Error loops") ----------------------------------


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: error_dynamics.error_loops("pi", 0.5), r"^method must be one of clrrmc-ts, "),
        (lambda: error_dynamics.error_loops(None, 0.5), r"^method must be one of .* \(got None\)"),
        (lambda: error_dynamics.error_loops("clrrmc-ts", NAN), r"^tau must be > 0 s "),
        (lambda: error_dynamics.error_loops("clrrmc-ts", [1, 2]), r"^tau must be one value or 3"),
        (lambda: error_dynamics.step_response(0.5, [0.0, NAN]), r"^times must be a finite numb"),
        (lambda: error_dynamics.step_response(0.5, [[0.0, 1.0]]), r"^times must be a finite numb"),
        (lambda: error_dynamics.step_response(0.5, "abc"), r"^times must be a finite number"),
        (lambda: error_dynamics.step_response(0.5, []), r"^times must be at least 2 .*0 times"),
        (lambda: error_dynamics.step_response(0.5, [0.0]), r"^times must be at least 2 .*1 time\)"),
        (lambda: error_dynamics.step_response(0.5, [1.0, 2.0]), r"^times .*first time of 1 s"),
        (
            lambda: error_dynamics.step_response(0.5, [0, 2, 1]),
            r"^times .* increasing, .*\(got times\[2\] = 2 s then times\[3\] = 1 s\)",
        ),
        (lambda: error_dynamics.step_response(0.5, [0, 1, 3]), r"^times .*equally spaced"),
        (lambda: error_dynamics.error_response(0.5, [0, INF]), r"^times must be a finite number"),
        (lambda: error_dynamics.closed_form_step(NAN, [0, 1]), r"^tau must be > 0 s "),
        (lambda: error_dynamics.closed_form_step(0.0, [0, 1]), r"^tau must be > 0 s "),
        (lambda: error_dynamics.closed_form_step("1", [0, 1]), r"^tau must be > 0 s "),
        (lambda: error_dynamics.closed_form_step(0.5, [0, NAN]), r"^times must be a finite num"),
        (lambda: error_dynamics.closed_form_step(0.5, [0, -1]), r"^times must be >= 0 s "),
        (lambda: error_dynamics.loop_summary(INF), r"^tau must be a finite time constant "),
        (lambda: error_dynamics.velocity_loop(NAN, 1.0, 1.0), r"^mass must be a finite number"),
        (lambda: error_dynamics.velocity_loop(0.0, 1.0, 1.0), r"^mass must be > 0"),
        (lambda: error_dynamics.velocity_loop(1.0, -1.0, 1.0), r"^damping must be >= 0"),
        (lambda: error_dynamics.velocity_loop(1.0, 1.0, NAN), r"^bandwidth must be a finite"),
        (lambda: error_dynamics.velocity_loop(1.0, 1.0, 1e9), r"^bandwidth must be <= 10000"),
        (lambda: error_dynamics.velocity_loop_summary(1.0, 0.0, 0.0), r"^bandwidth must be > 0"),
        (
            lambda: error_dynamics.saturated_velocity_step(1.0, 1.0, 1.0, 0.0, 1.0, [0, 1]),
            r"^force_limit must be > 0",
        ),
        (
            lambda: error_dynamics.saturated_velocity_step(1.0, 1.0, 1.0, 1.0, NAN, [0, 1]),
            r"^step must be a finite number",
        ),
        (
            lambda: error_dynamics.saturated_velocity_step(1.0, 1.0, 1.0, 1.0, 1.0, [0, 2, 1]),
            r"^times must be at least 2 finite times \(s\), increasing, starting at 0 and ending ",
        ),
        (  # numpy's ambiguous truth value before
            lambda: error_dynamics.check_response_times([0, 1], spaced=np.array([True, False])),
            r"^spaced must be true or false \(got ",
        ),
        (  # a text was taken as True before
            lambda: error_dynamics.check_response_times([0, 1, 3], spaced="no"),
            r"^spaced must be true or false \(got 'no'\)$",
        ),
    ],
)
def test_error_loops_refuse_bad_input_naming_the_parameter(call, message):
    with pytest.raises(ParameterError, match=message) as info:
        call()
    one_line(info)


def test_error_loops_of_valid_input_are_unchanged():
    times = np.linspace(0.0, 3.0, 31)
    expected = 1.0 - np.exp(-times / 0.5)
    assert np.array_equal(error_dynamics.closed_form_step(0.5, times), expected)
    assert error_dynamics.closed_form_step(0.5, 1.5) == 1.0 - np.exp(-1.5 / 0.5)
    np.testing.assert_allclose(error_dynamics.step_response(0.5, times), expected, atol=1e-9)
    assert np.all(error_dynamics.step_response(INF, [0.0, 1.0]) == 0.0)
    assert error_dynamics.loop_summary(0.5)["pole_1_s"] == pytest.approx(-2.0)
    summary = error_dynamics.velocity_loop_summary(15.0, 15.0, 0.0)  # damping alone
    assert summary["pole_1_s"] == pytest.approx(-1.0)
