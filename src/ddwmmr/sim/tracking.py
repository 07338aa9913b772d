"""The tracking task: follow a desired end-effector trajectory, record every sample.

:class:`TrackingTask` feeds :func:`ddwmmr.sim.loop.run_loop` the trajectory's pose and
velocity and records, per sample, only what the loop knows cheaply (time, state, applied
input ``v, w, th1dot, th2dot``, the measured base velocities ``v_measured, w_measured``
(which lag the command on plants with dynamics), the desired pose, the controller's flags
and timing, the plant's extra columns).
Everything derived (end-effector pose, errors, wheel speeds, manipulability, stability) is
computed afterwards, vectorised over the run, by :func:`derive_columns`. The wheel speeds
are the base's actual ones: from the measured (v, w) on a plant that takes wheel forces
(its base has dynamics: its velocities are states that lag the command), from the applied
command on a velocity-only plant (the kinematic model, where the command is the motion).
"""

from __future__ import annotations

import math
from typing import Any, NoReturn

import numpy as np

from ddwmmr.commands import FORCE, WheelForces
from ddwmmr.errors import ParameterError, bracketed, finite_values, raise_plugin_error, shown
from ddwmmr.inheritance import defining_class
from ddwmmr.model import Robot
from ddwmmr.model.stability import stability_arrays
from ddwmmr.plants.base import Observation, Plant, PlantDivergedError
from ddwmmr.plants.checked import checked_extra_values
from ddwmmr.trajectories.base import Trajectory, sample_each, sampler, trajectory_name
from ddwmmr.trajectories.scaled import ScaledTrajectory
from ddwmmr.user_warnings import warn_user

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
        capacity = 0 if grid is None else int(grid[1]) + 1
        self.rows = RowStore(len(RECORDED), capacity)
        self.extra = RowStore(len(plant.extra_columns), capacity if plant.extra_columns else 0)
        self.diverged_at: int | None = None
        self.diverged_message = ""
        self._pose = trajectory.pose
        self._velocity = trajectory.velocity
        # Reference cache: RK4 asks twice at t + dt/2, and the recorder again at t.
        self._cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        sample = sampler(trajectory)
        self._blocks = None if grid is None or sample is None else ReferenceBlocks(sample, *grid)
        self._table: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self._extra_values = checked_extra_values(plant) if plant.extra_columns else None

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

    def record(
        self,
        k: int,
        t: float,
        obs: Observation,
        command: Any,
        applied: Any,
        saturated: bool,
        info: Any,
        step_ns: int,
    ) -> None:
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
        table = self.rows.array()
        recorded = {name: table[:, i] for i, name in enumerate(RECORDED)}
        measured = FORCE in self.plant.interfaces
        derived = derive_columns(robot, recorded, measured_wheels=measured)
        series = {name: recorded[name] if name in recorded else derived[name] for name in COLUMNS}
        if self.plant.extra_columns:
            extra = self.extra.array()
            for i, name in enumerate(self.plant.extra_columns):
                series[name] = extra[:, i]
        return series


class RowStore:
    """Rows of ``width`` numbers, appended one per sample, kept as one float64 array.

    A tuple of Python floats costs about 35 bytes per number, an array 8: rows are
    gathered :data:`BLOCK` at a time and converted together, by
    ``np.array(rows, dtype=float)`` (each number as ``float`` converts it), into a table
    allocated for ``capacity`` rows (grown when a run records more), so a long run holds
    at most one block of tuples. Appending is a list append: the step loop pays nothing
    more per sample.
    """

    #: Rows gathered before they are converted into the table.
    BLOCK = 4096

    def __init__(self, width: int, capacity: int = 0) -> None:
        self.width = width
        self._table = np.empty((max(capacity, 0), width))
        self._count = 0
        self._pending: list[tuple[float, ...]] = []

    def __len__(self) -> int:
        return self._count + len(self._pending)

    def append(self, row: tuple[float, ...]) -> None:
        """Add one row of ``width`` numbers."""
        self._pending.append(row)
        if len(self._pending) >= self.BLOCK:
            self._flush()

    def array(self) -> np.ndarray:
        """The rows so far, an array of shape ``(len(self), width)`` (a view of the table,
        which later appends leave unchanged)."""
        self._flush()
        return self._table[: self._count]

    def _flush(self) -> None:
        pending = self._pending
        if not pending:
            return
        block = np.array(pending, dtype=float).reshape(len(pending), self.width)
        end = self._count + len(pending)
        if end > len(self._table):
            grown = np.empty((max(end, 2 * len(self._table)), self.width))
            grown[: self._count] = self._table[: self._count]
            self._table = grown
        self._table[self._count : end] = block
        self._count = end
        self._pending = []


