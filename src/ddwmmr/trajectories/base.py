"""The trajectory interface.

A trajectory is any object with

* ``duration`` - the length of one run (s);
* ``pose(t)`` - desired end-effector pose ``[xE, yE, phiE]`` at time t (world frame, m, rad);
* ``velocity(t)`` - its time derivative ``[xEdot, yEdot, phiEdot]`` (m/s, rad/s).

Optionally ``samples`` (int): the resolution N; simulation uses ``dt = duration / samples``
when no step is given; and ``sample(times) -> (poses, velocities)``, many times in one
vectorised call (:func:`sampler`).
"""

from __future__ import annotations

import math
import os
import unicodedata
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt

from ddwmmr.errors import (
    UNPRINTABLE_CATEGORIES,
    ParameterError,
    check_finite,
    check_int_at_least,
    printable_line,
    shown,
)
from ddwmmr.inheritance import defining_class, overrides


@runtime_checkable
class Trajectory(Protocol):
    """Structural type of every desired end-effector trajectory."""

    @property
    def duration(self) -> float:  # pragma: no cover - protocol
        """Length of one run (s)."""
        ...

    def pose(self, t: float) -> npt.ArrayLike:  # pragma: no cover - protocol
        """Desired pose ``[xE, yE, phiE]`` (m, m, rad) at time t (s): 3 finite numbers
        (an array, a list, a tuple)."""
        ...

    def velocity(self, t: float) -> npt.ArrayLike:  # pragma: no cover - protocol
        """Desired velocity ``[xEdot, yEdot, phiEdot]`` (m/s, m/s, rad/s) at time t (s): 3
        finite numbers (an array, a list, a tuple)."""
        ...


def check_time(t: Any) -> float:
    """``t`` (s) as a float if it is a finite number, else :class:`ParameterError` naming t.

    The shipped trajectories' ``pose`` and ``velocity`` test ``isinstance(t, float) and
    math.isfinite(t)`` per call and come here only when that fails (ints, numpy scalars
    or a bad t), so a valid call costs two C calls.
    """
    return check_finite("t", t)


def check_times(times: Any) -> np.ndarray:
    """``times`` (s) of a vectorised ``sample`` as a 1-D float array: one number or a 1-D
    sequence of numbers, each finite (any sign, any order; none is fine). Anything else
    (text, booleans, None, NaN, inf, a 2-D array) is a :class:`ParameterError` naming
    ``times``. A float array is returned as it is (no copy)."""
    try:
        raw = np.asarray(times)
    except (TypeError, ValueError, OverflowError):  # ragged rows, odd objects
        raise _bad_times("got ragged or non-numeric values") from None
    kind = raw.dtype.kind
    numbers = kind in "iuf" or (
        kind == "O"
        and all(
            isinstance(v, int | float | np.integer | np.floating)
            and not isinstance(v, bool | np.bool_)
            for v in raw.ravel().tolist()
        )
    )
    if not numbers:
        raise _bad_times(f"got {shown(times)}")
    if raw.ndim > 1:
        raise _bad_times(f"got an array of shape {raw.shape}")
    try:
        array = np.asarray(raw, dtype=float)
    except OverflowError:  # an integer beyond float range
        raise _bad_times("got a value beyond float range") from None
    finite = np.isfinite(array)
    if not np.all(finite):
        index = int(np.argmin(finite.ravel()))
        got = f"got {shown(float(array.ravel()[index]))}"
        raise _bad_times(got if array.ndim == 0 else f"{got} as times[{index + 1}]")
    return array.reshape(1) if array.ndim == 0 else array


def _bad_times(got: str) -> ParameterError:
    return ParameterError(
        f"times must be a finite number or a 1-D sequence of finite numbers (s) ({got})"
    )


def require_trajectory(trajectory: Any) -> None:
    """Refuse (one-line :class:`ParameterError`) what is not a trajectory: it needs
    ``duration`` (s), ``pose(t)`` and ``velocity(t)``."""
    if isinstance(trajectory, str):
        raise ParameterError(
            f"trajectory must be a trajectory object, not its name {shown(trajectory)} "
            f"(ddwmmr.load_trajectory({shown(trajectory)}) builds one)"
        )
    missing = [
        name
        for name in ("duration", "pose", "velocity")
        if not hasattr(trajectory, name)
        or (name != "duration" and not callable(getattr(trajectory, name)))
    ]
    if missing:
        raise ParameterError(
            "trajectory must have duration (s), pose(t) and velocity(t) "
            f"(got {shown(trajectory)}, without {', '.join(missing)})"
        )


