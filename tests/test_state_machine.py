"""The state-machine arbiter: priorities, transitions, hysteresis."""

from __future__ import annotations

import dataclasses

import pytest

from arbiter_fixtures import BASE_PERCEPT, ROBOT, behaviours
from ddwmmr.arbiters import (
    MANIPULABILITY,
    MOVE_ARM,
    MOVE_BASE,
    OBSTACLE,
    STABILITY,
    Hysteresis,
    StateMachineArbiter,
)
from ddwmmr.errors import ParameterError
from ddwmmr.thesis_controller import ThesisController


def at(s: float, eta: float):
    return dataclasses.replace(BASE_PERCEPT, s=s, eta=eta)


def states(arbiter, sequence, beh):
    return [arbiter.select(at(s, eta), beh).state for s, eta in sequence]


def test_stability_hysteresis_enter_below_1_25_leave_at_1_60():
    arbiter = StateMachineArbiter()
    seq = [(1.3, 1.0), (1.24, 1.0), (1.3, 1.0), (1.59, 1.0), (1.60, 1.0), (1.3, 1.0)]
    got = states(arbiter, seq, behaviours())
    assert got == [MOVE_ARM, STABILITY, STABILITY, STABILITY, MOVE_ARM, MOVE_ARM]


def test_no_stability_hysteresis_leaves_at_enter_threshold():
    arbiter = StateMachineArbiter(stability=Hysteresis(1.25, 1.25))
    got = states(arbiter, [(1.24, 1.0), (1.25, 1.0), (1.24, 1.0)], behaviours())
    assert got == [STABILITY, MOVE_ARM, STABILITY]


def test_manipulability_hysteresis_and_soft_priority():
    arbiter = StateMachineArbiter()
    seq = [(2.0, 0.8), (2.0, 0.74), (2.0, 0.85), (1.2, 0.85), (1.7, 0.85), (2.0, 0.9)]
    got = states(arbiter, seq, behaviours())
    # stability preempts manipulability; afterwards eta 0.85 is above the 0.75 enter
    # threshold, so manipulability is not re-entered and the task resumes
    assert got == [MOVE_ARM, MANIPULABILITY, MANIPULABILITY, STABILITY, MOVE_ARM, MOVE_ARM]


def test_manipulability_only_while_objective_reaches_with_arm():
    arbiter = StateMachineArbiter()
    assert states(arbiter, [(2.0, 0.5)], behaviours("base")) == [MOVE_BASE]
    assert states(arbiter, [(2.0, 0.5)], behaviours("arm")) == [MANIPULABILITY]
    # the waypoint changes (objective back to driving): the fix state ends
    assert states(arbiter, [(2.0, 0.5)], behaviours("base")) == [MOVE_BASE]


def test_priority_stability_over_manipulability_over_objective():
    beh = behaviours()
    selection = StateMachineArbiter().select(at(1.0, 0.1), beh)
    assert (selection.state, selection.behaviour) == (STABILITY, "stability")
    assert selection.proposal is beh["stability"].proposal
    assert beh["manipulability"].calls == 0  # lower priorities are not evaluated


def test_obstacle_only_replaces_base_movement_and_yields_to_fix_states():
    arbiter = StateMachineArbiter()
    assert states(arbiter, [(2.0, 1.0)], behaviours("base", obstacle=True)) == [OBSTACLE]
    assert states(arbiter, [(2.0, 1.0)], behaviours("arm", obstacle=True)) == [MOVE_ARM]
    assert states(arbiter, [(1.1, 1.0)], behaviours("base", obstacle=True)) == [STABILITY]
    off = behaviours("base", obstacle=True)
    off["obstacle"].proposal = None
    assert states(arbiter, [(2.0, 1.0)], off) == [MOVE_BASE]


def test_thresholds_validated():
    with pytest.raises(ParameterError, match="enter must be <= exit"):
        Hysteresis(1.6, 1.25)


def test_controller_latches_hold_point_on_entering_a_state():
    """On entering stability the held end-effector point is where the EE was then."""
    controller = ThesisController(ROBOT)
    controller.reset((0.2, 0.75))
    q = (0.0, 0.0, 0.0, 1.45, 0.05)  # stretched to the left: S < 1.25
    assert ROBOT.stability(q)[2] < 1.25
    controller.act(0.0, q, 0.0, 0.0)
    assert controller.state == STABILITY
    xe, ye, _ = ROBOT.fk(list(q))
    assert controller.last_percept.hold == pytest.approx((xe, ye))
    controller.act(0.01, (0.05, 0.0, 0.1, 1.4, 0.05), 0.0, 0.0)
    assert controller.last_percept.hold == pytest.approx((xe, ye))  # still latched


def test_arbiter_is_replaceable():
    """Any object with state/reset/select drives the controller (here: objective only)."""
    from ddwmmr.arbiters import Selection
    from ddwmmr.plants.thesis import ThesisPlant, ThesisState

    class ObjectiveOnly:
        state = MOVE_BASE

        def reset(self):
            self.state = MOVE_BASE

        def select(self, p, behaviours):
            proposal = behaviours["objective"].propose(p)
            self.state = MOVE_ARM if proposal.label == "arm" else MOVE_BASE
            return Selection(self.state, "objective", proposal)

    controller = ThesisController(ROBOT, arbiter=ObjectiveOnly())
    controller.reset((1.5, -0.5))
    plant = ThesisPlant(ROBOT)
    state = ThesisState(0.0, 0.0, 0.0, *controller.default_pose)
    for k in range(1500):
        f_left, f_right, a1, a2 = controller.act(k * 0.01, state.q, state.v, state.w)
        plant.advance(state, f_left, f_right, (a1, a2), 0.01)
    xe, ye, _ = ROBOT.fk(list(state.q))
    assert (xe, ye) == pytest.approx((1.5, -0.5), abs=1e-3)
