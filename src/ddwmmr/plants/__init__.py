"""Plants: what the controllers' commands act on (kinematic model, thesis dynamics)."""

from ddwmmr.plants.kinematic import INTEGRATORS, KinematicPlant

__all__ = ["INTEGRATORS", "KinematicPlant"]
