"""The mpc's last node with the arm braked to rest: the yaw its momentum leaves the base
with, and the edge loads of that turn (docs/mpc.md, "The physics plant: tipping while
moving")."""

import math
from dataclasses import replace

import casadi as ca
import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.stability import GRAVITY_M_S2
from ddwmmr.model.support_loads import DEFAULT_MIN_EDGE_LOAD, EdgeLoadModel
from ddwmmr.mpc.models import LaggedArmPrediction, ThesisPrediction
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from mpc_plans import converged_reach_plan

ROBOT = Robot().with_payload(3.0)
LIMITS = (12.8, 33.3)  # the physics plant's joint acceleration limits with 3 kg (rad/s^2)
TAU = 0.02


def test_the_stopped_arm_leaves_the_base_turning_as_the_lagged_model_integrates_it():
    """Closed form ``w = (I(th2) w + H) / I(th2_stop)`` against the lagged-arm model
    itself, integrated in 1 ms steps with the joints braked at their limit (the command
    leading each rate down by ``a tau``) and no wheel force or damping until they rest: the
    yaw rate then within 1 % (the integrated arm stops a little later and elsewhere than
    the closed-form stopping pose, which changes I(th2) slightly); the configuration is the
    stopping pose, v untouched. Without an acceleration limit, or without the lag, there
    is no stopped-arm motion."""
    free = replace(sym.ThesisDynamics.from_robot(ROBOT), c1=0.0, c2=0.0)
    model = LaggedArmPrediction(ROBOT, free, TAU, LIMITS)
    x, u = ca.SX.sym("x", 9), ca.SX.sym("u", 4)
    step = ca.Function("step", [x, u], [model.integrate(x, u, 1e-3, 1)])
    stopped = ca.Function("stopped", [x], [ca.vertcat(*model.stopped_arm_motion(x))])
    for state in (
        [0.2, -0.3, 0.4, -1.0, 1.5, -1.0, 0.5, -2.0, -2.0],
        [0.0, 0.0, 0.0, 0.5, 0.7, 0.8, -0.2, 1.8, -1.2],
    ):
        state = np.array(state)
        predicted = np.asarray(stopped(state)).ravel()  # q (5), v, w
        current = state.copy()
        for _ in range(2000):
            rates = current[7:9]
            if np.all(np.abs(rates) < 1e-6):
                break
            lead = np.minimum(np.abs(rates), np.array(LIMITS) * TAU)
            command = rates - np.sign(rates) * lead
            current = np.asarray(step(current, np.r_[0.0, 0.0, command])).ravel()
        assert np.all(np.abs(current[7:9]) < 1e-6)
        assert abs(predicted[6] - state[6]) > 0.5  # braking the arm turns the base a lot
        assert predicted[6] == pytest.approx(current[6], rel=0.01)
        assert predicted[5] == state[5] and current[5] == pytest.approx(state[5])
        np.testing.assert_allclose(predicted[3:5], current[3:5], atol=0.02)
        np.testing.assert_allclose(predicted[:3], state[:3], atol=0.0)
    assert LaggedArmPrediction(ROBOT, free, TAU).stopped_arm_motion(x) is None
    assert ThesisPrediction(ROBOT, free).stopped_arm_motion(x[:7]) is None


def _reach_plan_end(with_row: bool) -> tuple[float, np.ndarray, float]:
    """A converged minimum-time reach plan from a robot reversing at 1 m/s and turning at
    0.5 rad/s with the payload out on its right and the shoulder and elbow swinging at
    -2 rad/s, towards a target 0.2 s down that motion: ``(T, edge loads of the last node
    with the arm braked to rest (N), largest slack)``, the loads from the numeric model."""
    dynamics = sym.ThesisDynamics.from_robot(ROBOT)
    model = LaggedArmPrediction(ROBOT, dynamics, TAU, LIMITS)
    if not with_row:
        model.stopped_arm_motion = lambda x: None  # the plan before the row
    x0 = np.array([0.0, 0.0, 0.0, -1.0, 1.5, -1.0, 0.5, -2.0, -2.0])
    x, u = ca.SX.sym("x", 9), ca.SX.sym("u", 4)
    coast = ca.Function("coast", [x, u], [model.integrate(x, u, 0.2, 20)])
    ahead = np.asarray(coast(x0, np.array([0.0, 0.0, -2.0, -2.0]))).ravel()
    target = ROBOT.fk(ahead[:5])[:2]
    ocp, w = converged_reach_plan(ROBOT, model, x0, target)
    last = ocp.trajectories(w)[0][-1]
    rates = last[7:9]
    stop = last[3:5] + rates * np.abs(rates) / (2.0 * np.array(LIMITS))
    momentum = dynamics.inertia(last[4]) * last[6] + dynamics.arm_momentum(last[4], rates)
    turn = momentum / dynamics.inertia(stop[1])
    loads = EdgeLoadModel.from_robot(ROBOT).loads_of_motion(
        stop[0], stop[1], (0.0, 0.0), (0.0, 0.0), last[5], turn, 0.0, 0.0
    )
    return ocp.horizon_of(w), np.array(loads), ocp.max_slack(w)


def test_a_reach_plan_ends_where_braking_the_arm_leaves_every_edge_loaded():
    """Reversing with the payload out on the right, the arm swinging: a minimum-time plan
    that passes its target with the arm moving ends, without the row, where braking the
    arm turns the base (about -1.4 rad/s) so that the sideways acceleration ``v w`` takes
    the load off the left side (under 2 N; on MuJoCo that is how scenarios 20 and 86 of
    seed 1 tipped, docs/mpc.md). With the row the converged plan ends where that turn
    leaves every edge at least ``min_edge_load`` (14.7 N), without slack, a little later."""
    floor = DEFAULT_MIN_EDGE_LOAD * ROBOT.total_mass * GRAVITY_M_S2
    fast, unloaded, _ = _reach_plan_end(with_row=False)
    assert unloaded.min() < 2.0
    later, loads, slack = _reach_plan_end(with_row=True)
    assert slack < 1e-9
    assert loads.min() >= floor - 1e-3
    assert fast < later < fast + 0.1


def test_scenario_20_of_seed_1_no_longer_tips_when_the_arm_stops_at_its_third_waypoint():
    """The run that tipped at 14.4 s (the third waypoint passed reversing at 1 m/s with the
    shoulder at -2 rad/s; the arm braked, its momentum turned the base at -1 rad/s and the
    left edge lost its load) runs to 15 s on MuJoCo without tipping, an edge unloaded
    under 0.15 s."""
    scenario = generate(20, seed=1)[19]
    config = RunConfig(controller="mpc", plant="mujoco", time_limit=15.0)
    metrics = run_scenario(scenario, config).metrics
    assert metrics["reason"] != "tipped (physics)"
    assert metrics["time_s"] == pytest.approx(15.0, abs=0.02) or metrics["success"]
    assert metrics["unloaded_time_s"] < 0.15
    assert not math.isnan(metrics["min_stability"]) and metrics["min_stability"] > 1.25