class ReferenceBlocks:
    """References at a run's sample and RK4 stage times, computed a block of steps at a
    time through the trajectory's vectorised ``sample(times)``.

    The times are ``k dt``, ``k dt + dt/2`` and ``k dt + dt``, computed as the loop and
    the integrator compute them, so the float keys match exactly. A block of
    :data:`BLOCK` steps costs one ``sample`` call and keeps memory bounded on long runs;
    rows are read-only arrays. A ``sample`` that does not return two ``(len(times), 3)``
    arrays of finite numbers (:func:`sampled_references`: an unrelated method of that name)
    switches the blocks off: the task then evaluates the trajectory call by call.
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
        found = sampled_references(self.sample, times)
        if found is None:
            self.enabled, self.table = False, {}
            return
        poses, velocities = found
        poses.setflags(write=False)
        velocities.setflags(write=False)
        self._block = block
        self.table = dict(zip(times.tolist(), zip(poses, velocities)))


def sampled_references(sample: Any, times: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """``sample(times)`` as new float arrays ``(poses, velocities)``, each of shape
    ``(len(times), 3)``, if it returns that with finite numbers only; else None (an
    unrelated method of that name, or one that does not give the numbers of ``pose`` and
    ``velocity``): the caller then takes ``pose`` and ``velocity`` call by call."""
    try:
        poses, velocities = (np.array(part, dtype=float) for part in sample(times))
    except (TypeError, ValueError, OverflowError):
        return None
    if poses.shape != (len(times), 3) or velocities.shape != poses.shape:
        return None
    if not (np.all(np.isfinite(poses)) and np.all(np.isfinite(velocities))):
        return None
    return poses, velocities


#: What a trajectory's ``pose(t)`` and ``velocity(t)`` return (docs/api.md, "Trajectories").
_RETURNS = {
    "pose": "[xE, yE, phiE] (m, m, rad)",
    "velocity": "[xEdot, yEdot, phiEdot] (m/s, m/s, rad/s)",
}


def reference_values(value: Any, method: str, t: float) -> np.ndarray:
    """What the trajectory's ``method`` (``"pose"`` or ``"velocity"``) returned at time t
    (s), as a float array of shape (3,): any sequence of 3 finite numbers (a float64 array
    as it is); anything else (None, 2 values, text, NaN) is a one-line
    :class:`ParameterError` naming the method and t."""
    array = finite_values(value, 3)
    if array is None:
        raise ParameterError(
            f"trajectory {method}(t) must return 3 finite numbers {_RETURNS[method]} (got "
            f"{shown(value, 60)} at t = {t:g} s)"
        )
    return array


class CheckedTrajectory:
    """A trajectory written outside the library, as a simulation's consumers (the tracking
    task, the controllers' ``reset``, the start configuration) see it.

    ``pose(t)`` and ``velocity(t)`` return float arrays of shape (3,) whatever sequence of
    3 finite numbers the trajectory returns (:func:`reference_values`; the same numbers,
    so a list gives the run of the equivalent array), and refuse anything else naming
    ``pose`` or ``velocity``. ``sample(times)``, present if the trajectory has one
    (:func:`~ddwmmr.trajectories.base.sampler`), returns what the trajectory's returns if
    that is what ``sample`` promises (:func:`sampled_references`), else ``pose`` and
    ``velocity`` call by call. Two spot checks at :func:`spot_times` warn of a trajectory
    that breaks its contract (docs/api.md, "Trajectories"): a ``sample`` whose numbers are
    not those of ``pose`` and ``velocity`` (:func:`_sample_agrees`) is then not used, and
    a ``velocity`` that is not the time derivative of ``pose`` (:func:`_check_derivative`)
    is used as it is (nothing better is known). Every other attribute (``duration``,
    ``samples``, ``name``, the trajectory's own) is the trajectory's; ``trajectory`` is
    the trajectory itself.

    Anything else the trajectory's ``pose``, ``velocity`` or ``sample`` raise becomes a
    one-line :class:`~ddwmmr.errors.PluginError` "trajectory: <name>.<method>() raised
    <type>: '<message>' at t = <t> s" (:func:`~ddwmmr.errors.plugin_raised`, as for a
    plug-in controller or plant; the exception it raised is the ``__cause__``); a
    ParameterError or PluginError it raises passes as it is.
    """

    def __init__(self, trajectory: Any) -> None:
        self.trajectory = trajectory
        own = sampler(trajectory)
        times = spot_times(trajectory)
        if own is not None and times is not None and not _sample_agrees(self, own, times):
            own = None  # pose and velocity define the trajectory; sample only speeds it up
        if own is not None:
            self._own_sample: Any = own
            # an instance attribute: sampler() takes it as the trajectory's own word
            self.sample = self._sample
        if times is not None:
            _check_derivative(self, times[1:-1])

    def __getattr__(self, name: str) -> Any:
        # Only for names the wrapper lacks. Not ``sample`` (the trajectory's would bypass
        # the check) nor dunders (copy and pickle look for them before __init__ runs).
        trajectory = self.__dict__.get("trajectory")
        if trajectory is None or name == "sample" or name.startswith("__"):
            raise AttributeError(name)
        return getattr(trajectory, name)

    def pose(self, t: float) -> np.ndarray:
        """Desired pose ``[xE, yE, phiE]`` (m, m, rad) at time t (s)."""
        try:
            value = self.trajectory.pose(t)
        except Exception as error:
            self._raised("pose", error, f" at t = {t:g} s")
        return reference_values(value, "pose", t)

    def velocity(self, t: float) -> np.ndarray:
        """Desired velocity ``[xEdot, yEdot, phiEdot]`` (m/s, m/s, rad/s) at time t (s)."""
        try:
            value = self.trajectory.velocity(t)
        except Exception as error:
            self._raised("velocity", error, f" at t = {t:g} s")
        return reference_values(value, "velocity", t)

    def _raised(self, method: str, error: Exception, where: str) -> NoReturn:
        """Raise the one-line error for ``error``, raised by the trajectory's ``method``
        (``where``: the time of the call; called from the ``except`` block)."""
        call = f"trajectory: {trajectory_name(self.trajectory)}.{method}()"
        raise_plugin_error(call, error, where, quoted=True)

    def _sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Poses and velocities at ``times`` (s), arrays of shape ``(len(times), 3)``."""
        own = self._own_sample
        if own is not None:
            try:
                found = sampled_references(own, times)
            except Exception as error:
                every = np.ravel(times)
                span = f"{every.min():g} to {every.max():g}" if every.size else "none"
                self._raised("sample", error, f" at t = {span} s")
            if found is not None:
                return found
            self._own_sample = None  # not the vectorised reference: call by call from now on
        return sample_each(self, times)


