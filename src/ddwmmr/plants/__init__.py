"""Plants: what the controllers' commands act on (kinematic model, thesis dynamics).

Every plant implements :class:`ddwmmr.plants.base.Plant`; :func:`make_plant` builds one by
name (``available_plants()`` lists the names) for the simulation loop.
"""

from __future__ import annotations

import importlib
from typing import Any

from ddwmmr.errors import ParameterError
from ddwmmr.plants.base import Observation, Plant, PlantDivergedError
from ddwmmr.plants.kinematic import INTEGRATORS, KinematicPlant
from ddwmmr.plants.thesis import ThesisPlant, ThesisState, VelocityServo

#: Plant name -> "module:class" (imported on first use, so optional engines stay optional).
PLANT_CLASSES = {
    "kinematic": "ddwmmr.plants.kinematic:KinematicPlant",
    "thesis": "ddwmmr.plants.thesis:ThesisPlant",
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
    """Build the plant ``name`` for ``robot`` with its keyword ``options``."""
    return plant_class(name)(robot, **options)


__all__ = [
    "INTEGRATORS",
    "PLANT_CLASSES",
    "KinematicPlant",
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
