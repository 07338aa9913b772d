"""User-written trajectories and controllers in ``simulate`` (docs/api.md invites both).

A trajectory's ``pose(t)``/``velocity(t)`` may return any sequence of 3 finite numbers and
gives the run of the equivalent numpy array; anything else is one line naming ``pose`` or
``velocity``. A controller's ``command`` must return 4 finite numbers (a ``WheelForces``
on the force interface) and a controller object needs ``reset``; anything else is one line
naming the command and the step. Before, these were AttributeError/TypeError/ValueError from
deep inside, a FloatingPointError, or (the thesis plant) a silent run with NaN in ``v``.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from ddwmmr import Robot, simulate
from ddwmmr.commands import FORCE, WheelForces
from ddwmmr.errors import ParameterError
from ddwmmr.trajectories import Ellipse

METHODS = ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs", "qp"]
POSE = "trajectory pose(t) must return 3 finite numbers [xE, yE, phiE] (m, m, rad)"
VELOCITY = (
    "trajectory velocity(t) must return 3 finite numbers [xEdot, yEdot, phiEdot] (m/s, m/s, rad/s)"
)
COMMAND = (
    "method: {name}.command() must return 4 finite numbers u = [v, w, th1dot, th2dot] "
    "(m/s, rad/s, rad/s, rad/s)"
)


def _refused(call) -> str:
    with pytest.raises(ParameterError) as error:
        call()
    message = str(error.value)
    assert "\n" not in message
    return message


def _recorded(result) -> dict[str, np.ndarray]:
    """The time series without the wall-clock timing."""
    return {k: v for k, v in result.timeseries.items() if k != "step_us"}


def _assert_same_run(a, b) -> None:
    ts_a, ts_b = _recorded(a), _recorded(b)
    assert ts_a.keys() == ts_b.keys()
    for name in ts_a:
        np.testing.assert_array_equal(ts_a[name], ts_b[name], err_msg=name)


class Circle:
    """A user's trajectory: a circle of radius 1.5 m, ``form`` says what its methods
    return (``np.array``, ``list`` or ``tuple``)."""

    duration = 20.0
    name = "circle"

    def __init__(self, form=np.array) -> None:
        self.form = form

    def pose(self, t):
        return self.form([1.5 * math.cos(t / 5), 1.5 * math.sin(t / 5), t / 5 + math.pi / 2])

    def velocity(self, t):
        return self.form([-0.3 * math.sin(t / 5), 0.3 * math.cos(t / 5), 0.2])


class SampledCircle(Circle):
    """The circle with a vectorised ``sample`` returning lists of lists."""

    def sample(self, times):
        return [list(self.pose(t)) for t in times], [list(self.velocity(t)) for t in times]


_CIRCLE = object()  # Returns: the circle's own value


class Returns:
    """A trajectory on the circle whose ``pose`` or ``velocity`` returns ``value``."""

    duration = 20.0

    def __init__(self, pose=_CIRCLE, velocity=_CIRCLE) -> None:
        self._pose, self._velocity = pose, velocity

    def pose(self, t):
        return Circle().pose(t) if self._pose is _CIRCLE else self._pose

    def velocity(self, t):
        return Circle().velocity(t) if self._velocity is _CIRCLE else self._velocity


# -- trajectories -------------------------------------------------------------------------


@pytest.mark.parametrize("method", [*METHODS, "mpc"])
@pytest.mark.parametrize("form", [list, tuple])
def test_a_trajectory_returning_lists_gives_the_run_of_arrays(method, form):
    # was AttributeError: 'list' object has no attribute 'tolist' (sim/tracking.py,
    # sim/loop.py or resolution/reference.py)
    duration = 0.2 if method == "mpc" else 0.4
    expected = simulate(Robot(), Circle(), method, duration=duration)
    got = simulate(Robot(), Circle(form), method, duration=duration)
    _assert_same_run(got, expected)
    assert got.summary["trajectory"] == "circle"


@pytest.mark.parametrize("plant", ["kinematic", "thesis"])
def test_a_list_sample_gives_the_run_of_pose_and_velocity(plant):
    for method in ("ats", "clrrmc-cs"):  # the task's reference blocks and clrrmc-cs's own
        expected = simulate(Robot(), Circle(), method, duration=0.4, plant=plant)
        _assert_same_run(
            simulate(Robot(), SampledCircle(), method, duration=0.4, plant=plant), expected
        )


@pytest.mark.parametrize(
    "sample",
    [
        lambda self, times: "junk",
        lambda self, times: (np.full((len(times), 3), np.nan), np.zeros((len(times), 3))),
        lambda self, times: (np.zeros((len(times), 2)), np.zeros((len(times), 2))),
    ],
)
def test_a_sample_that_is_not_the_reference_is_not_used(sample):
    # clrrmc-cs's reference used it regardless: ValueError (too many values to unpack)
    odd = type("OddSample", (Circle,), {"sample": sample})()
    for method in ("ats", "clrrmc-cs"):
        expected = simulate(Robot(), Circle(), method, duration=0.4)
        _assert_same_run(simulate(Robot(), odd, method, duration=0.4), expected)


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        ([1.0, 0.0], "[1.0, 0.0]"),  # was ValueError: not enough values to unpack
        (None, "None"),  # TypeError: 'NoneType' object is not iterable
        ("abc", "'abc'"),  # ValueError: could not convert string to float: 'a'
        (np.zeros((1, 3)), "array([[0., 0., 0.]])"),  # TypeError: only 0-dimensional...
        (["1", "0", "0"], "['1', '0', '0']"),  # text is not a number
        ([True, False, False], "[True, False, False]"),  # nor are booleans
        ([0.5, True, 0.0], "[0.5, True, 0.0]"),  # not even among numbers
        ([math.nan, 0.0, 0.0], "[nan, 0.0, 0.0]"),  # "pose_e[1] must be a finite number"
    ],
)
@pytest.mark.parametrize("method", METHODS)
def test_a_pose_that_is_not_3_finite_numbers_is_refused_naming_pose(method, value, shown):
    message = _refused(lambda: simulate(Robot(), Returns(pose=value), method, duration=0.4))
    assert message == f"{POSE} (got {shown} at t = 0 s)"


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        (None, "None"),  # clrrmc-cs: AttributeError: 'NoneType' object has no attribute...
        (np.zeros(4), "array([0., 0., 0., 0.])"),  # clrrmc-cs: too many values to unpack
        ((0.0, math.inf, 0.0), "(0.0, inf, 0.0)"),
    ],
)
@pytest.mark.parametrize("method", METHODS)
def test_a_velocity_that_is_not_3_finite_numbers_is_refused_naming_velocity(method, value, shown):
    message = _refused(lambda: simulate(Robot(), Returns(velocity=value), method, duration=0.4))
    assert message == f"{VELOCITY} (got {shown} at t = 0 s)"


def test_a_velocity_turning_nan_mid_run_names_the_time():
    class Late(Circle):
        def velocity(self, t):
            return super().velocity(t) * (math.nan if t >= 0.2 else 1.0)

    # clrrmc-cs integrated it into its reference and then blamed "q, pose_d: too large for
    # the command to be finite"
    message = _refused(lambda: simulate(Robot(), Late(), "clrrmc-cs", duration=0.4))
    assert message == f"{VELOCITY} (got array([nan, nan, nan]) at t = 0.2 s)"


def test_the_library_trajectories_are_used_as_they_are():
    from ddwmmr.sim.tracking import CheckedTrajectory, checked_trajectory
    from ddwmmr.trajectories import Rectangle, load_trajectory

    for trajectory in (Ellipse(), Rectangle(), load_trajectory("figure8")):
        assert checked_trajectory(trajectory) is trajectory  # nothing added to their steps

    class Shifted(Ellipse):  # a user's pose below the library's: checked
        def pose(self, t):
            return super().pose(t).tolist()

    checked = checked_trajectory(Shifted())
    assert isinstance(checked, CheckedTrajectory) and checked_trajectory(checked) is checked
    assert checked.pose(1.0).tolist() == Ellipse().pose(1.0).tolist()
    assert checked.duration == Ellipse().duration and checked.samples == Ellipse().samples


def test_a_scaled_users_trajectory_is_checked_as_the_users_own():
    """ScaledTrajectory is the library's, but what it wraps may be a user's: its NaN is
    refused in one line naming the time, as without the scale."""
    from ddwmmr.sim.tracking import CheckedTrajectory, checked_trajectory
    from ddwmmr.trajectories import ScaledTrajectory

    assert checked_trajectory(ScaledTrajectory(Ellipse(), 2.0)).scale == 2.0  # as it is
    checked = checked_trajectory(ScaledTrajectory(Circle(), 2.0))  # what it wraps, checked
    assert isinstance(checked, ScaledTrajectory) and checked.scale == 2.0
    assert isinstance(checked.trajectory, CheckedTrajectory)
    assert checked_trajectory(checked) is checked

    class Late(Circle):
        def velocity(self, t):
            return super().velocity(t) * (math.nan if t >= 0.2 else 1.0)

    scaled = ScaledTrajectory(Late(), 2.0)
    message = _refused(lambda: simulate(Robot(), scaled, "clrrmc-cs", duration=0.4))
    assert message.startswith(f"{VELOCITY} (got array([nan, nan, nan]) at t = 0.2")


def test_the_controller_sees_the_trajectorys_attributes_and_the_result_keeps_it():
    seen = {}

    class Peek:
        def reset(self, trajectory, q0):
            seen.update(duration=trajectory.duration, name=trajectory.name, own=trajectory.form)
            seen["pose"] = trajectory.pose(0.0)

        def command(self, t, q, pose_d, velocity_d):
            return np.zeros(4)

    trajectory = Circle(list)
    result = simulate(Robot(), trajectory, Peek(), duration=0.1)
    assert seen["duration"] == 20.0 and seen["name"] == "circle" and seen["own"] is list
    assert seen["pose"].tolist() == Circle().pose(0.0).tolist()  # a float array
    assert result.trajectory is trajectory


def test_a_checked_trajectory_pickles():
    from ddwmmr.sim.tracking import checked_trajectory

    copy = pickle.loads(pickle.dumps(checked_trajectory(SampledCircle(list))))
    assert copy.pose(2.0).tolist() == Circle().pose(2.0).tolist()
    poses, _ = copy.sample(np.array([2.0]))
    assert poses.tolist() == [Circle().pose(2.0).tolist()]


# -- controllers --------------------------------------------------------------------------


class Fixed:
    """A user's controller commanding ``out`` (or ``out(t)``) at every call."""

    def __init__(self, out) -> None:
        self.out = out

    def reset(self, trajectory, q0) -> None:
        pass

    def command(self, t, q, pose_d, velocity_d, **_):
        return self.out(t) if callable(self.out) else self.out


