"""Exceptions raised by ddwmmr.

Every user-facing validation problem raises :class:`ParameterError`, whose message is a
single line naming the parameter and the allowed range; the command-line tools print it and
exit with status 2.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path


class ParameterError(ValueError):
    """A parameter, option or input file is invalid (message: one line, names the parameter)."""


def check_positive(name: str, value: float) -> float:
    """Return ``value`` as float if it is finite and > 0, else raise :class:`ParameterError`."""
    value = _as_float(name, value)
    if not value > 0.0:
        raise ParameterError(f"{name} must be > 0 (got {value:g})")
    return value


def check_nonnegative(name: str, value: float) -> float:
    """Return ``value`` as float if it is finite and >= 0, else raise :class:`ParameterError`."""
    value = _as_float(name, value)
    if not value >= 0.0:
        raise ParameterError(f"{name} must be >= 0 (got {value:g})")
    return value


def check_finite(name: str, value: float) -> float:
    """Return ``value`` as float if it is finite, else raise :class:`ParameterError`."""
    return _as_float(name, value)


def check_int_at_least(name: str, value: int, minimum: int) -> int:
    """Return ``value`` as int if it is an integer >= ``minimum``."""
    if isinstance(value, bool) or not float(value).is_integer():
        raise ParameterError(f"{name} must be an integer >= {minimum} (got {value!r})")
    if int(value) < minimum:
        raise ParameterError(f"{name} must be an integer >= {minimum} (got {value!r})")
    return int(value)


def _as_float(name: str, value: float) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number (got {value!r})") from None
    if not math.isfinite(number):
        raise ParameterError(f"{name} must be a finite number (got {value!r})")
    return number


def load_toml(path: str | Path, label: str) -> dict:
    """Parse a TOML file; unreadable or invalid files raise :class:`ParameterError`.

    ``label`` names the option in the message (``robot``, ``traj``, ``obstacles``).
    """
    path = Path(path)
    try:
        return tomllib.loads(path.read_text())
    except OSError as exc:
        raise ParameterError(f"{label}: cannot read {path} ({exc.strerror})") from None
    except tomllib.TOMLDecodeError as exc:
        message = str(exc).splitlines()[0]
        raise ParameterError(f"{label}: {path} is not valid TOML ({message})") from None
