"""The obstacle margin and the waypoint ``reach_speed`` on robots of other sizes (docs/qp.md
and docs/mpc.md, "Robot size").

Not given, ``obstacle_margin`` is the robot's own, 0.05 of its length unit (``L1 / 0.35
m``), in the ``qp`` and the ``mpc`` alike, and the ``mpc``'s ``reach_speed`` 0.05 of the
unit per second: exactly 0.05 m and 0.05 m/s on the default robot. A robot scaled by a
power of two then runs the default robot's steps round a scaled post with ``s`` times its
errors, the margin left alone; the 1/20 robot takes obstacles at all (the qp refused them:
its default 0.05 m was beyond its obstacle influence, 0.6 of the unit). A given margin
stays in metres, and the qp refuses one at or beyond its influence, naming
``obstacle_margin`` and its range for the robot.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ddwmmr import Robot, make_controller
from ddwmmr.errors import ParameterError
from scaled_robots import TWENTIETH, scaled_robot
from test_mpc_scale import errors as mpc_errors
from test_mpc_scale import solver_calls
from test_qp_scale import ARRAYS, POST, built
from test_qp_scale import errors as qp_errors
from test_qp_scale import run as qp_run

#: The shipped post, position tracking; the margin left to its default.
SCENE = {"obstacles": [POST], "track_orientation": False}


def quietly(method: str, robot: Robot, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a small robot's lengths look like unit mistakes
        return make_controller(method, robot, **options)


@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_qp_a_power_of_two_scale_gets_the_default_robots_problem_with_the_default_margin(
    factor,
):
    """Two posts near the base, the margin not given: the solver's arrays are the default
    robot's bit for bit (the obstacle rows' bounds hold the margin: they differ with 0.1)."""
    options = {"obstacles": [POST, (0.9, -0.2, 0.2)], "track_orientation": False}
    _, reference = built(1.0, options)
    _, other_margin = built(1.0, {**options, "obstacle_margin": 0.1})
    assert not np.array_equal(other_margin.lower, reference.lower)
    for compiled in (True, False):
        _, problem = built(factor, options, compiled)
        for array in ARRAYS:
            assert np.array_equal(getattr(problem, array), getattr(reference, array)), array


@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_mpc_a_power_of_two_scale_passes_the_post_alike_with_the_default_margin(factor):
    reference = mpc_errors(Robot(), 1.0, **SCENE)
    scaled = mpc_errors(scaled_robot(factor), factor, **SCENE)
    assert reference[0].max() > 0.04
    np.testing.assert_array_equal(scaled, reference)


@pytest.mark.parametrize("options", [{}, {"obstacles": [(0.3, 1.8, 0.1)]}])
def test_mpc_waypoint_defaults_hand_the_solver_the_default_robots_problem(options):
    """``reach_speed`` and ``obstacle_margin`` not given: the solver's inputs and solution
    are the default robot's bit for bit, the command's ``v`` is twice the default's."""
    reference, default_commands = solver_calls(1.0, options)
    calls, commands = solver_calls(2.0, options)
    for call, expected in zip(calls, reference):
        for value, wanted in zip(call, expected):
            np.testing.assert_array_equal(value, wanted)
    for u, wanted in zip(commands, default_commands):
        np.testing.assert_array_equal(u, wanted * [2.0, 1.0, 1.0, 1.0])


def test_the_twentieth_robot_takes_obstacles_in_both_methods():
    """0.05 of its unit (1/20 m): 2.5 mm, in the qp's limit and the mpc's OCP and record."""
    post = [(0.05 * x, 0.05 * y, 0.05 * r) for x, y, r in [POST]]
    qp = quietly("qp", TWENTIETH, obstacles=post)
    (limit,) = [piece for piece in qp.limits if piece.name == "obstacles"]
    assert limit.margin == pytest.approx(0.0025, rel=1e-12)
    mpc = quietly("mpc", TWENTIETH, obstacles=post)
    mpc.reset(None, np.array([0.0, 0.0, 0.0, 0.3, 1.2]))
    assert mpc._config("reach").obstacle_margin == pytest.approx(0.05, rel=1e-12)  # unit
    record = mpc.resolved.record("reach", 0.02, mpc.unit, mpc.length_unit)
    assert record["obstacle_margin"] == pytest.approx(0.0025, rel=1e-12)
    assert record["reach_speed"] == pytest.approx(0.0025, rel=1e-12)


