"""The mpc's braking step (``ddwmmr.mpc.braking``) and the rule that takes it when a plan
on a physics plant needs its stability rows' slack."""

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot
from ddwmmr.commands import WheelForces, traits_of
from ddwmmr.controllers import make_controller
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc.braking import BRAKE_SLACK, BRAKE_TIME, braking_input
from ddwmmr.plants import ThesisPlant
from ddwmmr.plants.thesis import ThesisState
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.scenarios.protocol import make_scenario_plant

ROBOT = Robot().with_payload(3.0)
LIMITS, TAU = (12.8, 33.3), 0.02


def _decelerations(forces, v, w, th2):
    """(vdot, wdot) of the thesis plant (a second formulation of the force model) over
    one 1 ms step from (v, w) under the forces."""
    plant = ThesisPlant(ROBOT)
    plant.reset(np.zeros(5), 1e-3)
    plant.state = ThesisState(0.0, 0.0, 0.0, -0.7, th2, v, w)
    plant.step(0.0, WheelForces(forces[0], forces[1], -0.7, th2), 1e-3)
    after = plant.observe()
    return (after.v - v) / 1e-3, (after.w - w) / 1e-3


def test_the_braking_forces_shed_speed_and_turn_with_one_time_constant():
    """Unsaturated, the thesis plant decelerates at v / BRAKE_TIME and w / BRAKE_TIME
    (to 1 %, one 1 ms step); fast, both wheels stay within the force limit, the larger at
    it, and the base still decelerates along its motion (v and w shrink in proportion)."""
    dynamics = sym.ThesisDynamics.from_robot(ROBOT)
    th2 = 1.2
    slow = braking_input(dynamics, th2, (0.2, -0.1), (0.0, 0.0), LIMITS, TAU)
    vdot, wdot = _decelerations(slow, 0.2, -0.1, th2)
    assert vdot == pytest.approx(-0.2 / BRAKE_TIME, rel=0.01)
    assert wdot == pytest.approx(0.1 / BRAKE_TIME, rel=0.01)
    assert max(abs(slow[0]), abs(slow[1])) < dynamics.force_limit
    fast = braking_input(dynamics, th2, (1.2, 0.9), (0.0, 0.0), LIMITS, TAU)
    assert max(abs(fast[0]), abs(fast[1])) == pytest.approx(dynamics.force_limit, rel=1e-12)
    vdot, wdot = _decelerations(fast, 1.2, 0.9, th2)
    assert vdot < 0.0 and wdot < 0.0
    # scaled together: the same request as with motors strong enough for it, made smaller
    strong = sym.ThesisDynamics.from_robot(ROBOT, force_limit=1e6)
    wanted = braking_input(strong, th2, (1.2, 0.9), (0.0, 0.0), LIMITS, TAU)
    assert max(abs(wanted[0]), abs(wanted[1])) > dynamics.force_limit
    factor = dynamics.force_limit / max(abs(wanted[0]), abs(wanted[1]))
    np.testing.assert_allclose(fast[:2], factor * wanted[:2], rtol=1e-12)


def test_the_braking_step_slows_each_joint_at_its_acceleration_limit():
    """A joint faster than ``a tau`` gets a command ``a tau`` below its rate (the lag
    then decelerates it at ``a``); a slower one is commanded to stop."""
    dynamics = sym.ThesisDynamics.from_robot(ROBOT)
    step = braking_input(dynamics, 1.0, (0.0, 0.0), (2.0, -0.1), LIMITS, TAU)
    assert step[2] == pytest.approx(2.0 - 12.8 * TAU, rel=1e-12)
    assert step[3] == 0.0
    assert (step[2] - 2.0) / TAU == pytest.approx(-12.8)
    step = braking_input(dynamics, 1.0, (0.0, 0.0), (-1.5, 1.0), LIMITS, TAU)
    assert step[2:] == pytest.approx([-1.5 + 12.8 * TAU, 1.0 - 33.3 * TAU])


def _physics_mpc(**options):
    """The mpc on the scenarios' MuJoCo plant (its base damping) at their step: with the
    default options its problem is scenario 26's below, built once per process."""
    mpc = make_controller("mpc", ROBOT, dt=0.01, **options)
    mpc.adopt_plant(traits_of(make_scenario_plant(ROBOT, RunConfig(plant="mujoco"))))
    return mpc


