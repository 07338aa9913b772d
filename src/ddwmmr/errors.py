"""Exceptions raised by ddwmmr, input checks and the documented caps on input sizes.

Every user-facing validation problem raises :class:`ParameterError`, whose message is a
single line naming the parameter and the allowed range; the command-line tools print it and
exit with status 2.

The caps below are the one home of every documented limit (docs/cli.md, "Limits"): they
keep absurd inputs (``--duration 1e12``, ``N = 1e30``, ``a = 1e300``) from reaching an
allocation or overflow, and are checked before anything is allocated.
"""

from __future__ import annotations

import difflib
import math
import os
import re
import stat
import sys
import tomllib
import unicodedata
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

#: Most simulation steps of one run. The recorded time series holds 31 float64 columns per
#: step (kinematic plant), so a run at the cap keeps about 250 MB of it in memory (and
#: timeseries.csv ~500 MB, written in blocks).
MAX_STEPS = 1_000_000
#: Most worker processes any tool's --jobs may ask for (compare, scenarios, bench).
MAX_JOBS = 256
#: Most samples a trajectory may have: ``N`` of a parametric trajectory (the default step
#: is T / N) and data rows of a sampled CSV trajectory.
MAX_TRAJECTORY_SAMPLES = 1_000_000
#: Most scenarios of one ``python -m ddwmmr.scenarios`` batch (the thesis runs 100).
MAX_SCENARIOS = 100_000
#: Most circular obstacles of one run (an obstacle file's ``[[obstacle]]`` tables, the
#: ``obstacles=`` option of ``qp`` and ``mpc``). Each is one more row of the qp's problem
#: (four unknowns, five rows without obstacles) and more constraints of the mpc's, checked
#: at every control step: at this count a ``qp`` step still takes less than the default
#: 20 ms control step; ten times more took seconds per step.
MAX_OBSTACLES = 1000
#: Largest input file read (robot/trajectory/obstacle TOML, trajectory CSV), bytes.
MAX_INPUT_BYTES = 64 * 1024 * 1024
#: Deepest nesting of arrays and tables in a TOML input (ddwmmr's own files use at most
#: four levels). The parser recurses per level: a deeper file is refused, not parsed into
#: a RecursionError here or in whatever walks the values later.
MAX_TOML_DEPTH = 32
#: Allowed range of every length (m): robot links, wheel radius, track width, footprint,
#: trajectory semi-axes. A micrometre to a kilometre covers any mobile manipulator.
LENGTH_RANGE_M = (1e-6, 1e3)
#: Largest |coordinate| (m) of a trajectory centre, and largest |angle| (rad) of a rotation.
MAX_COORDINATE_M = 1e6
MAX_ANGLE_RAD = 1e6
#: Allowed range of masses (kg; payload and link masses may be 0) and inertias (kg m^2).
MASS_RANGE_KG = (0.0, 1e5)
INERTIA_RANGE_KG_M2 = (1e-9, 1e6)
#: Allowed range of speed limits (rad/s) and of durations / periods (s).
SPEED_RANGE_RAD_S = (1e-6, 1e6)
#: Motor torque limits (N m).
TORQUE_RANGE_N_M = (1e-6, 1e6)
DURATION_RANGE_S = (1e-6, 1e9)
#: Largest weight of a cost term (the qp's tasks, the mpc's costs): far above every default
#: (the qp's tracking slack 1e4, the mpc's position 100), before the problem's conditioning
#: makes the solve meaningless (the mpc's LQR terminal design fails at 1e300).
MAX_COST_WEIGHT = 1e6


class ParameterError(ValueError):
    """A parameter, option or input file is invalid (message: one line, names the parameter).

    One line by construction: a control character in the message (a line break or a tab
    in a file name it quotes) is written as its escape, ``\\n`` or ``\\t``
    (:func:`escaped_controls`)."""

    def __init__(self, *args: object) -> None:
        if len(args) == 1 and isinstance(args[0], str):
            args = (message_line(args[0]),)
        super().__init__(*args)


#: Most characters of one word (a run without whitespace) a message shows
#: (:func:`clipped_words`): a file path, a name or a number a user gave, quoted whole
#: unless it is absurdly long (a 5000-digit ``--seed``).
MAX_WORD = 200


