"""The competitive-dynamics arbiter: advantages, thresholds as fixed points, priorities,
blending in the thesis controller, and the scenario-protocol hookup."""

from __future__ import annotations

import dataclasses
import math

import pytest

from arbiter_fixtures import BASE_PERCEPT, ROBOT, behaviours
from ddwmmr.arbiters import (
    BEHAVIOURS,
    MANIPULABILITY,
    MOVE_ARM,
    MOVE_BASE,
    OBSTACLE,
    STABILITY,
    Blend,
    CompetitiveDynamicsArbiter,
    CompetitiveParameters,
    Hysteresis,
    StateMachineArbiter,
    make_arbiter,
)
from ddwmmr.behaviours import BRAKE, ObstacleAvoidance, Proposal
from ddwmmr.errors import ParameterError
from ddwmmr.plants.thesis import ThesisPlant, ThesisState
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.thesis_controller import ThesisController


class Clock:
    """Feeds an arbiter percepts at the controller's 0.01 s step."""

    def __init__(self, arbiter, beh) -> None:
        self.arbiter, self.beh, self.t = arbiter, beh, 0.0
        arbiter.reset()

    def hold(self, seconds: float, s: float = 2.0, eta: float = 1.0) -> Blend:
        blend = None
        for _ in range(round(seconds / 0.01)):
            p = dataclasses.replace(BASE_PERCEPT, t=self.t, s=s, eta=eta)
            blend = self.arbiter.weigh(p, self.beh)
            self.t += 0.01
        return blend


def advantage_of(arbiter, s, eta=1.0, label="arm"):
    p = dataclasses.replace(BASE_PERCEPT, s=s, eta=eta)
    objective = Proposal(BRAKE, (0.0, 0.0), label=label)
    return dict(zip(BEHAVIOURS, arbiter.advantages(p, objective, None, None)))


def test_advantages_and_interactions_follow_the_thresholds():
    arbiter = CompetitiveDynamicsArbiter(Hysteresis(1.25, 1.60), Hysteresis(0.75, 0.90))
    margin = arbiter.parameters.margin
    r = dict(zip(BEHAVIOURS, arbiter.interactions(2.0)))  # rows: who suppresses
    h_s, h_m = r["objective"][0], r["objective"][1]
    # each fix behaviour's advantage: zero at its exit threshold, equal to the task's
    # suppression of it at its enter threshold
    assert advantage_of(arbiter, 1.60)["stability"] == pytest.approx(0.0, abs=1e-12)
    assert advantage_of(arbiter, 1.25)["stability"] == pytest.approx(h_s, rel=1e-12)
    assert advantage_of(arbiter, 2.0, eta=0.90)["manipulability"] == pytest.approx(0.0, abs=1e-12)
    assert advantage_of(arbiter, 2.0, eta=0.75)["manipulability"] == pytest.approx(h_m, rel=1e-12)
    values = [advantage_of(arbiter, s)["stability"] for s in (2.0, 1.6, 1.4, 1.25, 1.1, 1.0)]
    assert values == sorted(values)  # more wanted the lower S
    assert advantage_of(arbiter, 2.0, eta=0.1, label="base")["manipulability"] < 0
    assert advantage_of(arbiter, 2.0)["obstacle"] < 0  # nothing in the way
    # stability's suppression of the task: low at enter, a_O at enter - margin, high below
    low, high = arbiter.parameters.task_suppression
    a_o = arbiter.parameters.objective
    assert arbiter.task_suppression(1.25) == pytest.approx(low * a_o)
    assert arbiter.task_suppression(1.40) == pytest.approx(low * a_o)
    assert arbiter.task_suppression(1.25 - margin) == pytest.approx(a_o)
    assert arbiter.task_suppression(1.25 - 2 * margin) == pytest.approx(high * a_o)
    assert arbiter.task_suppression(0.5) == pytest.approx(high * a_o)
    assert arbiter.interactions(1.2)[0][3] == arbiter.task_suppression(1.2)


def settle(arbiter, s, eta=1.0, seconds=6.0, beh=None):
    clock = Clock(arbiter, beh or behaviours())
    return clock.hold(seconds, s=s, eta=eta)


QUIET = CompetitiveParameters(noise=0.0, floor=1e-3)


