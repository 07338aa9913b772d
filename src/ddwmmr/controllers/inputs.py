"""Validation of the arguments of ``Controller.command`` shared by every method.

A NaN or an infinity in the configuration, the desired pose, the desired velocity or the
time would otherwise come out of the closed-form methods as a NaN/inf command without a
word (and the QP would count a fallback); so would a finite value too large for the
arithmetic (``q = [1.7e308, ...]`` gave ``u = [-inf, inf, 0, -inf]``). :func:`check_inputs`
turns either into a one-line :class:`~ddwmmr.errors.ParameterError` (a ``ValueError``)
that names the argument: every entry of ``q``, ``pose_d`` and ``velocity_d`` must be
finite with magnitude at most :data:`MAX_INPUT_MAGNITUDE`. With it and the gains capped
(:data:`ddwmmr.gains.MAX_GAIN`) every method's command is finite.

It runs every control step, so the common case is one ``math.hypot`` over the values (as
cheap as their sum): their norm is at most the bound only if every entry is finite and
within it (a NaN makes the norm NaN, an infinity infinite). Only when the check fails (or
when the arguments are not flat numeric sequences) does the slow path look at each
argument, which also clears entries whose norm merely exceeds the bound. It returns the
arguments as lists of floats, which the closed-form controllers work with anyway (one
conversion instead of two).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ddwmmr.errors import ParameterError, shown

#: (argument, expected length, what its entries are) of ``command(t, q, pose_d, velocity_d)``.
_ARGUMENTS = (
    ("q", 5, "[x, y, phi, th1, th2] (m, rad)"),
    ("pose_d", 3, "[xE, yE, phiE] (m, rad)"),
    ("velocity_d", 3, "[xEdot, yEdot, phiEdot] (m/s, rad/s)"),
)


#: Largest magnitude of any entry of q, pose_d, velocity_d (m, rad, m/s, rad/s): a
#: thousand times the largest trajectory coordinate or heading a file may hold (1e6), far
#: from where squares and products of the entries overflow.
MAX_INPUT_MAGNITUDE = 1e9

Lists = tuple[list[float], list[float], list[float]]
_isfinite = math.isfinite
_hypot = math.hypot


def check_inputs(t: float, q: Any, pose_d: Any, velocity_d: Any) -> Lists:
    """Raise :class:`ParameterError` naming the first argument that is not finite.

    Args:
        t: time (s).
        q: configuration, 5 numbers.
        pose_d: desired end-effector pose, 3 numbers.
        velocity_d: desired end-effector velocity, 3 numbers.

    Returns:
        ``(q, pose_d, velocity_d)`` as lists of floats.
    """
    try:
        ql, pl, vl = q.tolist(), pose_d.tolist(), velocity_d.tolist()
        values = ql + pl + vl
        if (
            len(values) == 11
            and len(ql) == 5
            and len(pl) == 3
            and _isfinite(t)
            and _hypot(*values) <= MAX_INPUT_MAGNITUDE
        ):
            return ql, pl, vl
    except (AttributeError, TypeError):
        pass
    _check_each(t, q, pose_d, velocity_d)
    return (
        np.asarray(q, dtype=float).tolist(),
        np.asarray(pose_d, dtype=float).tolist(),
        np.asarray(velocity_d, dtype=float).tolist(),
    )


def _check_each(t: Any, q: Any, pose_d: Any, velocity_d: Any) -> None:
    """The slow path: check every argument on its own and name the bad one."""
    try:
        time = float(t)
    except (TypeError, ValueError):
        raise ParameterError(f"t must be a finite time in s (got {shown(t)})") from None
    if not math.isfinite(time):
        raise ParameterError(f"t must be a finite time in s (got {shown(time)})")
    for (name, size, entries), value in zip(_ARGUMENTS, (q, pose_d, velocity_d)):
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"{name} must be {size} finite numbers {entries}") from None
        if array.shape != (size,):
            raise ParameterError(
                f"{name} must be {size} finite numbers {entries} (got shape {array.shape})"
            )
        if not np.all(np.isfinite(array)):
            raise ParameterError(
                f"{name} must be {size} finite numbers {entries} (got {array.tolist()})"
            )
        if np.max(np.abs(array)) > MAX_INPUT_MAGNITUDE:
            raise ParameterError(
                f"{name} must be {size} numbers {entries} of magnitude at most "
                f"{MAX_INPUT_MAGNITUDE:g} (got {array.tolist()})"
            )
