"""What the app offers: method options (:mod:`ddwmmr.controllers.option_specs`, their one
home) and the plants.
"""

from __future__ import annotations

from ddwmmr.controllers.option_specs import (
    CHOICES,
    NOTES,
    UNITS,
    OptionSpec,
    format_choice,
    option_spec,
    option_specs,
    parse_option,
)

#: The editable options of a method (the app's name for
#: :func:`ddwmmr.controllers.option_specs.option_specs`).
method_options = option_specs

__all__ = [
    "CHOICES",
    "NOTES",
    "UNITS",
    "OptionSpec",
    "format_choice",
    "method_options",
    "option_spec",
    "parse_option",
    "plant_keywords",
    "plant_names",
]


def plant_names() -> list[str]:
    """Plants the app offers: ``ddwmmr.sim.available_plants()`` (the one place the app
    reads this, so a new plant appears by itself)."""
    from ddwmmr import sim

    return list(sim.available_plants())


def plant_keywords(plant: str, integrator: str) -> dict[str, str]:
    """Keyword arguments of :func:`ddwmmr.simulate` selecting ``plant``; the integrator
    goes to the kinematic plant only (the others integrate their own dynamics)."""
    if plant == "kinematic":
        return {"plant": plant, "integrator": integrator}
    return {"plant": plant}
