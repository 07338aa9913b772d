"""The app's settings and how they become a run of :func:`ddwmmr.simulate`.

A :class:`Settings` value is everything the control panel sets. It is immutable: the app
builds a changed copy, checks it with :func:`check_settings`, and only then replaces the
current one, so a bad field never leaves a half-applied setting behind.

Trajectory geometry ``(x0, y0, a, b, beta, N, T)`` (docs/theory.md, "Trajectories") applies
to every trajectory:

* parametric ones (ellipse, rectangle, their TOML files) take the values directly;
* sampled ones (CSV files such as the figure-eight) are placed by the same numbers: their
  samples are scaled so that the bounding box has half-extents (a, b), rotated by beta
  and centred on (x0, y0); their times are stretched to last T. N is the resolution:
  the step defaults to T / N like for the parametric shapes. With the file's own values
  the file's trajectory is used unchanged.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ddwmmr.controllers.base import make_controller
from ddwmmr.errors import (
    DURATION_RANGE_S,
    LENGTH_RANGE_M,
    MAX_ANGLE_RAD,
    MAX_COORDINATE_M,
    MAX_TRAJECTORY_SAMPLES,
    ParameterError,
    check_int_at_least,
    check_positive,
    check_range,
    check_step_count,
    one_of,
    shown,
)
from ddwmmr.gui.options import method_options, plant_keywords, plant_names
from ddwmmr.model import Robot
from ddwmmr.plants.kinematic import INTEGRATORS
from ddwmmr.registry import unknown_hint
from ddwmmr.resolution.reference import default_offset, initial_configuration
from ddwmmr.sim import SimulationResult, simulate
from ddwmmr.sim.simulate import check_start, check_tracks
from ddwmmr.trajectories import SampledTrajectory, load_trajectory
from ddwmmr.trajectories.base import resolution_step
from ddwmmr.trajectories.parametric import check_geometry_value

#: Trajectory geometry parameters, in panel order, with unit and allowed range.
GEOMETRY = (
    ("x0", "m", "any"),
    ("y0", "m", "any"),
    ("a", "m", "> 0"),
    ("b", "m", "> 0"),
    ("beta", "rad", "any"),
    ("N", "-", ">= 2"),
    ("T", "s", "> 0"),
)
#: What each geometry value means, with the range the trajectories accept (the tool's
#: --help; the panel's labels keep GEOMETRY's short form).
GEOMETRY_HELP = {
    "x0": f"centre x in m, world frame (|x0| <= {MAX_COORDINATE_M:g})",
    "y0": f"centre y in m, world frame (|y0| <= {MAX_COORDINATE_M:g})",
    "a": f"semi-axis along the shape's own x in m, in [{LENGTH_RANGE_M[0]:g}, "
    f"{LENGTH_RANGE_M[1]:g}]",
    "b": f"semi-axis along the shape's own y in m, in [{LENGTH_RANGE_M[0]:g}, "
    f"{LENGTH_RANGE_M[1]:g}]",
    "beta": f"rotation of the shape about its centre in rad, counter-clockwise "
    f"(|beta| <= {MAX_ANGLE_RAD:g})",
    "N": f"samples per period, an integer in [2, {MAX_TRAJECTORY_SAMPLES}]",
    "T": f"period in s, in [{DURATION_RANGE_S[0]:g}, {DURATION_RANGE_S[1]:g}]",
}

#: The two method slots: A (always on) and B (side-by-side comparison, may be off).
SLOTS = ("A", "B")
#: The allowed form of :attr:`Settings.methods` and :attr:`Settings.options`, for messages.
METHODS_FORM = "a pair (A, B) of method names, B None for no comparison, e.g. ('clrrmc-ts', None)"
OPTIONS_FORM = "a pair (A's, B's) of option mappings, e.g. ({}, {})"


def _per_slot(name: str, value: Any, form: str) -> tuple[Any, Any]:
    """``value`` as a tuple of one entry per slot of :data:`SLOTS`; a one-line
    :class:`ParameterError` naming ``name`` and ``form`` for a string, a non-sequence or
    another number of entries."""
    if not isinstance(value, tuple | list):  # a string would be read letter by letter
        raise ParameterError(f"{name} must be {form} (got {shown(value)})")
    if len(value) != len(SLOTS):
        raise ParameterError(
            f"{name} must be {form}: {len(SLOTS)} entries (got {len(value)}: {shown(value)})"
        )
    return tuple(value)


@dataclass(frozen=True)
class Settings:
    """Everything one run depends on (units: m, rad, s, kg).

    Attributes:
        trajectory: a trajectory name (``available_trajectories()``) or a file path.
        geometry: geometry values changed from the trajectory's own (see module doc).
        methods: method of slot A and of slot B (None: no comparison), exactly two
            entries (a tuple; a list is taken as one).
        options: per slot (two mappings), the method options changed from their
            defaults.
        plant: plant name (see :func:`ddwmmr.gui.options.plant_names`).
        payload: payload at the end effector (kg).
        integrator: ``rk4`` or ``euler``.
        dt: control step (s); None: T / N.
        duration: simulated time (s); None: one period T.
        offset: initial end-effector offset (dx, dy) (m); default the robot's own
            (:func:`~ddwmmr.resolution.reference.default_offset`; the window's robot is
            the default one).
    """

    trajectory: str = "ellipse"
    geometry: Mapping[str, float] = field(default_factory=dict)
    methods: tuple[str, str | None] = ("clrrmc-ts", None)
    options: tuple[Mapping[str, Any], Mapping[str, Any]] = ({}, {})
    plant: str = "kinematic"
    payload: float = Robot().payload
    integrator: str = "rk4"
    dt: float | None = None
    duration: float | None = None
    offset: tuple[float, float] = default_offset(Robot())

    def __post_init__(self) -> None:
        # Every slot index (widgets, labels, export) assumes one entry per slot: a bare
        # string would be read letter by letter, a third entry would have no slot.
        object.__setattr__(self, "methods", _per_slot("methods", self.methods, METHODS_FORM))
        object.__setattr__(self, "options", _per_slot("options", self.options, OPTIONS_FORM))

    def replace(self, **changes: Any) -> Settings:
        """A copy with ``changes`` applied (not yet checked)."""
        return dataclasses.replace(self, **changes)

    def with_method(self, slot: int, method: str | None) -> Settings:
        """Slot ``slot`` (0 = A, 1 = B) switched to ``method``, with default options."""
        methods = list(self.methods)
        options = list(self.options)
        if methods[slot] != method:
            methods[slot], options[slot] = method, {}
        return self.replace(methods=tuple(methods), options=tuple(options))

    def with_option(self, slot: int, name: str, value: Any) -> Settings:
        """Option ``name`` of slot ``slot`` set to ``value`` (its default drops the entry)."""
        method = self.methods[slot]
        spec = {s.name: s for s in method_options(method)}[name]
        changed = dict(self.options[slot])
        if value == spec.default and type(value) is type(spec.default):
            changed.pop(name, None)
        else:
            changed[name] = value
        options = list(self.options)
        options[slot] = changed
        return self.replace(options=tuple(options))

    def with_geometry(self, name: str, value: float) -> Settings:
        """Geometry parameter ``name`` set to ``value`` (the file's own value drops it)."""
        changed = dict(self.geometry)
        own = geometry_of(load_trajectory(self.trajectory))
        if own.get(name) == value:
            changed.pop(name, None)
        else:
            changed[name] = value
        return self.replace(geometry=changed)

    @property
    def active_slots(self) -> list[int]:
        """Indices of the slots holding a method (A, and B when comparing)."""
        return [i for i, m in enumerate(self.methods) if m is not None]


def geometry_of(trajectory: Any) -> dict[str, float]:
    """The geometry values ``x0, y0, a, b, beta, N, T`` of a trajectory (see module doc).

    Trajectories that are neither parametric nor sampled give only N and T.
    """
    if isinstance(trajectory, SampledTrajectory):
        xy = trajectory.points[:, :2]
        low, high = xy.min(axis=0), xy.max(axis=0)
        centre, half = (low + high) / 2, (high - low) / 2
        return {
            "x0": float(centre[0]),
            "y0": float(centre[1]),
            "a": float(half[0]),
            "b": float(half[1]),
            "beta": 0.0,
            # steps per run at the default step (the rows' spacing, made no coarser
            # than SampledTrajectory.default_step allows): N = T / dt as for the others
            "N": round(trajectory.duration / trajectory.default_step),
            "T": float(trajectory.duration),
        }
    if dataclasses.is_dataclass(trajectory) and all(
        hasattr(trajectory, name) for name, _, _ in GEOMETRY
    ):
        return {name: getattr(trajectory, name) for name, _, _ in GEOMETRY}
    values: dict[str, float] = {"T": float(trajectory.duration)}
    if getattr(trajectory, "samples", None):
        values["N"] = int(trajectory.samples)
    return values


def check_geometry(name: str, value: Any) -> float | int:
    """Validate one geometry value (any input: text is refused naming the allowed range):
    the signs of :data:`GEOMETRY`, then the documented caps of :mod:`ddwmmr.errors` the
    parametric trajectories enforce, so that a sampled trajectory placed by the same
    numbers is refused with a message naming the value."""
    if name == "N":
        return check_int_at_least("N", value, 2, MAX_TRAJECTORY_SAMPLES)
    return check_geometry_value(name, value)


def build_trajectory(settings: Settings) -> Any:
    """The desired trajectory of ``settings`` (the loaded one placed by its geometry)."""
    base = load_trajectory(settings.trajectory)
    changes = {name: check_geometry(name, v) for name, v in settings.geometry.items()}
    if not changes:
        return base
    if isinstance(base, SampledTrajectory):
        own = geometry_of(base)
        for name, axis in (("a", "x"), ("b", "y")):
            if name in changes and own[name] == 0:  # nothing to scale: it would be ignored
                raise ParameterError(
                    f"{name}: {settings.trajectory} does not move along {axis}, so it has no "
                    f"{name} to change (leave {name} at its own value, 0)"
                )
        try:
            return place_samples(base, {**own, **changes})
        except ParameterError as exc:  # the samples' check names no geometry value
            names = ", ".join(name for name, _, _ in GEOMETRY if name in changes)
            raise ParameterError(
                f"{names}: placing the samples of {settings.trajectory} there: {exc}"
            ) from None
    own = geometry_of(base)
    unknown = sorted(set(changes) - set(own) - {"N"})
    if unknown or not dataclasses.is_dataclass(base):
        raise ParameterError(
            f"{unknown[0] if unknown else 'geometry'}: not a parameter of {settings.trajectory}"
        )
    # ignore: changes holds numbers for the shape's own numeric fields (checked above)
    return dataclasses.replace(base, **changes)  # type: ignore[arg-type]


def place_samples(base: SampledTrajectory, geometry: Mapping[str, float]) -> SampledTrajectory:
    """``base`` scaled to half-extents (a, b), rotated by beta about its centre, centred on
    (x0, y0) and stretched in time to last T (a sampled orientation is turned by beta).

    An axis along which the samples do not move keeps its scale (nothing to stretch).
    """
    own = geometry_of(base)
    scale = np.array([geometry[k] / own[k] if own[k] > 0 else 1.0 for k in ("a", "b")])
    c, s = math.cos(geometry["beta"]), math.sin(geometry["beta"])
    rotation = np.array([[c, -s], [s, c]])
    local = (base.points[:, :2] - [own["x0"], own["y0"]]) * scale
    points = local @ rotation.T + [geometry["x0"], geometry["y0"]]
    if base.points.shape[1] == 3:
        points = np.column_stack([points, base.points[:, 2] + geometry["beta"]])
    start = base.times[0]
    times = start + (base.times - start) * (geometry["T"] / own["T"])
    return SampledTrajectory(times, points, name=base.name)


def control_step(settings: Settings, trajectory: Any) -> float | None:
    """The step passed to simulate: the set dt, else T / N when N was changed for a sampled
    trajectory (whose own step is its ``default_step``), else None (simulate's default,
    :func:`resolution_step`)."""
    if settings.dt is not None:
        return settings.dt
    if isinstance(trajectory, SampledTrajectory) and "N" in settings.geometry:
        return trajectory.duration / settings.geometry["N"]
    return None


def build_robot(settings: Settings) -> Robot:
    """The default robot carrying the chosen payload."""
    return Robot().with_payload(settings.payload)


def build_controller(settings: Settings, slot: int) -> Any:
    """The controller of slot ``slot``, built by :func:`make_controller`."""
    return make_controller(
        # ignore: the slots built are active ones, which have a method
        settings.methods[slot],  # type: ignore[arg-type]
        build_robot(settings),
        **dict(settings.options[slot]),
    )


def check_settings(settings: Settings) -> Settings:
    """Raise :class:`ParameterError` if ``settings`` cannot be run; return them unchanged.

    Everything a run needs is built once (trajectory, robot, controllers); what only the
    simulation itself can find (e.g. dt longer than the run) shows when it runs.
    """
    for slot in settings.active_slots:  # as simulate refuses them, with the plug-in hint
        # ignore: an active slot holds a method (None is an inactive slot)
        check_tracks(settings.methods[slot])  # type: ignore[arg-type]
    if settings.methods[0] is None:
        raise ParameterError("method: slot A needs a method")
    if not one_of(settings.plant, plant_names()):
        raise ParameterError(
            f"plant must be one of {', '.join(plant_names())} (got {shown(settings.plant)})"
            + unknown_hint(settings.plant, plant_names())
        )
    if not one_of(settings.integrator, INTEGRATORS):
        raise ParameterError(
            f"integrator must be one of {', '.join(INTEGRATORS)} (got {shown(settings.integrator)})"
        )
    for name in ("dt", "duration"):
        value = getattr(settings, name)
        if value is not None:
            check_positive(name, value)
    if len(settings.offset) != 2:
        raise ParameterError("offset must be two numbers dx, dy in m")
    robot = build_robot(settings)
    for value in settings.offset:
        check_range("offset", value, -robot.reach, robot.reach, "m (the arm's reach)")
    trajectory = build_trajectory(settings)
    start = initial_configuration(robot, trajectory, settings.offset)
    for slot in settings.active_slots:
        controller = build_controller(settings, slot)
        check_start(robot, start, getattr(controller, "obstacles", ()), "payload", "the offset")
    return settings


def check_run_length(settings: Settings) -> int:
    """The number of steps of a run of ``settings`` (:func:`check_step_count`), what
    :func:`check_settings` leaves to the run; a duration shorter than the step is refused
    naming T and N when the step is their T / N (dt not set), a step the user never typed.
    Called by the command line, which refuses bad input before the window is built; the
    window's Run (:func:`simulate_settings`) checks the same by :func:`run_length` on the
    trajectory it runs."""
    return run_length(settings, build_trajectory(settings))


def run_length(settings: Settings, trajectory: Any) -> int:
    """:func:`check_run_length` of ``settings`` whose trajectory, already built by
    :func:`build_trajectory`, is ``trajectory`` (a file is then read once per Run)."""
    duration = trajectory.duration if settings.duration is None else settings.duration
    dt = control_step(settings, trajectory) or resolution_step(trajectory)
    if settings.dt is None and dt > duration:
        samples = trajectory.duration / dt
        raise ParameterError(
            f"duration must be >= one step T/N = {trajectory.duration:g} s / {samples:g} = "
            f"{dt:g} s (got {duration:g}); raise N or duration, lower T, or set dt"
        )
    return check_step_count(duration, dt)


def simulate_settings(
    settings: Settings, progress: Callable[[int, int, int], None] | None = None
) -> list[SimulationResult]:
    """Run every active slot with :func:`ddwmmr.simulate`, A first.

    ``progress(slot_index, step, steps)`` is called after every simulated step.
    """
    trajectory = build_trajectory(settings)
    # simulate would refuse such a run too, but as "dt must be <= duration ... (got T/N)"
    # with a dt the window's blank dt field never showed.
    run_length(settings, trajectory)
    robot = build_robot(settings)
    results = []
    for index, slot in enumerate(settings.active_slots):
        controller = build_controller(settings, slot)

        def report(step: int, steps: int, index: int = index) -> None:
            if progress is not None:
                progress(index, step, steps)

        results.append(
            simulate(
                robot,
                trajectory,
                controller,
                dt=control_step(settings, trajectory),
                duration=settings.duration,
                initial_offset=tuple(settings.offset),
                progress=report,
                # ignore: plant_keywords gives plant= and integrator= only (mypy matches
                # the dict against every keyword, plant_options included)
                **plant_keywords(settings.plant, settings.integrator),  # type: ignore[arg-type]
            )
        )
    return results
