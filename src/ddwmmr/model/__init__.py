"""The robot model: kinematics, wheel map, manipulability and tip-over stability."""

from ddwmmr.model.robot import Robot

__all__ = ["Robot"]
