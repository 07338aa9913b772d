"""numpy's numbers, a 0-d array among them, as the parameters of the documented API: an
integer parameter took ``np.array(36)`` nowhere (``budget_bound(arcs=...)`` refused it
while ``cell=np.array(0.2)`` passed), a number check took ``np.array(True)`` and
``np.array("0.2")`` as numbers, and ``load_trajectory``'s overrides refused
``np.float64``. One rule now: a 0-d array stands for the scalar it holds, which is then
judged as itself (a boolean or text is no number)."""

import numpy as np
import pytest

from ddwmmr.bounds.lower import budget_bound
from ddwmmr.errors import (
    ParameterError,
    check_bool,
    check_int_at_least,
    check_number_type,
    check_positive,
)
from ddwmmr.model import Robot
from ddwmmr.trajectories import Ellipse, load_trajectory
from one_line import one_line


def test_budget_bound_takes_a_0d_integer_array_like_a_0d_float_array():
    robot = Robot()
    given = budget_bound(
        robot, [(1.0, 0.5)], cell=np.array(0.2), arcs=np.array(36), chunk=np.array(4)
    )
    plain = budget_bound(robot, [(1.0, 0.5)], cell=0.2, arcs=36, chunk=4)
    assert (given.value, given.arcs, given.cells) == (plain.value, plain.arcs, plain.cells)
    assert type(given.arcs) is int


@pytest.mark.parametrize("value", [np.array(36), np.array(36.0), np.array(36, dtype=np.uint8)])
def test_an_integer_check_takes_a_0d_array(value):
    number = check_int_at_least("n", value, 1)
    assert number == 36 and type(number) is int


@pytest.mark.parametrize(
    "value",
    [np.array(True), np.array(2.5), np.array("3"), np.array([3]), np.array(3, dtype=object) + 0.5],
)
def test_an_integer_check_refuses_what_a_0d_array_holds_if_no_integer(value):
    with pytest.raises(ParameterError, match=r"^n must be an integer >= 1 \(got ") as info:
        check_int_at_least("n", value, 1)
    one_line(info)


@pytest.mark.parametrize(
    "value", [np.array(True), np.array("0.2"), np.array(b"1"), np.array("3", dtype=object)]
)
def test_a_number_check_refuses_a_boolean_or_text_in_a_0d_array(value):
    with pytest.raises(ParameterError, match=r"^cell must be a finite number > 0 \(got array\("):
        check_positive("cell", value)
    with pytest.raises(ParameterError, match=r"^N must be a number \(got array\("):
        check_number_type("N", value)


def test_a_boolean_check_takes_a_0d_boolean_array():
    assert check_bool("flag", np.array(True)) is True
    with pytest.raises(ParameterError, match=r"^flag must be true or false \(got array\(1\)\)"):
        check_bool("flag", np.array(1))


def test_load_trajectory_overrides_take_numpy_numbers():
    given = load_trajectory("ellipse", N=np.int32(200), a=np.float64(1.2), b=np.array(0.8))
    plain = load_trajectory("ellipse", N=200, a=1.2, b=0.8)
    for t in (0.0, 1.7, 5.0):
        assert np.array_equal(given.pose(t), plain.pose(t))
    assert isinstance(plain, Ellipse)
    with pytest.raises(ParameterError, match=r"N must be a number \(got np\.True_\)"):
        load_trajectory("ellipse", N=np.True_)


def test_arm_ik_refuses_a_numpy_boolean_elbow_and_takes_a_numpy_sign():
    robot = Robot()
    assert robot.arm_ik(0.3, 0.2, elbow=np.array(-1)) == robot.arm_ik(0.3, 0.2, elbow=-1)
    assert robot.arm_ik(0.3, 0.2, elbow=np.int8(1)) == robot.arm_ik(0.3, 0.2, elbow=1)
    for flag in (np.True_, np.array(True), True, np.array([1])):
        with pytest.raises(ParameterError, match=r"^elbow must be \+1 or -1 \(got "):
            robot.arm_ik(0.3, 0.2, elbow=flag)


@pytest.mark.parametrize(
    ("option", "message"),
    [
        ("speed_budget", r"^speed_budget must be two numbers > 0"),
        ("tasks", r"^tasks must be a list of Task objects"),
        ("limits", r"^limits must be a list of Limit objects"),
        ("obstacles", r"^obstacles must be circles, \(x, y, radius\) triples or a TOML file"),
    ],
)
def test_a_0d_array_where_a_sequence_goes_is_refused_naming_it(option, message):
    """A 0-d array has __iter__ and __len__, yet iter() and len() raise TypeError: the
    qp's sequence options took it for a sequence and failed inside."""
    from ddwmmr.controllers import make_controller

    with pytest.raises(ParameterError, match=message + r".*\(got array\(3\)\)$") as info:
        make_controller("qp", Robot(), **{option: np.array(3)})
    one_line(info)
