"""A plug-in arbiter handed straight to ThesisController is checked like one the scenario
protocol builds (the library's own arbiters run unwrapped), and a blend's behaviour,
shares and proposals are checked field by field, each fault one line naming the arbiter."""

from __future__ import annotations

import dataclasses
import math

import pytest

from arbiter_fixtures import BASE_PERCEPT, ROBOT, behaviours
from ddwmmr.arbiters import (
    MOVE_BASE,
    Blend,
    CheckedArbiter,
    CompetitiveDynamicsArbiter,
    Selection,
    StateMachineArbiter,
)
from ddwmmr.arbiters.checked import check_blend
from ddwmmr.behaviours import BRAKE, DRIVE, Proposal
from ddwmmr.errors import ParameterError, PluginError
from ddwmmr.plants import make_plant
from ddwmmr.scenarios import RunConfig, generate
from ddwmmr.scenarios.protocol import make_scenario_controller
from ddwmmr.thesis_controller import ThesisController

Q = (0.0, 0.0, 0.0, -0.7, 1.57)
GIVEN = "allowed: objective, manipulability, stability (the behaviours it was given)"
SHARES = "each share must be a finite number in [0, 1], together at most 1"


class Picking:
    """A plug-in arbiter: the state machine's decisions passed through ``spoil``."""

    name = "picker"

    def __init__(self, spoil=lambda selection: selection) -> None:
        self.inner, self.spoil = StateMachineArbiter(), spoil

    @property
    def state(self) -> str:
        return self.inner.state

    def reset(self) -> None:
        self.inner.reset()

    def select(self, p, behaviours):
        return self.spoil(self.inner.select(p, behaviours))


class Weighing:
    """A plug-in blending arbiter handing out ``shares`` with ``proposals`` (objective's)."""

    name = "weigher"
    state = MOVE_BASE

    def __init__(self, shares, proposals=None, behaviour="objective") -> None:
        self.shares, self.proposals, self.behaviour = shares, proposals, behaviour

    def reset(self) -> None:
        pass

    def select(self, p, behaviours):  # pragma: no cover - the controller weighs
        raise AssertionError("a blending arbiter is weighed")

    def weigh(self, p, behaviours):
        proposals = self.proposals
        if proposals is None:
            proposals = {"objective": behaviours["objective"].propose(p)}
        return Blend(MOVE_BASE, self.behaviour, dict(self.shares), proposals)


def _act(arbiter) -> tuple[float, float, float, float]:
    controller = ThesisController(ROBOT, arbiter)
    controller.reset((3.0, 0.0))
    return controller.act(0.0, Q, 0.0, 0.0)


# -- the API path: ThesisController(robot, arbiter) ----------------------------------------
def test_an_unknown_behaviour_from_an_arbiter_given_to_the_controller_is_one_line():
    """Without the wrap: KeyError: 'nope' from the controller's behaviour lookup."""
    arbiter = Picking(lambda s: Selection(s.state, "nope", s.proposal))
    with pytest.raises(PluginError) as error:
        _act(arbiter)
    assert str(error.value) == (
        f"arbiter: picker.select() returned behaviour 'nope' at t = 0 s; {GIVEN}"
    )


def test_a_nan_share_from_an_arbiter_given_to_the_controller_is_refused():
    """Without the wrap the NaN share went silently into the wheel forces."""
    with pytest.raises(PluginError) as error:
        _act(Weighing({"objective": math.nan}))
    assert str(error.value) == (
        f"arbiter: weigher.weigh() returned shares['objective'] = nan at t = 0 s; {SHARES}"
    )


def test_a_plug_in_is_wrapped_once_and_the_library_arbiters_not_at_all():
    plug_in = Picking()
    wrapped = ThesisController(ROBOT, plug_in).arbiter
    assert isinstance(wrapped, CheckedArbiter) and wrapped.arbiter is plug_in
    assert wrapped.name == "picker"
    already = CheckedArbiter(plug_in, "mine")
    assert ThesisController(ROBOT, already).arbiter is already
    for own in (StateMachineArbiter(), CompetitiveDynamicsArbiter()):
        assert ThesisController(ROBOT, own).arbiter is own
    # the scenario protocol wraps a plug-in; the controller it builds keeps that one wrap
    robot = ROBOT
    controller = make_scenario_controller(
        robot, generate(1, 0)[0], RunConfig(arbiter=plug_in), make_plant("thesis", robot)
    )
    assert isinstance(controller.arbiter, CheckedArbiter)
    assert controller.arbiter.arbiter is plug_in


