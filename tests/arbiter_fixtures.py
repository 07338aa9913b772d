"""Behaviours and a percept shared by the arbiter tests (state machine, competitive)."""

from __future__ import annotations

from ddwmmr.behaviours import BRAKE, DRIVE, Proposal, sense
from ddwmmr.model import Robot

ROBOT = Robot().with_payload(3.0)
BASE_PERCEPT = sense(ROBOT, 0.0, (0.0, 0.0, 0.0, -0.7, 1.57), 0.0, 0.0, (3.0, 0.0))


class Fixed:
    """A behaviour returning a fixed proposal (None: off); counts its calls."""

    def __init__(self, name: str, proposal: Proposal | None) -> None:
        self.name = name
        self.proposal = proposal
        self.calls = 0

    def propose(self, p):
        self.calls += 1
        return self.proposal


def behaviours(objective_label: str = "arm", obstacle: bool = False) -> dict[str, Fixed]:
    """Objective (braking, label ``objective_label``), manipulability and stability (and
    obstacle avoidance) behaviours with distinct fixed proposals."""
    found = {
        "objective": Fixed("objective", Proposal(BRAKE, (0.0, 0.0), label=objective_label)),
        "manipulability": Fixed("manipulability", Proposal(DRIVE, (0.1, 0.1))),
        "stability": Fixed("stability", Proposal(DRIVE, (0.2, 0.2))),
    }
    if obstacle:
        found["obstacle"] = Fixed("obstacle", Proposal(DRIVE, (0.3, 0.3)))
    return found