#: Shares of the duration at which :class:`CheckedTrajectory` spot-checks a trajectory:
#: both ends and six times between, off the simple fractions where a path's corners lie.
SPOT_FRACTIONS = (0.0, 0.137, 0.291, 0.433, 0.577, 0.719, 0.863, 1.0)
#: Relative and absolute tolerance of ``sample`` against ``pose`` and ``velocity`` (m,
#: rad, m/s, rad/s): "to rounding", as the trajectory protocol asks.
SAMPLE_TOLERANCE = 1e-9
#: Relative tolerance of ``velocity`` against the central difference of ``pose`` over
#: +-:data:`DIFFERENCE_STEP` x duration (whose truncation and rounding errors are far
#: smaller): a velocity off by more than 5 % is no derivative.
DERIVATIVE_TOLERANCE = 0.05
#: Half-width of that central difference, as a share of the duration.
DIFFERENCE_STEP = 1e-6


def spot_times(trajectory: Any) -> np.ndarray | None:
    """The times (s) :data:`SPOT_FRACTIONS` of the trajectory's ``duration``, or None when
    the duration is not a finite number > 0 (the run refuses it with its own message)."""
    duration: Any = getattr(trajectory, "duration", None)
    number = isinstance(duration, int | float | np.integer | np.floating)
    if not number or isinstance(duration, bool) or not 0.0 < float(duration) < math.inf:
        return None
    return np.array(SPOT_FRACTIONS) * float(duration)


