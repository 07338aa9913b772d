"""Plants: what the controllers' commands act on (kinematic model, thesis dynamics)."""

from ddwmmr.plants.kinematic import INTEGRATORS, KinematicPlant
from ddwmmr.plants.thesis import ThesisPlant, ThesisState

__all__ = ["INTEGRATORS", "KinematicPlant", "ThesisPlant", "ThesisState"]
