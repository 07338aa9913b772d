"""What the app offers: method options read from constructor signatures, and the plants.

Nothing here knows a method by name: :func:`method_options` inspects the constructor of
whatever :func:`ddwmmr.make_controller` builds, so a newly registered method shows up in
the app with its options. A controller class may declare the values of its closed-set
options in ``option_choices`` (option name -> function returning the values; the qp's
installed solvers, the mpc's solvers). The few option *names* below only add presentation
(a list of choices, a unit) to options that any method may have.
"""

from __future__ import annotations

import inspect
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any

from ddwmmr.controllers.base import make_controller
from ddwmmr.errors import ParameterError, shown


def _aux_rows() -> list[str]:
    from ddwmmr.model.kinematics import AUX_ROWS

    return list(AUX_ROWS)


#: Options with a closed set of values whatever the method, shown as a button cycling
#: through them (a controller's own ``option_choices`` come first).
CHOICES: dict[str, Callable[[], list[str]]] = {"aux": _aux_rows}

#: Units shown next to known option names (SI; "-" for dimensionless ones).
UNITS = {
    "tau": "s",
    "dt": "s",
    "stability_min": "-",
    "stability_gain": "1/s",
    "manipulability_weight": "-",
    "obstacles": "TOML file",
    "obstacle_margin": "m",
    "singularity_margin": "rad",
    "singularity_threshold": "-",
    "max_speed": "m/s",
    "max_base_speed": "m/s",
    "max_yaw_rate": "rad/s",
    "max_acceleration": "m/s2",
    "max_yaw_acceleration": "rad/s2",
    "speed_budget": "m/s, rad/s",
    "reference_step": "s",
    "horizon": "s",  # the mpc's prediction horizon
    "first_interval": "s",
    "arm_time_constant": "s",
    "reach_speed": "m/s",
    "huber": "m",
    "wheel_force_limit": "N",
    "joint_acceleration_limit": "rad/s2",
    "brake_slack": "m",
}


@dataclass(frozen=True)
class OptionSpec:
    """One constructor option of a method, as the app edits it.

    Attributes:
        name: keyword of the constructor.
        default: its default value.
        kind: ``"choice"`` (a button cycling through ``choices``), ``"number"`` (a text
            field holding one number, or several when ``several`` is set) or ``"text"``
            (a text field, e.g. a file path).
        choices: the values of a ``"choice"`` option.
        optional: a blank field means None (the method's automatic value).
        several: the option accepts a sequence of numbers (e.g. one tau per channel).
        unit: unit shown in the label ("" if unknown).
    """

    name: str
    default: Any
    kind: str
    choices: tuple[Any, ...] = ()
    optional: bool = False
    several: bool = False
    unit: str = ""

    @property
    def label(self) -> str:
        """Field label: the name, with the unit when known."""
        return f"{self.name} ({self.unit})" if self.unit else self.name

    def format(self, value: Any) -> str:
        """Text shown for ``value`` (a field's content or a button's label part)."""
        if self.kind == "choice":
            return format_choice(value)
        if value is None:
            return ""
        if isinstance(value, list | tuple):
            return " ".join(_format_number(v) for v in value)
        if isinstance(value, float | int) and not isinstance(value, bool):
            return _format_number(value)
        return str(value)

    def parse(self, text: str) -> Any:
        """The option value a field's ``text`` stands for; bad text raises ParameterError."""
        text = text.strip()
        if self.kind == "choice":
            for choice in self.choices:
                if text == format_choice(choice):
                    return choice
            allowed = ", ".join(format_choice(c) for c in self.choices)
            raise ParameterError(f"{self.name} must be one of {allowed} (got {shown(text)})")
        if not text:
            if self.optional:
                return None
            if self.kind == "text":
                return self.default
            raise ParameterError(f"{self.name} needs a number")
        if self.kind == "text":
            return text
        return self._parse_numbers(text)

    def _parse_numbers(self, text: str) -> float | int | tuple[float, ...]:
        try:
            numbers = [float(part) for part in re.split(r"[\s,]+", text) if part]
        except ValueError:
            raise ParameterError(f"{self.name} must be a number (got {shown(text)})") from None
        if any(math.isnan(v) for v in numbers):
            raise ParameterError(f"{self.name} must be a number (got {shown(text)})")
        if len(numbers) > 1:
            if not self.several:
                raise ParameterError(f"{self.name} takes one number (got {shown(text)})")
            return tuple(numbers)
        (value,) = numbers
        if isinstance(self.default, int) and not isinstance(self.default, bool):
            if not value.is_integer():
                raise ParameterError(f"{self.name} must be an integer (got {shown(text)})")
            return int(value)
        return value


