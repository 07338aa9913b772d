"""Feedback gains from time constants: ``K = 1/tau`` (1/s), validated."""

from __future__ import annotations

import math
from collections.abc import Sequence

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


def check_gain(name: str, value: float, zero: bool = False) -> float:
    """``value`` as a float if it is a gain in (0, MAX_GAIN] 1/s ([0, MAX_GAIN] with
    ``zero``: a gain that may switch its term off), else :class:`ParameterError`."""
    value = check_nonnegative(name, value) if zero else check_positive(name, value)
    if value > MAX_GAIN:
        raise ParameterError(f"{name} must be <= {MAX_GAIN:g} 1/s (got {value:g})")
    return value


def gains_from_tau(tau: float | Sequence[float], size: int) -> tuple[float, ...]:
    """Gains ``K_i = 1/tau_i`` (1/s) from one time constant or ``size`` of them (s).

    ``tau = inf`` switches a channel's feedback off (gain 0).
    """
    if isinstance(tau, str | bytes | bool) or tau is None:
        raise ParameterError(
            f"tau must be a time constant in s or {size} of them (got {shown(tau)})"
        )
    if isinstance(tau, int | float | np.integer | np.floating) or np.ndim(tau) == 0:
        values = [tau] * size
    else:
        values = list(tau)
    if len(values) != size:
        raise ParameterError(f"tau must be one value or {size} values in s (got {len(values)})")
    for value in values:
        if isinstance(value, str | bytes | bool) or value is None:
            raise ParameterError(f"tau must be numbers in s (got {shown(value)})")
    try:
        values = [float(value) for value in values]
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"tau must be numbers in s (got {shown(values, 60)})") from None
    gains = []
    for value in values:
        if math.isnan(value) or value < MIN_TAU:
            raise ParameterError(
                f"tau must be > 0 s (at least {MIN_TAU:g} s), or inf to disable a channel "
                f"(got {value:g})"
            )
        gains.append(0.0 if math.isinf(value) else 1.0 / value)
    return tuple(gains)
