"""An arbiter from outside the library, its decisions checked where they are returned.

The thesis controller trusts its arbiter: the state it names is counted by the scenario
protocol and the behaviour it names is looked up in the controller's behaviours. A plug-in
arbiter that names a state outside :data:`~ddwmmr.arbiters.STATES`, a behaviour the
controller does not have, or returns no decision would otherwise fail far from its cause
(a KeyError in the protocol's tally, an AttributeError in the controller).
:class:`CheckedArbiter` wraps it: every ``select`` (and ``weigh``) result is checked at
once, and anything wrong, or raised, becomes a one-line :class:`~ddwmmr.errors.PluginError`
naming the arbiter, what it returned and the allowed values (docs/thesis.md, "Writing an
arbiter"). The library's own arbiters are not wrapped.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, NoReturn

from ddwmmr.arbiters.state_machine import STATES
from ddwmmr.behaviours.base import Behaviour, Percept, Proposal
from ddwmmr.errors import PluginError, raise_plugin_error, shown

#: What ``select`` must return, for the messages.
SELECTION_FORM = "a Selection(state, behaviour, proposal) (ddwmmr.arbiters.Selection)"
#: What ``weigh`` must return, for the messages.
BLEND_FORM = "a Blend(state, behaviour, shares, proposals) (ddwmmr.arbiters.Blend)"


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
        """The arbiter's current state (the controller reads it when built and reset)."""
        try:
            return self.arbiter.state
        except AttributeError:
            raise PluginError(
                f"arbiter {self.name}: has no attribute state (the state it is in, one of "
                "ddwmmr.arbiters.STATES; ddwmmr.arbiters.Arbiter)"
            ) from None

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
        raise_plugin_error(f"arbiter {self.name}: {method}()", error, when)


def check_selection(
    name: str, selection: Any, behaviours: Mapping[str, Behaviour], t: float
) -> None:
    """Raise a one-line :class:`PluginError` unless ``selection`` (returned by arbiter
    ``name``'s ``select`` at time ``t`` s) names a state of :data:`STATES`, a behaviour of
    ``behaviours`` and carries a :class:`~ddwmmr.behaviours.base.Proposal`."""
    fields = ("state", "behaviour", "proposal")
    if not all(hasattr(selection, field) for field in fields):
        _refuse(
            name, "select", f"returned {shown(selection)}", t, f"it must return {SELECTION_FORM}"
        )
    _check_state(name, "select", selection.state, t)
    _check_behaviour(name, "select", selection.behaviour, behaviours, t)
    if not isinstance(selection.proposal, Proposal):
        got = f"returned proposal {shown(selection.proposal)}"
        _refuse(name, "select", got, t, "it must be a behaviour's Proposal")


def check_blend(name: str, blend: Any, behaviours: Mapping[str, Behaviour], t: float) -> None:
    """Raise a one-line :class:`PluginError` unless ``blend`` (returned by arbiter ``name``'s
    ``weigh`` at time ``t`` s) names a state of :data:`STATES` and shares of behaviours of
    ``behaviours``."""
    fields = ("state", "shares", "proposals")
    if not all(hasattr(blend, field) for field in fields):
        _refuse(name, "weigh", f"returned {shown(blend)}", t, f"it must return {BLEND_FORM}")
    _check_state(name, "weigh", blend.state, t)
    if not isinstance(blend.shares, Mapping):
        got = f"returned shares {shown(blend.shares)}"
        _refuse(name, "weigh", got, t, "they must be a mapping behaviour -> share")
    for behaviour in blend.shares:
        _check_behaviour(name, "weigh", behaviour, behaviours, t)


def _check_state(name: str, method: str, state: Any, t: float) -> None:
    if not (isinstance(state, str) and state in STATES):
        allowed = f"allowed: {', '.join(STATES)} (ddwmmr.arbiters.STATES)"
        _refuse(name, method, f"returned state {shown(state)}", t, allowed)


def _check_behaviour(
    name: str, method: str, behaviour: Any, behaviours: Mapping[str, Behaviour], t: float
) -> None:
    if not isinstance(behaviour, str) or behaviour not in behaviours:
        allowed = f"allowed: {', '.join(behaviours)} (the behaviours it was given)"
        _refuse(name, method, f"returned behaviour {shown(behaviour)}", t, allowed)


def _refuse(name: str, method: str, got: str, t: float, wanted: str) -> NoReturn:
    """One line: the arbiter, what its ``method`` returned at time ``t`` (s), what is wanted."""
    raise PluginError(f"arbiter {name}: {method}() {got} at t = {t:g} s; {wanted}")