def message_line(text: str) -> str:
    """``text``, an error message, as every message is shown: on one line
    (:func:`escaped_controls`) with each word of more than :data:`MAX_WORD` characters cut
    (:func:`clipped_words`). :class:`ParameterError` and the tools' argparse errors
    (:class:`ddwmmr.cli.common.ArgumentParser`) pass their message through it."""
    return clipped_words(escaped_controls(text))


def clipped_words(text: str, width: int = MAX_WORD) -> str:
    """``text`` with each word (run without whitespace) longer than ``width`` characters
    cut in the middle to ``width``, "..." in place of the middle: the start and the end
    of a long path or number stay (``'99999...99999'``); ``text`` itself when no word is
    that long."""
    if len(text) <= width or all(len(word) <= width for word in text.split()):
        return text
    head = (width - 3) * 2 // 3
    tail = width - 3 - head

    def clip(match: re.Match[str]) -> str:
        word = match.group()
        return word if len(word) <= width else f"{word[:head]}...{word[-tail:]}"

    return re.sub(r"\S+", clip, text)


def escaped_controls(text: str, undecodable: bool = True) -> str:
    """``text`` with each character that breaks a line (:data:`LINE_BREAKING_CATEGORIES`:
    a line break, a tab, an escape, U+2028) written as Python writes it in a string's repr
    (``\\n``, ``\\t``, ``\\x1b``, ``\\u2028``), so that it prints on one line; ``text``
    itself when it has none.
    ``undecodable``: a lone surrogate (a file name's undecodable byte, which a tool's output
    streams write back as that byte) is kept; else it is escaped too (``\\udcff``: a
    window draws no such character)."""
    if text.isprintable() or printable_line(text, undecodable):
        return text
    refused = LINE_BREAKING_CATEGORIES if undecodable else UNPRINTABLE_CATEGORIES
    return "".join(repr(c)[1:-1] if unicodedata.category(c) in refused else c for c in text)


class PluginError(RuntimeError):
    """A controller from outside the library raised while the run called it (message: one
    line naming it, what it raised, the step and the time; the exception it raised is the
    ``__cause__``). The command-line tools print the line and exit with status 1."""


def check_positive(name: str, value: float) -> float:
    """Return ``value`` as float if it is finite and > 0, else raise :class:`ParameterError`."""
    value = _as_float(name, value, "> 0")
    if not value > 0.0:
        raise ParameterError(f"{name} must be > 0 (got {value:g})")
    return value


def check_nonnegative(name: str, value: float) -> float:
    """Return ``value`` as float if it is finite and >= 0, else raise :class:`ParameterError`."""
    value = _as_float(name, value, ">= 0")
    if not value >= 0.0:
        raise ParameterError(f"{name} must be >= 0 (got {value:g})")
    return value


def check_finite(name: str, value: float, allowed: str = "") -> float:
    """Return ``value`` as float if it is finite, else raise :class:`ParameterError`;
    ``allowed`` (e.g. ``"> 0"``), the range the caller checks next, completes the message."""
    return _as_float(name, value, allowed)


def check_range(name: str, value: float, low: float, high: float, unit: str = "") -> float:
    """Return ``value`` as float if ``low <= value <= high`` (finite), else raise."""
    suffix = f" {unit}" if unit else ""
    value = _as_float(name, value, f"in [{low:g}, {high:g}]{suffix}")
    if not low <= value <= high:
        got, (lo, hi) = texts_apart(value, low, high)
        raise ParameterError(f"{name} must be in [{lo}, {hi}]{suffix} (got {got})")
    return value


def texts_apart(value: float, *bounds: float) -> tuple[str, list[str]]:
    """``value`` and ``bounds`` as a refusal shows them: ``:g``, but where a bound differs
    from the value and ``:g`` spells both alike (0.1000000001 and 0.1), each number ``:g``
    rounds is spelt in full (``repr``), so the message never reads "must be <= 0.1 (got
    0.1)"."""
    got, texts = f"{value:g}", [f"{bound:g}" for bound in bounds]
    if not any(t == got and float(b) != float(value) for t, b in zip(texts, bounds)):
        return got, texts

    def exact(number: float, text: str) -> str:
        return text if float(text) == float(number) else repr(float(number))

    return exact(value, got), [exact(b, t) for b, t in zip(bounds, texts)]


