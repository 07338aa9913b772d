"""Plants: what the controllers' commands act on (kinematic model, thesis dynamics, MuJoCo)."""

from ddwmmr.plants.kinematic import INTEGRATORS, KinematicPlant
from ddwmmr.plants.thesis import ThesisPlant, ThesisState

__all__ = ["INTEGRATORS", "KinematicPlant", "MujocoPlant", "ThesisPlant", "ThesisState"]


def __getattr__(name: str):
    # MujocoPlant is imported on first use: importing mujoco takes ~0.4 s, which every
    # other user of the package (CLI start-up, kinematic runs) should not pay.
    if name == "MujocoPlant":
        from ddwmmr.plants.mujoco import MujocoPlant

        return MujocoPlant
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
