"""Validation of the arguments of ``Controller.command`` shared by every method, and of
the closed-form methods' result.

A NaN or an infinity in the configuration, the desired pose, the desired velocity or the
time would otherwise come out of the closed-form methods as a NaN/inf command without a
word (and the QP would count a fallback). :func:`check_inputs` turns it into a one-line
:class:`~ddwmmr.errors.ParameterError` (a ``ValueError``) that names the argument. Finite
values too large for the arithmetic (``q = [1.7e308, ...]`` gave ``clrrmc-ts`` the command
``[-inf, inf, 0, -inf]``) are the same error from :func:`check_command`, which the
closed-form methods apply to their result; ``qp`` and ``mpc`` keep every limit and return
a finite command at any finite state (tests/test_qp_limits_extreme.py).

It runs every control step, so the common case (everything finite) is one sum over the
values: a sum is finite only if every term is finite. Only when it is not (or when the
arguments are not flat numeric sequences, or hold an integer beyond a float such as
``10**400``) does the slow path look at each argument, which also clears sums that merely
overflowed. It returns the time as a float and the arguments as lists of floats, which the
closed-form controllers work with anyway (one conversion instead of two): a ``float32``
time or array computes in double precision as a float would, not in single precision.

:func:`check_start` is the same check for the start configuration ``q0`` of
``Controller.reset``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ddwmmr.errors import ParameterError, float_values, shown
from ddwmmr.model.kinematics import check_configuration

#: (argument, expected length, what its entries are) of ``command(t, q, pose_d, velocity_d)``.
_ARGUMENTS = (
    ("q", 5, "[x, y, phi, th1, th2] (m, rad)"),
    ("pose_d", 3, "[xE, yE, phiE] (m, rad)"),
    ("velocity_d", 3, "[xEdot, yEdot, phiEdot] (m/s, rad/s)"),
)


Lists = tuple[float, list[float], list[float], list[float]]
_isfinite = math.isfinite
#: Types float() converts that are no time: text ("0" would reach the methods as a string,
#: which some compare with floats) and booleans (a flag, not 1 s).
_NOT_TIMES = (str, bytes, bool, np.bool_)


def check_inputs(t: float, q: Any, pose_d: Any, velocity_d: Any) -> Lists:
    """Raise :class:`ParameterError` naming the first argument that is not finite.

    Args:
        t: time (s).
        q: configuration, 5 numbers.
        pose_d: desired end-effector pose, 3 numbers.
        velocity_d: desired end-effector velocity, 3 numbers.

    Returns:
        ``(t, q, pose_d, velocity_d)``: ``t`` as a float, the others as lists of floats
        (Python floats, double precision, whatever the numbers' numpy type).
    """
    try:
        ql, pl, vl = q.tolist(), pose_d.tolist(), velocity_d.tolist()
        values = ql + pl + vl
        # A boolean t sums as a number: refused on the slow path (a text t fails the sum).
        if (
            len(values) == 11
            and len(ql) == 5
            and len(pl) == 3
            and _isfinite(sum(values, t))
            and not isinstance(t, _NOT_TIMES)
        ):
            return (t if type(t) is float else float(t)), ql, pl, vl
    except (AttributeError, TypeError, OverflowError):  # OverflowError: an int like 10**400
        pass
    time = check_time(t)
    ql, pl, vl = (
        check_numbers(name, value, size, entries)
        for (name, size, entries), value in zip(_ARGUMENTS, (q, pose_d, velocity_d))
    )
    return time, ql, pl, vl


def check_start(q0: Any) -> list[float]:
    """``q0``, the start configuration of ``Controller.reset``, as a list of 5 floats
    ``[x, y, phi, th1, th2]`` (m, rad), or :class:`ParameterError` naming ``q0``
    (:func:`~ddwmmr.model.kinematics.check_configuration`)."""
    return check_configuration(q0)


def check_numbers(name: str, value: Any, size: int, entries: str) -> list[float]:
    """``value`` as a list of ``size`` floats if it is a flat sequence of ``size`` finite
    numbers, else :class:`ParameterError` naming ``name`` and saying what its entries are
    (``entries``, e.g. ``"[x, y, phi, th1, th2] (m, rad)"``)."""
    wanted = f"{name} must be {size} finite numbers {entries}"
    values = float_values(value, size)
    if values is None:  # text, booleans, another length or shape, an int like 10**400
        raise ParameterError(f"{wanted} (got {_what(value, size)})")
    if not all(map(math.isfinite, values)):
        raise ParameterError(f"{wanted} (got {values})")
    return values


def _what(value: Any, size: int) -> str:
    """What ``value`` is, for a message: its shape if it is an array or a list of another
    shape than ``(size,)``, else the value shown."""
    if isinstance(value, list | tuple | np.ndarray):
        try:
            shape = np.shape(value)
        except ValueError:  # ragged
            shape = None
        if shape is not None and shape != (size,):
            return f"shape {shape}"
    return shown(value, 60)


def check_time(t: Any) -> float:
    """The time ``t`` (s) as a float if it is a finite real number (an int, a float, a
    numpy scalar such as ``float32``), else :class:`ParameterError` naming ``t`` (text and
    booleans are no time, even where ``float()`` reads them)."""
    if isinstance(t, _NOT_TIMES):
        raise ParameterError(f"t must be a finite time in s (got {shown(t)})")
    try:
        time = float(t)
    except (TypeError, ValueError, OverflowError):  # OverflowError: an int like 10**400
        raise ParameterError(f"t must be a finite time in s (got {shown(t)})") from None
    if not math.isfinite(time):
        raise ParameterError(f"t must be a finite time in s (got {shown(time)})")
    return time


def check_command(u: tuple[float, ...], q: list[float], pose_d: list[float]) -> None:
    """Raise :class:`ParameterError` if a closed-form command ``u`` is not finite although
    its (validated, finite) arguments were: they are too large for the arithmetic."""
    if not _isfinite(sum(u)):
        raise ParameterError(
            f"q, pose_d: too large for the command to be finite (q = {shown(q, 80)}, "
            f"pose_d = {shown(pose_d, 60)})"
        )