def check_weight(name: str, value: float) -> float:
    """``value`` as a float if it is a cost weight in [0, :data:`MAX_COST_WEIGHT`] (the
    qp's tasks, the mpc's costs), else raise :class:`ParameterError`."""
    return check_range(name, value, 0.0, MAX_COST_WEIGHT)


def check_int_at_least(name: str, value: int, minimum: int, maximum: int | None = None) -> int:
    """Return ``value`` as int if it is an integer >= ``minimum`` (and <= ``maximum``)."""
    allowed = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
    given, value = value, unwrapped(value)
    integral = isinstance(value, int | np.integer) or (
        isinstance(value, float | np.floating)
        and math.isfinite(value)
        and float(value).is_integer()
    )
    if isinstance(value, bool | np.bool_) or not integral:
        raise ParameterError(f"{name} must be an integer {allowed} (got {shown(given)})")
    number = int(value)
    if number < minimum or (maximum is not None and number > maximum):
        # the integer it is, not its float spelling (a command line reads 1 as 1.0), unless
        # the float is spelt in e-notation, the shorter one (from 1e+16)
        got = number if abs(number) < 10**16 else value
        raise ParameterError(f"{name} must be an integer {allowed} (got {shown(got)})")
    return number


def check_bool(name: str, value: Any) -> bool:
    """Return ``value`` if it is True or False (numpy's too), else raise."""
    if not isinstance(unwrapped(value), bool | np.bool_):
        raise ParameterError(f"{name} must be true or false (got {shown(value)})")
    return bool(value)


def length_of(value: Any) -> int | None:
    """``len(value)``, or None for what has no length: a number, or a 0-d numpy array,
    which has ``__len__`` but whose ``len()`` raises."""
    try:
        return len(value)
    except TypeError:
        return None


def iterable(value: Any) -> bool:
    """Whether ``iter(value)`` works: a 0-d numpy array has ``__iter__`` but refuses."""
    try:
        iter(value)
    except TypeError:
        return False
    return True


def list_items(name: str, value: Any, wanted: str, size: int | None = None) -> tuple[Any, ...]:
    """The items of ``value``, an ordered collection (a list, a tuple, a numpy array, an
    iterator: read once), ``size`` of them if given; else a one-line
    :class:`ParameterError` "<name> must be <wanted> (got ...)". Text, a mapping, a set
    and a frozenset are refused though iterable: a text's letters, a mapping's keys and a
    set's members in the order the set iterates (waypoints visited in hash order, an
    (x, y) pair read as (y, x)) are no list."""
    refused = ParameterError(f"{name} must be {wanted} (got {shown(value, 60)})")
    if isinstance(value, str | bytes | Mapping | set | frozenset):
        raise refused
    try:
        items = tuple(value)
    except TypeError:  # not iterable, or a 0-d numpy array
        raise refused from None
    if size is not None and len(items) != size:
        raise refused
    return items


def xy_pairs(name: str, value: Any, empty: bool = False) -> tuple[tuple[float, float], ...]:
    """``value``, a list of (x, y) points in m (waypoints, a route), as a tuple of float
    pairs, each coordinate finite and within +-:data:`MAX_COORDINATE_M`; at least one
    point unless ``empty``. Anything else raises a one-line :class:`ParameterError` naming
    ``name``, the entry (numbered from 1) and the coordinate at fault, and the allowed
    range: "waypoints must be a non-empty list of (x, y) pairs in m (got [])",
    "waypoints[2] must be an (x, y) pair of numbers in m (got (1, 2, 3))", "waypoints[2] y
    must be in [-1e+06, 1e+06] m (got 2e+07)". What :func:`list_items` refuses is refused
    here too, at either level (a set of pairs, a pair given as a set)."""
    wanted = f"a {'' if empty else 'non-empty '}list of (x, y) pairs in m"
    items = list_items(name, value, wanted)
    if not items and not empty:
        raise ParameterError(f"{name} must be {wanted} (got {shown(value, 60)})")
    points = []
    for number, item in enumerate(items, start=1):
        entry = f"{name}[{number}]"
        x, y = list_items(entry, item, "an (x, y) pair of numbers in m", 2)
        points.append(
            (
                check_range(f"{entry} x", x, -MAX_COORDINATE_M, MAX_COORDINATE_M, "m"),
                check_range(f"{entry} y", y, -MAX_COORDINATE_M, MAX_COORDINATE_M, "m"),
            )
        )
    return tuple(points)


