"""What to run, and running it: :class:`CompareConfig`, :class:`RunSpec` and
:class:`RunOutput`, the :class:`Plan` of runs per report section (main comparison under the
chosen preset, the same under the other preset, the effect of each preset setting alone,
explanatory variants, studies) and :func:`execute` (serial or in worker processes).

Presets (:mod:`ddwmmr.controllers.presets`) enter the runs as options: a run under the
``slides`` preset carries exactly the options whose slides value differs from the
method's default, so a method the presets treat alike runs once and serves both rankings.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import as_completed
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ddwmmr.controllers.base import make_controller
from ddwmmr.controllers.presets import PRESETS, check_preset, preset_differences
from ddwmmr.errors import ParameterError, shown
from ddwmmr.model import Robot
from ddwmmr.plants import available_plants, make_plant
from ddwmmr.progress import ProgressBar
from ddwmmr.reports.compare.constants import (
    CORNER_TRAJECTORY,
    DEFAULT_TRAJECTORIES,
    OFFSET_SCALES,
    STEP_SIZES,
    STUDIES,
    STUDY_TRAJECTORY,
    TAUS,
    VARIANTS,
)
from ddwmmr.resolution.reference import (
    default_offset,
    offset_configuration,
    start_configuration,
)
from ddwmmr.sim.simulate import engine_multiple, simulate
from ddwmmr.trajectories.base import resolution_step
from ddwmmr.workers import process_pool

# -- configuration and plan ---------------------------------------------------------------

#: Longest trajectory name of a report: it becomes part of file names such as
#: ``plant_mujoco_<name>.png``, which must stay well under the 255 bytes a file name has.
MAX_REPORT_NAME = 100
#: A report name: letters, digits, ``_``, ``-`` and inner dots (a file name on any system,
#: a Markdown link target, no path).
_REPORT_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")


def report_name(name: str) -> str:
    """``name`` made a report name: every character other than a letter, a digit, ``_``,
    ``-`` or ``.`` becomes ``_`` (a leading dot too, and ``..`` becomes ``__``), cut to
    :data:`MAX_REPORT_NAME` characters; a valid one is returned unchanged."""
    safe = re.sub(r"[^A-Za-z0-9_.-]", "_", str(name)).replace("..", "__")
    safe = "_" + safe[1:] if safe[:1] in (".", "-", "") else safe
    return safe[:MAX_REPORT_NAME]


def check_report_name(name: Any) -> str:
    """``name`` if it is a report name (:func:`report_name` leaves it as it is), else
    :class:`ParameterError` before any run (it names files the report writes)."""
    if not (
        isinstance(name, str)
        and len(name) <= MAX_REPORT_NAME
        and _REPORT_NAME.fullmatch(name)
        and ".." not in name
    ):
        raise ParameterError(
            f"trajectory name {shown(name)} cannot name the report's files: use letters, "
            f"digits, _, - and inner dots, at most {MAX_REPORT_NAME} characters "
            f"(e.g. {report_name(str(name))[:40]!r})"
        )
    return name


@dataclass
class CompareConfig:
    """What to compare.

    Attributes:
        methods: registered method names.
        trajectories: name -> trajectory object, in report order.
        robot: the robot every run uses.
        duration: simulated time per run (s); None = one period of each trajectory.
        studies: studies to run (subset of :data:`STUDIES`).
        study_methods: methods the studies run. Default: the compared methods except
            those whose controller class sets ``in_studies = False`` (a slow method, such
            as an MPC, is then compared and ranked but not swept); naming it here
            includes it.
        command: the command line, quoted in the report so it can be reproduced.
        command_note: what ``command`` needs besides, shown after it (a plug-in a script
            registered: :func:`ddwmmr.registry.script_note`); empty for none.
        preset: the option preset of the main comparison and the studies (``"default"``
            or ``"slides"``); the report also ranks the methods under the other one.
        plants: extra plants (``"thesis"``, ``"mujoco"``) on which the main comparison is
            repeated, next to the kinematic plant (section "Plants").
        options: method -> the user's options of that method (``--option``), over the
            preset's values in every run of it; a study's own setting (e.g. the swept
            tau) still wins in that study. Values must be hashable (tuples, not lists).
        shown_names: trajectory key -> the name the reports, ``metrics.csv`` and the
            console show for it (the trajectory's own name, any text); a key missing here
            is shown as itself. The keys stay the file-safe names of the figure files.
    """

    methods: tuple[str, ...]
    trajectories: dict[str, Any]
    robot: Robot = field(default_factory=Robot)
    duration: float | None = None
    studies: tuple[str, ...] = STUDIES
    study_methods: tuple[str, ...] | None = None
    command: str = ""
    command_note: str = ""
    preset: str = "default"
    plants: tuple[str, ...] = ()
    options: dict[str, dict[str, Any]] = field(default_factory=dict)
    shown_names: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_preset(self.preset)
        for name in self.trajectories:
            check_report_name(name)
        for name, text in self.shown_names.items():
            if name not in self.trajectories or not isinstance(text, str):
                raise ParameterError(
                    f"shown_names must map trajectory keys ({', '.join(self.trajectories)}) "
                    f"to text (got {shown(name)}: {shown(text)})"
                )
        for plant in self.plants:
            if plant not in available_plants() or plant == "kinematic":
                others = [p for p in available_plants() if p != "kinematic"]
                raise ParameterError(
                    f"plant must be one of {', '.join(others)} (the kinematic plant always "
                    f"runs) (got {plant!r})"
                )
        self.study_methods = self.studied  # the default resolved once, here

    @property
    def studied(self) -> tuple[str, ...]:
        """The methods the studies run: ``study_methods``, or where it is None (its
        default, resolved at construction and again if set back to None) the compared
        methods that run in the studies (:func:`in_studies`)."""
        if self.study_methods is None:
            self.study_methods = tuple(m for m in self.methods if in_studies(m))
        return self.study_methods

    def shown(self, name: str) -> str:
        """The shown name of trajectory key ``name`` (see ``shown_names``)."""
        return self.shown_names.get(name, name)

    @property
    def other_preset(self) -> str:
        """The preset the report compares the main one with."""
        return next(p for p in PRESETS if p != self.preset)


def in_studies(method: str) -> bool:
    """Whether ``method`` runs in the studies by default (class attribute ``in_studies``)."""
    return bool(getattr(make_controller(method, Robot()), "in_studies", True))


@dataclass(frozen=True)
class RunSpec:
    """One simulation: method (+ options) on a trajectory with a step, integrator, offset
    (dx, dy) in m in the end effector's start frame (None: the robot's default,
    :func:`~ddwmmr.resolution.reference.default_offset`; :func:`main_spec` writes it out,
    so equal runs have equal specs)."""

    method: str
    trajectory: str
    dt: float
    integrator: str | None = "rk4"
    initial_offset: tuple[float, float] | None = None
    options: tuple[tuple[str, Any], ...] = ()
    #: The plant (``integrator`` is the kinematic plant's; None on the others).
    plant: str = "kinematic"

    def label(self) -> str:
        """Short text such as ``ap (K3=0)``."""
        extra = ", ".join(
            f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in self.options
        )
        return f"{self.method} ({extra})" if extra else self.method


@dataclass
class RunOutput:
    """What a run returns to the report: its summary and its time series."""

    summary: dict[str, Any]
    timeseries: dict[str, np.ndarray]


@dataclass
class Plan:
    """Runs per report section (a run needed by two sections is listed in both)."""

    main: list[RunSpec]
    variants: list[RunSpec] = field(default_factory=list)
    studies: dict[str, list[RunSpec]] = field(default_factory=dict)
    #: The main runs under the other preset (same order as ``main``).
    alternative: list[RunSpec] = field(default_factory=list)
    #: The default settings with one slides setting applied, for methods whose runs under
    #: the two presets differ in more than one setting (:func:`effect_settings`).
    preset_effects: list[RunSpec] = field(default_factory=list)
    #: The main runs repeated on each extra plant (``--plant``), same order as ``main``.
    plants: dict[str, list[RunSpec]] = field(default_factory=dict)

    def all_specs(self) -> list[RunSpec]:
        """Every distinct run, in a fixed order (so results never depend on scheduling)."""
        seen: dict[RunSpec, None] = {}
        sections = [self.main, self.alternative, self.preset_effects, self.variants]
        sections += list(self.plants.values())
        sections += list(self.studies.values())
        for spec in (s for section in sections for s in section):
            seen.setdefault(spec, None)
        return list(seen)


def default_step(trajectory: Any) -> float:
    """The simulation's default step (s) on the kinematic plant: the trajectory's
    :func:`~ddwmmr.trajectories.base.resolution_step`."""
    return resolution_step(trajectory)


def run_duration(config: CompareConfig, name: str) -> float:
    """Simulated time (s) of runs on trajectory ``name``."""
    return config.duration if config.duration is not None else config.trajectories[name].duration


def preset_changes(method: str, preset: str) -> tuple[tuple[str, Any], ...]:
    """Run options of ``preset`` for ``method``: the values that differ from its defaults."""
    if preset == "default":
        return ()
    return tuple((key, slides) for key, (slides, _) in preset_differences(method).items())


def run_differences(method: str, options: Mapping[str, Any]) -> dict[str, tuple[Any, Any]]:
    """The settings in which the runs of ``method`` under the two presets differ: name ->
    (slides, default) for each :func:`~ddwmmr.controllers.presets.preset_differences`
    entry that the user's ``options`` of the method (``--option``) leave unset (a setting
    the user gives is the same in every run of the method)."""
    return {k: v for k, v in preset_differences(method).items() if k not in options}


def main_spec(
    config: CompareConfig, method: str, name: str, *, preset: str | None = None, **changes: Any
) -> RunSpec:
    """The comparison's standard run of ``method`` on ``name`` with ``changes`` applied.

    ``preset`` defaults to the config's; the config's ``options`` of the method override
    its values, and ``options`` in ``changes`` override both. The run starts at the
    robot's default offset (:func:`~ddwmmr.resolution.reference.default_offset`) unless
    ``changes`` give ``initial_offset``.
    """
    options = dict(preset_changes(method, config.preset if preset is None else preset))
    options.update(config.options.get(method, {}))
    options.update(changes.pop("options", ()))
    spec = {
        "dt": default_step(config.trajectories[name]),
        "initial_offset": default_offset(config.robot),
        **changes,
    }
    return RunSpec(method, name, options=tuple(options.items()), **spec)


def effect_settings(config: CompareConfig, method: str, name: str) -> list[tuple[str, RunSpec]]:
    """(setting, run) per setting of :func:`run_differences`: the default preset and the
    user's options with that one slides setting applied; none when the runs under the two
    presets differ in fewer than two settings (the one setting alone is the slides run)."""
    differences = run_differences(method, config.options.get(method, {}))
    if len(differences) < 2:
        return []
    return [
        (key, main_spec(config, method, name, preset="default", options=((key, slides),)))
        for key, (slides, _) in differences.items()
    ]


def effect_specs(config: CompareConfig, method: str, name: str) -> list[RunSpec]:
    """The runs of :func:`effect_settings`."""
    return [spec for _, spec in effect_settings(config, method, name)]


def study_tau(config: CompareConfig, method: str, tau: float) -> float | tuple[float, ...]:
    """The ``tau`` option (s) of the tau sweep: ``tau`` on every channel the compared runs
    feed back, i.e. the preset's tau under the user's ``--option`` tau (a channel switched
    off with inf stays off, e.g. the slides' K3 = 0), so the sweep varies the gains of the
    controller the comparison ranks and never switches a channel on or off."""
    compared = dict(preset_changes(method, config.preset))
    compared.update(config.options.get(method, {}))
    base = compared.get("tau")
    if isinstance(base, tuple):
        return tuple(tau if math.isfinite(v) else v for v in base)
    return tau


def accepts_option(method: str, option: str, value: Any) -> bool:
    """Whether the registered ``method`` takes controller option ``option``."""
    try:
        make_controller(method, Robot(), **{option: value})
    except ParameterError:
        return False
    return True


def plan_runs(config: CompareConfig) -> Plan:
    """The runs the report needs: main comparison, explanatory variants, studies."""
    names = list(config.trajectories)
    plan = Plan(main=[main_spec(config, m, n) for n in names for m in config.methods])
    plan.alternative = [
        main_spec(config, m, n, preset=config.other_preset) for n in names for m in config.methods
    ]
    plan.preset_effects = [
        spec for n in names for m in config.methods for spec in effect_specs(config, m, n)
    ]
    plan.variants = [
        main_spec(config, method, n, options=options)
        for method, options in VARIANTS
        if method in config.methods
        for n in names
        if n in DEFAULT_TRAJECTORIES
    ]
    engines = {plant: make_plant(plant, config.robot) for plant in config.plants}
    plan.plants = {
        plant: [
            # a physics plant's control step must be a whole multiple of its engine step
            replace(spec, plant=plant, integrator=None, dt=engine_multiple(spec.dt, engine))
            for spec in plan.main
        ]
        for plant, engine in engines.items()
    }
    builders: dict[str, Callable[[CompareConfig], list[RunSpec]]] = {
        "tau": _plan_tau,
        "dt": _plan_dt,
        "integrator": _plan_integrator,
        "init": _plan_init,
        "corners": lambda c: [],  # uses the main rectangle runs
    }
    for study in config.studies:
        if _study_possible(config, study):
            plan.studies[study] = builders[study](config)
    return plan


def study_trajectory(study: str) -> str:
    """The trajectory a study runs on (the corner study the rectangle, the others the
    ellipse)."""
    return CORNER_TRAJECTORY if study == "corners" else STUDY_TRAJECTORY


def _study_possible(config: CompareConfig, study: str) -> bool:
    return study_trajectory(study) in config.trajectories


def skipped_studies(config: CompareConfig, plan: Plan) -> dict[str, str]:
    """Study -> the trajectory it needs, for each requested study (``config.studies``,
    every one by default) that ``plan`` leaves out because that trajectory is not compared
    (``--only``/``--traj``)."""
    return {study: study_trajectory(study) for study in config.studies if study not in plan.studies}


def tau_methods(config: CompareConfig) -> list[str]:
    """Selected methods with a closed-loop time constant option ``tau``."""
    return [m for m in config.studied if accepts_option(m, "tau", 1.0)]


def _plan_tau(config: CompareConfig) -> list[RunSpec]:
    names = [n for n in (STUDY_TRAJECTORY, CORNER_TRAJECTORY) if n in config.trajectories]
    return [
        main_spec(config, m, n, options=(("tau", study_tau(config, m, tau)),))
        for m in tau_methods(config)
        for n in names
        for tau in TAUS
    ]


def study_steps(config: CompareConfig) -> list[float]:
    """Steps of the dt sweep that fit at least ten times in the run."""
    duration = run_duration(config, STUDY_TRAJECTORY)
    return [dt for dt in STEP_SIZES if dt <= duration / 10]


def _plan_dt(config: CompareConfig) -> list[RunSpec]:
    # No initial offset: every error left is numerical drift.
    return [
        main_spec(config, m, STUDY_TRAJECTORY, dt=dt, integrator=i, initial_offset=(0.0, 0.0))
        for m in config.studied
        for i in ("euler", "rk4")
        for dt in study_steps(config)
    ]


def _plan_integrator(config: CompareConfig) -> list[RunSpec]:
    return [
        main_spec(config, m, STUDY_TRAJECTORY, integrator=i, initial_offset=(0.0, 0.0))
        for m in config.studied
        for i in ("euler", "rk4")
    ]


def study_offsets(config: CompareConfig) -> list[tuple[float, float]]:
    """Initial offsets (dx, dy) in m of the offset sweep, multiples of the robot's default
    (:func:`~ddwmmr.resolution.reference.default_offset`), that its arm can reach from the
    start configuration within its joint limits (an arm of other proportions or limits may
    not take the largest ones)."""
    dx, dy = default_offset(config.robot)
    start = start_configuration(config.robot, config.trajectories[STUDY_TRAJECTORY])
    offsets = []
    for scale in OFFSET_SCALES:
        try:
            q = offset_configuration(config.robot, start, (scale * dx, scale * dy))
        except ParameterError:
            continue
        if config.robot.joints_outside(q) is None:  # else the run's start check refuses it
            offsets.append((scale * dx, scale * dy))
    return offsets


def _plan_init(config: CompareConfig) -> list[RunSpec]:
    return [
        main_spec(config, m, STUDY_TRAJECTORY, initial_offset=offset)
        for m in config.studied
        for offset in study_offsets(config)
    ]


# -- execution ----------------------------------------------------------------------------


def run_one(task: tuple[Robot, Any, float | None, RunSpec]) -> RunOutput:
    """Simulate one :class:`RunSpec` (module level, so worker processes can run it)."""
    robot, trajectory, duration, spec = task
    # built here, not by simulate(): a controller option may share a name with one of
    # simulate's own keywords (the qp's and the mpc's ``dt``)
    controller = make_controller(spec.method, robot, **dict(spec.options))
    result = simulate(
        robot,
        trajectory,
        controller,
        dt=spec.dt,
        duration=duration,
        integrator=spec.integrator,
        initial_offset=spec.initial_offset,
        plant=spec.plant,
    )
    return RunOutput(dict(result.summary), dict(result.timeseries))


def execute(
    config: CompareConfig, specs: Sequence[RunSpec], jobs: int = 1, progress: bool = False
) -> dict[RunSpec, RunOutput]:
    """Run every spec, in ``jobs`` worker processes when ``jobs > 1``.

    Each run is deterministic and independent, so the outputs do not depend on ``jobs``
    (only the wall-clock timings such as ``median_step_us`` vary).
    """
    # Longest runs first keeps every worker busy to the end; the order never changes results.
    queue = sorted(specs, key=lambda s: -estimated_cost(config, s))
    tasks = [(config.robot, config.trajectories[s.trajectory], config.duration, s) for s in queue]
    outputs: dict[RunSpec, RunOutput] = {}
    with ProgressBar(len(tasks), "compare: runs", enabled=progress) as bar:
        if jobs <= 1:
            for spec, task in zip(queue, tasks):
                outputs[spec] = run_one(task)
                bar.advance()
        else:
            with process_pool(jobs) as pool:
                futures = {pool.submit(run_one, task): spec for spec, task in zip(queue, tasks)}
                try:
                    for future in as_completed(futures):
                        outputs[futures[future]] = future.result()
                        bar.advance()
                except BaseException:
                    pool.shutdown(cancel_futures=True)
                    raise
    return {spec: outputs[spec] for spec in specs}


def estimated_cost(config: CompareConfig, spec: RunSpec) -> float:
    """Rough relative cost of a run: its number of controller calls (RK4 calls 4 a step);
    a physics step costs about as much as four."""
    calls = 4 if spec.integrator == "rk4" or spec.plant == "mujoco" else 1
    return run_duration(config, spec.trajectory) / spec.dt * calls
