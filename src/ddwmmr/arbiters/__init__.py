"""Arbiters: choose which behaviour's proposal reaches the low-level controllers.

The thesis's priority state machine is :class:`StateMachineArbiter`; any object with
``state``, ``reset()`` and ``select(percept, behaviours) -> Selection`` (:class:`Arbiter`)
can replace it. :class:`CompetitiveDynamicsArbiter` (Ellekilde & Christensen 2009) is the
alternative: behaviour weights under competitive dynamics, proposals blended by the weights
(it also has ``weigh(percept, behaviours) -> Blend``, :class:`BlendingArbiter`).
:func:`make_arbiter` builds a registered one (:func:`available_arbiters`) from a scenario
configuration. :func:`checked_arbiter` wraps an arbiter from outside the library in
:class:`CheckedArbiter` (the thesis controller passes every arbiter it is given through it,
and so does the scenario protocol for any controller that takes an arbiter), which refuses
in one line a state outside :data:`STATES`, a behaviour the controller does not have, a
malformed proposal or a share outside [0, 1].
"""

from ddwmmr.arbiters.base import Arbiter, BlendingArbiter
from ddwmmr.arbiters.checked import CheckedArbiter, checked_arbiter
from ddwmmr.arbiters.competitive import (
    BEHAVIOURS,
    Blend,
    CompetitiveDynamics,
    CompetitiveDynamicsArbiter,
    CompetitiveParameters,
)
from ddwmmr.arbiters.factory import (
    DEFAULT_ARBITER,
    arbiter_description,
    available_arbiters,
    check_arbiter,
    make_arbiter,
)
from ddwmmr.arbiters.state_machine import (
    MANIPULABILITY,
    MOVE_ARM,
    MOVE_BASE,
    OBSTACLE,
    STABILITY,
    STATES,
    Hysteresis,
    Selection,
    StateMachineArbiter,
)
from ddwmmr.registry import register_arbiter

__all__ = [
    "BEHAVIOURS",
    "DEFAULT_ARBITER",
    "MANIPULABILITY",
    "MOVE_ARM",
    "MOVE_BASE",
    "OBSTACLE",
    "STABILITY",
    "STATES",
    "Arbiter",
    "Blend",
    "BlendingArbiter",
    "CheckedArbiter",
    "CompetitiveDynamics",
    "CompetitiveDynamicsArbiter",
    "CompetitiveParameters",
    "Hysteresis",
    "Selection",
    "StateMachineArbiter",
    "arbiter_description",
    "available_arbiters",
    "check_arbiter",
    "checked_arbiter",
    "make_arbiter",
    "register_arbiter",
]
