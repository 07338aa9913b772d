"""An arbiter plug-in in one file: the objective always wins."""

from ddwmmr.arbiters import MOVE_ARM, MOVE_BASE, Selection, register_arbiter


@register_arbiter("objective-only")
class ObjectiveOnly:
    """The objective behaviour alone: no fix state ever interrupts it."""

    def __init__(self, stability=None, manipulability=None):
        self.state = MOVE_BASE  # thresholds accepted and ignored

    def reset(self):
        self.state = MOVE_BASE

    def select(self, p, behaviours):
        proposal = behaviours["objective"].propose(p)
        self.state = MOVE_ARM if proposal.label == "arm" else MOVE_BASE
        return Selection(self.state, "objective", proposal)
