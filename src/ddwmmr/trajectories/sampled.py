"""Trajectories defined by samples, interpolated smoothly (C1 cubic Hermite).

CSV format (header required): ``t,x,y`` and optionally ``phi``; times in s strictly
increasing (spanning a duration of 1e-6 s to 1e9 s, each step at least
:data:`MIN_STEP_FRACTION` of that duration), positions in m, angles in rad. A ``phi``
column may wrap at +-pi (as ``atan2`` writes it): a column within [-pi, pi] (give or take
:data:`ATAN2_ROUNDING_RAD`) is unwrapped before interpolation (:func:`unwrap_phi`). A
``phi`` column that turns far more than the path does draws a warning: degrees read as
radians (:func:`heading_units_warning`); so do a CSV file's positions spanning more than
a robot's plausible length: millimetres read as metres (:func:`length_units_warning`).
Without ``phi`` the orientation is the direction of travel (unwrapped). If the first and last
points coincide the path is treated as closed and the tangents at the ends are matched
(periodic). Outside the samples' time range the trajectory holds still: the pose stays at
the first (before) or last (after) sample and the velocity is zero.
"""

from __future__ import annotations

import bisect
import csv
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ddwmmr.errors import (
    DURATION_RANGE_S,
    MAX_ANGLE_RAD,
    MAX_COORDINATE_M,
    MAX_TRAJECTORY_SAMPLES,
    ParameterError,
    as_path,
    plain_float,
    plain_number_text,
    read_text_file,
    shown,
)
from ddwmmr.model.robot import PLAUSIBLE_LENGTH_M
from ddwmmr.trajectories.base import (
    atan2_array,
    check_name,
    check_time,
    check_times,
    file_name,
)
from ddwmmr.user_warnings import warn_user

MAX_TIME_S = DURATION_RANGE_S[1]
#: Smallest step between two sample times, as a share of the duration (last minus first
#: time). Relative, so stretching a trajectory in time (the GUI's T) keeps it valid; it
#: bounds the interpolant's speed by 1e9 x (distance / duration) instead of letting
#: ``times = [0, 1e-300, 1]`` ask for 1e300 m/s. Also how far (the same share) past
#: either end the velocity keeps the end's speed before the trajectory holds still.
MIN_STEP_FRACTION = 1e-9
#: How far beyond +-pi (rad) an angle may lie and still count as ``atan2`` output for
#: :func:`unwrap_phi`: a log that rounds atan2's pi writes 3.141593 (6 decimals, pi +
#: 3.5e-7) or 3.142 (3 decimals, pi + 4.1e-4); a heading meant to be continuous that
#: stays this close to +-pi and still steps by more than pi between rows is no
#: plausible path.
ATAN2_ROUNDING_RAD = 1e-3
#: :func:`heading_units_warning` warns when the ``phi`` column's total turn (rad) exceeds
#: this many times the path's own turn plus :data:`DEGREES_SLACK_RAD`: a heading in
#: degrees turns 57.3 times the radians it means, one that follows or ignores the
#: direction of travel turns about as much as the path or not at all.
DEGREES_FACTOR = 10.0
#: Turning (rad) a ``phi`` column may do beyond :data:`DEGREES_FACTOR` times the path's
#: turn without a warning: two whole turns of the end effector on its own (a spin).
DEGREES_SLACK_RAD = 4.0 * math.pi
#: Longest default control step (s) of a sampled trajectory: that of the shipped ellipse
#: and rectangle (40 s / 2000 samples).
MAX_DEFAULT_STEP_S = 0.02
#: What ``points`` takes: rows of numbers (lists, tuples, arrays) or a 2-D array. Spelled
#: out because mypy types the docs' ``[[0, 0], [1, 0.2]]`` as ``list[object]`` against
#: ``numpy.typing.ArrayLike`` alone (its many alternatives hide the rows' element type).
SampleRows = Sequence[Sequence[float]] | Sequence[npt.ArrayLike] | npt.NDArray[Any]