@pytest.mark.parametrize("plant", ["kinematic", "thesis"])
@pytest.mark.parametrize(
    ("out", "shown"),
    [
        (np.array([math.nan, 0.0, 0.0, 0.0]), "array([nan, 0., 0., 0.])"),  # thesis: silent
        (np.array([math.inf, 0.0, 0.0, 0.0]), "array([inf, 0., 0., 0.])"),
        (None, "None"),
        (np.zeros(3), "array([0., 0., 0.])"),
        (np.zeros(5), "array([0., 0., 0., 0., 0.])"),
        ("abcd", "'abcd'"),
        (np.zeros((1, 4)), "array([[0., 0., 0., 0.]])"),
        ({}, "{}"),
        (0.1, "0.1"),
        (np.array([True, False, False, False]), "array([ True, False, False, False])"),
        ([0.1, True, 0.0, 0.0], "[0.1, True, 0.0, 0.0]"),
    ],
)
def test_a_command_that_is_not_4_finite_numbers_is_refused_naming_the_step(plant, out, shown):
    message = _refused(lambda: simulate(Robot(), Ellipse(), Fixed(out), plant=plant, duration=0.4))
    assert message == COMMAND.format(name="Fixed") + f" (got {shown} at step 0, t = 0 s)"


@pytest.mark.parametrize("plant", ["kinematic", "thesis"])
def test_a_command_turning_nan_names_its_step(plant):
    late = Fixed(lambda t: np.array([0.1, 0.0, 0.0, math.nan if t > 0.2 else 0.0]))
    late.name = "late"
    message = _refused(lambda: simulate(Robot(), Ellipse(), late, plant=plant, duration=0.4))
    # the kinematic plant's RK4 asks at the stage t = 0.2 + 0.01 s of step 10 (from 0.2 s),
    # the thesis plant holds the command of the sample at 0.22 s (step 11)
    where = "step 10, t = 0.21 s" if plant == "kinematic" else "step 11, t = 0.22 s"
    assert message == COMMAND.format(name="late") + f" (got array([0.1, 0. , 0. , nan]) at {where})"


