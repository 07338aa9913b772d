"""Controllers: the registry and the resolution/closed-loop methods."""

from ddwmmr.controllers.base import (
    Controller,
    StepInfo,
    WaypointRun,
    available_controllers,
    available_methods,
    controller_class,
    controller_traits,
    make_controller,
    method_description,
    method_options,
    register,
    register_controller,
)

__all__ = [
    "Controller",
    "StepInfo",
    "WaypointRun",
    "available_controllers",
    "available_methods",
    "controller_class",
    "controller_traits",
    "make_controller",
    "method_description",
    "method_options",
    "register",
    "register_controller",
]
