"""Static tip-over stability and manipulability of the planar arm (SPEC §1, thesis 4.1).

The arm is horizontal and mounted at the base centre. In the base frame the combined centre
of mass of links (their midpoints) and payload (at the end effector) is

    x_com = A cos(th1) + B cos(th1 + th2),   y_com = A sin(th1) + B sin(th1 + th2)

with ``A = (m1/2 + m2 + mp) L1 / M`` and ``B = (m2/2 + mp) L2 / M`` (the base's own centre of
mass is at the origin and contributes nothing). The stability margin is the ratio of the
counter moment to the tipping moment about each footprint edge:

    S_lon = (length/2) / |x_com|,   S_lat = (width/2) / |y_com|,   S = min(S_lon, S_lat)

``S > 1`` is statically stable. Values are capped at :data:`STABILITY_CAP` where the
tipping moment vanishes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Reported stability is capped here: a vanishing tipping moment gives an infinite ratio.
STABILITY_CAP = 10.0


@dataclass(frozen=True)
class ComCoefficients:
    """Coefficients ``A``, ``B`` (m) of the arm+payload centre of mass in the base frame."""

    A: float
    B: float
    half_length: float
    half_width: float


def com_coefficients(
    L1: float,
    L2: float,
    m1: float,
    m2: float,
    payload: float,
    base_mass: float,
    base_length: float,
    base_width: float,
) -> ComCoefficients:
    """Precompute the centre-of-mass coefficients for :func:`stability_terms`."""
    total = base_mass + m1 + m2 + payload
    return ComCoefficients(
        A=(0.5 * m1 + m2 + payload) * L1 / total,
        B=(0.5 * m2 + payload) * L2 / total,
        half_length=0.5 * base_length,
        half_width=0.5 * base_width,
    )


def centre_of_mass(k: ComCoefficients, th1: float, th2: float) -> tuple[float, float]:
    """Combined centre of mass ``(x_com, y_com)`` in the base frame (m)."""
    return (
        k.A * math.cos(th1) + k.B * math.cos(th1 + th2),
        k.A * math.sin(th1) + k.B * math.sin(th1 + th2),
    )


def stability_terms(k: ComCoefficients, th1: float, th2: float) -> tuple[float, float, float]:
    """``(S_lon, S_lat, S)``, each capped at :data:`STABILITY_CAP` (dimensionless)."""
    return margins(k, *centre_of_mass(k, th1, th2))


def margins(k: ComCoefficients, x_com: float, y_com: float) -> tuple[float, float, float]:
    """``(S_lon, S_lat, S)`` for a centre of mass ``(x_com, y_com)`` (m, base frame): each
    term ``half extent / |offset|``, capped at :data:`STABILITY_CAP`."""
    offset, half = abs(x_com), k.half_length
    s_lon = STABILITY_CAP if offset * STABILITY_CAP <= half else half / offset
    offset, half = abs(y_com), k.half_width
    s_lat = STABILITY_CAP if offset * STABILITY_CAP <= half else half / offset
    return s_lon, s_lat, min(s_lon, s_lat)


def stability_gradient(k: ComCoefficients, th1: float, th2: float) -> tuple[float, float, float]:
    """``(S, dS/dth1, dS/dth2)`` of the capped margin ``S`` (zero gradient where capped).

    At a tie between ``S_lon`` and ``S_lat`` the lateral term's gradient is returned.
    """
    s1, c1 = math.sin(th1), math.cos(th1)
    s12, c12 = math.sin(th1 + th2), math.cos(th1 + th2)
    x_com = k.A * c1 + k.B * c12
    y_com = k.A * s1 + k.B * s12
    s_lon, s_lat, _ = margins(k, x_com, y_com)
    if s_lat <= s_lon:
        if s_lat >= STABILITY_CAP:
            return s_lat, 0.0, 0.0
        # S = h / |y|  =>  dS = -S * dy / y
        factor = -s_lat / y_com
        return s_lat, factor * (k.A * c1 + k.B * c12), factor * (k.B * c12)
    if s_lon >= STABILITY_CAP:
        return s_lon, 0.0, 0.0
    factor = -s_lon / x_com
    return s_lon, factor * (-k.A * s1 - k.B * s12), factor * (-k.B * s12)


def manipulability(th2: float) -> float:
    """Normalised manipulability ``eta = |sin(th2)|`` in [0, 1] (thesis 4.1.1)."""
    return abs(math.sin(th2))


def stability_arrays(
    k: ComCoefficients, th1: np.ndarray, th2: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`stability_terms` over arrays of joint angles: ``(S_lon, S_lat, S)``."""
    th1 = np.asarray(th1, dtype=float)
    th2 = np.asarray(th2, dtype=float)
    x_com = k.A * np.cos(th1) + k.B * np.cos(th1 + th2)
    y_com = k.A * np.sin(th1) + k.B * np.sin(th1 + th2)
    s_lon = _ratio_array(k.half_length, x_com)
    s_lat = _ratio_array(k.half_width, y_com)
    return s_lon, s_lat, np.minimum(s_lon, s_lat)


def _ratio_array(half_extent: float, offset: np.ndarray) -> np.ndarray:
    magnitude = np.abs(offset)
    capped = magnitude * STABILITY_CAP <= half_extent
    with np.errstate(divide="ignore"):
        return np.where(capped, STABILITY_CAP, half_extent / np.where(capped, 1.0, magnitude))