@pytest.mark.parametrize("form", [list, tuple])
def test_a_command_as_a_list_gives_the_run_of_an_array(form):
    # the thesis plant recorded a list within the joint-speed limit as saturated (the
    # kinematic plant gave the array's run already)
    u = [0.1, 0.05, 0.1, -0.1]
    expected = simulate(Robot(), Ellipse(), Fixed(np.array(u)), plant="thesis", duration=0.4)
    got = simulate(Robot(), Ellipse(), Fixed(form(u)), plant="thesis", duration=0.4)
    _assert_same_run(got, expected)
    assert got.summary["saturated_steps"] == 0


@pytest.mark.parametrize(
    ("out", "shown"),
    [
        (np.zeros(4), "array([0., 0., 0., 0.])"),
        (
            WheelForces(math.nan, 0.0, 0.0, 0.0),
            "WheelForces(left=nan, right=0.0, th1_target=0.0, th2_targ...",
        ),
        (
            WheelForces(0.0, 0.0, None, 0.0),
            "WheelForces(left=0.0, right=0.0, th1_target=None, th2_tar...",
        ),
    ],
)
def test_a_force_command_must_be_wheel_forces_of_finite_numbers(out, shown):
    forces = Fixed(out)
    forces.interface = FORCE
    message = _refused(lambda: simulate(Robot(), Ellipse(), forces, plant="thesis", duration=0.4))
    assert message == (
        "method: Fixed.command() must return a WheelForces(left, right, th1_target, "
        "th2_target) of 4 finite numbers (N, N, rad, rad) "
        f"(got {shown} at step 0, t = 0 s)"
    )