@pytest.mark.parametrize("s", [1.17, 1.20, 1.23])
def test_below_enter_stability_and_task_coexist_at_the_closed_form_weights(s):
    """Fixed point of eq. (3) for two behaviours (Large et al.): w_S^2 = (1 - rho) /
    (1 - rho sigma), w_O^2 = (1 - sigma) / (1 - rho sigma), rho = h_S / a_S, sigma = r_T / a_O."""
    arbiter = CompetitiveDynamicsArbiter(parameters=QUIET)
    a = advantage_of(arbiter, s)
    r = arbiter.interactions(s)
    rho = r[3][0] / a["stability"]
    sigma = r[0][3] / a["objective"]
    assert rho < 1.0 and sigma < 1.0  # the coexistence regime
    blend = settle(arbiter, s)
    w = arbiter.weights
    # (to 1e-3: the other behaviours' floors, |w| = 1e-3, press on the two a little)
    assert w["stability"] ** 2 == pytest.approx((1 - rho) / (1 - rho * sigma), rel=1e-3)
    assert w["objective"] ** 2 == pytest.approx((1 - sigma) / (1 - rho * sigma), rel=1e-3)
    assert 0.0 < blend.shares["stability"] < 1.0 and 0.0 < blend.shares["objective"] < 1.0


def test_stability_comes_in_gradually_below_enter_and_stops_the_task_at_the_margin():
    margin = QUIET.margin
    rows = []
    for s in (1.60, 1.40, 1.26, 1.24, 1.20, 1.17, 1.14, 1.10, 1.00):
        blend = settle(CompetitiveDynamicsArbiter(parameters=QUIET), s)
        rows.append((s, blend.shares.get("stability", 0.0), blend.shares.get("objective", 0.0)))
    stab = [row[1] for row in rows]
    task = [row[2] for row in rows]
    assert stab == sorted(stab) and task == sorted(task, reverse=True)
    assert all(st == 0.0 and t > 0.99 for (s, st, t) in rows if s > 1.25)  # above enter
    assert 0.0 < stab[3] < 0.5  # just below enter: a little stability
    assert all(t == 0.0 for (s, _, t) in rows if s < 1.25 - margin - 0.01)  # task stopped
    assert all(t > 0.0 for (s, _, t) in rows if s > 1.25 - margin + 0.01)
    assert stab[-1] == pytest.approx(1.0, abs=1e-4)


def test_stability_sequence_under_changing_stability():
    """The state machine's enter/exit sequence of test_state_machine, continuously."""
    clock = Clock(CompetitiveDynamicsArbiter(parameters=QUIET), behaviours())
    assert clock.hold(2.0, s=1.30).state == MOVE_ARM  # above enter: the task alone
    assert clock.hold(0.5, s=1.05).state == STABILITY  # far below: stability alone
    assert "objective" not in clock.hold(0.5, s=1.05).shares
    back = clock.hold(2.0, s=1.20)  # in the band: both
    assert 0.0 < back.shares["objective"] < 1.0 and back.shares["stability"] > 0.0
    blend = clock.hold(1.0, s=1.30)  # above enter: the task alone again
    assert blend.state == MOVE_ARM
    assert blend.shares["objective"] == pytest.approx(1.0, abs=1e-4)  # less the floors'
    assert "stability" not in blend.shares


def test_no_hysteresis_stability_takes_full_weight_below_the_threshold():
    arbiter = CompetitiveDynamicsArbiter(Hysteresis(1.25, 1.25), parameters=QUIET)
    assert settle(arbiter, 1.27).state == MOVE_ARM
    settle(arbiter, 1.22)
    assert abs(arbiter.weights["stability"]) == pytest.approx(1.0, abs=1e-6)  # rho = 0
    sigma = arbiter.task_suppression(1.22) / QUIET.objective
    assert arbiter.weights["objective"] ** 2 == pytest.approx(1.0 - sigma, rel=1e-3)


def test_manipulability_hysteresis_is_a_bistable_band():
    clock = Clock(CompetitiveDynamicsArbiter(), behaviours())
    assert clock.hold(2.0, s=2.0, eta=0.80).state == MOVE_ARM  # in the band: stays
    assert clock.hold(1.0, s=2.0, eta=0.70).state == MANIPULABILITY  # below enter
    assert clock.hold(2.0, s=2.0, eta=0.85).state == MANIPULABILITY  # in the band: stays
    assert clock.hold(2.0, s=2.0, eta=0.95).state == MOVE_ARM  # above exit


def test_priority_stability_over_manipulability_over_objective():
    clock = Clock(CompetitiveDynamicsArbiter(), behaviours())
    assert clock.hold(1.0, s=2.0, eta=0.6).state == MANIPULABILITY
    blend = clock.hold(1.0, s=1.05, eta=0.6)
    assert blend.state == STABILITY
    assert "manipulability" not in blend.shares  # fully suppressed
    assert "objective" not in blend.shares  # S far below enter: the task stops
    assert abs(clock.arbiter.weights["stability"]) == pytest.approx(1.0, abs=0.02)  # +-1


