"""Feedback gains from time constants: ``K = 1/tau`` (1/s), validated."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, cast

import numpy as np

from ddwmmr.errors import (
    ParameterError,
    check_nonnegative,
    check_positive,
    round_significant,
    shown,
)

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
    # ignore: past the one-value tests tau is a sequence (mypy does not follow `one`)
    values = (
        [tau] * size
        if one or tau is None or np.ndim(tau) == 0
        else list(cast("Sequence[float]", tau))
    )
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


#: Largest gain times control step, ``K dt``, at which the sampled loop of ``e' = -K e``
#: still shrinks the error, by how the law reaches the plant over one step: ``"hold"``, a
#: command held over the step (a zero-order hold, or explicit Euler): ``e+ = (1 - K dt) e``,
#: ``|1 - x| < 1`` for ``x < 2``; ``"rk4"``, the law evaluated at the four RK4 stages:
#: ``e+ = R(-x) e`` with ``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24``, ``|R(-x)| < 1`` below the
#: real root of ``x^3 - 4 x^2 + 12 x - 24``. At the limit the error no longer decays; above
#: it, it grows every step.
STABLE_GAIN_STEP = {"hold": 2.0, "rk4": 2.785293563405282}
#: What each scheme of :data:`STABLE_GAIN_STEP` is, as the warning words it.
SCHEME_WORDS = {
    "hold": "a command held over each step (zero-order hold or Euler)",
    "rk4": "RK4 with the control law at its stages",
}
#: Share of the limit from which :func:`gain_step_warning` warns. The robot's loop is not
#: the linear one (the Jacobian turns within a step, commands saturate, the trajectory is
#: sampled as coarsely as the step) and fails well below the limit: on the default ellipse
#: under RK4 the qp tracks at ``K dt`` = 1.8 and not at 2.0 (0.72 of 2.785), clrrmc-ts not
#: from 2.3; with held commands clrrmc-ts tracks at 1.7 and not at 1.8 (0.9 of 2).
GAIN_STEP_MARGIN = 0.65


def gain_step_warning(gains: Sequence[float], dt: float, scheme: str) -> str | None:
    """The one-line warning for feedback ``gains`` (1/s, 0 for a channel off) run at the
    control step ``dt`` (s) under ``scheme`` (a key of :data:`STABLE_GAIN_STEP`), or None
    while the largest ``K dt`` stays below :data:`GAIN_STEP_MARGIN` of the scheme's limit.
    The message names tau, dt, K dt, the limit (beyond it, or the share of it reached) and
    a dt and a tau that stay below the warning's threshold."""
    gain = max(gains, default=0.0)
    limit = STABLE_GAIN_STEP[scheme]
    allowed = GAIN_STEP_MARGIN * limit
    product = gain * dt
    if not product >= allowed:
        return None
    tau = 1.0 / gain
    shortest = " (the shortest)" if len({k for k in gains if k > 0.0}) > 1 else ""
    if product >= limit:
        where = f"is beyond {limit:.4g}, the stability limit of {SCHEME_WORDS[scheme]}: the "
        what = "tracking error grows every step"
    else:
        where = (
            f"is {product / limit:.2f} of {limit:.4g}, the stability limit of "
            f"{SCHEME_WORDS[scheme]}: "
        )
        what = f"the robot's runs fail from about {GAIN_STEP_MARGIN:g} of it"
    return (
        f"tau = {tau:g} s{shortest} with dt = {dt:g} s: K dt = {product:.3g} (K = 1/tau) "
        f"{where}{what}; use dt below {round_significant(allowed / gain, 3, math.floor):g} s "
        f"or tau above {round_significant(dt / allowed, 3, math.ceil):g} s"
    )
