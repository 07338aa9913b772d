"""Method options as text: what each registered method's options are, and how a text
``NAME=VALUE`` becomes an option value (the simulator's fields, every tool's
``--option NAME=VALUE``).

Nothing here knows a method by name: :func:`option_specs` inspects the constructor of
the class registered for the method, so a newly registered method shows up with its
options. A controller class may declare the values of its closed-set options in
``option_choices`` (option name -> function returning the values; the qp's installed
solvers, the mpc's solvers). The few option *names* below only add presentation (a list
of choices, a unit) to options that any method may have.
"""

from __future__ import annotations

import inspect
import math
import re
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from functools import cache
from typing import Any

from ddwmmr.controllers.base import NumberText, method_parameters
from ddwmmr.controllers.base import controller_class as registered_class
from ddwmmr.errors import ParameterError, did_you_mean, plain_float, plain_number_text, shown

__all__ = [
    "CHOICES",
    "NOTES",
    "UNITS",
    "OptionSpec",
    "format_choice",
    "option_names",
    "option_spec",
    "option_specs",
    "parse_option",
    "parse_options",
    "parse_typed",
]


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
    "lookahead_horizon": "s",
}


#: What an option is, for the option names whose name alone misleads, shown under the
#: tools' ``--help`` list of each method's options and in the app's message area beside
#: its field. ``dt`` reads as the run's step (``--dt``), but the ``qp`` and ``mpc`` take
#: it as the step they plan each command for (docs/qp.md, docs/mpc.md). At most about 230
#: characters: the app's message box holds three lines of its smallest font.
NOTES = {
    "dt": "the step the controller plans each command for, s (qp: its stability check's "
    "look-ahead and its acceleration limits' step; mpc: its plan's first interval); "
    "default: the run's control step (--dt), which the option does not change",
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
        """The option value a field's ``text`` stands for; a choice that is not one of the
        choices raises ParameterError. An optional option's blank text, or ``auto`` for an
        optional number, is None (the method's automatic value).

        A number option's text that is not one number of the option's kind (``abc``, empty,
        ``1,2`` for one number, ``1.5`` for an integer, a number a float cannot hold:
        ``1e999``, ``1e-400``, :func:`~ddwmmr.errors.plain_float`) comes back as a
        :class:`~ddwmmr.controllers.base.NumberText`, as ``nan`` comes back as nan: the
        method's own check (``make_controller``), the one place that knows the allowed
        range, refuses it naming the range."""
        text = text.strip()
        if self.kind == "choice":
            for choice in self.choices:
                if text == format_choice(choice):
                    return choice
            allowed = ", ".join(format_choice(c) for c in self.choices)
            raise ParameterError(f"{self.name} must be one of {allowed} (got {shown(text)})")
        if not text or (text == "auto" and self.optional and self.kind == "number"):
            if self.optional:
                return None
            if self.kind == "text":
                return self.default
            return NumberText(text)  # no number: the method's check names the range
        if self.kind == "text":
            return text
        return self._parse_numbers(text)

    def _parse_numbers(self, text: str) -> float | int | tuple[float, ...] | NumberText:
        items = _number_items(text)
        if "" in items:  # a doubled, leading or trailing comma: no number there
            if not self.several:  # one number expected: the method's check names the range
                return NumberText(text, "one number")
            raise ParameterError(
                f"{self.name}: item {items.index('') + 1} is empty (got {shown(text)}); "
                "separate the numbers by one comma or by spaces"
            )
        try:
            if not plain_number_text(text):
                raise ValueError(text)
            numbers = [plain_float(item) for item in items]  # 1e-400 is not 0
        except ValueError:  # passed on, as nan is: the method's check names the range
            return NumberText(text)
        if len(numbers) > 1:
            if not self.several:  # one number expected: the method's check names the range
                return NumberText(text, "one number")
            return tuple(numbers)
        (value,) = numbers
        if isinstance(self.default, int) and not isinstance(self.default, bool):
            if not math.isfinite(value):  # the method's check names the allowed range
                return value
            if not value.is_integer():  # the method's check names the allowed range
                return NumberText(text, "an integer")
            return int(value)
        return value


def _number_items(text: str) -> list[str]:
    """The items of a number option's ``text``, in order: separated by commas or by
    whitespace (``"0.5, 0.5 inf"``), an empty string for each comma with no item before
    or after it (``"0.5,,0.5"``, ``",0.5"``, ``"0.5,"``)."""
    items: list[str] = []
    for part in text.split(","):
        items.extend(part.split() or [""])
    return items


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
def option_specs(method: str) -> tuple[OptionSpec, ...]:
    """Editable options of a registered method, in :func:`method_parameters` order.

    The options are those ``make_controller`` accepts (:func:`ddwmmr.controllers.
    method_options`: the keyword parameters of the registered class's ``__init__`` and its
    parents', except ``robot``). Options whose type cannot be typed into a field (e.g.
    lists of user task objects, a mapping of another controller's options) are left out:
    the API alone sets them.
    """
    return tuple(_specs(method, _choices(method)))


def _choices(method: str) -> dict[str, Callable[[], list[Any]]]:
    """The closed-set options of ``method``: :data:`CHOICES`, then the class's own."""
    return {**CHOICES, **getattr(registered_class(method), "option_choices", {})}


def _specs(method: str, choices: dict[str, Callable[[], list[Any]]]) -> list[OptionSpec]:
    specs = []
    for parameter in method_parameters(method).values():
        spec = option_spec(parameter.name, parameter.default, _annotation_text(parameter), choices)
        if spec is not None:
            specs.append(spec)
    return specs


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
        flags = (None, True, False) if optional else (True, False)
        return OptionSpec(name, default, "choice", flags, optional, unit=unit)
    numeric = isinstance(default, int | float) or (default is None and words & {"float", "int"})
    if numeric and not words & {"str", "Path"}:
        several = bool(words & {"Sequence", "tuple", "list"})
        return OptionSpec(name, default, "number", (), optional, several, unit)
    if words & {"str", "Path"} or isinstance(default, str):
        return OptionSpec(name, default, "text", (), optional, unit=unit)
    return None


def _annotation_text(parameter: inspect.Parameter) -> str:
    """``parameter``'s annotation as text (as ``from __future__ import annotations``
    leaves it, or formatted), "" for none."""
    annotation = parameter.annotation
    if annotation is inspect.Parameter.empty:
        return ""
    return annotation if isinstance(annotation, str) else inspect.formatannotation(annotation)


def constructor_option_specs(cls: type, skip: Collection[str]) -> dict[str, OptionSpec]:
    """The options a command line sets on the class ``cls`` (a plant, an arbiter): the
    keyword parameters of its constructor but ``skip`` (those the tool passes itself),
    each an :class:`OptionSpec` as :func:`option_spec` types it (name -> spec); a
    parameter no text stands for (a mapping, an object) is left out."""
    specs: dict[str, OptionSpec] = {}
    for parameter in inspect.signature(cls).parameters.values():
        variadic = parameter.kind in (parameter.VAR_POSITIONAL, parameter.VAR_KEYWORD)
        if variadic or parameter.name in skip:
            continue
        spec = option_spec(parameter.name, parameter.default, _annotation_text(parameter))
        if spec is not None:
            specs[spec.name] = spec
    return specs


def option_names(method: str) -> tuple[str, ...]:
    """The names of :func:`option_specs` of ``method``, without listing any choice's values
    (no solver is imported): what ``--help`` lists."""
    unlisted: dict[str, Callable[[], list[Any]]] = {name: list for name in _choices(method)}
    return tuple(spec.name for spec in _specs(method, unlisted))


def parse_option(
    method: str, text: str, what: str = "option", unlisted: Collection[str] = ()
) -> tuple[str, Any]:
    """``NAME=VALUE`` -> (name, value) for ``method``, parsed as the simulator's field
    for that option parses it. A text without ``=`` or a name the method does not take (the
    message lists the names it takes but ``unlisted``, those a front end sets itself, and
    the closest of all, which may be one of those: their own message then says what sets
    it) is a one-line :class:`ParameterError` starting with ``what`` (the
    command-line option); a bad choice one naming the option. A number option's text that
    is no number comes back as a :class:`~ddwmmr.controllers.base.NumberText` for
    ``make_controller`` to refuse."""
    name, value = split_option(text, what)
    specs = {spec.name: spec for spec in option_specs(method)}
    if name not in specs:
        offered = [known for known in specs if known not in unlisted]
        listed = ", ".join(offered) or "none"
        raise ParameterError(
            f"{what}: {method} has no option {name!r}{did_you_mean(name, specs)} "
            f"(options: {listed})"
        )
    return name, parse_typed(specs[name], value, what)


def parse_typed(spec: OptionSpec, value: str, what: str = "option") -> Any:
    """The value of ``NAME=VALUE`` typed on a command line for the option ``spec``, read
    as :meth:`OptionSpec.parse` reads a field, except for an empty ``value``: where a
    blank field means "automatic" (or the default), an empty value typed (``--option
    damping=``, a shell variable that is not set) is never taken as not given. A number
    option's comes back as :class:`~ddwmmr.controllers.base.NumberText`, refused by the
    method's or plant's own check, which names the range; a text option's is a one-line
    :class:`ParameterError` starting with ``what``; a choice's is refused by ``parse``."""
    if value.strip() or spec.kind == "choice":
        return spec.parse(value)
    if spec.kind == "number":
        return NumberText(value)
    raise ParameterError(
        f"{what}: {spec.name} has an empty value (got {shown(spec.name + '=' + value)}); "
        "give one or leave the option out"
    )


def split_option(text: str, what: str = "option") -> tuple[str, str]:
    """``NAME=VALUE`` -> (name without surrounding spaces, the value's text); a text
    without ``=`` or an empty name is a one-line :class:`ParameterError` starting with
    ``what`` (the command-line option)."""
    name, sep, value = text.partition("=")
    name = name.strip()
    if not sep or not name:
        raise ParameterError(f"{what} must be NAME=VALUE (got {shown(text)})")
    return name, value


def parse_options(
    method: str, texts: Sequence[str] | None, what: str = "option", unlisted: Collection[str] = ()
) -> dict[str, Any]:
    """``{name: value}`` of several ``NAME=VALUE`` texts for ``method`` (see
    :func:`parse_option`); a name given twice is refused."""
    options: dict[str, Any] = {}
    for text in texts or ():
        name, value = parse_option(method, text, what, unlisted)
        if name in options:
            raise ParameterError(f"{what}: {name} given twice (got {shown(text)})")
        options[name] = value
    return options
