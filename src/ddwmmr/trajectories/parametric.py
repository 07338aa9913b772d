"""Elliptical and rectangular end-effector trajectories (docs/theory.md, "Trajectories").

Both are parametrised by ``(x0, y0, a, b, beta, N, T)``: centre (m), semi-axes (m), rotation
(rad), number of samples per period and period (s). With ``alpha = 2 pi t / T``:

    ellipse:    [xE, yE] = [x0, y0] + R(beta) [a cos(alpha), b sin(alpha)]
    rectangle:  [xE, yE] = [x0, y0] + R(beta) [a(|c|c - |s|s), b(|c|c + |s|s)]

Both run counter-clockwise. The desired orientation is the direction of travel
(``orientation="tangent"``, unwrapped so that it is continuous, jumping by pi/2 only at the
rectangle's corners) or a fixed angle (``orientation="constant"``, ``phi=...``).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, cast

import numpy as np

from ddwmmr.errors import (
    DURATION_RANGE_S,
    LENGTH_RANGE_M,
    MAX_ANGLE_RAD,
    MAX_COORDINATE_M,
    MAX_STEPS,
    MAX_TRAJECTORY_SAMPLES,
    ParameterError,
    check_int_at_least,
    check_positive,
    check_range,
    one_of,
    shown,
)
from ddwmmr.trajectories.base import atan2_array, check_name, check_time, check_times

ORIENTATIONS = ("tangent", "constant")
#: Why ``phi`` is refused with the tangent orientation, in the API and in the file loaders.
PHI_NEEDS_CONSTANT = (
    'phi is used only with orientation = "constant" (the orientation here is tangent, the '
    'direction of travel); set orientation = "constant" or drop phi'
)
_isfinite = math.isfinite

#: An angle or a length of the shapes: a float (pose, velocity) or an array (sample).
_Real = float | np.ndarray


class _Math(Protocol):
    """The ``math`` functions the shapes use: the ``math`` module (floats) or
    :class:`_ArrayMath` (arrays)."""

    def sin(self, x: _Real, /) -> _Real: ...
    def cos(self, x: _Real, /) -> _Real: ...
    def floor(self, x: _Real, /) -> _Real: ...
    def atan2(self, y: _Real, x: _Real, /) -> _Real: ...


class _ArrayMath:
    """The ``math`` functions the shapes use, on arrays (for :meth:`_Parametric.sample`;
    ``atan2`` through the C library's, as :func:`~ddwmmr.trajectories.base.atan2_array`)."""

    sin = staticmethod(np.sin)
    cos = staticmethod(np.cos)
    floor = staticmethod(np.floor)
    atan2 = staticmethod(atan2_array)


# cast: numpy's ufunc stubs have no overload taking float | ndarray; on arrays they give arrays
_ARRAY_MATH = cast(_Math, _ArrayMath())


def check_geometry_value(name: str, value: float) -> float:
    """One continuous geometry parameter of the parametric shapes, checked: ``a``, ``b``
    (m) and ``T`` (s) positive, ``x0``, ``y0`` (m), ``beta``, ``phi`` (rad) finite, each
    within the documented magnitudes of :mod:`ddwmmr.errors` (no overflow, no absurd
    allocation later). Also what the GUI checks a sampled file's placement with.

    Every refusal is a one-line :class:`~ddwmmr.errors.ParameterError` naming the
    parameter and its range, whatever the value (text, None, NaN, too large, zero), e.g.
    ``x0 must be a finite number in [-1e+06, 1e+06] m``."""
    if name in ("a", "b", "T"):
        low, high, unit = (*DURATION_RANGE_S, "s") if name == "T" else (*LENGTH_RANGE_M, "m")
        return check_range(name, value, low, high, unit)
    cap, unit = (MAX_ANGLE_RAD, "rad") if name in ("beta", "phi") else (MAX_COORDINATE_M, "m")
    return check_range(name, value, -cap, cap, unit)


@dataclass(frozen=True)
class _Parametric(ABC):
    """Shared parameters and validation of the parametric trajectories.

    Args:
        x0, y0: centre (m, world frame), magnitude <= 1e6.
        a, b: semi-axes (m) along the shape's own x and y, in [1e-6, 1e3].
        beta: rotation of the shape about its centre (rad, counter-clockwise from the
            world x axis), magnitude <= 1e6.
        N: samples per period, an integer in [2, 1e6].
        T: period (s), in [1e-6, 1e9].
        orientation: ``"tangent"`` (the direction of travel) or ``"constant"``.
        phi: the fixed orientation (rad, world frame) of ``orientation="constant"``,
            magnitude <= 1e6. The tangent orientation has no use for it: a ``phi`` other
            than 0 (the default) with it raises :class:`~ddwmmr.errors.ParameterError`
            (the message of a TOML file that sets it), instead of being ignored.
        name: label used in reports (each shape's own by default), a non-empty string.

    Anything else raises a one-line :class:`~ddwmmr.errors.ParameterError` naming the
    parameter and its range.
    """

    x0: float = 0.0
    y0: float = 0.0
    a: float = 2.0
    b: float = 1.5
    beta: float = 0.0
    N: int = 2000
    T: float = 40.0
    orientation: str = "tangent"
    phi: float = 0.0
    if TYPE_CHECKING:
        # Each shape's own field, after phi (Ellipse, Rectangle: a default of its own).
        name: str = ""

    def __post_init__(self) -> None:
        check_name(self.name)  # each shape's field, "ellipse" or "rectangle" by default
        for name in ("x0", "y0", "beta", "phi", "a", "b", "T"):
            object.__setattr__(self, name, check_geometry_value(name, getattr(self, name)))
        object.__setattr__(self, "N", check_int_at_least("N", self.N, 2, MAX_TRAJECTORY_SAMPLES))
        if not one_of(self.orientation, ORIENTATIONS):
            raise ParameterError(
                f"orientation must be one of {', '.join(ORIENTATIONS)}"
                f" (got {shown(self.orientation)})"
            )
        # By value, not by presence: dataclasses.replace and a recorded run pass the
        # default phi = 0 back in, and it means nothing with the tangent orientation.
        if self.orientation == "tangent" and self.phi != 0.0:
            raise ParameterError(f"{PHI_NEEDS_CONSTANT} (got phi = {self.phi:g})")

    @property
    def duration(self) -> float:
        """One period T (s)."""
        return self.T

    @property
    def samples(self) -> int:
        """Resolution N (samples per period)."""
        return self.N

    @property
    def alpha_rate(self) -> float:
        """``alphadot = 2 pi / T`` (rad/s)."""
        return 2.0 * math.pi / self.T

    def sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Poses and velocities at many times at once: ``(poses, velocities)``, both
        ``(len(times), 3)`` (rows as :meth:`pose` and :meth:`velocity` give them, to the
        last bit where numpy's sin/cos are the C library's, within an ulp elsewhere).
        ``times`` (s): one number or a 1-D sequence, each finite, else
        :class:`~ddwmmr.errors.ParameterError` naming ``times``
        (:func:`~ddwmmr.trajectories.base.check_times`)."""
        t = check_times(times)
        rate = self.alpha_rate
        alpha = rate * t
        px, py = self._shape(alpha, _ARRAY_MATH)
        rx, ry = self._rotate(px, py)
        if self.orientation == "tangent":
            heading = self.beta + self._tangent(alpha, _ARRAY_MATH)
            turn = self._tangent_rate(alpha, _ARRAY_MATH) * rate
        else:
            heading, turn = np.full_like(t, self.phi), np.zeros_like(t)
        dx, dy = self._shape_derivative(alpha, _ARRAY_MATH)
        vx, vy = self._rotate(dx * rate, dy * rate)
        poses = np.column_stack([self.x0 + rx, self.y0 + ry, heading])
        return poses, np.column_stack([vx, vy, np.broadcast_to(turn, t.shape)])

    def _rotate(self, px: _Real, py: _Real) -> tuple[_Real, _Real]:
        cb, sb = math.cos(self.beta), math.sin(self.beta)
        return cb * px - sb * py, sb * px + cb * py

    def pose(self, t: float) -> np.ndarray:
        """Desired ``[xE, yE, phiE]`` at time t (s); t must be finite."""
        if not (isinstance(t, float) and _isfinite(t)):
            check_time(t)
        alpha = self.alpha_rate * t
        px, py = self._shape(alpha)
        rx, ry = self._rotate(px, py)
        if self.orientation == "tangent":
            heading = self.beta + self._tangent(alpha)
        else:
            heading = self.phi
        return np.array([self.x0 + rx, self.y0 + ry, heading])

    def velocity(self, t: float) -> np.ndarray:
        """Desired ``[xEdot, yEdot, phiEdot]`` at time t (s); t must be finite."""
        if not (isinstance(t, float) and _isfinite(t)):
            check_time(t)
        alpha = self.alpha_rate * t
        dx, dy = self._shape_derivative(alpha)
        rx, ry = self._rotate(dx * self.alpha_rate, dy * self.alpha_rate)
        rate = self._tangent_rate(alpha) * self.alpha_rate if self.orientation == "tangent" else 0.0
        return np.array([rx, ry, rate])

    # Shape-specific pieces, in the unrotated frame, as functions of alpha: a float with
    # m = math, or an array with m = _ARRAY_MATH (the same expressions, vectorised).
    @abstractmethod
    def _shape(self, alpha: _Real, m: _Math = math) -> tuple[_Real, _Real]:
        """Unrotated offset from the centre (m)."""

    @abstractmethod
    def _shape_derivative(self, alpha: _Real, m: _Math = math) -> tuple[_Real, _Real]:
        """d(offset)/d(alpha) (m/rad)."""

    @abstractmethod
    def _tangent(self, alpha: _Real, m: _Math = math) -> _Real:
        """Unwrapped direction of travel in the unrotated frame (rad)."""

    @abstractmethod
    def _tangent_rate(self, alpha: _Real, m: _Math = math) -> _Real:
        """d(tangent)/d(alpha) (dimensionless)."""


@dataclass(frozen=True)
class Ellipse(_Parametric):
    """Elliptical trajectory. Defaults: 2.0 m x 1.5 m semi-axes, 40 s period.

    The smallest radius of curvature, b^2/a = 1.1 m, exceeds the arm reach (0.65 m): with a
    tighter ellipse the base cannot follow a tangent-oriented end effector without driving
    the shoulder into its singularity (docs/theory.md, "Trajectories").
    """

    name: str = "ellipse"

    def _shape(self, alpha: _Real, m: _Math = math) -> tuple[_Real, _Real]:
        return self.a * m.cos(alpha), self.b * m.sin(alpha)

    def _shape_derivative(self, alpha: _Real, m: _Math = math) -> tuple[_Real, _Real]:
        return -self.a * m.sin(alpha), self.b * m.cos(alpha)

    def _tangent(self, alpha: _Real, m: _Math = math) -> _Real:
        # Direction of (-a sin, b cos), measured from the radial normal (-sin, cos) at angle
        # alpha + pi/2; that offset stays in (-pi/2, pi/2), so the sum is continuous.
        s, c = m.sin(alpha), m.cos(alpha)
        offset = m.atan2((self.a - self.b) * s * c, self.a * s * s + self.b * c * c)
        return alpha + 0.5 * math.pi + offset

    def _tangent_rate(self, alpha: _Real, m: _Math = math) -> _Real:
        # d(heading)/d(alpha) = (x' y'' - y' x'') / |p'|^2 = a b / (a^2 sin^2 + b^2 cos^2)
        s, c = m.sin(alpha), m.cos(alpha)
        return self.a * self.b / (self.a**2 * s * s + self.b**2 * c * c)


@dataclass(frozen=True)
class Rectangle(_Parametric):
    """Rectangular trajectory: corners at alpha = k pi/2, non-uniform timing."""

    name: str = "rectangle"

    def _shape(self, alpha: _Real, m: _Math = math) -> tuple[_Real, _Real]:
        c, s = m.cos(alpha), m.sin(alpha)
        # ignore: mypy types abs() of a float | ndarray as object (float * array is fine)
        return (
            self.a * (abs(c) * c - abs(s) * s),  # type: ignore[operator]
            self.b * (abs(c) * c + abs(s) * s),  # type: ignore[operator]
        )

    def _shape_derivative(self, alpha: _Real, m: _Math = math) -> tuple[_Real, _Real]:
        c, s = m.cos(alpha), m.sin(alpha)
        # ignore: mypy types abs() of a float | ndarray as object (float * array is fine)
        return (
            self.a * (-2.0 * abs(c) * s - 2.0 * abs(s) * c),  # type: ignore[operator]
            self.b * (-2.0 * abs(c) * s + 2.0 * abs(s) * c),  # type: ignore[operator]
        )

    def _tangent(self, alpha: _Real, m: _Math = math) -> _Real:
        # Edges run -x, -y, +x, +y in turn; at a corner the edge being entered counts.
        # The small offset keeps sampled corners (alpha = k pi/2 up to rounding) on that edge.
        edge = m.floor(alpha / (0.5 * math.pi) + 1e-9)
        return math.pi + 0.5 * math.pi * edge

    def _tangent_rate(self, alpha: _Real, m: _Math = math) -> _Real:
        return 0.0

    #: Corner window length after each corner, as a share of the period T: the orientation
    #: steps by pi/2 there and the closed-loop transients last a few time constants.
    CORNER_SETTLE = 0.1

    def corner_times(self, duration: float) -> list[float]:
        """Times (s) of the corners alpha = k pi/2, k >= 1, up to ``duration`` (inclusive).

        ``duration`` (s) must be finite and > 0, at most ``DURATION_RANGE_S[1]`` (1e9 s)
        and at most :data:`ddwmmr.errors.MAX_STEPS` corners long (one every T / 4: no run
        has more steps than that); else a one-line
        :class:`~ddwmmr.errors.ParameterError`, before the list is built.
        """
        duration = check_positive("duration", duration)
        quarter = 0.25 * self.T
        longest = min(DURATION_RANGE_S[1], MAX_STEPS * quarter)
        if duration > longest:
            raise ParameterError(
                f"duration must be in (0, {longest:g}] s for T = {self.T:g} s (at most "
                f"{DURATION_RANGE_S[1]:g} s and {MAX_STEPS} corners, one every T / 4) "
                f"(got {duration:g})"
            )
        count = int(duration / quarter + 1e-9)
        return [k * quarter for k in range(1, count + 1)]

    def corner_windows(self, duration: float) -> list[tuple[float, float]]:
        """``(start, end)`` (s) around each corner: from just before it (the sample at the
        corner already sees the new orientation) to ``CORNER_SETTLE * T`` after it.
        ``duration`` as in :meth:`corner_times`."""
        lead = 1e-6 * self.T
        return [(c - lead, c + self.CORNER_SETTLE * self.T) for c in self.corner_times(duration)]
