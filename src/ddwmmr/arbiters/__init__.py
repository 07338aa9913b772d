"""Arbiters: choose which behaviour's proposal reaches the low-level controllers.

The thesis's priority state machine is :class:`StateMachineArbiter`; any object with
``state``, ``reset()`` and ``select(percept, behaviours) -> Selection`` (:class:`Arbiter`)
can replace it.
"""

from ddwmmr.arbiters.base import Arbiter
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

__all__ = [
    "MANIPULABILITY",
    "MOVE_ARM",
    "MOVE_BASE",
    "OBSTACLE",
    "STABILITY",
    "STATES",
    "Arbiter",
    "Hysteresis",
    "Selection",
    "StateMachineArbiter",
]
