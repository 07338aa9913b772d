"""A trajectory defined by a Python class: a sine wave driven along the x axis.

Any object with ``duration``, ``pose(t)`` and ``velocity(t)`` is a trajectory; ``samples``
(optional) sets the default step ``dt = duration / samples``, and ``sample(times)``
(optional) gives many poses and velocities in one vectorised call, which ``simulate`` uses
to compute a run's references in a few calls instead of one per time. Prints only.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ddwmmr import Robot, simulate
from ddwmmr.cli.common import run_script  # bad input: one line, status 2


class SineWave:
    """End effector moving at ``speed`` along +x while oscillating in y, facing its travel.

    ``y = amplitude sin(2 pi t / period)``. The smallest radius of curvature,
    ``speed^2 / (amplitude (2 pi / period)^2)`` = 1.14 m with the defaults, must exceed the
    arm reach (0.65 m) for the base to follow a tangent-facing end effector.
    """

    name = "sine-wave"

    def __init__(
        self,
        speed: float = 0.1,
        amplitude: float = 0.2,
        period: float = 30.0,
        duration: float = 30.0,
        samples: int = 1500,
    ) -> None:
        """Speed along x (m/s), amplitude (m), period (s), run length (s), samples."""
        self.speed, self.amplitude, self.period = speed, amplitude, period
        self.duration, self.samples = duration, samples

    def _y(self, t: float | np.ndarray) -> tuple[Any, Any, Any]:
        """Lateral offset y (m) and its first and second time derivatives (m/s, m/s^2);
        ``t`` is a time (s) or an array of times."""
        omega = 2.0 * math.pi / self.period
        s, c = np.sin(omega * t), np.cos(omega * t)
        a = self.amplitude
        return a * s, a * omega * c, -a * omega * omega * s

    def pose(self, t: float) -> np.ndarray:
        """``[xE, yE, phiE]`` (m, m, rad), world frame."""
        y, ydot, _ = self._y(t)
        return np.array([self.speed * t, y, math.atan2(ydot, self.speed)])

    def velocity(self, t: float) -> np.ndarray:
        """``[xEdot, yEdot, phiEdot]`` (m/s, m/s, rad/s): phiEdot is the path's turn rate."""
        _, ydot, yddot = self._y(t)
        turn_rate = self.speed * yddot / (self.speed**2 + ydot**2)
        return np.array([self.speed, ydot, turn_rate])

    def sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Optional: ``(poses, velocities)`` at many times, each ``(len(times), 3)``, the
        numbers ``pose`` and ``velocity`` give (to rounding), in one vectorised call."""
        t = np.asarray(times, dtype=float)
        y, ydot, yddot = self._y(t)
        poses = np.column_stack([self.speed * t, y, np.arctan2(ydot, self.speed)])
        turn_rate = self.speed * yddot / (self.speed**2 + ydot**2)
        velocities = np.column_stack([np.full_like(t, self.speed), ydot, turn_rate])
        return poses, velocities


def main() -> None:
    """Track the sine wave with an open-loop and a closed-loop method; print the errors."""
    trajectory = SineWave()
    for method in ("ats", "clrrmc-ts"):
        summary = simulate(Robot(), trajectory, method).summary
        print(
            f"{method:<10} rms {summary['rms_position_error_m'] * 1000:7.2f} mm   "
            f"final {summary['final_position_error_m'] * 1000:7.3f} mm   "
            f"singular steps {summary['singular_steps']}"
        )


if __name__ == "__main__":
    run_script(main)