@pytest.mark.parametrize("reset", [None, 5])
def test_a_controller_without_a_callable_reset_is_refused(reset):
    # was AttributeError: 'NoReset' object has no attribute 'reset' (sim/loop.py)
    members = {"command": lambda self, t, q, pose_d, velocity_d: np.zeros(4)}
    if reset is not None:
        members["reset"] = reset
    controller = type("NoReset", (), members)()
    message = _refused(lambda: simulate(Robot(), Ellipse(), controller, duration=0.2))
    assert message.startswith(
        "method must be a method name or a controller with reset(trajectory, q0) and "
        "command(t, q, pose_d, velocity_d) (got <"
    )
    assert message.endswith(", without reset)")


def _run_recording_errors(controller) -> tuple[object, list[tuple[int, str]]]:
    """``controller`` on the kinematic plant (10 steps of 0.02 s on the ellipse) under a
    task that ends a run on a controller error, as the scenarios' does: how the run ended
    and the (step, message) of each error the task was given."""
    from ddwmmr.plants.kinematic import KinematicPlant
    from ddwmmr.resolution.reference import start_configuration
    from ddwmmr.sim.loop import run_loop
    from ddwmmr.sim.tracking import TrackingTask

    errors = []

    class Quiet(TrackingTask):
        def controller_error(self, k, error):
            errors.append((k, str(error)))
            return True

    robot, trajectory = Robot(), Ellipse()
    plant = KinematicPlant(robot)
    task = Quiet(trajectory, plant)
    end = run_loop(plant, controller, task, start_configuration(robot, trajectory), 0.02, 10)
    return end, errors


def test_a_bad_command_goes_through_the_tasks_controller_error():
    bad = Fixed(lambda t: np.zeros(4) if t < 0.05 else None)
    bad.zero_order_hold = True  # no RK4 stages: every command is a sample's
    end, errors = _run_recording_errors(bad)
    assert (end.samples, end.reason) == (3, "controller_error")
    assert errors == [(3, COMMAND.format(name="Fixed") + " (got None at step 3, t = 0.06 s)")]


def test_a_controller_failing_at_an_integrator_stage_goes_through_controller_error():
    # the error reaches the loop through the library plant's RK4 step; the task records
    # it (a scenario fails) instead of the whole batch ending
    # fine at the samples (t = k 0.02 s), None between them: only an RK4 stage sees it
    bad = Fixed(lambda t: np.zeros(4) if abs(t / 0.02 - round(t / 0.02)) < 1e-9 else None)
    end, errors = _run_recording_errors(bad)
    assert (end.samples, end.reason) == (0, "controller_error")
    assert errors == [(0, COMMAND.format(name="Fixed") + " (got None at step 0, t = 0.01 s)")]
