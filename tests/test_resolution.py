"""Resolution kernels against the matrix formulations of SPEC §3 (second formulation)."""

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, make_controller
from ddwmmr.model.kinematics import qdot_from_u
from ddwmmr.resolution import kernels


def random_states(rng, n=25):
    """Configurations away from the cos(th1) = 0 singularity, with random task rates."""
    out = []
    while len(out) < n:
        q = rng.uniform(-math.pi, math.pi, 5)
        if abs(math.cos(q[3])) > 0.2:
            out.append((q, rng.normal(size=3)))
    return out


def test_pseudoinverse_equals_numpy_pinv(robot, rng):
    for q, xdot in random_states(rng):
        expected = np.linalg.pinv(robot.jacobian(q)) @ np.r_[xdot, 0.0]
        u, singular = kernels.pseudoinverse(robot.L1, robot.L2, *q[2:], *xdot)
        assert not singular
        np.testing.assert_allclose(qdot_from_u(q[2], u), expected, atol=1e-10)


@pytest.mark.parametrize("aux", ["sum", "shoulder"])
def test_ats_equals_inverse_of_augmented_jacobian(robot, rng, aux):
    for q, xdot in random_states(rng):
        expected = np.linalg.solve(robot.augmented_jacobian(q, aux), np.r_[xdot, 0.0, 0.0])
        u, _ = kernels.ats(robot.L1, robot.L2, *q[2:], *xdot, aux=aux)
        np.testing.assert_allclose(qdot_from_u(q[2], u), expected, atol=1e-10)


def test_artificial_potential_equals_null_space_projection(robot, rng):
    controller = make_controller("ap", robot, K1=1.0, K2=0.25, K3=0.66)
    for q, xdot in random_states(rng):
        J = robot.jacobian(q)
        pinv = np.linalg.pinv(J)
        gradient = np.array([0, 0, 2 * 0.66 * q[2], 2 * 1.0 * q[3], 2 * 0.25 * q[4]])
        expected = pinv @ np.r_[xdot, 0] + (np.eye(5) - pinv @ J) @ (-gradient)
        u = controller.command(0.0, q, np.zeros(3), xdot)
        np.testing.assert_allclose(qdot_from_u(q[2], u), expected, atol=1e-9)


def test_null_space_of_J_is_base_yaw_against_shoulder(robot, rng):
    z = np.array([0, 0, 1, -1, 0]) / math.sqrt(2)
    for q, _ in random_states(rng, 10):
        J = robot.jacobian(q)
        projector = np.eye(5) - np.linalg.pinv(J) @ J
        np.testing.assert_allclose(projector, np.outer(z, z), atol=1e-10)


@pytest.mark.parametrize("method", ["pi", "ats", "ap", "clrrmc-ts"])
def test_commands_stay_bounded_through_the_singularity(robot, method):
    # Sweep th1 across pi/2 (det = 0): damping keeps every command finite and bounded.
    controller = make_controller(method, robot)
    xdot = np.array([0.2, 0.1, 0.05])
    peaks, singular = [], 0
    for th1 in np.linspace(math.pi / 2 - 0.1, math.pi / 2 + 0.1, 2001):
        q = np.array([0.0, 0.0, 0.2, th1, 0.8])
        u = controller.command(0.0, q, robot.fk(q), xdot)
        assert np.all(np.isfinite(u))
        peaks.append(np.max(np.abs(u)))
        singular += controller.last.singular
    assert max(peaks) < 200.0  # undamped would reach ~ |xdot| / (L1 |cos th1|) ~ 1e16
    assert 0 < singular < 2001


def test_damping_is_zero_away_from_the_singularity_and_continuous():
    assert kernels.damping_squared(0.5, 0.05, 0.05) == 0.0
    assert kernels.damping_squared(0.05, 0.05, 0.05) == 0.0
    assert kernels.damping_squared(0.0, 0.05, 0.05) == pytest.approx(0.0025)
    assert kernels.damping_squared(0.0499999, 0.05, 0.05) == pytest.approx(0.0, abs=1e-8)


def test_unknown_method_and_option_errors(robot):
    with pytest.raises(ParameterError, match="unknown method 'nope'"):
        make_controller("nope", robot)
    with pytest.raises(ParameterError, match="unknown option 'K9'"):
        make_controller("ap", robot, K9=1.0)
    with pytest.raises(ParameterError, match="aux must be one of"):
        make_controller("ats", robot, aux="elbow")
    with pytest.raises(ParameterError, match="tau must be > 0"):
        make_controller("clrrmc-ts", robot, tau=-1.0)
    with pytest.raises(ParameterError, match="tau must be > 0"):
        make_controller("clrrmc-cs", robot, tau=float("nan"))