def _sample_agrees(checked: CheckedTrajectory, sample: Any, times: np.ndarray) -> bool:
    """Whether ``sample(times)`` gives the numbers of ``pose`` and ``velocity`` to
    :data:`SAMPLE_TOLERANCE` (True too if it fails or returns no such arrays: the run
    then takes pose and velocity call by call anyway, or reports the trajectory's own
    error). On a disagreement, a one-line ``UserWarning``: the run takes ``pose`` and
    ``velocity`` call by call, which define the trajectory (the start pose among them),
    rather than refusing a trajectory that can still be followed, only slower."""
    try:
        found = sampled_references(sample, times)
        wanted = [(checked.pose(t), checked.velocity(t)) for t in times.tolist()]
    except Exception:  # the run meets it again and reports it as it always does
        return True
    if found is None:
        return True
    for index, (pose, velocity) in enumerate(wanted):
        for own, what, name in (
            (pose, found[0][index], "pose"),
            (velocity, found[1][index], "velocity"),
        ):
            if not np.allclose(what, own, rtol=SAMPLE_TOLERANCE, atol=SAMPLE_TOLERANCE):
                warn_user(
                    f"trajectory {_name(checked)}: sample(times) disagrees with {name}(t) at "
                    f"t = {times[index]:g} s ({_numbers(what)} vs {_numbers(own)}); simulating "
                    "with pose(t) and velocity(t) call by call instead (slower): make sample "
                    "give their numbers"
                )
                return False
    return True


def _check_derivative(checked: CheckedTrajectory, times: np.ndarray) -> None:
    """Warn (one line, ``UserWarning``) when ``velocity(t)`` differs from the central
    difference of ``pose`` by more than :data:`DERIVATIVE_TOLERANCE` of either, in some
    component, at more than half of ``times`` (s): a velocity that is no derivative (a
    factor, a sign, a unit). A single time may lie on a corner of the path (a rectangle's
    heading jumps there), so one disagreement is no proof. The heading's difference is
    wrapped to [-pi, pi) (a pose may give atan2's wrapped angle)."""
    h = DIFFERENCE_STEP * float(checked.duration)
    try:
        pairs = [
            (checked.velocity(t), checked.pose(t - h), checked.pose(t + h)) for t in times.tolist()
        ]
    except Exception:  # the run meets it again and reports it as it always does
        return
    bad = []
    for t, (velocity, before, after) in zip(times.tolist(), pairs):
        step = after - before
        step[2] = (step[2] + math.pi) % (2.0 * math.pi) - math.pi
        difference = step / (2.0 * h)
        # rounding of the two poses, magnified by the division: far below any real speed
        noise = 1e-6 + 1e3 * np.finfo(float).eps * (np.abs(before) + np.abs(after)) / h
        scale = DERIVATIVE_TOLERANCE * np.maximum(np.abs(velocity), np.abs(difference))
        if np.any(np.abs(velocity - difference) > scale + noise):
            bad.append((t, velocity, difference))
    if 2 * len(bad) > len(times):
        t, velocity, difference = bad[0]
        warn_user(
            f"trajectory {_name(checked)}: velocity(t) is not the time derivative of pose(t) "
            f"at {len(bad)} of {len(times)} checked times (t = {t:g} s: {_numbers(velocity)} vs "
            f"{_numbers(difference)} from pose); the open-loop methods integrate velocity, so "
            "the run follows another path"
        )


