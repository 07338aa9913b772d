"""Controllers: the registry and the resolution/closed-loop methods."""

from ddwmmr.controllers.base import (
    Controller,
    StepInfo,
    available_methods,
    make_controller,
    method_description,
    method_options,
    register,
)

__all__ = [
    "Controller",
    "StepInfo",
    "available_methods",
    "make_controller",
    "method_description",
    "method_options",
    "register",
]
