"""A trajectory scaled in space about the world origin, its timing kept.

:class:`ScaledTrajectory` ``(trajectory, s)`` is ``trajectory`` with every position and
linear velocity multiplied by ``s`` (> 0) and the headings, their rates and the duration
unchanged: ``pose(t) = [s x, s y, phi]``, ``velocity(t) = [s xdot, s ydot, phidot]``. It
is the path a robot whose every length is ``s`` times the default robot's follows as the
default robot follows ``trajectory`` (the same timing: speeds scale by ``s``, angular
rates do not), so that such a robot runs the default robot's run with ``s`` times its
position errors (docs/api.md, "Scaled trajectories").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ddwmmr.errors import check_range
from ddwmmr.trajectories.base import (
    check_times,
    require_trajectory,
    sample_each,
    sampler,
    trajectory_name,
)

#: The scale factors :class:`ScaledTrajectory` takes: as far apart as the robot's length
#: unit ``L1 / 0.35 m`` ranges over (:data:`ddwmmr.errors.LENGTH_RANGE_M`), and more.
SCALE_RANGE = (1e-6, 1e6)
#: Attributes of the scaled trajectory's base that are times or counts, not lengths: the
#: scaled trajectory has each as its base does (and lacks it where its base does), so that
#: the default step (``samples``, ``default_step``), a rectangle's corner metric
#: (``corner_times``, ``corner_windows``) and the reports' period (``T``) are the base's.
TIMING_ATTRIBUTES = frozenset(
    {"samples", "default_step", "N", "T", "corner_times", "corner_windows", "CORNER_SETTLE"}
)


def check_scale(value: Any, name: str = "scale") -> float:
    """``value`` as a float if it is a scale factor in :data:`SCALE_RANGE`, else a one-line
    :class:`~ddwmmr.errors.ParameterError` naming ``name`` and the range."""
    return check_range(name, value, *SCALE_RANGE)


@dataclass(frozen=True)
class ScaledTrajectory:
    """``trajectory`` scaled by ``scale`` about the world origin, its timing kept.

    Args:
        trajectory: any trajectory (``duration``, ``pose(t)``, ``velocity(t)``; docs/api.md,
            "Trajectories"), else a one-line :class:`~ddwmmr.errors.ParameterError`.
        scale: the factor s, in :data:`SCALE_RANGE` (1e-6 to 1e6), else a one-line
            :class:`~ddwmmr.errors.ParameterError` naming ``scale``.

    ``pose(t)`` is ``[s xE, s yE, phiE]`` (m, m, rad) and ``velocity(t)`` ``[s xEdot,
    s yEdot, phiEdot]`` (m/s, m/s, rad/s) of the base at the same t (s); ``duration`` and
    the attributes in :data:`TIMING_ATTRIBUTES` are the base's; ``sample(times)`` scales
    the base's own vectorised ``sample`` (:func:`~ddwmmr.trajectories.base.sampler`) or
    calls ``pose`` and ``velocity`` at each time. A power-of-two s scales exactly (no
    rounding). The name is the base's followed by `` x<s>`` (``ellipse x10``).
    """

    trajectory: Any
    scale: float

    def __post_init__(self) -> None:
        require_trajectory(self.trajectory)
        object.__setattr__(self, "scale", check_scale(self.scale))
        factors = np.array([self.scale, self.scale, 1.0])
        object.__setattr__(self, "_factors", factors)

    def __getattr__(self, name: str) -> Any:
        # Only reached for names the class lacks: the base's times and counts, nothing else
        # (its lengths, x0 or a, would be the unscaled ones).
        base = self.__dict__.get("trajectory")
        if base is None or name not in TIMING_ATTRIBUTES:
            raise AttributeError(name)
        return getattr(base, name)

    @property
    def name(self) -> str:
        """The base's name and the factor, ``ellipse x10`` (a label for reports)."""
        return f"{trajectory_name(self.trajectory)} x{self.scale:g}"

    @property
    def duration(self) -> float:
        """The base's duration (s)."""
        duration: float = self.trajectory.duration
        return duration

    def pose(self, t: float) -> np.ndarray:
        """``[s xE, s yE, phiE]`` (m, m, rad) of the base's pose at time t (s)."""
        pose: np.ndarray = np.asarray(self.trajectory.pose(t), dtype=float) * self._factors
        return pose

    def velocity(self, t: float) -> np.ndarray:
        """``[s xEdot, s yEdot, phiEdot]`` (m/s, m/s, rad/s) of the base's at time t (s)."""
        velocity: np.ndarray = np.asarray(self.trajectory.velocity(t), dtype=float) * self._factors
        return velocity

    def sample(self, times: Any) -> tuple[np.ndarray, np.ndarray]:
        """Poses and velocities at many times (s) at once, both ``(len(times), 3)``: the
        numbers of :meth:`pose` and :meth:`velocity`, from the base's own ``sample`` when
        it has one. ``times``: one finite number or a 1-D sequence of them, else a one-line
        :class:`~ddwmmr.errors.ParameterError` naming ``times``."""
        t = check_times(times)
        own = sampler(self.trajectory)
        if own is None:
            return sample_each(self, t)
        poses, rates = own(t)
        factors = self._factors
        return np.asarray(poses, dtype=float) * factors, np.asarray(rates, dtype=float) * factors
