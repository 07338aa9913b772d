"""The tracking task: follow a desired end-effector trajectory, record every sample.

:class:`TrackingTask` feeds :func:`ddwmmr.sim.loop.run_loop` the trajectory's pose and
velocity and records, per sample, only what the loop knows cheaply (time, state, applied
input ``v, w, th1dot, th2dot``, the measured base velocities ``v_measured, w_measured``
(which lag the command on plants with dynamics), the desired pose, the controller's flags
and timing, the plant's extra columns).
Everything derived (end-effector pose, errors, wheel speeds, manipulability, stability) is
computed afterwards, vectorised over the run, by :func:`derive_columns`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ddwmmr.commands import WheelForces
from ddwmmr.model import Robot
from ddwmmr.model.stability import stability_arrays
from ddwmmr.plants.base import Observation, Plant, PlantDivergedError
from ddwmmr.trajectories.base import sampler

#: Column names of the recorded time series, in order (plant columns follow).
COLUMNS = (
    "t",
    "x",
    "y",
    "phi",
    "th1",
    "th2",
    "v",
    "w",
    "th1dot",
    "th2dot",
    "v_measured",
    "w_measured",
    "xE",
    "yE",
    "phiE",
    "xE_d",
    "yE_d",
    "phiE_d",
    "position_error_m",
    "orientation_error_rad",
    "wheel_left_rad_s",
    "wheel_right_rad_s",
    "manipulability",
    "stability_lon",
    "stability_lat",
    "stability",
    "nonholonomic_residual_m_s",
    "singular",
    "saturated",
    "fallback",
    "step_us",
)
#: Columns computed after the run by :func:`derive_columns` (vectorised).
DERIVED = (
    "xE",
    "yE",
    "phiE",
    "position_error_m",
    "orientation_error_rad",
    "wheel_left_rad_s",
    "wheel_right_rad_s",
    "manipulability",
    "stability_lon",
    "stability_lat",
    "stability",
)
#: What is recorded per sample, in the order of :meth:`TrackingTask.record`'s rows.
RECORDED = tuple(name for name in COLUMNS if name not in DERIVED)


class TrackingTask:
    """Reference from ``trajectory``; records every sample; never ends a run early.

    Args:
        trajectory: any object with ``pose(t)`` and ``velocity(t)`` (world frame).
        plant: the plant (for its extra columns).
        grid: ``(dt, steps)`` of the run: when the trajectory has a vectorised
            ``sample(times)``, the references at the samples ``k dt`` and at the RK4 stage
            times ``k dt + dt/2``, ``k dt + dt`` are computed a block of steps at a time
            (:class:`ReferenceBlocks`; the same numbers :meth:`reference` would compute
            one by one).
    """

    def __init__(
        self, trajectory: Any, plant: Plant, grid: tuple[float, int] | None = None
    ) -> None:
        self.trajectory = trajectory
        self.plant = plant
        self.rows: list[tuple[float, ...]] = []
        self.extra: list[tuple[float, ...]] = []
        self.diverged_at: int | None = None
        self.diverged_message = ""
        self._pose = trajectory.pose
        self._velocity = trajectory.velocity
        # Reference cache: RK4 asks twice at t + dt/2, and the recorder again at t.
        self._cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        sample = sampler(trajectory)
        self._blocks = None if grid is None or sample is None else ReferenceBlocks(sample, *grid)
        self._table: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self._extra_values = plant.extra_values if plant.extra_columns else None

    # -- Task protocol ----------------------------------------------------------------------
    def start(self, obs: Observation) -> bool:
        """Tracking starts from any state."""
        return False

    def finished(self, k: int, t: float, obs: Observation) -> bool:
        """Tracking runs to the end."""
        return False

    def reference(self, t: float, obs: Observation | None) -> tuple[np.ndarray, np.ndarray]:
        """The trajectory's pose and velocity at t (s) (the arrays must not be modified)."""
        cached = self._table.get(t)  # the current block of precomputed references
        return cached if cached is not None else self._lookup(t)

    def _lookup(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """A reference not in the current block: the next block, else one evaluation."""
        blocks = self._blocks
        if blocks is not None:
            found = blocks.get(t)
            self._table = blocks.table
            if found is not None:
                return found
        cached = self._cache.get(t)
        if cached is None:
            if len(self._cache) > 4:
                self._cache.clear()
            cached = self._cache[t] = (self._pose(t), self._velocity(t))
        return cached

    def record(self, k, t, obs, command, applied, saturated, info, step_ns) -> None:
        """One row: t, q, u, the desired pose, flags, timing (us)."""
        if isinstance(applied, WheelForces):
            u = _force_equivalent(obs)
        else:
            u = applied.tolist()
        self.rows.append(
            (
                t,
                *obs.values,
                *u,
                obs.v,
                obs.w,
                *self.reference(t, obs)[0].tolist(),
                info.nonholonomic_residual,
                float(info.singular),
                float(saturated),
                float(info.fallback),
                step_ns / 1000.0,
            )
        )
        if self._extra_values is not None:
            self.extra.append(tuple(self._extra_values()))

    def after_step(self, k: int, t: float, obs: Observation, applied: Any) -> bool:
        """Tracking never fails."""
        return False

    def controller_error(self, k: int, error: Exception) -> bool:
        """A controller error is the caller's problem: re-raise."""
        return False

    def diverged(self, k: int, error: PlantDivergedError) -> None:
        """Keep what was recorded; remember where the plant blew up."""
        self.diverged_at = k + 1
        self.diverged_message = str(error).splitlines()[0] if str(error) else "diverged"

    # -- results ----------------------------------------------------------------------------
    def timeseries(self, robot: Robot) -> dict[str, np.ndarray]:
        """Every column of :data:`COLUMNS` (and the plant's), one entry per recorded sample."""
        table = np.array(self.rows, dtype=float).reshape(len(self.rows), len(RECORDED))
        recorded = {name: table[:, i] for i, name in enumerate(RECORDED)}
        derived = derive_columns(robot, recorded)
        series = {name: recorded[name] if name in recorded else derived[name] for name in COLUMNS}
        if self.plant.extra_columns:
            extra = np.array(self.extra, dtype=float).reshape(
                len(self.extra), len(self.plant.extra_columns)
            )
            for i, name in enumerate(self.plant.extra_columns):
                series[name] = extra[:, i]
        return series


class ReferenceBlocks:
    """References at a run's sample and RK4 stage times, computed a block of steps at a
    time through the trajectory's vectorised ``sample(times)``.

    The times are ``k dt``, ``k dt + dt/2`` and ``k dt + dt``, computed as the loop and
    the integrator compute them, so the float keys match exactly. A block of
    :data:`BLOCK` steps costs one ``sample`` call and keeps memory bounded on long runs;
    rows are read-only arrays. A ``sample`` that does not return two ``(len(times), 3)``
    arrays (an unrelated method of that name) switches the blocks off: the task then
    evaluates the trajectory call by call.
    """

    #: Steps per block.
    BLOCK = 4096

    def __init__(self, sample: Any, dt: float, steps: int) -> None:
        self.sample, self.dt, self.steps = sample, dt, steps
        self.enabled = True
        self._block = -1
        #: The current block: ``{t: (pose, velocity)}``.
        self.table: dict[float, tuple[np.ndarray, np.ndarray]] = {}

    def get(self, t: float) -> tuple[np.ndarray, np.ndarray] | None:
        """``(pose, velocity)`` at t (s), or None for a time off the grid."""
        found = self.table.get(t)
        if found is None and self.enabled:
            k = int(t / self.dt + 0.25)  # the step k of k dt and k dt + dt/2 (rounding-proof)
            block = k // self.BLOCK
            if 0 <= k <= self.steps and block != self._block:
                self._load(block)
                found = self.table.get(t)
        return found

    def _load(self, block: int) -> None:
        first = block * self.BLOCK
        start = np.arange(first, min(first + self.BLOCK, self.steps + 1)) * self.dt
        end = start + self.dt  # mostly the next start already: keep those rounding apart
        following = np.append(start[1:], np.nan)
        times = np.concatenate([start, start + 0.5 * self.dt, end[end != following]])
        try:
            poses, velocities = (np.array(part, dtype=float) for part in self.sample(times))
        except (TypeError, ValueError):
            poses = velocities = np.zeros(0)
        if poses.shape != (len(times), 3) or velocities.shape != poses.shape:
            self.enabled, self.table = False, {}
            return
        poses.setflags(write=False)
        velocities.setflags(write=False)
        self._block = block
        self.table = dict(zip(times.tolist(), zip(poses, velocities)))


def _force_equivalent(obs: Observation) -> list[float]:
    """Inputs of a force-commanded sample: measured (v, w); joint rates unknown (NaN)."""
    return [obs.v, obs.w, math.nan, math.nan]


def derive_columns(robot: Robot, ts: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """End-effector pose, errors, wheel speeds, manipulability and stability, vectorised.

    Errors: position ``|p_d - p_E|`` (m), orientation ``phiE_d - phiE`` wrapped to
    [-pi, pi) (rad).
    """
    phi, th1, th2 = ts["phi"], ts["th1"], ts["th2"]
    a1 = phi + th1
    a12 = a1 + th2
    x_e = ts["x"] + robot.L1 * np.cos(a1) + robot.L2 * np.cos(a12)
    y_e = ts["y"] + robot.L1 * np.sin(a1) + robot.L2 * np.sin(a12)
    r, lw = robot.wheel_radius, robot.track_width
    v, w = ts["v"], ts["w"]
    s_lon, s_lat, s = stability_arrays(robot.com_coefficients, th1, th2)
    heading_error = ts["phiE_d"] - a12
    return {
        "xE": x_e,
        "yE": y_e,
        "phiE": a12,
        "position_error_m": np.hypot(ts["xE_d"] - x_e, ts["yE_d"] - y_e),
        "orientation_error_rad": np.mod(heading_error + math.pi, 2.0 * math.pi) - math.pi,
        "wheel_left_rad_s": (2.0 * v - lw * w) / (2.0 * r),
        "wheel_right_rad_s": (2.0 * v + lw * w) / (2.0 * r),
        "manipulability": np.abs(np.sin(th2)),
        "stability_lon": s_lon,
        "stability_lat": s_lat,
        "stability": s,
    }
