"""The thesis's state-machine arbiter (thesis 4.3, Figs 4.6 and 4.12).

States: ``move_base`` / ``move_arm`` (the objective behaviour, by its label),
``manipulability``, ``stability`` and ``obstacle``. Priorities: stability > manipulability >
objective > obstacle avoidance, where obstacle avoidance can only replace the objective's
base movement (the thesis enters it from the moving-base state) and manipulability only
acts while the objective is reaching with the arm (the target is in range; its soft
threshold keeps the arm going for the target).

Hysteresis: a fix state is entered when its metric drops below ``enter`` and left when it
rises to ``exit`` (``exit == enter`` is "no hysteresis"). Stability: S enter 1.25 / exit
1.60; manipulability: eta enter 0.75 / exit 0.90 (thesis Table 5.1).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from ddwmmr.behaviours.base import Behaviour, Percept, Proposal
from ddwmmr.errors import ParameterError
from ddwmmr.registry import register_arbiter

MOVE_BASE, MOVE_ARM = "move_base", "move_arm"
MANIPULABILITY, STABILITY, OBSTACLE = "manipulability", "stability", "obstacle"
#: Every state, in reporting order.
STATES = (MOVE_BASE, MOVE_ARM, MANIPULABILITY, STABILITY, OBSTACLE)


@dataclass(frozen=True)
class Hysteresis:
    """Enter / exit thresholds of one fix state (enter <= exit)."""

    enter: float
    exit: float

    def __post_init__(self) -> None:
        if not self.enter <= self.exit:
            raise ParameterError(
                f"thresholds: enter must be <= exit (got enter {self.enter:g}, exit {self.exit:g})"
            )

    def active(self, value: float, currently: bool) -> bool:
        """Whether the fix state is (still) wanted for metric ``value``."""
        return value < (self.exit if currently else self.enter)


#: The thesis's thresholds (Table 5.1): S enter 1.25 / exit 1.60, eta enter 0.75 / exit 0.90.
THESIS_STABILITY = Hysteresis(1.25, 1.60)
THESIS_MANIPULABILITY = Hysteresis(0.75, 0.90)


@dataclass(slots=True)
class Selection:
    """The arbiter's decision: state, the behaviour that produced the proposal, proposal
    (read-only by convention; one is made every control step)."""

    state: str
    behaviour: str
    proposal: Proposal


@register_arbiter("state-machine")
class StateMachineArbiter:
    """Priority state machine with hysteresis thresholds (thesis 4.3)."""

    def __init__(
        self,
        stability: Hysteresis = THESIS_STABILITY,
        manipulability: Hysteresis = THESIS_MANIPULABILITY,
    ) -> None:
        self.stability = stability
        self.manipulability = manipulability
        self.state = MOVE_BASE

    def reset(self) -> None:
        """Start a new run in the moving-base state."""
        self.state = MOVE_BASE

    def select(self, p: Percept, behaviours: Mapping[str, Behaviour]) -> Selection:
        """Decide the state for percept p and return the chosen behaviour's proposal.

        ``behaviours`` maps names ("objective", "manipulability", "stability" and
        optionally "obstacle") to behaviours; only the needed ones are evaluated.
        """
        objective = behaviours["objective"].propose(p)
        assert objective is not None  # the objective is always on
        task_state = MOVE_ARM if objective.label == "arm" else MOVE_BASE
        if self.stability.active(p.s, self.state == STABILITY):
            return self._go(STABILITY, "stability", behaviours, p)
        in_manip = self.state == MANIPULABILITY
        if task_state == MOVE_ARM and self.manipulability.active(p.eta, in_manip):
            return self._go(MANIPULABILITY, "manipulability", behaviours, p)
        if task_state == MOVE_BASE and "obstacle" in behaviours:
            avoid = behaviours["obstacle"].propose(p)
            if avoid is not None:
                self.state = OBSTACLE
                return Selection(OBSTACLE, "obstacle", avoid)
        self.state = task_state
        return Selection(task_state, "objective", objective)

    def _go(
        self, state: str, name: str, behaviours: Mapping[str, Behaviour], p: Percept
    ) -> Selection:
        self.state = state
        proposal = behaviours[name].propose(p)
        assert proposal is not None  # fix behaviours are always on
        return Selection(state, name, proposal)
