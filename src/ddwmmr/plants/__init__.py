"""Plants: what the controllers' commands act on (kinematic model, thesis dynamics, MuJoCo).

Every plant implements :class:`ddwmmr.plants.base.Plant`; :func:`make_plant` builds one by
name (``available_plants()`` lists the names) for the simulation loop.
"""

from __future__ import annotations

import importlib
import inspect
from typing import Any

from ddwmmr.errors import ParameterError, check_instance
from ddwmmr.model import Robot
from ddwmmr.plants.base import Observation, Plant, PlantDivergedError
from ddwmmr.plants.kinematic import INTEGRATORS, KinematicPlant
from ddwmmr.plants.thesis import ThesisPlant, ThesisState, VelocityServo

#: Plant name -> "module:class" (imported on first use: importing mujoco takes ~0.4 s, which
#: every other user of the package, such as CLI start-up or kinematic runs, should not pay).
PLANT_CLASSES = {
    "kinematic": "ddwmmr.plants.kinematic:KinematicPlant",
    "thesis": "ddwmmr.plants.thesis:ThesisPlant",
    "mujoco": "ddwmmr.plants.mujoco:MujocoPlant",
}


def available_plants() -> list[str]:
    """Names accepted by :func:`make_plant` (and by ``simulate(..., plant=...)``)."""
    return list(PLANT_CLASSES)


def plant_class(name: str) -> type:
    """The class registered under ``name``."""
    if name not in PLANT_CLASSES:
        raise ParameterError(f"plant must be one of {', '.join(PLANT_CLASSES)} (got {name!r})")
    module, _, attribute = PLANT_CLASSES[name].partition(":")
    return getattr(importlib.import_module(module), attribute)


def make_plant(name: str, robot: Any, **options: Any) -> Plant:
    """Build the plant ``name`` for ``robot`` with its keyword ``options``; an unknown
    option is a :class:`ParameterError` naming the accepted ones."""
    cls = plant_class(name)
    check_instance("robot", robot, Robot)
    parameters = inspect.signature(cls).parameters
    accepted = sorted(p for p in parameters if p != "robot")
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise ParameterError(
            f"plant {name}: unknown option {unknown[0]!r} (accepted: {', '.join(accepted)})"
        )
    return cls(robot, **options)


def __getattr__(name: str) -> Any:
    # ``from ddwmmr.plants import MujocoPlant`` works, importing mujoco only then.
    if name == "MujocoPlant":
        return plant_class("mujoco")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "INTEGRATORS",
    "PLANT_CLASSES",
    "KinematicPlant",
    "MujocoPlant",
    "Observation",
    "Plant",
    "PlantDivergedError",
    "ThesisPlant",
    "ThesisState",
    "VelocityServo",
    "available_plants",
    "make_plant",
    "plant_class",
]
