"""Plants: what the controllers' commands act on (kinematic model, thesis dynamics, MuJoCo).

Every plant implements :class:`ddwmmr.plants.base.Plant` and registers itself with
:func:`ddwmmr.registry.register_plant`; :func:`make_plant` builds one by name
(``available_plants()`` lists the names) for the simulation loop. A plant's module is
imported when it is first built (importing mujoco takes ~0.4 s, which every other user of
the package, such as CLI start-up or kinematic runs, should not pay).
"""

from __future__ import annotations

import inspect
from typing import Any

from ddwmmr.errors import ParameterError, check_instance, shown
from ddwmmr.model import Robot
from ddwmmr.plants.base import Observation, Plant, PlantDivergedError, PlantNotResetError
from ddwmmr.plants.kinematic import INTEGRATORS, KinematicPlant
from ddwmmr.plants.thesis import ThesisPlant, ThesisState, VelocityServo
from ddwmmr.registry import PLANTS, build, register_plant


def available_plants(interface: str | None = None) -> list[str]:
    """Names accepted by :func:`make_plant` (and by ``simulate(..., plant=...)``), in
    listing order; ``interface`` (``"velocity"`` or ``"force"``) keeps those that take it."""
    return PLANTS.names() if interface is None else PLANTS.names(interfaces=interface)


def plant_description(name: str) -> str:
    """First docstring line of a registered plant."""
    return PLANTS.describe(name)


def plant_class(name: str) -> type:
    """The class registered under ``name``."""
    return PLANTS.load(name)


def make_plant(name: str, robot: Robot, **options: Any) -> Plant:
    """Build the plant ``name`` for ``robot`` with its keyword ``options``; an unknown
    option is a :class:`ParameterError` naming the accepted ones. Anything but a
    ParameterError the constructor of a plug-in (a class from outside the library) raises
    is a one-line :class:`~ddwmmr.errors.PluginError` naming the plant, its class and what
    it raised (the ``__cause__``)."""
    cls = plant_class(name)
    check_instance("robot", robot, Robot)
    parameters = inspect.signature(cls).parameters
    accepted = sorted(p for p in parameters if p != "robot")
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise ParameterError(
            f"plant {name}: unknown option {shown(unknown[0])} (accepted: {', '.join(accepted)})"
        )
    plant: Plant = build(
        cls, f"plant: {name}: {cls.__qualname__}(robot, **options)", (robot,), options
    )
    return plant


def __getattr__(name: str) -> Any:
    # ``from ddwmmr.plants import MujocoPlant`` works, importing mujoco only then.
    if name == "MujocoPlant":
        return plant_class("mujoco")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "INTEGRATORS",
    "KinematicPlant",
    "MujocoPlant",
    "Observation",
    "Plant",
    "PlantDivergedError",
    "PlantNotResetError",
    "ThesisPlant",
    "ThesisState",
    "VelocityServo",
    "available_plants",
    "make_plant",
    "plant_class",
    "plant_description",
    "register_plant",
]
