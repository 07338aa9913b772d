"""A choice parameter (a name among a few: integrator, solver, orientation...) given an
array or a list: ``value not in CHOICES`` compared a numpy array elementwise and raised
numpy's "truth value of an array ... is ambiguous" ValueError. Each is a one-line
ParameterError naming the parameter and its choices now (``errors.one_of``). And a
trajectory or obstacle name longer than the file system takes raised OSError "File name
too long" from the API (the command line printed it without naming the option)."""

import warnings

import numpy as np
import pytest

from ddwmmr import (
    Ellipse,
    ParameterError,
    Rectangle,
    Robot,
    load_trajectory,
    make_controller,
    simulate,
)
from ddwmmr.plants import make_plant
from ddwmmr.scenarios.protocol import RunConfig
from one_line import one_line

ROBOT = Robot()
CALLS = {
    "integrator": lambda v: simulate(ROBOT, Ellipse(), "ats", integrator=v, duration=0.1),
    "tipped_start": lambda v: simulate(ROBOT, Ellipse(), "ats", tipped_start=v, duration=0.1),
    "orientation": lambda v: Rectangle(orientation=v),
    "mode": lambda v: make_controller("qp", ROBOT, mode=v),
    "solver": lambda v: make_controller("qp", ROBOT, solver=v),
    "cone": lambda v: make_plant("mujoco", ROBOT, cone=v),
    "controller": lambda v: RunConfig(controller=v),
}
MPC = {
    "model": lambda v: make_controller("mpc", ROBOT, model=v),
    "qp_solver": lambda v: make_controller("mpc", ROBOT, qp_solver=v),
}


@pytest.mark.parametrize("value", [np.array(["rk4", "euler"]), np.array([]), ["rk4"], {"a": 1}])
@pytest.mark.parametrize("name", [*CALLS, *MPC])
def test_an_array_or_list_for_a_choice_is_refused_naming_it(name, value):
    call = CALLS.get(name) or MPC[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ParameterError, match=rf"^{name} must be one of ") as info:
            call(value)
    one_line(info)


def test_one_of_is_membership_an_unhashable_value_never_passes():
    from ddwmmr.errors import one_of

    assert one_of("rk4", ("euler", "rk4")) and one_of(np.str_("rk4"), ("rk4",))
    assert not one_of(np.array(["rk4"]), ("rk4",)) and not one_of(["rk4"], ("rk4",))
    assert not one_of("RK4", ("rk4",))


@pytest.mark.parametrize(
    "call", [load_trajectory, lambda name: make_controller("qp", ROBOT, obstacles=name)]
)
def test_a_name_longer_than_the_file_system_takes_is_an_unknown_name(call):
    with pytest.raises(ParameterError, match=r"^(traj|obstacles): unknown ") as info:
        call("x" * 300)
    one_line(info)