def _name(checked: CheckedTrajectory) -> str:
    return trajectory_name(checked.trajectory)


def _numbers(values: np.ndarray) -> str:
    return bracketed(values.tolist(), ".4g")


#: Where the library's trajectories are defined: their ``pose`` and ``velocity`` return
#: float arrays of 3 finite numbers by construction (their parameters are checked).
_LIBRARY = "ddwmmr.trajectories."


def checked_trajectory(trajectory: Any) -> Any:
    """``trajectory`` as a simulation's consumers see it: the library's own (an
    :class:`~ddwmmr.trajectories.Ellipse`, ``Rectangle`` or ``SampledTrajectory`` whose
    ``pose``, ``velocity`` and ``sample`` are the library's) as it is, so that nothing is
    added to their steps; any other in a :class:`CheckedTrajectory`. A library wrapper of
    another trajectory (a :class:`~ddwmmr.trajectories.ScaledTrajectory`) is the library's
    only if what it wraps is; else it scales what it wraps, checked (a wrong value is
    refused as it is without the scale, not broadcast by the scaling)."""
    if isinstance(trajectory, CheckedTrajectory):
        return trajectory
    if isinstance(trajectory, ScaledTrajectory):
        inner = trajectory.trajectory
        checked = checked_trajectory(inner)
        return trajectory if checked is inner else ScaledTrajectory(checked, trajectory.scale)
    instance = getattr(trajectory, "__dict__", {})
    for name in ("pose", "velocity", "sample"):
        owner = defining_class(type(trajectory), name)
        if owner is None and name == "sample":
            continue
        library = owner is not None and owner is not Trajectory
        if name in instance or not (library and owner.__module__.startswith(_LIBRARY)):
            return CheckedTrajectory(trajectory)
    return trajectory


def _force_equivalent(obs: Observation) -> list[float]:
    """Inputs of a force-commanded sample: measured (v, w); joint rates unknown (NaN)."""
    return [obs.v, obs.w, math.nan, math.nan]


def derive_columns(
    robot: Robot, ts: dict[str, np.ndarray], measured_wheels: bool = False
) -> dict[str, np.ndarray]:
    """End-effector pose, errors, wheel speeds, manipulability and stability, vectorised.

    Errors: position ``|p_d - p_E|`` (m), orientation ``phiE_d - phiE`` wrapped to
    [-pi, pi) (rad). Wheel speeds (rad/s): ``(2 v -+ track_width w) / (2 wheel_radius)``
    of the measured ``v_measured, w_measured`` with ``measured_wheels`` (a plant whose base
    has dynamics), else of the applied ``v, w``.
    """
    phi, th1, th2 = ts["phi"], ts["th1"], ts["th2"]
    a1 = phi + th1
    a12 = a1 + th2
    x_e = ts["x"] + robot.L1 * np.cos(a1) + robot.L2 * np.cos(a12)
    y_e = ts["y"] + robot.L1 * np.sin(a1) + robot.L2 * np.sin(a12)
    r, lw = robot.wheel_radius, robot.track_width
    v, w = (ts["v_measured"], ts["w_measured"]) if measured_wheels else (ts["v"], ts["w"])
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