def format_choice(value: Any) -> str:
    """Button text of a choice: on/off for booleans, auto for None."""
    if value is None:
        return "auto"
    if isinstance(value, bool):
        return "on" if value else "off"
    return str(value)


def _format_number(value: float) -> str:
    return f"{value:g}"


@cache
def method_options(method: str) -> tuple[OptionSpec, ...]:
    """Editable options of a registered method, in constructor order.

    The controller class is the type of what ``make_controller(method)`` builds; its
    constructor's keyword parameters (except ``robot``) are the options, as
    ``make_controller`` accepts them. Options whose type cannot be typed into a field
    (e.g. lists of user task objects) are left out.
    """
    controller_class = type(make_controller(method))
    choices = {**CHOICES, **getattr(controller_class, "option_choices", {})}
    specs = []
    for parameter in inspect.signature(controller_class).parameters.values():
        if parameter.name == "robot" or parameter.kind in (
            inspect.Parameter.VAR_POSITIONAL,
            inspect.Parameter.VAR_KEYWORD,
        ):
            continue
        spec = option_spec(parameter.name, parameter.default, _annotation_text(parameter), choices)
        if spec is not None:
            specs.append(spec)
    return tuple(specs)


def option_spec(
    name: str,
    default: Any,
    annotation: str,
    choices: dict[str, Callable[[], list[Any]]] | None = None,
) -> OptionSpec | None:
    """The :class:`OptionSpec` of one constructor parameter, or None if it is not editable.

    ``annotation`` is the parameter's annotation as text (``"float | None"``...);
    ``choices`` maps closed-set option names to their values (default :data:`CHOICES`).
    Mappings (e.g. another controller's options) cannot be typed into a field: None.
    """
    choices = CHOICES if choices is None else choices
    if default is inspect.Parameter.empty:
        default = None
    words = set(re.findall(r"[A-Za-z_]+", annotation))
    optional = default is None or "None" in words
    unit = UNITS.get(name, "")
    if name in choices:
        values = tuple(choices[name]())
        if default not in values and default is not None:
            values = (default, *values)
        return OptionSpec(name, default, "choice", values, optional, unit=unit)
    if words & {"dict", "Mapping"} or isinstance(default, dict):
        return None
    if isinstance(default, bool) or words == {"bool"} or words == {"bool", "None"}:
        choices = (None, True, False) if optional else (True, False)
        return OptionSpec(name, default, "choice", choices, optional, unit=unit)
    numeric = isinstance(default, int | float) or (default is None and words & {"float", "int"})
    if numeric and not words & {"str", "Path"}:
        several = bool(words & {"Sequence", "tuple", "list"})
        return OptionSpec(name, default, "number", (), optional, several, unit)
    if words & {"str", "Path"} or isinstance(default, str):
        return OptionSpec(name, default, "text", (), optional, unit=unit)
    return None


def _annotation_text(parameter: inspect.Parameter) -> str:
    annotation = parameter.annotation
    if annotation is inspect.Parameter.empty:
        return ""
    return annotation if isinstance(annotation, str) else inspect.formatannotation(annotation)


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
