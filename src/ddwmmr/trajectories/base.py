"""The trajectory interface.

A trajectory is any object with

* ``duration`` - the length of one run (s);
* ``pose(t)`` - desired end-effector pose ``[xE, yE, phiE]`` at time t (world frame, m, rad);
* ``velocity(t)`` - its time derivative ``[xEdot, yEdot, phiEdot]`` (m/s, rad/s).

Optionally ``samples`` (int): the resolution N; simulation uses ``dt = duration / samples``
when no step is given.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Trajectory(Protocol):
    """Structural type of every desired end-effector trajectory."""

    @property
    def duration(self) -> float:  # pragma: no cover - protocol
        """Length of one run (s)."""
        ...

    def pose(self, t: float) -> np.ndarray:  # pragma: no cover - protocol
        """Desired pose ``[xE, yE, phiE]`` at time t (s)."""
        ...

    def velocity(self, t: float) -> np.ndarray:  # pragma: no cover - protocol
        """Desired velocity ``[xEdot, yEdot, phiEdot]`` at time t (s)."""
        ...


def trajectory_name(trajectory: object) -> str:
    """A short human name for a trajectory (its ``name`` attribute or its class name)."""
    return str(getattr(trajectory, "name", type(trajectory).__name__.lower()))
