"""Brute-force footprint geometry for the obstacle tests, independent of
ddwmmr.qp.limits.obstacles: points sampled densely on the base's rectangular outline."""

from __future__ import annotations

import math

import numpy as np


def footprint_outline(half_length: float, half_width: float, n: int) -> np.ndarray:
    """``(4 n, 2)`` points on the outline of the footprint, base frame (m): ``n`` per edge."""
    s = np.linspace(-1.0, 1.0, n)
    return np.concatenate(
        [
            np.column_stack([s * half_length, np.full(n, half_width)]),
            np.column_stack([s * half_length, np.full(n, -half_width)]),
            np.column_stack([np.full(n, half_length), s * half_width]),
            np.column_stack([np.full(n, -half_length), s * half_width]),
        ]
    )


def outline_clearance(
    half_length: float,
    half_width: float,
    pose: tuple[float, float, float],
    circle: tuple[float, float, float],
    n: int,
) -> float:
    """Distance (m) from the sampled outline of the footprint at base ``pose = (x, y, phi)``
    to the circle ``(cx, cy, radius)``: smallest point distance minus the radius."""
    outline = footprint_outline(half_length, half_width, n)
    x, y, phi = pose
    c, s = math.cos(phi), math.sin(phi)
    wx = x + c * outline[:, 0] - s * outline[:, 1]
    wy = y + s * outline[:, 0] + c * outline[:, 1]
    cx, cy, radius = circle
    return float(np.min(np.hypot(wx - cx, wy - cy)) - radius)