def one_of(value: Any, choices: Iterable[Any]) -> bool:
    """Whether ``value`` is one of ``choices`` (names of a choice parameter): ``value in
    choices`` for a hashable value; an unhashable one (a numpy array, a list, a dict) is
    none of them, where ``in`` would compare an array elementwise and fail on its
    ambiguous truth."""
    try:
        hash(value)
    except TypeError:
        return False
    return value in choices


def check_instance(name: str, value: Any, kind: type) -> Any:
    """Return ``value`` if it is a ``kind`` (or a subclass), else raise
    :class:`ParameterError` naming the parameter and the expected type."""
    if not isinstance(value, kind):
        raise ParameterError(f"{name} must be a {kind.__name__} (got {shown(value, 60)})")
    return value


def check_step_count(duration: float, dt: float) -> int:
    """Number of steps ``max(1, round(duration / dt))`` of a run, within :data:`MAX_STEPS`.

    ``duration`` and ``dt`` (s) must be finite and > 0 with ``dt <= duration``; each
    message names the parameter at fault. Call it before allocating the time series.
    """
    duration = check_positive("duration", duration)
    dt = check_positive("dt", dt)
    if dt > duration:
        raise ParameterError(f"dt must be <= duration ({duration:g} s) (got {dt:g})")
    ratio = duration / dt
    # duration and dt are each read from decimal text (half an ulp off each), and the
    # division adds half an ulp: 600 s / 0.0006 s gives 1000000.0000000001, and round()
    # makes exactly MAX_STEPS steps of it. A few ulps of slack admit those, no more.
    if not ratio <= MAX_STEPS * (1.0 + 4.0 * sys.float_info.epsilon):
        got = f"{ratio:.3g}"
        if not float(got) > MAX_STEPS:  # rounded onto the cap: "= 1e+06" against 1000000
            got, _ = texts_apart(ratio, MAX_STEPS)
        raise ParameterError(
            f"duration / dt must be <= {MAX_STEPS} steps per run (got {duration:g} s / "
            f"{dt:g} s = {got}); use a larger dt or a shorter duration"
        )
    return max(1, round(ratio))


def check_number_type(name: str, value: Any) -> Any:
    """Reject values read from a file, or given to override them, that are not numbers
    (strings, booleans, tables); numpy's numbers (a 0-d array too) are numbers."""
    number = unwrapped(value)
    if isinstance(number, bool | np.bool_) or not isinstance(
        number, int | float | np.integer | np.floating
    ):
        raise ParameterError(f"{name} must be a number (got {shown(value)})")
    return value


def plain_number_text(text: str) -> bool:
    """Whether ``text`` may be a number as a user types or a file holds one: ASCII without
    underscores. Python's ``float`` and ``int`` also read ``1_0`` as 10 and non-ASCII
    digits (``０.５``); a mistyped ``0_02`` taken as 2.0 would run silently. ``float``
    or ``int`` decides the rest."""
    return text.isascii() and "_" not in text


def plain_float(text: str) -> float:
    """The number ``text`` holds, read as a number a user types or a file holds
    (:func:`plain_number_text`: a mistyped ``0_02`` or a full-width digit is none);
    ValueError for a text that holds none, as ``float`` raises it, and for one whose
    number a float cannot hold (:func:`float_range_note`: ``1e999`` would read as inf,
    ``1e-400`` as 0). ``inf``, ``nan`` and a zero (``0``, ``-0.0``) are read as they are."""
    if not plain_number_text(text):
        raise ValueError(text)
    value = float(text)
    if float_range_note(text, value):
        raise ValueError(text)
    return value


#: Largest float's magnitude, as a message states it.
_FLOAT_LIMIT = f"{sys.float_info.max:.4g}"
#: The texts ``float`` reads as an infinity (after a sign), in lower case.
_INFINITY_WORDS = ("inf", "infinity")


