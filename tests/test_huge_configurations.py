"""Finite configurations too large for the kinematics are one ParameterError naming q.

Found by an API fuzz: with ``q = [0, 0, 1e308, 1e308, 0]`` the link heading
``phi + th1`` overflowed to inf and ``cos(inf)`` raised a plain ``ValueError: math domain
error`` from pi, ats, ap, clrrmc-ts, qp, mpc and from ``Robot.fk``, ``jacobian``,
``stability`` and friends; and ``simulate(..., q0=[1e308, 0, 0, 0, 0])`` ran to an rms
error of inf. The angles of a configuration are now bounded by
``MAX_CONFIGURATION_ANGLE_RAD`` (5e307 rad: three of them always sum to a finite float),
and simulate's start position by the trajectories' own ``MAX_COORDINATE_M``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr import Robot, make_controller, simulate
from ddwmmr.errors import MAX_COORDINATE_M, ParameterError
from ddwmmr.resolution import kernels
from ddwmmr.trajectories import Ellipse

ROBOT = Robot()
BOUND = 5e307  # ddwmmr.model.kinematics.MAX_CONFIGURATION_ANGLE_RAD
#: Just beyond the bound: the sums still fit a float, so only the range check refuses it.
BEYOND = math.nextafter(BOUND, math.inf)
OVERFLOWING = [
    [0.0, 0.0, 1e308, 1e308, 0.0],  # the fuzz's case: phi + th1 = inf
    [0.0, 0.0, 1.7e308, 1.7e308, 1.7e308],
    [0.0, 0.0, -1e308, 1e308, 1e308],  # phi + th1 = 0, th1 + th2 = inf (stability)
    [0.0, 0.0, BEYOND, 0.3, 0.3],  # no sum overflows: refused by the range alone
]
REFUSAL = r"^q must be 5 finite numbers \[x, y, phi, th1, th2\] \(m, rad\) with \|phi\|, "
REFUSAL += r"\|th1\|, \|th2\| <= 5e\+307 rad \(got phi, th1, th2 = "
ALL_METHODS = ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs", "qp", "mpc"]
ROBOT_METHODS = [
    "fk",
    "jacobian",
    "augmented_jacobian",
    "stability",
    "stability_gradient",
    "centre_of_mass",
    "manipulability",
    "joints_outside",
]


def _refused(call, match: str) -> str:
    with pytest.raises(ParameterError, match=match) as error:
        call()
    message = str(error.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize("q", OVERFLOWING)
@pytest.mark.parametrize("name", ROBOT_METHODS)
def test_robot_methods_refuse_angles_beyond_the_bound(name, q):
    method = getattr(ROBOT, name)
    for given in (q, tuple(q), np.array(q)):
        _refused(lambda given=given: method(given), REFUSAL)


def test_the_bound_is_the_documented_one():
    from ddwmmr.model.kinematics import MAX_CONFIGURATION_ANGLE_RAD

    assert MAX_CONFIGURATION_ANGLE_RAD == BOUND
    assert math.isfinite(3.0 * BOUND)


def test_robot_methods_take_angles_at_the_bound_and_any_finite_position():
    at_bound = [1.7e308, -1.7e308, BOUND, -BOUND, BOUND]  # x, y have no bound here
    pose = ROBOT.fk(at_bound)
    assert pose[0] == 1.7e308 and pose[1] == -1.7e308
    assert pose[2] == pytest.approx(BOUND, rel=1e-15)
    assert np.all(np.isfinite(ROBOT.jacobian(at_bound)))
    assert all(math.isfinite(s) for s in ROBOT.stability(at_bound))
    assert ROBOT.fk([1e308, 0.0, 0.0, 0.0, 0.0])[0] == 1e308
    # a rate is no angle: qdot keeps no such bound
    speeds = ROBOT.wheel_speeds([0.0, 0.0, 0.0, 0.3, 0.3], [0.0, 0.0, 1e308, 0.0, 0.0])
    assert speeds[0] == pytest.approx(-speeds[1], rel=1e-12) and abs(speeds[0]) > 1e300


@pytest.mark.parametrize("q", OVERFLOWING)
@pytest.mark.parametrize("method", ALL_METHODS)
def test_every_command_refuses_angles_whose_sums_overflow(method, q):
    controller = make_controller(method, ROBOT)
    trajectory = Ellipse()
    controller.reset(trajectory, np.array([1.0, 0.0, 0.0, 0.3, 0.5]))
    state = np.array(q)
    _refused(
        lambda: controller.command(0.0, state, trajectory.pose(0.0), trajectory.velocity(0.0)),
        REFUSAL,
    )


@pytest.mark.parametrize("method", ["qp", "mpc", "pi", "ats", "ap"])
def test_a_state_at_the_bound_still_gets_a_finite_command(method):
    controller = make_controller(method, ROBOT)
    trajectory = Ellipse()
    controller.reset(trajectory, np.array([1.0, 0.0, 0.0, 0.3, 0.5]))
    for q in ([0.0, 0.0, BOUND, BOUND, BOUND], [1e308, -1e308, -BOUND, BOUND, -BOUND]):
        u = controller.command(0.0, np.array(q), trajectory.pose(0.0), trajectory.velocity(0.0))
        assert u.shape == (4,) and np.all(np.isfinite(u)), (q, u)


@pytest.mark.parametrize("kernel", [kernels.ats, kernels.pseudoinverse])
def test_the_kernels_refuse_them_too(kernel):
    _refused(lambda: kernel(0.5, 0.4, 1e308, 1e308, 0.0, 0.1, 0.0, 0.0), REFUSAL)
    _refused(lambda: kernel(0.5, 0.4, BEYOND, 0.0, 0.0, 0.1, 0.0, 0.0), REFUSAL)
    (v, w, t1, t2), _ = kernel(0.5, 0.4, BOUND, BOUND, BOUND, 0.1, 0.0, 0.0)
    assert all(math.isfinite(value) for value in (v, w, t1, t2))


@pytest.mark.parametrize("method", ALL_METHODS)
def test_reset_refuses_such_a_start(method):
    controller = make_controller(method, ROBOT)
    message = _refused(
        lambda: controller.reset(Ellipse(), np.array([0.0, 0.0, 1e308, 1e308, 0.0])),
        r"^q0 must be 5 finite numbers .* <= 5e\+307 rad",
    )
    assert message.endswith("(got phi, th1, th2 = 1e+308, 1e+308, 0)")


def test_simulate_refuses_a_start_position_beyond_the_trajectories_bound():
    assert MAX_COORDINATE_M == 1e6
    for q0, match in (
        ([1e308, 0.0, 0.0, 0.3, 0.5], r"^q0 x must be in \[-1e\+06, 1e\+06\] m \(got 1e\+308\)$"),
        ([0.0, -2e6, 0.0, 0.3, 0.5], r"^q0 y must be in \[-1e\+06, 1e\+06\] m \(got -2e\+06\)$"),
        ([0.0, 0.0, 1e308, 1e308, 0.0], r"^q0 must be 5 finite numbers .* <= 5e\+307 rad"),
    ):
        _refused(lambda q0=q0: simulate(ROBOT, Ellipse(), "ats", q0=q0, duration=0.1), match)


def test_simulate_runs_from_a_start_at_the_position_bound():
    result = simulate(ROBOT, Ellipse(), "ats", q0=[1e6, 0.0, 0.0, 0.3, 0.5], duration=0.1)
    assert result.configurations()[0][0] == 1e6


@pytest.mark.parametrize("name", ["fk", "jacobian", "stability", "centre_of_mass"])
def test_robot_methods_refuse_a_complex_configuration(name):
    """abs() of a complex entry is real, so the magnitude bound alone would let it in."""
    with pytest.raises(ParameterError, match=r"^q must be 5 finite numbers"):
        getattr(Robot(), name)([0.0, 0.0, 1j, 0.0, 0.0])