def test_brake_slack_is_on_where_the_lagged_arm_has_its_acceleration_limit():
    assert _physics_mpc().brake_slack == BRAKE_SLACK
    assert _physics_mpc(brake_slack=0.02).brake_slack == 0.02
    assert _physics_mpc(brake_slack=0).brake_slack is None
    assert _physics_mpc(joint_acceleration_limit=0).brake_slack is None
    on_thesis = make_controller("mpc", ROBOT, model="thesis")
    on_thesis.adopt_plant(traits_of(ThesisPlant(ROBOT)))
    assert on_thesis.brake_slack is None
    asked = make_controller("mpc", ROBOT, brake_slack=0.01)
    with pytest.raises(ParameterError, match="brake_slack needs the lagged arm"):
        asked.adopt_plant(traits_of(ThesisPlant(ROBOT)))
    for bad in (-0.1, 2.0, 1e-9):
        with pytest.raises(ParameterError, match=r"brake_slack must be 0 \(off\) or in"):
            make_controller("mpc", ROBOT, brake_slack=bad)
    with pytest.raises(ParameterError, match="brake_slack must be a finite number"):
        make_controller("mpc", ROBOT, brake_slack=math.nan)
    before = asked.resolved
    with pytest.raises(ParameterError):
        asked.adopt_plant(traits_of(ThesisPlant(ROBOT)))
    assert asked.resolved is before  # refused before anything changed


def test_a_plan_that_needs_slack_is_replaced_by_the_braking_step():
    """From a pose below the floor (S 1.22) no plan meets the rows. Moving (base at
    (0.6, -0.4), shoulder at -2 rad/s) the command is the braking step at the measured
    state, counted, and flagged in the step's info. At rest (nothing to brake) the plan's
    own first input goes out, so that it can move the arm back; and so it does when moving
    with ``brake_slack=0``."""
    q = np.array([0.0, 0.0, 0.0, -1.2, 0.5])
    assert ROBOT.stability(q)[2] < 1.25
    xe, ye, _ = ROBOT.fk(q)
    target = np.array([xe + 0.5, ye, 0.0])

    def first_command(mpc, velocity, rates):
        mpc.reset(None, q)
        mpc._predicted_rates = rates  # the lagged joints' rates (no sensor reports them)
        return mpc.command(0.0, q, target, np.zeros(3), base_velocity=velocity)

    moving = ((0.6, -0.4), (-2.0, 0.0))
    mpc = _physics_mpc()
    command = first_command(mpc, *moving)
    assert mpc.last.extra["mpc_slack"] > BRAKE_SLACK
    assert mpc.last.extra["mpc_braking"] == 1.0 and mpc.brakes == 1
    expected = braking_input(mpc.dynamics, q[4], *moving, mpc.joint_acceleration_limit, TAU)
    assert (command.left, command.right) == pytest.approx(tuple(expected[:2]), rel=1e-12)
    # the exact-S guard does not cut a braking step's rates (that would stop the arm at once)
    assert mpc.last.extra["arm_scale"] == 1.0
    assert (command.th1_target - q[3]) / 0.01 == pytest.approx(expected[2], rel=1e-9)
    resting = _physics_mpc(brake_slack=1e-3)
    first_command(resting, (0.0, 0.0), (0.0, 0.0))
    assert resting.last.extra["mpc_slack"] > resting.brake_slack
    assert resting.last.extra["mpc_braking"] == 0.0 and resting.brakes == 0
    off = _physics_mpc(brake_slack=0)
    planned = first_command(off, *moving)
    assert off.last.extra["mpc_braking"] == 0.0 and off.brakes == 0
    assert (planned.left, planned.right) != pytest.approx(tuple(expected[:2]), abs=0.1)


def test_braking_keeps_scenario_26_on_its_wheels():
    """Scenario 26 (seed 0) on MuJoCo, where the mpc without the braking step and with
    the continuous-deceleration stopping row tipped at 16.26 s: with the braking step the
    run is still on its wheels at 17 s, and it braked."""
    scenario = generate(26, 0)[25]
    on = RunConfig(controller="mpc", plant="mujoco", time_limit=17.0)
    metrics = run_scenario(scenario, on).metrics
    assert "tipped" not in metrics["reason"] and metrics["time_s"] >= 16.5