def float_range_note(text: str, value: float | None = None) -> str:
    """Why ``float(text)`` (``value``, computed when not given) is not the number
    ``text`` holds, for a message: ", beyond the largest float, 1.798e+308" for a number
    that reads as an infinity (``1e999``, ``-1e999``, a 400-digit integer), ", too small
    for a float, which reads it as 0" for a non-zero one that reads as 0 (``1e-400``);
    "" for every other text (one ``float`` refuses too)."""
    if value is None:
        try:
            value = float(text)
        except ValueError:
            return ""
    if math.isinf(value) and text.strip().lstrip("+-").lower() not in _INFINITY_WORDS:
        return f", beyond the largest float, {_FLOAT_LIMIT}"
    mantissa = text.lower().partition("e")[0]
    if value == 0.0 and any(digit in mantissa for digit in "123456789"):
        return ", too small for a float, which reads it as 0"
    return ""


def integer_digits_note(text: str) -> str:
    """Why ``int(text)`` refuses ``text`` though it is an integer, for a message: ", N
    digits, more than the 4300 Python reads" for one beyond Python's limit on the digits of
    an integer text (``sys.get_int_max_str_digits``); "" for every other text."""
    limit = sys.get_int_max_str_digits()
    digits = text.strip().lstrip("+-")
    if limit and digits.isascii() and digits.isdigit() and len(digits) > limit:
        return f", {len(digits)} digits, more than the {limit} Python reads"
    return ""


def shown_number_text(text: str, integer: bool = False) -> str:
    """``text``, given for a number and refused, as a message quotes it: :func:`shown`,
    then why it is no number where it looks like one (:func:`float_range_note`; for an
    ``integer``, :func:`integer_digits_note`):
    ``'1e-400', too small for a float, which reads it as 0``."""
    note = integer_digits_note(text) if integer else float_range_note(text)
    return shown(text) + note


def real_number(value: Any) -> float | None:
    """``value`` as a float (finite or not), or None if it is no number: text, a boolean,
    None, or an integer beyond a float. Strings and booleans are not numbers here, even
    though float() accepts them: a file saying N = "2000" or L1 = true is a mistake worth
    reporting. A 0-d numpy array stands for the scalar it holds (:func:`unwrapped`)."""
    value = unwrapped(value)
    if isinstance(value, bool | np.bool_ | str | bytes):
        return None
    try:
        return float(value)
    except (OverflowError, TypeError, ValueError):  # OverflowError: as infinite as inf
        return None


def unwrapped(value: Any) -> Any:
    """The scalar a 0-d numpy array holds (``np.array(36)`` -> ``np.int64(36)``,
    ``np.array(True)`` -> ``np.True_``), anything else as it is: the number checks take
    ``np.array(0.2)`` as 0.2 and ``np.array(36)`` as 36, and judge what it holds (a boolean
    or text inside is no number)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        return value[()]
    return value


def _as_float(name: str, value: float, allowed: str = "") -> float:
    # Whatever is not a finite number (:func:`real_number`, nan, inf) gets the one
    # message, which ``allowed`` (e.g. "> 0", the range the caller checks next) completes
    # so that it names the range too: "dt must be a finite number > 0 (got 'abc')".
    number = real_number(value)
    if number is None or not math.isfinite(number):
        raise _not_finite(name, value, allowed)
    return number


def _not_finite(name: str, value: Any, allowed: str) -> ParameterError:
    finite = f"a finite number {allowed}" if allowed else "a finite number"
    return ParameterError(f"{name} must be {finite} (got {shown(value)})")


#: What is not a number to :func:`float_values`, though numpy would read it as one.
_NOT_NUMBERS = (str, bytes, bool, np.bool_, type(None))


def float_values(value: Any, size: int) -> list[float] | None:
    """``value`` as a list of ``size`` floats (finite or not) if it is a flat sequence of
    ``size`` numbers, else None. Text, booleans, None and integers beyond a float are not
    numbers here (numpy would read ``"1.5"`` and ``True`` as ones)."""
    if isinstance(value, str | bytes | dict):
        return None
    if isinstance(value, list | tuple) and any(isinstance(v, _NOT_NUMBERS) for v in value):
        return None
    try:
        raw = np.asarray(value)
        if raw.dtype.kind not in "iufO" or (
            raw.dtype.kind == "O" and any(isinstance(v, _NOT_NUMBERS) for v in raw.flat)
        ):
            return None
        array = raw.astype(float)
    except (TypeError, ValueError, OverflowError):  # ragged, None, an int like 10**400
        return None
    return array.tolist() if array.shape == (size,) else None


#: numpy's float64: what the library's controllers, trajectories and plants pass around
#: (the fast paths of :func:`finite_values` and of the per-step checks that compare a
#: dtype with it by identity).
FLOAT64 = np.dtype(float)


def finite_values(value: Any, size: int) -> np.ndarray | None:
    """``value`` as a float array of shape ``(size,)`` if it is a flat sequence of ``size``
    finite numbers (a list, a tuple, a numpy array of any number type), else None. Text,
    booleans, None and complex numbers are not numbers here (:func:`float_values`). A
    float64 array is returned as it is (not copied), so a run fed arrays gives the numbers
    it gave before the check."""
    if type(value) is np.ndarray and value.dtype is FLOAT64 and value.shape == (size,):
        array = value  # the common case, no conversion
    else:
        values = float_values(value, size)
        if values is None:
            return None
        array = np.array(values)
    # a sum is finite only if every term is; a sum that overflowed looks again
    if math.isfinite(sum(array.tolist())) or bool(np.all(np.isfinite(array))):
        return array
    return None


def name_of(obj: Any) -> str:
    """What a message calls a plug-in (a controller, a plant): its ``name`` if that is a
    str, else its class's name."""
    name = getattr(obj, "name", None)
    return name if isinstance(name, str) else type(obj).__name__


