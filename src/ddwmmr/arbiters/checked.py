"""An arbiter from outside the library, its decisions checked where they are returned.

The thesis controller trusts its arbiter: the state it names is counted by the scenario
protocol, the behaviour it names is looked up in the controller's behaviours, and the
proposals and shares it returns become wheel forces and joint targets. A plug-in arbiter
that names a state outside :data:`~ddwmmr.arbiters.STATES`, a behaviour the controller does
not have, returns no decision, a malformed proposal or a share that is not a number in
[0, 1] would otherwise fail far from its cause (a KeyError in the protocol's tally, an
AttributeError in the controller) or put NaN into the commands. :class:`CheckedArbiter`
wraps it: every ``select`` (and ``weigh``) result is checked at once, and anything wrong,
or raised, becomes a one-line :class:`~ddwmmr.errors.PluginError` naming the arbiter, the
field and what is allowed (docs/thesis.md, "Writing an arbiter"). :func:`checked_arbiter`
is where that is decided: the thesis controller passes every arbiter it is given through
it, so a plug-in is checked whether the scenario protocol or a script built the controller;
the library's own arbiters are not wrapped.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from numbers import Real
from typing import Any, NoReturn

from ddwmmr.arbiters.state_machine import STATES
from ddwmmr.behaviours.base import PROPOSAL_MODES, Behaviour, Percept, Proposal
from ddwmmr.errors import (
    PluginError,
    length_of,
    name_of,
    one_of,
    raise_plugin_error,
    real_number,
    shown,
    texts_apart,
)
from ddwmmr.inheritance import from_library

#: What ``select`` must return, for the messages.
SELECTION_FORM = "a Selection(state, behaviour, proposal) (ddwmmr.arbiters.Selection)"
#: What ``weigh`` must return, for the messages.
BLEND_FORM = "a Blend(state, behaviour, shares, proposals) (ddwmmr.arbiters.Blend)"
#: Rounding allowed on the sum of the shares: a plug-in normalising its weights to 1 in
#: float32 arithmetic leaves a few 1e-8 (five weights: 1 + 3.7e-8).
SHARE_SUM_SLACK = 1e-6


def checked_arbiter(arbiter: Any, origin: str | None = None) -> Any:
    """``arbiter`` as the thesis controller calls it: wrapped in :class:`CheckedArbiter`
    when its class is from outside the library (:func:`~ddwmmr.inheritance.from_library`);
    the library's own arbiters, and one already wrapped (``CheckedArbiter`` is the
    library's), as they are, so their runs keep their speed and their numbers.

    Raises :class:`PluginError` (one line) when a plug-in has no ``select`` method; the
    message names the arbiter, or, with ``origin`` (what handed the arbiter over, e.g.
    ``"controller thesis: waypoint_options"``), that and what it gave."""
    if from_library(arbiter):
        return arbiter
    name = name_of(arbiter)
    if not callable(getattr(arbiter, "select", None)):
        method = "select(percept, behaviours) method"
        if origin is not None:
            raise PluginError(f"{origin} gave arbiter {shown(arbiter)}, which has no {method}")
        raise PluginError(
            f"arbiter: {name} has no {method} (ddwmmr.arbiters.Arbiter: state, reset(), select())"
        )
    return CheckedArbiter(arbiter, name)


class CheckedArbiter:
    """``arbiter`` (called ``name`` in messages) with its decisions checked.

    ``state``, ``reset()`` and ``select()`` are the arbiter's; ``weigh()`` exists only when
    the arbiter has it (the controller then blends). Every other attribute is read from
    the arbiter, so its own records (weights, history) stay where it keeps them.
    """

    def __init__(self, arbiter: Any, name: str) -> None:
        self.arbiter = arbiter
        self.name = name
        if callable(getattr(arbiter, "weigh", None)):
            self.weigh = self._weigh

    def __getattr__(self, attribute: str) -> Any:
        if attribute == "arbiter":  # not set yet (copy, unpickling): no recursion
            raise AttributeError(attribute)
        return getattr(self.arbiter, attribute)

    @property
    def state(self) -> str:
        """The arbiter's current state, one of :data:`STATES` (the controller reads it when
        built and reset)."""
        try:
            state = self.arbiter.state
        except AttributeError:
            raise PluginError(
                f"arbiter: {self.name} has no attribute state (the state it is in, one of "
                "ddwmmr.arbiters.STATES; ddwmmr.arbiters.Arbiter)"
            ) from None
        if not (isinstance(state, str) and state in STATES):
            # the scenario protocol counts this state from the first step on
            raise PluginError(
                f"arbiter: {self.name}.state is {shown(state)}; allowed: {', '.join(STATES)} "
                "(ddwmmr.arbiters.STATES)"
            )
        return state

    def reset(self) -> None:
        """Start a new run (the arbiter's ``reset()``)."""
        try:
            self.arbiter.reset()
        except Exception as error:
            self._raised("reset", error, None)

    def select(self, p: Percept, behaviours: Mapping[str, Behaviour]) -> Any:
        """The arbiter's selection for percept ``p``, checked (:func:`check_selection`)."""
        try:
            selection = self.arbiter.select(p, behaviours)
        except Exception as error:
            self._raised("select", error, p.t)
        check_selection(self.name, selection, behaviours, p.t)
        return selection

    def _weigh(self, p: Percept, behaviours: Mapping[str, Behaviour]) -> Any:
        """The arbiter's blend for percept ``p``, checked (:func:`check_blend`)."""
        try:
            blend = self.arbiter.weigh(p, behaviours)
        except Exception as error:
            self._raised("weigh", error, p.t)
        check_blend(self.name, blend, behaviours, p.t)
        return blend

    def _raised(self, method: str, error: Exception, t: float | None) -> NoReturn:
        """Re-raise what the arbiter's ``method`` raised: a ParameterError or PluginError as
        it is (one line already), anything else as a PluginError naming the arbiter."""
        when = "" if t is None else f" at t = {t:g} s"
        raise_plugin_error(f"arbiter: {self.name}.{method}()", error, when)


def check_selection(
    name: str, selection: Any, behaviours: Mapping[str, Behaviour], t: float
) -> None:
    """Raise a one-line :class:`PluginError` unless ``selection`` (returned by arbiter
    ``name``'s ``select`` at time ``t`` s) names a state of :data:`STATES`, a behaviour of
    ``behaviours`` and carries a well-formed :class:`~ddwmmr.behaviours.base.Proposal`
    (:func:`_check_proposal`)."""
    fields = ("state", "behaviour", "proposal")
    if not all(hasattr(selection, field) for field in fields):
        _refuse(
            name, "select", f"returned {shown(selection)}", t, f"it must return {SELECTION_FORM}"
        )
    _check_state(name, "select", selection.state, t)
    _check_behaviour(name, "select", selection.behaviour, behaviours, t)
    _check_proposal(name, "select", "proposal", selection.proposal, t)


def check_blend(name: str, blend: Any, behaviours: Mapping[str, Behaviour], t: float) -> None:
    """Raise a one-line :class:`PluginError` unless ``blend`` (returned by arbiter ``name``'s
    ``weigh`` at time ``t`` s) names a state of :data:`STATES` and a behaviour of
    ``behaviours``, has shares of behaviours of ``behaviours`` (each a finite number in
    [0, 1], together at most 1: the controller brakes with the rest) and proposals keyed by
    behaviours of ``behaviours``, each a well-formed Proposal (:func:`_check_proposal`)."""
    fields = ("state", "behaviour", "shares", "proposals")
    if not all(hasattr(blend, field) for field in fields):
        _refuse(name, "weigh", f"returned {shown(blend)}", t, f"it must return {BLEND_FORM}")
    _check_state(name, "weigh", blend.state, t)
    _check_behaviour(name, "weigh", blend.behaviour, behaviours, t)
    _check_shares(name, blend.shares, behaviours, t)
    if not isinstance(blend.proposals, Mapping):
        got = f"returned proposals {shown(blend.proposals)}"
        _refuse(name, "weigh", got, t, "they must be a mapping behaviour -> Proposal")
    for behaviour, proposal in blend.proposals.items():
        _check_behaviour(name, "weigh", behaviour, behaviours, t, "proposals key")
        _check_proposal(name, "weigh", f"proposals[{behaviour!r}]", proposal, t)


def refuse_unproposed(name: str, behaviour: str, share: float, t: float) -> NoReturn:
    """Raise a one-line :class:`PluginError`: arbiter ``name``'s ``weigh`` gave ``behaviour``
    a ``share`` at time ``t`` (s) but no proposal for it, and the behaviour proposes nothing
    (its ``propose`` returned None: the obstacle behaviour with nothing in the way). Only
    the controller knows, at the point of use: the behaviour is asked with its hold point."""
    _refuse(
        name,
        "weigh",
        f"returned shares[{behaviour!r}] = {share:g}",
        t,
        f"{behaviour} proposes nothing now (propose() returned None) and proposals has no "
        "entry for it: share only behaviours that propose, or return their proposals",
    )


def _check_shares(name: str, shares: Any, behaviours: Mapping[str, Behaviour], t: float) -> None:
    if not isinstance(shares, Mapping):
        got = f"returned shares {shown(shares)}"
        _refuse(name, "weigh", got, t, "they must be a mapping behaviour -> share")
    wanted = "each share must be a finite number in [0, 1], together at most 1"
    for behaviour, share in shares.items():
        _check_behaviour(name, "weigh", behaviour, behaviours, t)
        if not (_finite(share) and 0.0 <= share <= 1.0):
            _refuse(name, "weigh", f"returned shares[{behaviour!r}] = {shown(share)}", t, wanted)
    total = math.fsum(shares.values())
    if total > 1.0 + SHARE_SUM_SLACK:
        shown_total, _ = texts_apart(total, 1.0)  # never "adding up to 1 ... at most 1"
        _refuse(name, "weigh", f"returned shares adding up to {shown_total}", t, wanted)


def _check_proposal(name: str, method: str, field: str, proposal: Any, t: float) -> None:
    """Refuse ``proposal`` (arbiter ``name``'s ``method`` returned it as ``field``) unless it
    is a Proposal with a mode of
    :data:`~ddwmmr.behaviours.base.PROPOSAL_MODES`, finite ``bx``, ``by`` (m, world) and
    ``heading`` (rad, world) and a pair of finite joint targets ``arm`` (rad)."""
    if not isinstance(proposal, Proposal):
        got = f"returned {field} {shown(proposal)}"
        _refuse(name, method, got, t, "it must be a behaviour's Proposal")
    if not one_of(proposal.mode, PROPOSAL_MODES):
        got = f"returned {field}.mode {shown(proposal.mode)}"
        _refuse(name, method, got, t, f"allowed: {', '.join(PROPOSAL_MODES)}")
    for attribute in ("bx", "by", "heading"):
        value = getattr(proposal, attribute)
        if not _finite(value):
            got = f"returned {field}.{attribute} = {shown(value)}"
            _refuse(name, method, got, t, "it must be a finite number (m, or rad for heading)")
    arm = proposal.arm
    if not (length_of(arm) == 2 and all(map(_finite, arm))):
        got = f"returned {field}.arm = {shown(arm)}"
        _refuse(name, method, got, t, "it must be two finite joint targets (th1, th2) in rad")


def _finite(value: Any) -> bool:
    """Whether ``value`` is a finite real number (a bool is no number here, and an integer
    beyond a float, such as 10**400, is not finite)."""
    number = real_number(value) if isinstance(value, Real) else None
    return number is not None and math.isfinite(number)


def _check_state(name: str, method: str, state: Any, t: float) -> None:
    if not (isinstance(state, str) and state in STATES):
        allowed = f"allowed: {', '.join(STATES)} (ddwmmr.arbiters.STATES)"
        _refuse(name, method, f"returned state {shown(state)}", t, allowed)


def _check_behaviour(
    name: str,
    method: str,
    behaviour: Any,
    behaviours: Mapping[str, Behaviour],
    t: float,
    field: str = "behaviour",
) -> None:
    if not isinstance(behaviour, str) or behaviour not in behaviours:
        allowed = f"allowed: {', '.join(behaviours)} (the behaviours it was given)"
        _refuse(name, method, f"returned {field} {shown(behaviour)}", t, allowed)


def _refuse(name: str, method: str, got: str, t: float, wanted: str) -> NoReturn:
    """One line: the arbiter, what its ``method`` returned at time ``t`` (s), what is wanted."""
    raise PluginError(f"arbiter: {name}.{method}() {got} at t = {t:g} s; {wanted}")