def test_a_valid_plug_in_gives_the_library_arbiters_commands():
    """The check changes nothing: 200 steps of the same decisions, the same commands."""
    plug_in = ThesisController(ROBOT, Picking())
    own = ThesisController(ROBOT)
    for controller in (plug_in, own):
        controller.reset((1.5, -0.5))
    q = Q
    for k in range(200):
        commands = plug_in.act(k * 0.01, q, 0.1, 0.0)
        assert commands == own.act(k * 0.01, q, 0.1, 0.0)
        q = (0.002 * k, 0.0, 0.0, commands[2], commands[3])
    assert plug_in.state == own.state


def test_something_without_select_is_refused_by_name():
    class Nothing:
        state = MOVE_BASE

    with pytest.raises(PluginError) as error:
        ThesisController(ROBOT, Nothing())
    assert str(error.value) == (
        "arbiter: Nothing has no select(percept, behaviours) method "
        "(ddwmmr.arbiters.Arbiter: state, reset(), select())"
    )


# -- a blend's fields -----------------------------------------------------------------------
def _blend_error(**fields) -> str:
    beh = behaviours()
    base = {
        "state": MOVE_BASE,
        "behaviour": "objective",
        "shares": {"objective": 0.5, "stability": 0.5},
        "proposals": {"objective": Proposal(BRAKE, (0.0, 0.0), label="arm")},
    }
    blend = Blend(**{**base, **fields})
    with pytest.raises(PluginError) as error:
        check_blend("mine", blend, beh, 0.25)
    return str(error.value)


def test_a_blend_naming_an_unknown_dominant_behaviour_is_refused():
    assert _blend_error(behaviour="dancing") == (
        f"arbiter: mine.weigh() returned behaviour 'dancing' at t = 0.25 s; {GIVEN}"
    )


def test_blend_proposals_of_the_wrong_shape_or_with_nan_are_named():
    drive = Proposal(DRIVE, (0.1, 0.2), 1.0, 2.0)
    assert _blend_error(proposals=[drive]) == (
        "arbiter: mine.weigh() returned proposals [Proposal(mode='drive', arm=(0.1, 0.2... at "
        "t = 0.25 s; they must be a mapping behaviour -> Proposal"
    )
    assert _blend_error(proposals={"jump": drive}) == (
        f"arbiter: mine.weigh() returned proposals key 'jump' at t = 0.25 s; {GIVEN}"
    )
    assert _blend_error(proposals={"objective": (1.0, 2.0)}) == (
        "arbiter: mine.weigh() returned proposals['objective'] (1.0, 2.0) at t = 0.25 s; "
        "it must be a behaviour's Proposal"
    )
    assert _blend_error(proposals={"stability": dataclasses.replace(drive, by=math.nan)}) == (
        "arbiter: mine.weigh() returned proposals['stability'].by = nan at t = 0.25 s; "
        "it must be a finite number (m, or rad for heading)"
    )
    assert _blend_error(proposals={"objective": dataclasses.replace(drive, arm=(0.1,))}) == (
        "arbiter: mine.weigh() returned proposals['objective'].arm = (0.1,) at t = 0.25 s; "
        "it must be two finite joint targets (th1, th2) in rad"
    )
    assert _blend_error(proposals={"objective": dataclasses.replace(drive, mode="fly")}) == (
        "arbiter: mine.weigh() returned proposals['objective'].mode 'fly' at t = 0.25 s; "
        "allowed: drive, turn, brake"
    )


def test_shares_out_of_range_or_adding_up_beyond_one_are_named():
    assert _blend_error(shares={"stability": -0.25}) == (
        f"arbiter: mine.weigh() returned shares['stability'] = -0.25 at t = 0.25 s; {SHARES}"
    )
    assert _blend_error(shares={"objective": 0.75, "stability": 0.5}) == (
        f"arbiter: mine.weigh() returned shares adding up to 1.25 at t = 0.25 s; {SHARES}"
    )
    # a valid blend passes, rounding of shares normalised to 1 included
    thirds = {name: 1.0 / 3.0 for name in ("objective", "manipulability", "stability")}
    check_blend("mine", Blend(MOVE_BASE, "objective", thirds, {}), behaviours(), 0.0)
    # weights normalised in float32 add up to 1 + a few 1e-8
    import numpy as np

    weights = np.array([0.6, 0.7, 0.5], dtype=np.float32)
    names = ("objective", "manipulability", "stability")
    float32 = dict(zip(names, (weights / weights.sum()).tolist()))
    assert 1.0 + 1e-9 < math.fsum(float32.values()) < 1.0 + 1e-6
    check_blend("mine", Blend(MOVE_BASE, "objective", float32, {}), behaviours(), 0.0)
    # an excess that :g would print as 1 is spelt out
    over = {"objective": 0.5, "stability": 0.5 + 2e-6}
    assert _blend_error(shares=over) == (
        "arbiter: mine.weigh() returned shares adding up to 1.0000019999999998 at "
        f"t = 0.25 s; {SHARES}"
    )