def trajectory_name(trajectory: object) -> str:
    """A short human name for a trajectory (its ``name`` attribute or its class name)."""
    return str(getattr(trajectory, "name", type(trajectory).__name__.lower()))


def atan2_array(y: npt.ArrayLike, x: npt.ArrayLike) -> np.ndarray:
    """Elementwise ``math.atan2`` (the C library's): numpy's ``arctan2`` differs from it in
    the last bit for about one value in twelve, and a vectorised ``sample`` must give the
    numbers of the scalar ``pose``."""
    return np.array(list(map(math.atan2, np.ravel(y).tolist(), np.ravel(x).tolist())))


def sampler(trajectory: Any) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
    """The trajectory's vectorised ``sample(times)``, if it may stand in for ``pose`` and
    ``velocity``: None when it has none, or when a subclass overrides ``pose`` or
    ``velocity`` below the class that defines ``sample`` (the parent's ``sample`` would
    not know the change)."""
    sample: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = getattr(
        trajectory, "sample", None
    )
    owner = defining_class(type(trajectory), "sample")
    if sample is None or owner is None:
        return sample  # none, or an instance attribute: the trajectory's own word
    if overrides(trajectory, owner, "pose") or overrides(trajectory, owner, "velocity"):
        return None
    return sample


def sample_each(trajectory: Any, times: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Poses and velocities of ``trajectory`` at ``times`` (s, any shape, read flat), arrays
    of shape ``(len(times), 3)``, from one ``pose`` and one ``velocity`` call per time: the
    stand-in for a vectorised ``sample`` the trajectory lacks (:func:`sampler`)."""
    every = np.asarray(times, dtype=float).ravel().tolist()
    poses = np.array([trajectory.pose(t) for t in every]).reshape(len(every), 3)
    velocities = np.array([trajectory.velocity(t) for t in every]).reshape(len(every), 3)
    return poses, velocities


def resolution_step(trajectory: Any) -> float:
    """The trajectory's own step (s), the default control step of every tool and of
    :func:`ddwmmr.simulate`: its ``default_step`` if it has one (a sampled trajectory:
    :meth:`SampledTrajectory.default_step`), else ``duration / samples`` (its resolution
    N, an integer >= 1, else a one-line :class:`ParameterError` naming ``samples``), or
    ``duration / 1000``."""
    own = getattr(trajectory, "default_step", None)
    if own is not None:
        return float(own)
    samples = check_int_at_least(
        "trajectory: samples (its resolution N)", getattr(trajectory, "samples", 1000), 1
    )
    step: float = trajectory.duration / samples
    return step


def check_name(name: Any, prefix: str = "") -> str:
    """``name``, a trajectory's label in reports, if it is a non-empty string, else a
    one-line :class:`ParameterError` naming ``name`` (after ``prefix``, e.g.
    ``"trajectory samples: "``)."""
    if not isinstance(name, str) or not name:
        raise ParameterError(f"{prefix}name must be a string, not empty (got {shown(name)})")
    if not printable_line(name):
        raise ParameterError(
            f"{prefix}name must be text on one line, without control characters or lone "
            f"surrogates (got {shown(name)})"
        )
    return name


def file_name(path: str | os.PathLike[str]) -> str:
    """The name a trajectory file gives its trajectory: the file name without its suffix,
    as text :func:`check_name` takes. A file name's bytes are read as UTF-8 (also when the
    locale decoded them as ASCII: ``LC_ALL=POSIX``), any byte that is not UTF-8 as U+FFFD,
    and a control character as ``?``: an odd file name does not make the file unusable."""
    text = os.fsencode(Path(path).stem).decode("utf-8", errors="replace")
    return "".join("?" if unicodedata.category(c) in UNPRINTABLE_CATEGORIES else c for c in text)
