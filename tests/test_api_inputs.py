"""Bad input to the public API is one ParameterError naming the parameter (an audit's cases).

Before, these raised raw TypeError/ValueError/OverflowError/ZeroDivisionError from deep
inside, or were accepted and produced 1e16 commands or an endless reference integration.
"""

import math

import numpy as np
import pytest

from ddwmmr import Robot, make_controller, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.plants import make_plant
from ddwmmr.trajectories import Ellipse


def _refused(call, match: str) -> str:
    with pytest.raises(ParameterError, match=match) as error:
        call()
    message = str(error.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize("method", ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs"])
@pytest.mark.parametrize("damping", [0.0, -0.1, math.nan])
def test_damping_must_be_positive(method, damping):
    # Undamped, ats at cos th1 = 0 commanded 1.3e16 rad/s with singular=False.
    _refused(lambda: make_controller(method, Robot(), damping=damping), "damping")


def test_small_damping_still_bounds_the_singular_command():
    controller = make_controller("ats", Robot(), damping=1e-3)
    q = np.array([0.0, 0.0, 0.0, math.pi / 2, 0.6])  # cos th1 = 0: the shoulder singularity
    trajectory = Ellipse()
    controller.reset(trajectory, q)
    u = controller.command(0.0, q, trajectory.pose(0.0), trajectory.velocity(0.0))
    assert np.all(np.isfinite(u)) and controller.last.singular


@pytest.mark.parametrize("step", ["x", None, math.inf, 1e-7, 5.0])
def test_reference_step_is_a_number_in_range(step):
    _refused(lambda: make_controller("clrrmc-cs", Robot(), reference_step=step), "reference_step")


@pytest.mark.parametrize(
    "tau", ["0.5", None, True, ["a"] * 3, [10**400] * 3, 1e-300, [0.5, 0.5], -1.0]
)
def test_tau_forms_refused(tau):
    _refused(lambda: make_controller("clrrmc-ts", Robot(), tau=tau), "tau")


@pytest.mark.parametrize("tau", [np.float32(0.5), np.int64(1), np.array(0.5), np.array([0.5] * 3)])
def test_tau_numpy_forms_accepted(tau):
    controller = make_controller("clrrmc-ts", Robot(), tau=tau)
    gains = (controller.kx, controller.ky, controller.kphi)
    assert gains == pytest.approx((1.0 / float(np.ravel(tau)[0]),) * 3)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"intervals": math.nan}, "intervals must be an integer in"),
        ({"intervals": "x"}, "intervals must be an integer in"),
        ({"intervals": [1, 2]}, "intervals must be an integer in"),
        ({"horizon": 1e300}, "horizon must be in"),
        ({"first_interval": 1e-300}, "first_interval must be in"),
        ({"track_orientation": "yes"}, "track_orientation must be true or false"),
    ],
)
def test_mpc_grid_options(options, match):
    _refused(lambda: make_controller("mpc", Robot(), **options), match)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"limits": [1]}, "limits must be Limit objects"),
        ({"tasks": 3}, "tasks must be a list of Task objects"),
        ({"obstacles": 5}, "obstacles must be circles"),
        ({"track_orientation": math.nan}, "track_orientation must be true or false"),
        ({"warm_start": "x"}, "warm_start must be true or false"),
        ({"tracking_weight": -1.0}, r"tracking_weight must be in \[0, 1e\+06\]"),
        ({"posture_weight": 1e300}, r"posture_weight must be in \[0, 1e\+06\]"),
        ({"manipulability_weight": 1e300}, r"manipulability_weight must be in \[0, 1e\+06\]"),
    ],
)
def test_qp_options(options, match):
    _refused(lambda: make_controller("qp", Robot(), **options), match)


def test_qp_none_means_no_extra_pieces():
    plain = make_controller("qp", Robot())
    none = make_controller("qp", Robot(), obstacles=None, tasks=None, limits=None)
    assert len(none.tasks) == len(plain.tasks) and len(none.limits) == len(plain.limits)


def test_unknown_plant_option_names_the_accepted_ones():
    message = _refused(lambda: make_plant("thesis", Robot(), bogus=1), "plant thesis")
    assert "'bogus'" in message and "force_limit" in message
    _refused(
        lambda: simulate(Robot(), Ellipse(), "ats", plant_options={"bogus": 1}), "unknown option"
    )


@pytest.mark.parametrize("robot", ["x", 3, {"L1": 0.3}])
def test_robot_must_be_a_robot(robot):
    _refused(lambda: make_controller("ats", robot), "robot must be a Robot")
    _refused(lambda: make_plant("kinematic", robot), "robot must be a Robot")
    _refused(lambda: simulate(robot, Ellipse(), "ats"), "robot must be a Robot")


class _NoSamples(Ellipse):
    samples = 0


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: simulate(Robot(), Ellipse(), "ats", q0="abcde"), "q0 must be 5 finite numbers"),
        (lambda: simulate(Robot(), Ellipse(), "ats", initial_offset=5.0), "initial_offset"),
        (lambda: simulate(Robot(), Ellipse(), "ats", initial_offset=None), "initial_offset"),
        (lambda: simulate(Robot(), Ellipse(), "ats", plant=3), "plant must be a plant name"),
        (lambda: simulate(Robot(), Ellipse(), "ats", plant=None), "plant must be a plant name"),
        (lambda: simulate(Robot(), Ellipse(), "ats", progress="x"), "progress must be a callable"),
        (lambda: simulate(Robot(), Ellipse(), "ats", plant_options="x"), "plant_options"),
        (lambda: simulate(Robot(), Ellipse(), None), "method must be a method name"),
        (lambda: simulate(Robot(), _NoSamples(), "ats"), "samples"),
    ],
)
def test_simulate_arguments(call, match):
    _refused(call, match)


@pytest.mark.parametrize("make", [lambda: 10**5000, lambda: 10**400, lambda: "x" * 500])
def test_messages_stay_one_short_line_for_huge_values(make):
    from ddwmmr.errors import check_positive

    value = make()  # built here: pytest cannot show a 5000-digit int as a test id
    match = "L1 must be a number" if isinstance(value, str) else "L1 must be a finite number"
    message = _refused(lambda: check_positive("L1", value), match)
    assert len(message) < 100
