"""Feedback gains from time constants: ``K = 1/tau`` (1/s), validated."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ddwmmr.errors import ParameterError, check_nonnegative, check_positive, shown

#: Shortest time constant (s): gains above 1e4 1/s are no feedback a 2 rad/s arm or a
#: wheel-speed-limited base can follow, only numbers that overflow the commands.
MIN_TAU = 1e-4
#: Largest gain (1/s) of any controller: the feedback gains ``1/tau``, the potential gains
#: K1..K3 of ``ap`` and of the QP posture task, the QP's limit and task gains. The same
#: bound as MIN_TAU: more is no feedback the robot can follow, only commands that overflow
#: (``ap`` with K3 = 1e300 commanded 1.3e300 rad/s).
MAX_GAIN = 1.0 / MIN_TAU
#: The values a time constant may take, as the messages word them.
TAU_RANGE = f"> 0 s (at least {MIN_TAU:g} s), or inf to disable a channel"


def check_gain(name: str, value: float, zero: bool = False) -> float:
    """``value`` as a float if it is a gain in (0, MAX_GAIN] 1/s ([0, MAX_GAIN] with
    ``zero``: a gain that may switch its term off), else :class:`ParameterError`."""
    value = check_nonnegative(name, value) if zero else check_positive(name, value)
    if value > MAX_GAIN:
        raise ParameterError(f"{name} must be <= {MAX_GAIN:g} 1/s (got {value:g})")
    return value


def gains_from_tau(tau: float | Sequence[float], size: int) -> tuple[float, ...]:
    """Gains ``K_i = 1/tau_i`` (1/s) from one time constant or ``size`` of them (s).

    ``tau = inf`` switches a channel's feedback off (gain 0). A value that is not a time
    constant (text, a boolean, None, nan, below :data:`MIN_TAU`) is refused naming the
    allowed range, :data:`TAU_RANGE`.
    """
    one = isinstance(tau, str | bytes | int | float | np.integer | np.floating)
    values = [tau] * size if one or tau is None or np.ndim(tau) == 0 else list(tau)
    if len(values) != size:
        raise ParameterError(f"tau must be one value or {size} values in s (got {len(values)})")
    gains = []
    for value in values:
        number = _time_constant(value)
        gains.append(0.0 if math.isinf(number) else 1.0 / number)
    return tuple(gains)


def _time_constant(value: Any) -> float:
    """``value`` as a float if it is a time constant (:data:`TAU_RANGE`), else raise."""
    try:
        if isinstance(value, str | bytes | bool | np.bool_) or value is None:
            raise TypeError  # not a number, even where float() would read it
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"tau must be {TAU_RANGE} (got {shown(value)})") from None
    if math.isnan(number) or number < MIN_TAU:
        raise ParameterError(f"tau must be {TAU_RANGE} (got {number:g})")
    return number
