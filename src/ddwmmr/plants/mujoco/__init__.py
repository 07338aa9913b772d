"""The physics plant on MuJoCo: model generated from the robot, plant, tip-over readout."""

from ddwmmr.plants.mujoco.model import EngineOptions, build_model, mjcf, support_polygon, supports
from ddwmmr.plants.mujoco.plant import MujocoPlant

__all__ = ["EngineOptions", "MujocoPlant", "build_model", "mjcf", "support_polygon", "supports"]
