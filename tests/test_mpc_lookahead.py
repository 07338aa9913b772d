"""``lookahead``: the waypoint plan through the current target to the next one (two legs of
free duration), its hand-over at the target, and what it buys on a scenario."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, make_controller
from ddwmmr.commands import traits_of
from ddwmmr.controllers.base import WaypointRun
from ddwmmr.mpc.controller import MPCController
from ddwmmr.mpc.options import MPCOptions
from ddwmmr.plants import ThesisPlant
from ddwmmr.scenarios import RunConfig, generate, run_scenario

ROBOT = Robot().with_payload(3.0)
START = np.array([0.0, 0.0, 0.0, 0.3, 1.2])
FIRST, SECOND = (1.6, 0.4), (1.6, 2.2)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"lookahead_weight": 1.5}, r"lookahead_weight must be in \[0, 1\]"),
        ({"lookahead_horizon": 0.1}, r"lookahead_horizon must be in \[0.5, 100\] s"),
        ({"route": "nowhere"}, r"^route must be a list of \(x, y\) pairs in m \(got 'nowhere'\)$"),
        (
            {"route": [(1.0, 2.0, 3.0)]},
            r"^route\[1\] must be an \(x, y\) pair of numbers in m \(got \(1.0, 2.0, 3.0\)\)$",
        ),
    ],
)
def test_bad_lookahead_options_are_one_line_errors(options, match):
    with pytest.raises(ParameterError, match=match):
        MPCOptions(**options)


def test_the_next_target_is_searched_along_the_route_from_the_last_one_found():
    route = [(1.0, 0.0), (2.0, 0.0), (1.0, 0.0), (3.0, 0.0)]
    controller = MPCController(ROBOT, lookahead=True, route=route)
    steps = [(1.0, 0.0), (2.0, 0.0), (1.0, 0.0), (3.0, 0.0), (5.0, 5.0)]
    assert [controller._next_target(t) for t in steps] == [
        (2.0, 0.0),
        (1.0, 0.0),
        (3.0, 0.0),  # the second visit of (1, 0), not the first
        None,  # the route's end
        None,  # not on the route
    ]
    assert MPCController(ROBOT, route=route)._next_target((1.0, 0.0)) is None  # lookahead off


def test_the_protocol_hands_the_route_over_only_with_lookahead():
    scenario = generate(1, seed=0)[0]
    plant = traits_of(ThesisPlant(ROBOT))
    plain = MPCController.waypoint_options(
        WaypointRun(scenario, RunConfig(controller="mpc"), plant, ROBOT)
    )
    assert "route" not in plain and "lookahead" not in plain
    config = RunConfig(controller="mpc", controller_options=(("lookahead", True),))
    options = MPCController.waypoint_options(WaypointRun(scenario, config, plant, ROBOT))
    assert options["route"] == [tuple(w) for w in scenario.waypoints]


@pytest.fixture(scope="module")
def converged_two_leg_plan():
    """``(controller, its reach2 problem, the plan w)`` after one IPOPT step from START
    towards FIRST then SECOND (solved once per worker; the tests only read the plan)."""
    controller = make_controller(
        "mpc", ROBOT, model="thesis", lookahead=True, route=[FIRST, SECOND], solver="ipopt",
        track_orientation=False, dt=0.02,
    )  # fmt: skip
    controller.command(0.0, START, np.array([*FIRST, 0.0]), np.zeros(3), base_velocity=(0, 0))
    problem = controller._problem("reach2")
    w = controller._warm.copy()
    w.flags.writeable = False  # shared by the tests: none may change it
    return controller, problem, w


def test_a_two_leg_plan_passes_the_target_then_reaches_the_next(converged_two_leg_plan):
    """Solved to convergence (IPOPT): the first leg's last node within the reach cost's
    Huber scale (1 cm) of the target, the last node of the next; the second leg's nodes
    follow the first's in time."""
    _, problem, w = converged_two_leg_plan
    ocp = problem.ocp
    xs, _ = ocp.trajectories(w)
    ends = [ROBOT.fk(ocp.model.configuration(xs[k]))[:2] for k in (ocp.split, ocp.N)]
    assert np.linalg.norm(ends[0] - FIRST) < 0.011
    assert np.linalg.norm(ends[1] - SECOND) < 0.011
    t1, t2 = ocp.horizon_of(w), ocp.second_leg_of(w)
    times = ocp.node_times(t1, t2)
    assert times[ocp.split] == pytest.approx(t1) and times[-1] == pytest.approx(t1 + t2)
    assert 0.1 < t1 < 5.0 and 0.1 < t2 < 12.0


def test_the_hand_over_starts_the_next_leg_from_the_plan_that_went_through_the_target(
    converged_two_leg_plan,
):
    """At the target the plan's second leg becomes the first: the new first leg ends where
    the old plan ended (the old second leg's last node), and the new second leg waits
    there."""
    controller, problem, w = converged_two_leg_plan
    old = problem.ocp
    xs_old, _ = old.trajectories(w)
    elapsed = 0.5 * old.horizon_of(w)
    x0 = xs_old[0, : old.nxm]
    single = controller._problem("reach")  # the route's end: one leg left
    guess, horizon = single._shifted(w, elapsed, x0, source=old)
    xs, _ = single.ocp.trajectories(guess)
    assert horizon == pytest.approx(old.horizon_of(w) + old.second_leg_of(w) - elapsed)
    np.testing.assert_allclose(xs[-1, : old.nxm], xs_old[-1, : old.nxm], atol=1e-12)
    middle = 0.5 * (old.horizon_of(w) + horizon) + elapsed  # a time inside the old plan
    times = single.ocp.node_times(horizon) + elapsed
    k = int(np.argmin(np.abs(times - middle)))
    old_times = old.node_times(old.horizon_of(w), old.second_leg_of(w))
    expected = [np.interp(times[k], old_times, xs_old[:, i]) for i in range(old.nxm)]
    np.testing.assert_allclose(xs[k, : old.nxm], expected, atol=1e-12)


def test_looking_ahead_shortens_a_scenario_on_the_thesis_plant():
    """Scenario 2 of seed 0 (best known 13.22 s): one target at a time 20.18 s, through
    the next target about 16 s, every waypoint reached with S held."""
    scenario = generate(2, seed=0)[1]
    times = {}
    for lookahead in (False, True):
        config = RunConfig(controller="mpc", controller_options=(("lookahead", lookahead),))
        metrics = run_scenario(scenario, config).metrics
        assert metrics["success"] and metrics["min_stability"] >= 1.25 - 1e-6
        times[lookahead] = metrics["time_s"]
    assert times[False] == pytest.approx(20.18, abs=0.01)
    assert times[True] < 0.85 * times[False]


def test_a_plan_that_stays_at_its_shortest_horizon_falls_back_to_one_target():
    """Scenario 15 of seed 1: 2 cm from waypoint 4 the plans through it say "there in
    0.1 s" while the exact-S guard holds the arm back, step after step (the end effector
    creeps, so the stall watch does not fire); after 0.5 s of that the controller plans
    for that target alone and goes on."""
    scenario = generate(15, seed=1)[14]
    config = RunConfig(controller="mpc", controller_options=(("lookahead", True),))
    metrics = run_scenario(scenario, config).metrics
    assert metrics["success"] and metrics["waypoints_reached"] == 5
    assert metrics["time_s"] < 30.0  # it timed out (60 s) at waypoint 4 before