def shown(value: Any, width: int = 40) -> str:
    """``value`` for a message: its repr on one line, cut to ``width`` characters; an
    integer beyond about 1e60 as its magnitude (its repr is thousands of digits, or fails
    beyond Python's 4300-digit limit)."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value).bit_length() > 200:
        return f"an integer of about 1e{int(abs(value).bit_length() * 0.30103)}"
    try:
        text = repr(value)
    except ValueError:  # e.g. a container holding such an integer
        return f"a {type(value).__name__}"
    return one_line(text, width)


def bracketed(items: Iterable[Any], spec: str = "g") -> str:
    """``items`` for a message as a bracketed list: numbers in format ``spec``, texts as
    they are (``[90, 45]``, ``[[-1, 1], [0, 2]]`` from already bracketed texts)."""
    return "[" + ", ".join(i if isinstance(i, str) else format(i, spec) for i in items) + "]"


def round_significant(value: float, digits: int, rounding: Callable[[float], int]) -> float:
    """``value`` (> 0) to ``digits`` significant digits, rounded by ``rounding``
    (``math.floor`` or ``math.ceil``): a value a message suggests, on the safe side of
    the bound it was computed from."""
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(value)))
    return rounding(value * scale) / scale


#: Unicode categories that break a line: control characters (a newline splits a report's
#: line) and the line and paragraph separators U+2028 and U+2029 (``str.splitlines`` cuts
#: at them).
LINE_BREAKING_CATEGORIES = ("Cc", "Zl", "Zp")
#: Unicode categories a text printed on one line may not hold: those that break a line and
#: lone surrogates (an undecodable byte of a file name: it cannot be encoded, so a
#: figure's title fails to draw).
UNPRINTABLE_CATEGORIES = (*LINE_BREAKING_CATEGORIES, "Cs")


def printable_line(text: str, undecodable: bool = False) -> bool:
    """Whether ``text`` prints as one line: no character of :data:`UNPRINTABLE_CATEGORIES`
    (``undecodable``: lone surrogates allowed, as a file name's undecodable bytes, which
    a tool's output streams write back as the bytes they were)."""
    refused = LINE_BREAKING_CATEGORIES if undecodable else UNPRINTABLE_CATEGORIES
    return not any(unicodedata.category(c) in refused for c in text)


def one_line(text: str, width: int) -> str:
    """``text`` on one line (each run of whitespace one space), cut to ``width``
    characters with "..." at the end."""
    text = " ".join(text.split())
    return text if len(text) <= width else text[: width - 3] + "..."


def plugin_raised(call: str, error: Exception, where: str = "", quoted: bool = False) -> Exception:
    """What a run raises when a plug-in's ``call`` (``"arbiter: mine.select()"``) raised
    ``error``: a :class:`ParameterError` or :class:`PluginError` as it is (one line
    already), anything else a one-line :class:`PluginError` "<call> raised <type>:
    <message><where>", the message on one line and cut to 120 characters (``quoted``: as
    its repr). :func:`raise_plugin_error` raises it."""
    if isinstance(error, ParameterError | PluginError):
        return error
    if quoted:
        text = shown(" ".join(str(error).split()) or "(no message)", 120)
    else:
        text = one_line(str(error), 120) or "(no message)"
    return PluginError(f"{call} raised {type(error).__name__}: {text}{where}")


def raise_plugin_error(
    call: str, error: Exception, where: str = "", quoted: bool = False
) -> NoReturn:
    """Raise :func:`plugin_raised`'s error (called from the ``except`` block that caught
    ``error``), ``from error`` where it wraps it."""
    raise_as(plugin_raised(call, error, where, quoted), error)


def raise_as(wrapped: Exception, error: Exception) -> NoReturn:
    """Raise ``wrapped``, the one-line error standing for ``error``: ``error`` itself as it
    is, another ``from error``."""
    if wrapped is error:
        raise error
    raise wrapped from error


def as_path(path: Any, label: str) -> Path:
    """``path`` as a :class:`~pathlib.Path` if it is a ``str`` or an ``os.PathLike``
    (what ``Path`` takes), else a one-line :class:`ParameterError` naming ``label``: an
    input file given as a number, None or bytes is bad input, not a ``TypeError``."""
    if isinstance(path, str | os.PathLike):
        try:
            return Path(path)
        except TypeError:  # an os.PathLike whose __fspath__ gives bytes
            pass
    raise ParameterError(f"{label}: a file path (str or os.PathLike) is needed (got {shown(path)})")


#: What each file type but a regular file is called in a message.
_KINDS = {
    stat.S_IFDIR: "a folder",
    stat.S_IFLNK: "a symbolic link",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFIFO: "a FIFO",
    stat.S_IFSOCK: "a socket",
}


def file_kind(mode: int) -> str | None:
    """What a file whose ``st_mode`` is ``mode`` is called in a message ("a folder",
    "a character device", "a FIFO", ...), or None for a regular file. A type this list
    does not name (e.g. a Solaris door) is "a special file". ``mode`` from ``os.lstat``
    can name a symbolic link; from ``os.stat`` it is what the link points to."""
    if stat.S_ISREG(mode):
        return None
    return _KINDS.get(stat.S_IFMT(mode), "a special file")


def read_text_file(path: str | Path, label: str) -> str:
    """The UTF-8 text of a regular file (:func:`read_input_bytes`); anything else raises
    :class:`ParameterError`. ``label`` names the option in the message. A UTF-8
    byte-order mark at the start is not part of the text."""
    data = read_input_bytes(path, label)
    try:
        return data.decode("utf-8-sig")  # a leading byte-order mark (some editors') dropped
    except UnicodeDecodeError as exc:
        raise ParameterError(
            f"{label}: {path} is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
            f"{exc.start})"
        ) from None


def read_input_bytes(path: str | Path, label: str) -> bytes:
    """The bytes of an input file, a regular file of at most :data:`MAX_INPUT_BYTES`;
    anything else raises :class:`ParameterError` naming ``label``, the option.

    The file is checked with ``os.stat`` before it is opened, so a FIFO, a device or a
    folder is refused instead of blocking or failing; files above :data:`MAX_INPUT_BYTES`
    are refused too, by their size or, where that says 0 (a kernel's file under /proc),
    by what reading them gives (:func:`read_at_most`, which never blocks: /proc/kmsg read
    as root waited for the kernel's next message). ``path`` must be a ``str`` or an
    ``os.PathLike`` (:func:`as_path`).
    """
    path = as_path(path, label)
    try:
        info = os.stat(path)
    except OSError as exc:
        raise ParameterError(f"{label}: cannot read {path} ({exc.strerror})") from None
    except ValueError:  # e.g. an embedded NUL byte
        raise ParameterError(f"{label}: invalid file name {shown(str(path))}") from None
    kind = file_kind(info.st_mode)
    if kind is not None:
        raise ParameterError(f"{label}: {path} is not a regular file ({kind})")
    if info.st_size > MAX_INPUT_BYTES:
        raise ParameterError(
            f"{label}: {path} is too large ({info.st_size} bytes, at most {MAX_INPUT_BYTES})"
        )
    try:
        data = read_at_most(path, MAX_INPUT_BYTES + 1)
    except OSError as exc:
        raise ParameterError(f"{label}: cannot read {path} ({exc.strerror})") from None
    if len(data) > MAX_INPUT_BYTES:
        raise ParameterError(
            f"{label}: {path} is too large (more than {MAX_INPUT_BYTES} bytes read, at most "
            f"{MAX_INPUT_BYTES})"
        )
    return data


def read_at_most(path: Path, limit: int) -> bytes:
    """The first ``limit`` bytes of the file ``path`` (all of a shorter one), read without
    blocking: opened with ``O_NONBLOCK`` (where the platform has it), which a regular
    file ignores and which turns a read that would wait (/proc/kmsg, a FIFO put in the
    file's place after it was checked) into an :class:`OSError` or an end of file."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    fd = os.open(path, flags)
    try:
        chunks: list[bytes] = []
        left = limit
        while left > 0:
            chunk = os.read(fd, min(left, 1 << 20))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


#: A carriage return not followed by a line feed.
_LONE_CR = re.compile(r"\r(?!\n)")


def load_toml(
    path: str | Path, label: str, precheck: Callable[[str], None] | None = None
) -> dict[str, Any]:
    """Parse a TOML file; unreadable, invalid or too deeply nested files (more than
    :data:`MAX_TOML_DEPTH` levels of arrays and tables) raise :class:`ParameterError`.
    Its lines may end in LF, CRLF or CR alone.

    The one place every TOML input is read (robot, trajectory, obstacles, from every tool
    and the API). ``label`` names the option in the message (``robot``, ``traj``,
    ``obstacles``). ``precheck``, if given, is called with the text before it is parsed
    (the parser takes seconds per megabyte): it may refuse what a glance at the text
    shows, e.g. far more tables than allowed.
    """
    text = read_text_file(path, label)  # refuses a path of the wrong type (as_path)
    # Lines ended by CR alone (classic Mac OS editors) read as LF: TOML allows no lone CR
    # anywhere, so this changes no valid file, and the CSV inputs take them too.
    text = _LONE_CR.sub("\n", text)
    if precheck is not None:
        precheck(text)
    path = Path(path)
    too_deep = ParameterError(
        f"{label}: {path} nests arrays or tables more than {MAX_TOML_DEPTH} levels deep"
    )
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        message = str(exc).splitlines()[0]
        raise ParameterError(f"{label}: {path} is not valid TOML ({message})") from None
    except RecursionError:
        raise too_deep from None
    if nesting_depth(data) > MAX_TOML_DEPTH:
        raise too_deep
    return data


def nesting_depth(value: Any) -> int:
    """Levels of lists and dicts in ``value`` (0 for a scalar), counted without recursion."""
    deepest = 0
    pending = [(value, 0)]
    while pending:
        item, depth = pending.pop()
        if isinstance(item, dict):
            item = list(item.values())
        if isinstance(item, list):
            deepest = max(deepest, depth + 1)
            pending.extend((child, depth + 1) for child in item)
    return deepest


def did_you_mean(word: str, known: Iterable[str], prefix: str = "") -> str:
    """`` (did you mean PREFIXNAME?)`` for the name in ``known`` closest to ``word``, or
    ``""`` when none is close: the one wording of the suggestion every tool makes for a
    mistyped name. A name that differs from ``word`` in case alone is the closest (``l1``:
    ``L1``, which difflib's similarity ratio, 0.5, finds too far), else the closest by
    that ratio, if >= 0.6."""
    names = list(known)
    same = [name for name in names if name.casefold() == word.casefold()]
    close = same[:1] or difflib.get_close_matches(word, names, n=1)
    return f" (did you mean {prefix}{close[0]}?)" if close else ""
