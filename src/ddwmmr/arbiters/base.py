"""The arbiter interface: what the thesis controller needs from any arbiter.

The thesis's state machine (:mod:`ddwmmr.arbiters.state_machine`) is one implementation;
another (e.g. the competitive-dynamics arbiter, docs/thesis.md, "The dynamics") only has to
provide the same three members. An arbiter may evaluate any of the behaviours it is given,
but it must return a proposal made by one of them (or a blend in the common proposal format)
and name the state it is in, one of :data:`~ddwmmr.arbiters.STATES`, which the metrics
count. An arbiter that blends proposals instead of choosing one also provides ``weigh``
(:class:`BlendingArbiter`); the controller then uses its blending path. What it is given
and what it may return: docs/thesis.md, "Writing an arbiter" (the thesis controller checks
a plug-in's decisions, :func:`~ddwmmr.arbiters.checked.checked_arbiter`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Protocol

from ddwmmr.behaviours.base import Behaviour, Percept

if TYPE_CHECKING:  # the decisions are defined beside the arbiters that make them
    from ddwmmr.arbiters.competitive import Blend
    from ddwmmr.arbiters.state_machine import Selection


class Arbiter(Protocol):
    """Structural type of an arbiter."""

    state: str

    def reset(self) -> None:  # pragma: no cover - protocol
        """Start a new run."""
        ...

    def select(
        self, p: Percept, behaviours: Mapping[str, Behaviour]
    ) -> Selection:  # pragma: no cover - protocol
        """Choose the state and the proposal for percept p; ``behaviours`` maps
        "objective", "manipulability", "stability" (and "obstacle" with obstacles) to the
        controller's behaviours."""
        ...


class BlendingArbiter(Arbiter, Protocol):
    """An arbiter that returns weights: the controller blends the behaviours' proposals."""

    def weigh(
        self, p: Percept, behaviours: Mapping[str, Behaviour]
    ) -> Blend:  # pragma: no cover - protocol
        """Advance to time ``p.t`` and return the state and the blending shares."""
        ...