def test_an_integer_beyond_a_float_is_no_finite_share():
    assert _blend_error(shares={"objective": 10**400}) == (
        "arbiter: mine.weigh() returned shares['objective'] = "
        f"an integer of about 1e400 at t = 0.25 s; {SHARES}"
    )


def test_a_selected_proposal_with_nan_is_named():
    def spoil(selection):
        return dataclasses.replace(
            selection, proposal=dataclasses.replace(selection.proposal, arm=(math.nan, 0.0))
        )

    checked = CheckedArbiter(Picking(spoil), "picker")
    with pytest.raises(PluginError) as error:
        checked.select(BASE_PERCEPT, behaviours())
    assert str(error.value) == (
        "arbiter: picker.select() returned proposal.arm = (nan, 0.0) at t = 0 s; "
        "it must be two finite joint targets (th1, th2) in rad"
    )


# -- a share for a behaviour that proposes nothing; the state read at build and reset -------
def test_a_share_for_a_behaviour_with_nothing_to_propose_is_one_line():
    """Without the check: a bare AssertionError in ThesisController._proposal. The obstacle
    lies far behind the robot, so obstacle avoidance proposes nothing."""
    controller = ThesisController(
        ROBOT, Weighing({"objective": 0.5, "obstacle": 0.25}), obstacles=((-3.0, -3.0, 0.2),)
    )
    controller.reset((3.0, 0.0))
    assert controller.behaviours["obstacle"].propose(BASE_PERCEPT) is None
    with pytest.raises(PluginError) as error:
        controller.act(0.5, Q, 0.0, 0.0)
    assert str(error.value) == (
        "arbiter: weigher.weigh() returned shares['obstacle'] = 0.25 at t = 0.5 s; obstacle "
        "proposes nothing now (propose() returned None) and proposals has no entry for it: "
        "share only behaviours that propose, or return their proposals"
    )
    # with its proposal returned, the same share is used as it is
    drive = Proposal(DRIVE, (-0.7, 1.57), 1.0, 0.0)
    fine = ThesisController(
        ROBOT, Weighing({"obstacle": 1.0}, {"obstacle": drive}), obstacles=((-3.0, -3.0, 0.2),)
    )
    fine.reset((3.0, 0.0))
    own = ThesisController(ROBOT, Weighing({"objective": 1.0}, {"objective": drive}))
    own.reset((3.0, 0.0))
    assert fine.act(0.0, Q, 0.0, 0.0) == own.act(0.0, Q, 0.0, 0.0)


class Stating(Picking):
    """A plug-in arbiter whose ``state`` is ``initial``, and ``after_reset`` once reset."""

    def __init__(self, initial, after_reset=MOVE_BASE) -> None:
        super().__init__()
        self._state, self.after_reset = initial, after_reset

    @property
    def state(self):
        return self._state

    def reset(self) -> None:
        self._state = self.after_reset


STATE_ALLOWED = (
    "allowed: move_base, move_arm, manipulability, stability, obstacle (ddwmmr.arbiters.STATES)"
)


def test_a_state_outside_states_is_refused_when_the_controller_is_built_or_reset():
    """Without the check the state went unchecked into ``controller.state`` (the scenario
    tally then counts a state it has no column for)."""
    with pytest.raises(PluginError) as error:
        ThesisController(ROBOT, Stating("dancing"))
    assert str(error.value) == f"arbiter: picker.state is 'dancing'; {STATE_ALLOWED}"
    controller = ThesisController(ROBOT, Stating(MOVE_BASE, after_reset=None))
    assert controller.state == MOVE_BASE
    with pytest.raises(PluginError) as error:
        controller.reset((3.0, 0.0))
    assert str(error.value) == f"arbiter: picker.state is None; {STATE_ALLOWED}"


def test_checked_arbiter_is_exported_and_names_who_handed_over_a_non_arbiter():
    from ddwmmr.arbiters import checked_arbiter

    plug_in = Picking()
    assert checked_arbiter(plug_in).arbiter is plug_in
    own = StateMachineArbiter()
    assert checked_arbiter(own, "controller thesis: waypoint_options") is own
    with pytest.raises(PluginError) as error:
        checked_arbiter("mine", "controller thesis: waypoint_options")
    assert str(error.value) == (
        "controller thesis: waypoint_options gave arbiter 'mine', which has no "
        "select(percept, behaviours) method"
    )


def test_make_arbiter_refuses_what_is_no_run_configuration():
    """make_arbiter(config) read config.arbiter: a name given instead raised
    AttributeError."""
    from ddwmmr.arbiters import make_arbiter

    with pytest.raises(
        ParameterError, match=r"^config must be a RunConfig .*\(got 'competitive'\)"
    ):
        make_arbiter("competitive")