def test_the_twentieth_robot_runs_round_the_scaled_post_as_the_default_robot():
    reference = qp_run(Robot(), 1.0, **SCENE)
    scaled = qp_run(TWENTIETH, 0.05, **SCENE)
    np.testing.assert_allclose(qp_errors(scaled, 0.05)[0], qp_errors(reference)[0], rtol=1e-7)
    clearance = reference.summary["min_obstacle_clearance_m"]
    assert scaled.summary["min_obstacle_clearance_m"] == pytest.approx(0.05 * clearance)


def test_the_default_robots_defaults_are_its_old_numbers_exactly():
    mpc = make_controller("mpc", Robot(), obstacles=[(3.0, 3.0, 0.2)])
    record = mpc.resolved.record("reach", 0.02, mpc.unit, mpc.length_unit)
    assert (record["obstacle_margin"], record["reach_speed"]) == (0.05, 0.05)
    qp = make_controller("qp", Robot(), obstacles=[(3.0, 3.0, 0.2)])
    assert [piece.margin for piece in qp.limits if piece.name == "obstacles"] == [0.05]


@pytest.mark.parametrize(
    ("robot", "margin", "expected"),
    [
        (
            TWENTIETH,
            0.05,
            "obstacle_margin must be in [0, 0.03) m: below the qp's obstacle influence, 0.6 "
            "of the robot's length unit 0.05 m (got 0.05)",
        ),
        (
            Robot(),
            0.6,
            "obstacle_margin must be in [0, 0.6) m: below the qp's obstacle influence, 0.6 "
            "of the robot's length unit 1 m (got 0.6)",
        ),
    ],
)
def test_a_margin_beyond_the_qps_influence_is_refused_in_one_line(robot, margin, expected):
    with pytest.raises(ParameterError) as error:
        quietly("qp", robot, obstacles=[(3.0, 3.0, 0.2)], obstacle_margin=margin)
    assert str(error.value) == expected


def test_a_given_margin_stays_in_metres():
    """Just below the influence on the 1/20 robot: taken as it is (m); the mpc, whose
    rows hold every circle near or far, takes a margin beyond it."""
    qp = quietly("qp", TWENTIETH, obstacles=[(3.0, 3.0, 0.2)], obstacle_margin=0.029)
    assert [piece.margin for piece in qp.limits if piece.name == "obstacles"] == [0.029]
    mpc = quietly("mpc", TWENTIETH, obstacles=[(3.0, 3.0, 0.2)], obstacle_margin=0.5)
    assert mpc.resolved.record("reach", 0.02, mpc.unit, mpc.length_unit)["obstacle_margin"] == 0.5


def test_mpc_slack_is_reported_in_metres():
    """A start inside the keep-out of a post: the plans need the obstacle rows' slack (m^2),
    reported as the default robot's times ``s^2``, whatever the OCP's unit."""
    slacks = {}
    for factor in (1.0, 4.0):
        controller = quietly("mpc", scaled_robot(factor), obstacles=[(0.0, 0.0, 0.1 * factor)])
        q = np.array([0.36 * factor, 0.0, 0.0, 0.3, 1.2])
        with pytest.warns(UserWarning, match="inside the mpc's keep-out"):
            controller.reset(None, q)
        controller.command(0.0, q, np.array([factor, 0.0, 0.0]), np.zeros(3))
        slacks[factor] = controller.last.extra["mpc_slack"]
    assert slacks[1.0] > 1e-3
    assert slacks[4.0] == pytest.approx(16.0 * slacks[1.0], rel=1e-12)


def test_a_robot_in_its_length_unit_is_the_default_robot():
    """Every length divided by the unit, masses kept: the default robot 8 times as long
    (masses kept) in its unit 8 m is the default robot, casters included."""
    assert scaled_robot(8.0).in_length_unit(8.0) == Robot()
    casters = Robot(caster_positions=((0.2, 0.15), (-0.2, 0.0))).in_length_unit(0.5)
    assert casters.caster_positions == ((0.4, 0.3), (-0.4, 0.0))
    assert (casters.L1, casters.base_mass) == (0.7, Robot().base_mass)
    default = Robot()
    assert default.in_length_unit(1.0) is default