def test_manipulability_only_while_the_objective_reaches_and_obstacle_only_while_driving():
    in_the_way = behaviours("base")
    # a column 0.6 m ahead on the way to the target (3, 0): inside the behaviour's buffer
    in_the_way["obstacle"] = ObstacleAvoidance(ROBOT, [(0.6, 0.0, 0.3)])
    assert in_the_way["obstacle"].propose(BASE_PERCEPT) is not None
    clock = Clock(CompetitiveDynamicsArbiter(), in_the_way)
    assert clock.hold(1.0, s=2.0, eta=0.3).state == OBSTACLE
    reaching = behaviours("arm")
    reaching["obstacle"] = in_the_way["obstacle"]
    clock = Clock(CompetitiveDynamicsArbiter(), reaching)
    assert clock.hold(1.0, s=2.0, eta=0.8).state == MOVE_ARM
    off = behaviours("base", obstacle=True)
    off["obstacle"].proposal = None
    blend = Clock(CompetitiveDynamicsArbiter(), off).hold(1.0, s=2.0, eta=0.3)
    assert blend.state == MOVE_BASE
    assert "obstacle" not in blend.shares  # no proposal, no share


def test_shares_are_a_partition_of_at_most_one():
    clock = Clock(CompetitiveDynamicsArbiter(), behaviours())
    for s in (2.0, 1.5, 1.3, 1.2, 1.1, 1.4, 1.7):
        for _ in range(30):
            blend = clock.hold(0.01, s=s)
            assert all(v > 0.0 for v in blend.shares.values())
            assert sum(blend.shares.values()) <= 1.0 + 1e-12


def test_record_keeps_one_sample_per_call_and_reset_clears_it():
    arbiter = CompetitiveDynamicsArbiter(record=True)
    clock = Clock(arbiter, behaviours())
    clock.hold(0.5)
    assert len(arbiter.history["t"]) == 50
    assert len(arbiter.history["w_stability"]) == 50
    arbiter.reset()
    assert arbiter.history["t"] == []


def test_noise_seed_makes_runs_repeatable_and_distinct():
    def weights(seed):
        arbiter = CompetitiveDynamicsArbiter(seed=seed, record=True)
        Clock(arbiter, behaviours()).hold(0.5, s=1.2)
        return arbiter.history["w_manipulability"]

    assert weights(1) == weights(1)
    assert weights(1) != weights(2)


def test_parameters_are_validated():
    with pytest.raises(ParameterError, match="suppression must be > limit"):
        CompetitiveParameters(suppression=1.0)
    with pytest.raises(ParameterError, match="task_suppression must satisfy"):
        CompetitiveParameters(task_suppression=(0.5, 0.9))
    with pytest.raises(ParameterError, match="time_constants: missing obstacle"):
        CompetitiveParameters(
            time_constants={"stability": 0.1, "manipulability": 0.1, "objective": 0.1}
        )


# -- blending in the thesis controller -------------------------------------------------------
class Scripted:
    """A blending arbiter that hands out fixed shares (reports the objective's state)."""

    state = MOVE_BASE

    def __init__(self, shares):
        self.shares = shares

    def reset(self):
        self.state = MOVE_BASE

    def select(self, p, behaviours):  # pragma: no cover - the controller uses weigh
        raise AssertionError("a blending arbiter is weighed, not selected")

    def weigh(self, p, behaviours):
        objective = behaviours["objective"].propose(p)
        return Blend(MOVE_BASE, "objective", dict(self.shares), {"objective": objective})


def simulate(controller, target, steps, q0=None):
    plant = ThesisPlant(ROBOT)
    state = ThesisState(*(q0 or (0.0, 0.0, 0.0, *controller.default_pose)))
    controller.reset(target)
    for k in range(steps):
        f_left, f_right, a1, a2 = controller.act(k * 0.01, state.q, state.v, state.w)
        plant.advance(state, f_left, f_right, (a1, a2), 0.01)
    return state


def test_a_share_of_one_acts_exactly_as_the_chosen_behaviour():
    """Objective alone through the blending path = objective alone through select()."""

    class ObjectiveOnly:
        state = MOVE_BASE

        def reset(self):
            self.state = MOVE_BASE

        def select(self, p, beh):
            from ddwmmr.arbiters import Selection

            proposal = beh["objective"].propose(p)
            self.state = MOVE_ARM if proposal.label == "arm" else MOVE_BASE
            return Selection(self.state, "objective", proposal)

    target = (1.2, 0.6)
    chosen = simulate(ThesisController(ROBOT, ObjectiveOnly()), target, 600)
    blended = simulate(ThesisController(ROBOT, Scripted({"objective": 1.0})), target, 600)
    assert blended.q == pytest.approx(chosen.q, abs=1e-9)
    assert (blended.v, blended.w) == pytest.approx((chosen.v, chosen.w), abs=1e-9)


