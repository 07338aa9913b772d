"""One home for "a list of (x, y) pairs in m" (:func:`ddwmmr.errors.xy_pairs`): the
scenario protocol's waypoints, the lower bounds' waypoints, the mpc's ``route`` and a
robot's ``caster_positions`` take the same lists and refuse the same things in the same
words; a set, whose order is undefined, is refused everywhere (and by
:func:`ddwmmr.errors.list_items`, which a robot's pairs use too)."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr.errors import ParameterError, list_items, xy_pairs
from ddwmmr.model import Robot
from ddwmmr.mpc.options import MPCOptions
from ddwmmr.scenarios import RunConfig, run_scenario
from ddwmmr.scenarios.generator import Scenario

LIST = "a non-empty list of (x, y) pairs in m"


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (None, f"w must be {LIST} (got None)"),
        ("ab", f"w must be {LIST} (got 'ab')"),
        ({"a": 1}, f"w must be {LIST} (got {{'a': 1}})"),
        ({(1.0, 2.0)}, f"w must be {LIST} (got {{(1.0, 2.0)}})"),
        (frozenset({(1.0, 2.0)}), f"w must be {LIST} (got frozenset({{(1.0, 2.0)}}))"),
        ([], f"w must be {LIST} (got [])"),
        (np.array(3.0), f"w must be {LIST} (got array(3.))"),
        (
            [(1, 2), frozenset({1.0, 2.0})],
            "w[2] must be an (x, y) pair of numbers in m (got frozenset({1.0, 2.0}))",
        ),
        ([(1, 2, 3)], "w[1] must be an (x, y) pair of numbers in m (got (1, 2, 3))"),
        ([(1, "2")], "w[1] y must be a finite number in [-1e+06, 1e+06] m (got '2')"),
        ([(True, 2)], "w[1] x must be a finite number in [-1e+06, 1e+06] m (got True)"),
        ([(np.nan, 2)], "w[1] x must be a finite number in [-1e+06, 1e+06] m (got nan)"),
        ([(0, 1), (0, -2e6)], "w[2] y must be in [-1e+06, 1e+06] m (got -2e+06)"),
    ],
)
def test_xy_pairs_refuses_in_one_line_naming_the_entry_from_1(value, message):
    with pytest.raises(ParameterError) as info:
        xy_pairs("w", value)
    assert str(info.value) == message


def test_xy_pairs_takes_lists_tuples_arrays_and_iterators_in_order():
    expected = ((1.0, 2.0), (-3.0, 0.5))
    for value in (
        [[1, 2], [-3, 0.5]],
        ((1.0, 2.0), (-3.0, 0.5)),
        np.array([[1.0, 2.0], [-3.0, 0.5]]),
        iter([(1, 2), (-3, 0.5)]),
        (np.array([1.0, 2.0]), (np.float32(-3.0), np.array(0.5))),
    ):
        pairs = xy_pairs("w", value)
        assert pairs == expected
        assert all(type(c) is float for pair in pairs for c in pair)
    assert xy_pairs("route", [], empty=True) == ()
    with pytest.raises(ParameterError, match=r"^route must be a list of \(x, y\) pairs in m"):
        xy_pairs("route", {(1.0, 2.0)}, empty=True)


def test_list_items_refuses_unordered_and_textual_collections():
    assert list_items("p", np.array([1.0, 2.0]), "two numbers", 2) == (1.0, 2.0)
    for value in ({1.0, 2.0}, frozenset({1.0, 2.0}), "12", b"12", {1: 2, 3: 4}, 5, None):
        with pytest.raises(ParameterError, match=r"^p must be two numbers \(got "):
            list_items("p", value, "two numbers", 2)
    with pytest.raises(ParameterError, match=r"^p must be two numbers \(got \(1, 2, 3\)\)$"):
        list_items("p", (1, 2, 3), "two numbers", 2)


def test_a_hand_made_scenario_with_a_set_of_waypoints_is_refused():
    """run_scenario accepted a set (its check took anything with a length) and then
    failed with TypeError: 'set' object is not subscriptable."""
    scenario = Scenario(0, {(1.0, 0.5), (0.5, 1.0)})
    with pytest.raises(ParameterError, match=r"^scenario waypoints must be a non-empty list"):
        run_scenario(scenario, RunConfig(time_limit=0.1))


def test_a_hand_made_scenario_takes_waypoints_as_lower_bound_does():
    """An iterator of waypoints, which lower_bound takes, was refused by run_scenario (no
    length); it runs as the same waypoints in a tuple do."""
    config = RunConfig(time_limit=0.2)
    listed = run_scenario(Scenario(0, ((1.0, 0.5), (0.5, 1.0))), config)
    read_once = run_scenario(Scenario(0, iter([(1.0, 0.5), (0.5, 1.0)])), config)
    drop = ("wall_s",)
    assert {k: v for k, v in listed.metrics.items() if k not in drop} == {
        k: v for k, v in read_once.metrics.items() if k not in drop
    }


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"link_masses": {5.0, 2.0}}, "link_masses must be a pair of numbers kg (got {2.0, 5.0})"),
        (
            {"joint_limits": ({-3.0, 3.0}, (-2.0, 2.0))},
            "joint_limits[1] must be a pair of numbers rad (got {3.0, -3.0})",
        ),
        (
            {"caster_positions": {(0.2, 0.0), (-0.2, 0.0)}},
            f"caster_positions must be {LIST} (got {{(0.2, 0.0), (-0.2, 0.0)}})",
        ),
    ],
)
def test_a_robot_refuses_sets_for_ordered_fields(options, message):
    """A set was taken in the order it iterates: link_masses {5, 2} became (2, 5)."""
    with pytest.raises(ParameterError) as info:
        Robot(**options)
    assert str(info.value) == message


@pytest.mark.parametrize(
    ("route", "message"),
    [
        ({(1.0, 2.0), (3.0, 4.0)}, "route must be a list of (x, y) pairs in m (got {"),
        ([(True, 1.0)], "route[1] x must be a finite number in [-1e+06, 1e+06] m (got True)"),
        ([(0.0, 1.0), (1e300, 1.0)], "route[2] x must be in [-1e+06, 1e+06] m (got 1e+300)"),
    ],
)
def test_the_mpc_route_is_checked_as_waypoints_are(route, message):
    """A set (order undefined), a boolean and 1e300 m were taken as route points."""
    with pytest.raises(ParameterError) as info:
        MPCOptions(route=route)
    assert str(info.value).startswith(message)
    assert MPCOptions(route=[[1, 2]]).route == ((1.0, 2.0),)
