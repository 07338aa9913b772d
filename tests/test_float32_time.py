"""A float32 time ``t`` given to a controller's ``command`` computes as its float64 value."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, make_controller
from ddwmmr.trajectories import Ellipse

ROBOT = Robot()
Q = np.array([0.1, -0.05, 0.02, 0.31, 0.52])
METHODS = ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs", "qp", "mpc"]


@pytest.mark.parametrize("method", METHODS)
def test_a_float32_time_computes_as_its_float64_value(method):
    """clrrmc-cs computed in float32 from an np.float32 t (a float32 command ~1e-7 off):
    check_inputs hands every method t as a float."""
    trajectory = Ellipse()
    t32 = np.float32(1.3)
    pose, velocity = trajectory.pose(float(t32)), trajectory.velocity(float(t32))
    commands = []
    for t in (t32, float(t32)):
        controller = make_controller(method, ROBOT)
        controller.reset(trajectory, Q)
        commands.append(np.asarray(controller.command(t, Q, pose, velocity)))
    assert commands[0].dtype == np.float64
    assert commands[0].tolist() == commands[1].tolist()


def test_the_thesis_controller_takes_t_as_a_float_and_refuses_what_is_no_time():
    pose, velocity = np.array([2.0, 1.0, 0.0]), np.zeros(3)
    for t in ("0.1", True, math.nan):
        with pytest.raises(ParameterError, match=r"^t must be a finite time in s \(got "):
            make_controller("thesis").command(t, Q, pose, velocity)
    forces = []
    for form in (np.float32, float):
        controller = make_controller("thesis")
        for k in range(3):
            command = controller.command(form(0.02 * k), Q, pose, velocity, base_velocity=(0.1, 0))
        forces.append(command)
    assert forces[0] == forces[1]