def test_unclaimed_share_brakes_and_holds_and_arm_speed_scales_with_share():
    controller = ThesisController(ROBOT, Scripted({"objective": 0.25}))
    controller.reset((3.0, 0.0))
    q = (0.0, 0.0, 0.0, -0.2, 1.0)  # arm 0.5 rad off the default pose
    f_left, f_right, a1, a2 = controller.act(0.0, q, 0.4, 0.1)
    p = controller.last_percept
    drive = controller.base.wheel_forces(p, controller.behaviours["objective"].propose(p))
    brake = controller.base.mix(*controller.base.brake_forces(p))
    assert (f_left, f_right) == pytest.approx(
        (0.25 * drive[0] + 0.75 * brake[0], 0.25 * drive[1] + 0.75 * brake[1])
    )
    th1_goal, th2_goal = controller.default_pose
    e1, e2 = th1_goal - q[3], th2_goal - q[4]
    step = ROBOT.joint_speed_limit * 0.01 / max(abs(e1), abs(e2))  # servo: full speed
    assert (a1 - q[3], a2 - q[4]) == pytest.approx((0.25 * e1 * step, 0.25 * e2 * step))


def test_hold_is_latched_and_carried_by_the_other_behaviours_arm_motion():
    """Stability at share 0.5 with the objective: the hold follows the objective's half."""
    controller = ThesisController(ROBOT, Scripted({"stability": 0.5, "objective": 0.5}))
    controller.reset((3.0, 0.0))
    q = (0.0, 0.0, 0.0, 0.9, 1.2)
    controller.act(0.0, q, 0.0, 0.0)
    xe, ye, _ = ROBOT.fk(list(q))
    p = controller.last_percept
    objective = controller.behaviours["objective"].propose(p)
    e1, e2 = objective.arm[0] - q[3], objective.arm[1] - q[4]
    scale = min(1.0, ROBOT.joint_speed_limit * 0.01 / max(abs(e1), abs(e2)))
    moved = (q[3] + 0.5 * e1 * scale, q[4] + 0.5 * e2 * scale)
    xm, ym, _ = ROBOT.fk([0.0, 0.0, 0.0, *moved])
    hold = controller._holds["stability"]
    moved_by = math.hypot(xm - xe, ym - ye)
    assert moved_by > 1e-3  # it did move
    # first order in the joint motion: within 1 % of the exact displacement
    assert math.hypot(hold[0] - xm, hold[1] - ym) < 0.01 * moved_by


def test_stability_alone_keeps_the_end_effector_in_place_while_the_base_turns():
    controller = ThesisController(ROBOT, Scripted({"stability": 1.0}))
    q0 = (0.0, 0.0, 0.0, 1.45, 0.05)  # stretched to the left: lateral risk
    xe, ye, _ = ROBOT.fk(list(q0))
    state = simulate(controller, (0.2, 0.75), 300, q0)
    assert abs(state.phi) > 0.5  # the base turned toward the end effector
    assert ROBOT.fk(list(state.q))[:2] == pytest.approx((xe, ye), abs=0.02)
    assert ROBOT.stability(state.q)[2] > ROBOT.stability(q0)[2] + 0.2


# -- protocol hookup ------------------------------------------------------------------------
def test_protocol_builds_the_arbiter_from_the_run_configuration():
    config = RunConfig(arbiter="competitive", stability=(1.3, 1.7), arbiter_seed=4)
    arbiter = make_arbiter(config)
    assert isinstance(arbiter, CompetitiveDynamicsArbiter)
    assert (arbiter.stability.enter, arbiter.stability.exit) == (1.3, 1.7)
    assert arbiter.dynamics.seed == 4
    assert isinstance(make_arbiter(RunConfig()), StateMachineArbiter)
    instance = CompetitiveDynamicsArbiter()
    assert make_arbiter(RunConfig(arbiter=instance)) is instance
    with pytest.raises(ParameterError, match="arbiter must be one of state-machine, competitive"):
        RunConfig(arbiter="vote")
    with pytest.raises(ParameterError, match="only the thesis controller has an arbiter"):
        RunConfig(controller="qp", arbiter="competitive")
    with pytest.raises(ParameterError, match="arbiter: need a name or an object"):
        RunConfig(arbiter=3)


def test_competitive_run_succeeds_repeatably_and_records_weights():
    scenario = generate(1, 0)[0]
    first = run_scenario(scenario, RunConfig(arbiter="competitive"))
    assert first.metrics["success"]
    assert first.metrics["min_stability"] > 1.0
    assert run_scenario(scenario, RunConfig(arbiter="competitive")).metrics == first.metrics
    recorder = CompetitiveDynamicsArbiter(record=True)
    traced = run_scenario(scenario, RunConfig(arbiter=recorder))
    assert traced.metrics == first.metrics
    assert len(recorder.history["t"]) == traced.metrics["sim_steps"]
    assert all(abs(w) <= 1.5 for b in BEHAVIOURS for w in recorder.history[f"w_{b}"])
    assert {MOVE_BASE, MOVE_ARM} <= set(recorder.history["state"])
