"""High-level behaviours of the thesis controller and the controller that assembles them."""

from ddwmmr.behaviours.base import BRAKE, DRIVE, TURN, Behaviour, Percept, Proposal, sense
from ddwmmr.behaviours.controller import ThesisController
from ddwmmr.behaviours.lowlevel import ArmMover, BaseMover, PDGains
from ddwmmr.behaviours.manipulability import Manipulability
from ddwmmr.behaviours.objective import Objective, default_pose
from ddwmmr.behaviours.obstacle import ObstacleAvoidance
from ddwmmr.behaviours.stability import Stability

__all__ = [
    "BRAKE",
    "DRIVE",
    "TURN",
    "ArmMover",
    "BaseMover",
    "Behaviour",
    "Manipulability",
    "Objective",
    "ObstacleAvoidance",
    "PDGains",
    "Percept",
    "Proposal",
    "Stability",
    "ThesisController",
    "default_pose",
    "sense",
]
