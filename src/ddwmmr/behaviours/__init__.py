"""High-level behaviours of the thesis controller and its low-level movers (the controller
that assembles them with an arbiter is :mod:`ddwmmr.thesis_controller`)."""

from ddwmmr.behaviours.base import BRAKE, DRIVE, TURN, Behaviour, Percept, Proposal, sense
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
    "default_pose",
    "sense",
]
