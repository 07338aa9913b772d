"""Feedback gains from time constants: ``K = 1/tau`` (1/s), validated."""

from __future__ import annotations

import math
from collections.abc import Sequence

from ddwmmr.errors import ParameterError


def gains_from_tau(tau: float | Sequence[float], size: int) -> tuple[float, ...]:
    """Gains ``K_i = 1/tau_i`` (1/s) from one time constant or ``size`` of them (s).

    ``tau = inf`` switches a channel's feedback off (gain 0).
    """
    values = [tau] * size if isinstance(tau, int | float) else list(tau)
    if len(values) != size:
        raise ParameterError(f"tau must be one value or {size} values in s (got {len(values)})")
    gains = []
    for value in values:
        value = float(value)
        if math.isnan(value) or value <= 0.0:
            raise ParameterError(f"tau must be > 0 s, or inf to disable a channel (got {value:g})")
        gains.append(0.0 if math.isinf(value) else 1.0 / value)
    return tuple(gains)