def _tangents(times: np.ndarray, values: np.ndarray, periodic: bool) -> np.ndarray:
    """Catmull-Rom style slopes (finite differences) at each knot, per column."""
    slopes = np.empty_like(values)
    dt = np.diff(times)
    secant = np.diff(values, axis=0) / dt[:, None]
    slopes[1:-1] = (secant[:-1] * dt[1:, None] + secant[1:] * dt[:-1, None]) / (
        dt[:-1, None] + dt[1:, None]
    )
    if periodic:
        end = (secant[0] * dt[-1] + secant[-1] * dt[0]) / (dt[0] + dt[-1])
        slopes[0] = slopes[-1] = end
    else:
        slopes[0], slopes[-1] = secant[0], secant[-1]
    return slopes


@dataclass(frozen=True)
class SampledTrajectory:
    """End-effector trajectory through sampled points, C1 cubic Hermite interpolation.

    Args:
        times: n >= 3 sample times (s), strictly increasing, starting anywhere, |t| <= 1e9;
            the duration ``times[-1] - times[0]`` is in [1e-6, 1e9] s and every step is at
            least :data:`MIN_STEP_FRACTION` times it.
        points: (n, 2) positions (m) or (n, 3) poses with orientation phi (rad), world
            frame, each value finite with magnitude <= 1e6. phi may wrap at +-pi: a
            column with every angle in [-pi, pi] and a step between consecutive rows
            larger than pi is unwrapped (:func:`unwrap_phi`: such a step taken the short
            way round, the first row kept), and :attr:`points`, :meth:`pose` and
            :meth:`velocity` give the unwrapped, continuous orientation (magnitude <= 1e6
            rad after unwrapping too). Any other phi column is kept as given, bit for bit.
            "Within [-pi, pi]" allows :data:`ATAN2_ROUNDING_RAD` of rounding (3.141593).
            A phi column turning far more than the path (:func:`heading_units_warning`:
            degrees, most likely) draws a ``UserWarning``.
        name: label used in reports.

    Times ``t`` of :meth:`pose`, :meth:`velocity` and :meth:`sample` count from the first
    sample (``t = 0`` at ``times[0]``). Outside ``[0, duration]`` the trajectory holds
    still, so that the velocity stays the time derivative of the pose: the pose is that
    of the first sample before it and of the last after it (the orientation, without a
    phi column, the direction of travel there) and the velocity is zero. At ``t = 0`` and
    ``t = duration``, and within :data:`MIN_STEP_FRACTION` x ``duration`` outside them
    (the rounding of a time grid ending there), the velocity is the end's speed.

    Anything else raises :class:`~ddwmmr.errors.ParameterError` naming ``times``,
    ``points`` or ``name``.
    """

    times: np.ndarray
    points: np.ndarray
    name: str = "sampled"
    _slopes: np.ndarray = field(init=False, repr=False, compare=False)
    _knots: list[float] = field(init=False, repr=False, compare=False)
    _has_phi: bool = field(init=False, repr=False, compare=False)
    _moving: tuple[float, float] = field(init=False, repr=False, compare=False)

    def __init__(self, times: npt.ArrayLike, points: SampleRows, name: str = "sampled") -> None:
        # Written out (the dataclass keeps it) so that type checkers take any array-like
        # (lists, as the docs write them); the fields hold the checked float arrays.
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "name", name)
        self.__post_init__()

    def __post_init__(self) -> None:
        check_name(self.name, "trajectory samples: ")
        times = _float_array("times", self.times, "sample times (s)")
        points = _float_array("points", self.points, "an (n, 2) or (n, 3) array (m, rad)")
        if times.ndim != 1 or len(times) < 3:
            raise ParameterError(
                "trajectory samples: need at least 3 rows (t, x, y): times must be a 1-D "
                f"sequence of at least 3 sample times (got shape {times.shape})"
            )
        if points.ndim != 2 or points.shape[0] != len(times) or points.shape[1] not in (2, 3):
            raise ParameterError(
                f"trajectory samples: points must be (n, 2) or (n, 3) with n = {len(times)} "
                f"rows like times (got shape {points.shape})"
            )
        if len(times) > MAX_TRAJECTORY_SAMPLES:
            raise ParameterError(
                f"trajectory samples: at most {MAX_TRAJECTORY_SAMPLES} rows (got {len(times)})"
            )
        if not np.all(np.isfinite(times)):
            raise ParameterError(
                f"trajectory samples: times must be finite numbers (s) ({_where(times, None)})"
            )
        if not np.all(np.isfinite(points)):
            raise ParameterError(
                "trajectory samples: points must be finite numbers (m, rad) "
                f"({_where(points, None)})"
            )
        if np.max(np.abs(points)) > MAX_COORDINATE_M:
            raise ParameterError(
                f"trajectory samples: points |x|, |y|, |phi| must be <= {MAX_COORDINATE_M:g} "
                f"(m, rad) ({_where(points, MAX_COORDINATE_M)})"
            )
        if np.max(np.abs(times)) > MAX_TIME_S:
            raise ParameterError(
                f"trajectory samples: times |t| must be <= {MAX_TIME_S:g} s "
                f"({_where(times, MAX_TIME_S)})"
            )
        _check_steps(times)
        points = unwrap_phi(points)
        message = heading_units_warning(points)
        if message is not None:
            warn_user(f"trajectory {self.name}: {message}")
        periodic = bool(np.allclose(points[0, :2], points[-1, :2], atol=1e-9))
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "_has_phi", points.shape[1] == 3)
        object.__setattr__(self, "_slopes", _tangents(times, points, periodic))
        object.__setattr__(self, "_knots", times.tolist())
        object.__setattr__(self, "_moving", _moving_range(self._knots[0], self._knots[-1]))

    @property
    def duration(self) -> float:
        """Time from the first to the last sample (s)."""
        return float(self.times[-1] - self.times[0])

    @property
    def samples(self) -> int:
        """Resolution N of the trajectory protocol: the number of intervals between the
        samples (rows - 1), so that ``duration / samples`` is their spacing for evenly
        spaced rows."""
        return len(self.times) - 1

    @property
    def default_step(self) -> float:
        """The default control step (s): the rows' spacing ``duration / samples``, made
        finer where it exceeds :data:`MAX_DEFAULT_STEP_S` (``duration / n`` for the
        fewest whole steps ``n`` no longer than it). The rows are data, often far apart
        (0.5 s for a path recorded at 2 Hz); the step is a control choice, the same in
        every tool and the API."""
        steps = max(self.samples, math.ceil(self.duration / MAX_DEFAULT_STEP_S - 1e-9))
        return self.duration / steps

    def _holds(self, t: float) -> bool:
        """Whether t (s, from the first sample) is outside :func:`_moving_range`, where
        the trajectory holds still."""
        low, high = self._moving
        t_abs = t + self._knots[0]
        return t_abs < low or t_abs > high

    def _segment(self, t: float) -> tuple[int, float, float]:
        t_abs = min(max(t + self._knots[0], self._knots[0]), self._knots[-1])
        i = min(bisect.bisect_right(self._knots, t_abs) - 1, len(self._knots) - 2)
        h = self._knots[i + 1] - self._knots[i]
        return i, (t_abs - self._knots[i]) / h, h

    def _hermite(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Value, first and second time derivative of the interpolant at t (from start)."""
        i, s, h = self._segment(t)
        p0, p1 = self.points[i], self.points[i + 1]
        m0, m1 = self._slopes[i] * h, self._slopes[i + 1] * h
        value, first, second = _hermite_terms(s, p0, p1, m0, m1)
        return value, first / h, second / (h * h)

    def _heading_reference(self, t: float) -> float:
        """Unwrapped direction of travel at the knots, linearly interpolated (for unwrapping)."""
        i, s, _ = self._segment(t)
        headings = self._knot_headings()
        heading: float = (1 - s) * headings[i] + s * headings[i + 1]
        return heading

    def _knot_headings(self) -> np.ndarray:
        cached: np.ndarray | None = self.__dict__.get("_headings_cache")
        if cached is None:
            cached = np.unwrap(np.arctan2(self._slopes[:, 1], self._slopes[:, 0]))
            self.__dict__["_headings_cache"] = cached
        return cached

    def pose(self, t: float) -> np.ndarray:
        """Desired ``[xE, yE, phiE]`` at time t (s, from the first sample; finite)."""
        if not (isinstance(t, float) and _isfinite(t)):
            check_time(t)
        value, first, _ = self._hermite(t)
        if self._has_phi:
            return value.copy()
        heading = math.atan2(first[1], first[0])
        reference = self._heading_reference(t)
        heading += 2 * math.pi * round((reference - heading) / (2 * math.pi))
        return np.array([value[0], value[1], heading])

    def velocity(self, t: float) -> np.ndarray:
        """Desired ``[xEdot, yEdot, phiEdot]`` at time t (s, from the first sample; finite):
        zero outside ``[0, duration]`` (beyond :func:`_moving_range`), where the pose
        holds still."""
        if not (isinstance(t, float) and _isfinite(t)):
            check_time(t)
        if self._holds(t):
            return np.zeros(3)
        _, first, second = self._hermite(t)
        if self._has_phi:
            return first.copy()
        speed2 = first[0] ** 2 + first[1] ** 2
        rate = 0.0 if speed2 < 1e-12 else (first[0] * second[1] - first[1] * second[0]) / speed2
        return np.array([first[0], first[1], rate])

    def sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Poses and velocities at many times at once: ``(poses, velocities)``, both
        ``(len(times), 3)``, the numbers :meth:`pose` and :meth:`velocity` give, to the
        last bit (the same operations on whole columns; ``atan2`` through ``math``).
        ``times`` (s, from the first sample): one number or a 1-D sequence, each finite,
        else :class:`~ddwmmr.errors.ParameterError` naming ``times``
        (:func:`~ddwmmr.trajectories.base.check_times`)."""
        knots = self.times
        t_query = check_times(times) + knots[0]
        low, high = self._moving
        held = ((t_query < low) | (t_query > high))[:, None]
        t_abs = np.minimum(np.maximum(t_query, knots[0]), knots[-1])
        i = np.minimum(np.searchsorted(knots, t_abs, side="right") - 1, len(knots) - 2)
        h = knots[i + 1] - knots[i]
        s = (t_abs - knots[i]) / h
        p0, p1 = self.points[i], self.points[i + 1]
        m0, m1 = self._slopes[i] * h[:, None], self._slopes[i + 1] * h[:, None]
        value, first, second = _hermite_terms(s[:, None], p0, p1, m0, m1)
        first = first / h[:, None]
        second = second / (h * h)[:, None]
        if self._has_phi:
            return value, np.where(held, 0.0, first)
        heading = atan2_array(first[:, 1], first[:, 0])
        headings = self._knot_headings()
        reference = (1 - s) * headings[i] + s * headings[i + 1]
        heading = heading + 2 * math.pi * np.round((reference - heading) / (2 * math.pi))
        speed2 = _squares(first[:, 0]) + _squares(first[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            turn = (first[:, 0] * second[:, 1] - first[:, 1] * second[:, 0]) / speed2
        rate = np.where(speed2 < 1e-12, 0.0, turn)
        poses = np.column_stack([value[:, 0], value[:, 1], heading])
        return poses, np.where(held, 0.0, np.column_stack([first[:, 0], first[:, 1], rate]))


_isfinite = math.isfinite


def _moving_range(first: float, last: float) -> tuple[float, float]:
    """Absolute times (s) between which the velocity is the interpolant's: the first
    and last sample times widened by :data:`MIN_STEP_FRACTION` of the duration, the
    finest time the samples resolve. A time grid that ends at the last sample
    (``k dt`` and the RK4 stage ``k dt + dt``) may overshoot it by a rounding error;
    there the end's speed still applies, as the step integrated towards it needs."""
    slack = MIN_STEP_FRACTION * (last - first)
    return first - slack, last + slack


def _float_array(name: str, value: object, what: str) -> np.ndarray:
    """``value`` as a float array (no copy when it already is one); strings, booleans,
    ragged rows and numbers beyond float range raise :class:`ParameterError` naming it."""
    wanted = f"trajectory samples: {name} must be {what}, numbers only"
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError, OverflowError):  # ragged rows, odd objects
        raise ParameterError(f"{wanted} (got ragged or non-numeric rows)") from None
    kind = raw.dtype.kind
    if kind == "O":
        entries = raw.ravel().tolist()
        if not all(_is_number(v) for v in entries):
            raise ParameterError(f"{wanted} (got ragged or non-numeric rows)")
        try:
            return raw.astype(float)
        except OverflowError:
            raise ParameterError(f"{wanted} (got a value beyond float range)") from None
    if kind not in "iuf":
        got = {"U": "strings", "S": "bytes", "b": "booleans", "c": "complex numbers"}
        raise ParameterError(f"{wanted} (got {got.get(kind, raw.dtype.name)})")
    if not isinstance(value, np.ndarray) and _holds_booleans(value):
        raise ParameterError(f"{wanted} (got booleans)")
    return np.asarray(raw, dtype=float)


def _holds_booleans(value: Any) -> bool:
    """Whether a (regular, numeric) nested sequence holds a boolean: numpy turns ``True``
    beside numbers into 1 silently, as no other number check of the package does."""
    entries = np.asarray(value, dtype=object).ravel().tolist()
    return any(isinstance(v, bool | np.bool_) for v in entries)


def _is_number(value: object) -> bool:
    return isinstance(value, int | float | np.integer | np.floating) and not isinstance(
        value, bool | np.bool_
    )


def _where(values: np.ndarray, cap: float | None) -> str:
    """Where the first bad sample is, for a message: ``got nan in row 12, column x``
    (rows numbered from 1, the data rows of a CSV file), the first value that is not
    finite (``cap`` None) or whose magnitude exceeds ``cap``."""
    bad = ~np.isfinite(values) if cap is None else np.abs(values) > cap
    index = np.unravel_index(int(np.argmax(bad)), values.shape)
    where = f"row {int(index[0]) + 1}"
    if values.ndim == 2:
        where += f", column {('x', 'y', 'phi')[int(index[1])]}"
    return f"got {float(values[index]):g} in {where}"


def _check_steps(times: np.ndarray) -> None:
    """Strictly increasing times spanning a documented duration, no step below
    :data:`MIN_STEP_FRACTION` of it (the CSV's data row numbers in the message)."""
    steps = np.diff(times)
    if np.any(steps <= 0):
        row = int(np.argmax(steps <= 0)) + 2
        raise ParameterError(
            f"trajectory samples: times (column t) must be strictly increasing (row {row}: "
            f"{shown(float(times[row - 2]))} then {shown(float(times[row - 1]))})"
        )
    duration = float(times[-1] - times[0])
    low, high = DURATION_RANGE_S
    if not low <= duration <= high:
        raise ParameterError(
            f"trajectory samples: times must span a duration in [{low:g}, {high:g}] s "
            f"(last minus first; got {duration:g} s)"
        )
    shortest = MIN_STEP_FRACTION * duration
    if np.min(steps) < shortest:
        row = int(np.argmin(steps)) + 2
        raise ParameterError(
            f"trajectory samples: times must step by at least {MIN_STEP_FRACTION:g} x the "
            f"duration = {shortest:g} s (row {row}: step {steps[row - 2]:g} s)"
        )


def unwrap_phi(points: np.ndarray) -> np.ndarray:
    """``points`` with its orientation column (the third, rad) unwrapped as
    :func:`numpy.unwrap` does: each step between consecutive rows larger than pi in
    magnitude is taken the short way round (whole turns added to that row and the
    following ones), the first row kept. Interpolating the jump of a column wrapped at
    +-pi (rows 3.1 then -3.1) would otherwise turn the end effector the long way, a
    whole turn in one interval. Only a column that looks wrapped is unwrapped, every
    angle in [-pi, pi] give or take :data:`ATAN2_ROUNDING_RAD` (a log's rounded pi,
    3.141593, is atan2 output too): a column beyond that is continuous already (it may step by more
    than pi between coarse rows on purpose), and one unwrapped here and read back is not
    unwrapped again. Any other ``points`` (or without a third column) is returned as it
    is, keeping its exact bits (adding zero turns would still turn a -0.0 into 0.0). The
    unwrapped angles must stay within the documented 1e6 rad, else
    :class:`~ddwmmr.errors.ParameterError` naming ``points``."""
    if points.shape[1] != 3:
        return points
    phi = points[:, 2]
    if not (
        np.all(np.abs(phi) <= math.pi + ATAN2_ROUNDING_RAD)
        and np.any(np.abs(np.diff(phi)) > math.pi)
    ):
        return points
    unwrapped = points.copy()
    unwrapped[:, 2] = np.unwrap(phi)
    largest = float(np.max(np.abs(unwrapped[:, 2])))
    if largest > MAX_ANGLE_RAD:
        raise ParameterError(
            f"trajectory samples: points phi, unwrapped (each step between rows taken the "
            f"short way round), must stay within |phi| <= {MAX_ANGLE_RAD:g} rad "
            f"(got {largest:g})"
        )
    return unwrapped


def length_units_warning(points: np.ndarray) -> str | None:
    """One line saying the positions (x, y; m) of ``points`` span more than
    :data:`~ddwmmr.model.robot.PLAUSIBLE_LENGTH_M` in x or y, the length above which a
    robot file's lengths are taken for millimetres, else None. A path logged in
    millimetres spans a thousand times the metres it means (a 2 m ellipse spans 2000);
    where the path lies (an offset) does not count, only its extent. Checked for a CSV
    file (:func:`read_csv`), not for samples given in code, which a caller may have
    scaled on purpose (the simulator's placement, ``--traj-scale``)."""
    spans = np.ptp(points[:, :2], axis=0)
    long = [
        f"{axis} spans {span:g} m"
        for axis, span in zip("xy", spans.tolist())
        if span > PLAUSIBLE_LENGTH_M
    ]
    if not long:
        return None
    return (
        f"{' and '.join(long)}, above {PLAUSIBLE_LENGTH_M:g} m: positions are read in metres "
        "(given in millimetres? divide them by 1000); taken as given"
    )


def heading_units_warning(points: np.ndarray) -> str | None:
    """One line saying the ``phi`` column (rad, already unwrapped by :func:`unwrap_phi`)
    of ``points`` turns far more than its path plausibly does, else None (no ``phi``, or
    a plausible one). Its total turn, the sum of the magnitudes of its steps between rows,
    is compared with the path's: the sum of the turns (each wrapped to [-pi, pi]) between
    the directions of consecutive non-zero moves of (x, y). More than
    :data:`DEGREES_FACTOR` times the path's plus :data:`DEGREES_SLACK_RAD` is taken for a
    column in degrees (a quarter circle logged 0..90 turns 90 "rad" for the path's 1.57)."""
    if points.shape[1] != 3:
        return None
    heading = float(np.sum(np.abs(np.diff(points[:, 2]))))
    moves = np.diff(points[:, :2], axis=0)
    moves = moves[np.any(moves != 0.0, axis=1)]
    directions = np.arctan2(moves[:, 1], moves[:, 0])
    turns = np.mod(np.diff(directions) + math.pi, 2.0 * math.pi) - math.pi
    path = float(np.sum(np.abs(turns)))
    if heading <= DEGREES_FACTOR * path + DEGREES_SLACK_RAD:
        return None
    return (
        f"column phi turns {heading:.3g} rad in total while the path's direction of travel "
        f"turns {path:.3g} rad; phi is read in radians: if it holds degrees, convert it "
        "(math.radians)"
    )


def _hermite_terms(
    s: float | np.ndarray, p0: np.ndarray, p1: np.ndarray, m0: np.ndarray, m1: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cubic Hermite value and first and second derivatives with respect to s (in 0..1)
    between points p0, p1 with tangents m0, m1 (already times the segment length): one
    segment (``s`` a float, points of shape (d,)) or many (``s`` of shape (n, 1), points
    (n, d)), by the same operations in the same order."""
    s2, s3 = s * s, s * s * s
    value = (
        (2 * s3 - 3 * s2 + 1) * p0
        + (s3 - 2 * s2 + s) * m0
        + (-2 * s3 + 3 * s2) * p1
        + (s3 - s2) * m1
    )
    first = ((6 * s2 - 6 * s) * p0 + (3 * s2 - 4 * s + 1) * m0) + (
        (-6 * s2 + 6 * s) * p1 + (3 * s2 - 2 * s) * m1
    )
    second = (12 * s - 6) * p0 + (6 * s - 4) * m0 + (-12 * s + 6) * p1 + (6 * s - 2) * m1
    return value, first, second


def _squares(values: np.ndarray) -> np.ndarray:
    """``v ** 2`` of each value as a Python float computes it (the C library's ``pow``, as
    :meth:`SampledTrajectory.velocity` squares a scalar), not numpy's ``x * x`` on arrays,
    which differs in the last bit for about one value in a thousand."""
    return np.array([value**2 for value in values.tolist()])


def csv_text(trajectory: SampledTrajectory) -> str:
    """The CSV :func:`read_csv` reads back to the same samples, bit for bit: columns
    t, x, y[, phi], every number with the 17 significant digits of ``repr``."""
    keys = ["t", "x", "y", "phi"][: 1 + trajectory.points.shape[1]]
    rows = [",".join(keys)]
    for t, point in zip(trajectory.times.tolist(), trajectory.points.tolist()):
        rows.append(",".join(repr(value) for value in (t, *point)))
    return "\n".join(rows) + "\n"


#: The columns a trajectory CSV may have, in order.
CSV_COLUMNS = ("t", "x", "y", "phi")


def _csv_number(path: Path, number: int, row: Mapping[str, str | None], key: str) -> float:
    """The value of column ``key`` in data row ``number`` as a float (one-line errors;
    :func:`~ddwmmr.errors.plain_float`)."""
    text = row.get(key)
    if text is None or not text.strip():
        raise ParameterError(f"traj: {path} data row {number} has no value in column {key}")
    try:
        return plain_float(text)
    except ValueError:
        # Stripped of ASCII blanks only: str.strip would also take off a no-break space
        # that made the value unreadable, and show a plain number.
        value = shown(text.strip(" \t"))
        raise ParameterError(
            f"traj: {path} data row {number}, column {key}: {value} is not a number"
        ) from None


def _is_number_text(text: str) -> bool:
    """Whether a header field reads as a number (a data line taken for the header)."""
    try:
        float(text)
    except ValueError:
        return False
    return True


#: Longest line :func:`_plain_values` reads: the csv module's default field size limit,
#: beyond which the full reader refuses the file.
_PLAIN_LINE_LIMIT = csv.field_size_limit()


def _plain_values(lines: list[str]) -> npt.NDArray[np.float64] | None:
    """The values of a plain CSV trajectory, one row per data line, read without the csv
    module: a header of exactly ``t,x,y`` or ``t,x,y,phi`` and data lines of ASCII numbers
    with no quote, underscore or blank line, each with one value per column. None for
    anything else, which the full reader then reads or refuses, naming what is wrong:
    the result here is what it gives (the same ``float`` of the same fields), in a
    fraction of its time and memory (a million rows: dictionaries of strings, about
    1 GB, against the numbers alone)."""
    if not lines or lines[0] not in ("t,x,y", "t,x,y,phi"):
        return None
    columns = lines[0].count(",") + 1
    flat: list[float] = []
    try:
        for line in itertools.islice(lines, 1, None):
            if (
                line.count(",") != columns - 1
                or len(line) > _PLAIN_LINE_LIMIT
                or not plain_number_text(line)
                or '"' in line
            ):
                return None
            flat.extend(map(float, line.split(",")))
    except ValueError:  # an empty or unreadable value: the full reader names it
        return None
    if not flat:
        return None
    return np.array(flat, dtype=float).reshape(-1, columns)


def _split_names(name: str) -> list[str]:
    """The column names a one-column header ``name`` holds when split at semicolons, tabs
    or spaces (a spreadsheet's or a hand-written export), if they all are accepted
    columns (:data:`CSV_COLUMNS`) and more than one; else an empty list."""
    for separator in (";", "\t", None):  # None: runs of whitespace
        names = [part.strip() for part in name.split(separator)]
        if len(names) > 1 and all(part in CSV_COLUMNS for part in names):
            return names
    return []


def read_csv(path: str | Path) -> SampledTrajectory:
    """Load a :class:`SampledTrajectory` from a CSV file with columns t, x, y[, phi]; a
    file whose positions look like millimetres (:func:`length_units_warning`) is taken as
    given after a one-line :class:`UserWarning`, as a robot file's lengths are."""
    trajectory = _read_samples(path)
    message = length_units_warning(trajectory.points)
    if message is not None:
        warn_user(f"trajectory {trajectory.name}: {message}")
    return trajectory


def _read_samples(path: str | Path) -> SampledTrajectory:
    """:func:`read_csv` without the units warning: the file's samples, checked."""
    path = as_path(path, "traj")
    # The text is dropped once split: a large file is held once, as its lines.
    lines = [line for line in read_text_file(path, "traj").splitlines() if not line.startswith("#")]
    if len(lines) > MAX_TRAJECTORY_SAMPLES + 1:
        raise ParameterError(
            f"traj: {path} has {len(lines) - 1} rows (at most {MAX_TRAJECTORY_SAMPLES})"
        )
    plain = _plain_values(lines)
    if plain is not None:
        try:
            times, points = np.ascontiguousarray(plain[:, 0]), np.ascontiguousarray(plain[:, 1:])
            return SampledTrajectory(times, points, name=file_name(path))
        except ParameterError as exc:
            raise ParameterError(f"traj: {path}: {exc}") from None
    try:
        reader = csv.DictReader(lines)
        if reader.fieldnames:  # "t, x, y": names are read without the spaces around them
            reader.fieldnames = [name.strip() for name in reader.fieldnames]
        rows = list(reader)
    except csv.Error as exc:
        raise ParameterError(f"traj: {path} is not valid CSV ({exc})") from None
    if not rows:
        raise ParameterError(f"traj: {path} has no data rows")
    header = list(reader.fieldnames or [])
    expected = "a header line t,x,y or t,x,y,phi"
    blank = [i for i, name in enumerate(header) if not name.strip()]
    if blank:
        # A trailing comma (a spreadsheet's export) gives an unnamed, empty column: it is
        # left out. An unnamed column holding values is a header that lost its names.
        records = list(csv.reader(lines))[1:]
        if any(i < len(r) and r[i].strip() for r in records for i in blank):
            raise ParameterError(
                f"traj: {path} has a blank column name over values (column {blank[0] + 1}); "
                f"needs {expected}"
            )
        for row in rows:
            for name in {header[i] for i in blank}:
                row.pop(name, None)
        header = [name for name in header if name.strip()]
    if header and all(_is_number_text(name) for name in header):
        raise ParameterError(
            f"traj: {path} has no header line (its first line that does not start with # "
            f"holds numbers: {shown(','.join(header), 40)}); needs {expected} "
            "(a line starting with # is a comment)"
        )
    repeated = sorted({name for name in header if header.count(name) > 1})
    if repeated:
        raise ParameterError(
            f"traj: {path} repeats column(s) {', '.join(repeated)}; needs {expected}"
        )
    for number, row in enumerate(rows, start=1):
        if None in row:  # DictReader files values beyond the header under None
            raise ParameterError(
                f"traj: {path} data row {number} has more values than the header's "
                f"{len(header)} columns"
            )
    unknown = [name for name in header if name not in CSV_COLUMNS]
    if len(header) == 1 and _split_names(header[0]):
        raise ParameterError(
            f"traj: {path} separates its columns by something else than commas (header "
            f"{shown(header[0], 40)}); needs {expected}, comma-separated"
        )
    if unknown:
        raise ParameterError(
            f"traj: {path} has unknown column(s) {', '.join(shown(n, 40) for n in unknown)} "
            f"(accepted: {', '.join(CSV_COLUMNS)}, lower case); needs {expected}"
        )
    columns = set(rows[0])
    missing = {"t", "x", "y"} - columns
    if missing:
        raise ParameterError(
            f"traj: {path} lacks column(s) {', '.join(sorted(missing))}; needs {expected}"
        )
    keys = ["x", "y", "phi"] if "phi" in columns else ["x", "y"]
    values = [
        [_csv_number(path, number, r, k) for k in ("t", *keys)]
        for number, r in enumerate(rows, start=1)
    ]
    times = np.array([row[0] for row in values])
    points = np.array([row[1:] for row in values])
    try:
        return SampledTrajectory(times, points, name=file_name(path))
    except ParameterError as exc:
        raise ParameterError(f"traj: {path}: {exc}") from None
