"""Method comparison: run plan, parallel execution, analysis and the report.

``python -m ddwmmr.compare`` (see :mod:`ddwmmr.cli.compare`) runs every registered method on
the same trajectories with the same robot, start configuration, integrator and step, then
writes ``report.md``, a self-contained ``report.html``, ``metrics.csv`` and PNG figures.

Library use::

    config = CompareConfig(methods=("ats", "clrrmc-ts"), trajectories={"ellipse": Ellipse()})
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs(), jobs=2)
    info = write_report(config, plan, outputs, Path("report"))

**Ranking score** (documented in the report): the RMS end-effector position error over the
whole run (m), per trajectory; lower is better. Every method starts from the same
configuration with the same initial offset, so the score rewards removing the offset quickly
and penalises drift. Scores within 5 % (or 0.1 mm) of a better one count as a tie, which is
what the slides' ``>=`` allows. The overall score is the geometric mean over trajectories
(errors span orders of magnitude, so the mean of their logarithms is the fair summary).
"""

from __future__ import annotations

import base64
import csv
import html
import io
import itertools
import math
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ddwmmr.controllers.base import make_controller, method_description
from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.progress import ProgressBar
from ddwmmr.reports import compare_plots as plots
from ddwmmr.resolution.reference import (
    DEFAULT_INITIAL_OFFSET,
    offset_configuration,
    start_configuration,
)
from ddwmmr.sim.result import json_safe, write_atomic
from ddwmmr.sim.simulate import simulate

#: The slides' ranking, best first: CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS >= RR-PI.
SLIDES_ORDER = ("clrrmc-ts", "clrrmc-cs", "ap", "ats", "pi")
#: The slides' names of our methods.
SLIDES_NAMES = {
    "clrrmc-ts": "CLRRMC-TS",
    "clrrmc-cs": "CLRRMC-CS",
    "ap": "RR-AP",
    "ats": "RR-ATS",
    "pi": "RR-PI",
}
#: Studies selectable with ``--study`` (``all`` selects every one).
STUDIES = ("tau", "dt", "integrator", "init", "corners")
#: Trajectories every comparison includes; the studies use them.
DEFAULT_TRAJECTORIES = ("ellipse", "rectangle")
STUDY_TRAJECTORY = "ellipse"
CORNER_TRAJECTORY = "rectangle"
#: Relative and absolute (m) tolerance under which two scores count as a tie.
TIE_RELATIVE = 0.05
TIE_ABSOLUTE_M = 1e-4
#: Time constants (s) of the tau sweep.
TAUS = (0.1, 0.3, 1.0, 3.0)
#: Steps (s) of the step-size sweep.
STEP_SIZES = (0.01, 0.02, 0.04, 0.08, 0.16)
#: Initial offsets of the offset sweep, as multiples of the default offset (3 cm, -3 cm).
OFFSET_SCALES = (0.0, 0.5, 1.0, 2.0, 4.0)
#: Converged = the position error stays below this fraction of its initial value.
CONVERGED_FRACTION = 0.05
#: |cos th1| below this counts as reaching the shoulder singularity cos(th1) = 0.
SINGULAR_COS = 0.05
#: A run counts as lost at the singularity if its error afterwards exceeds twice the largest
#: error before it and this many metres (a QP on u passes cos(th1) = 0 unharmed).
SINGULAR_LOSS_M = 0.05
#: Extra runs that explain the ranking: (method, options) checked when the method runs.
VARIANTS = (("ap", (("K3", 0.0),)), ("ats", (("aux", "sum"),)))
#: Summary keys that are wall-clock timings (vary run to run; excluded from equality tests).
TIMING_KEYS = ("median_step_us",)
#: Marker file that identifies an output folder of this tool (so it may be replaced).
MARKER = "metrics.csv"


def slides_name(method: str) -> str:
    """The slides' name of ``method`` (``RR-PI``...), or the method name itself."""
    return SLIDES_NAMES.get(method, method)


def is_timing(key: str) -> bool:
    """True for summary keys that are wall-clock timings (not reproducible)."""
    return key in TIMING_KEYS or key.endswith("_us")


# -- configuration and plan ---------------------------------------------------------------


@dataclass
class CompareConfig:
    """What to compare.

    Attributes:
        methods: registered method names.
        trajectories: name -> trajectory object, in report order.
        robot: the robot every run uses.
        duration: simulated time per run (s); None = one period of each trajectory.
        studies: studies to run (subset of :data:`STUDIES`).
        study_methods: methods the studies run (default: ``methods``); sweeping fewer
            saves time when a method is slow.
        command: the command line, quoted in the report so it can be reproduced.
    """

    methods: tuple[str, ...]
    trajectories: dict[str, Any]
    robot: Robot = field(default_factory=Robot)
    duration: float | None = None
    studies: tuple[str, ...] = STUDIES
    study_methods: tuple[str, ...] | None = None
    command: str = ""

    def __post_init__(self) -> None:
        if self.study_methods is None:
            self.study_methods = tuple(self.methods)


@dataclass(frozen=True)
class RunSpec:
    """One simulation: method (+ options) on a trajectory with a step, integrator, offset."""

    method: str
    trajectory: str
    dt: float
    integrator: str = "rk4"
    initial_offset: tuple[float, float] = DEFAULT_INITIAL_OFFSET
    options: tuple[tuple[str, Any], ...] = ()

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

    def all_specs(self) -> list[RunSpec]:
        """Every distinct run, in a fixed order (so results never depend on scheduling)."""
        seen: dict[RunSpec, None] = {}
        for spec in [*self.main, *self.variants, *(s for v in self.studies.values() for s in v)]:
            seen.setdefault(spec, None)
        return list(seen)


def default_step(trajectory: Any) -> float:
    """The simulation's default step (s): ``duration / samples`` of the trajectory."""
    return trajectory.duration / getattr(trajectory, "samples", 1000)


def run_duration(config: CompareConfig, name: str) -> float:
    """Simulated time (s) of runs on trajectory ``name``."""
    return config.duration if config.duration is not None else config.trajectories[name].duration


def main_spec(config: CompareConfig, method: str, name: str, **changes: Any) -> RunSpec:
    """The comparison's standard run of ``method`` on ``name`` with ``changes`` applied."""
    spec = {"dt": default_step(config.trajectories[name]), **changes}
    return RunSpec(method, name, **spec)


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
    plan.variants = [
        main_spec(config, method, n, options=options)
        for method, options in VARIANTS
        if method in config.methods
        for n in names
        if n in DEFAULT_TRAJECTORIES
    ]
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


def _study_possible(config: CompareConfig, study: str) -> bool:
    needed = CORNER_TRAJECTORY if study == "corners" else STUDY_TRAJECTORY
    return needed in config.trajectories


def tau_methods(config: CompareConfig) -> list[str]:
    """Selected methods with a closed-loop time constant option ``tau``."""
    return [m for m in config.study_methods if accepts_option(m, "tau", 1.0)]


def _plan_tau(config: CompareConfig) -> list[RunSpec]:
    names = [n for n in (STUDY_TRAJECTORY, CORNER_TRAJECTORY) if n in config.trajectories]
    return [
        main_spec(config, m, n, options=(("tau", tau),))
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
        for m in config.study_methods
        for i in ("euler", "rk4")
        for dt in study_steps(config)
    ]


def _plan_integrator(config: CompareConfig) -> list[RunSpec]:
    return [
        main_spec(config, m, STUDY_TRAJECTORY, integrator=i, initial_offset=(0.0, 0.0))
        for m in config.study_methods
        for i in ("euler", "rk4")
    ]


def study_offsets(config: CompareConfig) -> list[tuple[float, float]]:
    """Initial offsets (dx, dy) in m of the offset sweep that the robot's arm can reach
    from the start configuration (a small arm cannot take the largest ones)."""
    dx, dy = DEFAULT_INITIAL_OFFSET
    start = start_configuration(config.robot, config.trajectories[STUDY_TRAJECTORY])
    offsets = []
    for scale in OFFSET_SCALES:
        try:
            offset_configuration(config.robot, start, (scale * dx, scale * dy))
        except ParameterError:
            continue
        offsets.append((scale * dx, scale * dy))
    return offsets


def _plan_init(config: CompareConfig) -> list[RunSpec]:
    return [
        main_spec(config, m, STUDY_TRAJECTORY, initial_offset=offset)
        for m in config.study_methods
        for offset in study_offsets(config)
    ]


# -- execution ----------------------------------------------------------------------------


def run_one(task: tuple[Robot, Any, float | None, RunSpec]) -> RunOutput:
    """Simulate one :class:`RunSpec` (module level, so worker processes can run it)."""
    robot, trajectory, duration, spec = task
    result = simulate(
        robot,
        trajectory,
        spec.method,
        dt=spec.dt,
        duration=duration,
        integrator=spec.integrator,
        initial_offset=spec.initial_offset,
        **dict(spec.options),
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
            with ProcessPoolExecutor(max_workers=jobs) as pool:
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
    """Rough relative cost of a run: its number of controller calls (RK4 calls 4 a step)."""
    return run_duration(config, spec.trajectory) / spec.dt * (4 if spec.integrator == "rk4" else 1)


# -- metrics and ranking ------------------------------------------------------------------


def metrics_rows(plan: Plan, outputs: Mapping[RunSpec, RunOutput]) -> list[dict[str, Any]]:
    """One row per main run: ``method``, ``trajectory`` and every summary field."""
    rows = []
    for spec in plan.main:
        summary = outputs[spec].summary
        rows.append({"method": spec.method, "trajectory": spec.trajectory, **summary})
    return rows


def metrics_csv(rows: Sequence[Mapping[str, Any]]) -> str:
    """CSV text of ``rows``: union of their keys, floats written exactly (repr)."""
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_csv_value(row.get(c, "")) for c in columns])
    return buffer.getvalue()


def _csv_value(value: Any) -> str:
    """Exact text of a summary value: floats by repr (round-trips), None as empty."""
    value = json_safe(value)
    if value is None:
        return ""
    return repr(value) if isinstance(value, float) else str(value)


def score(summary: Mapping[str, Any]) -> float:
    """Ranking score (m): RMS end-effector position error over the run; NaN counts as inf."""
    value = float(summary["rms_position_error_m"])
    return math.inf if math.isnan(value) else value


def at_least_as_good(a: float, b: float) -> bool:
    """Score ``a`` is better than or tied with ``b`` (see :data:`TIE_RELATIVE`)."""
    return a <= b * (1.0 + TIE_RELATIVE) + TIE_ABSOLUTE_M


def rank_with_ties(scores: Mapping[str, float]) -> dict[str, int]:
    """Competition ranks (1 = best); a score tied with its group's best shares its rank."""
    ranks: dict[str, int] = {}
    leader = math.nan
    rank = 0
    for position, (method, value) in enumerate(sorted(scores.items(), key=lambda x: (x[1], x[0]))):
        if position == 0 or not at_least_as_good(value, leader):
            leader, rank = value, position + 1
        ranks[method] = rank
    return ranks


def geometric_mean(values: Iterable[float]) -> float:
    """Geometric mean of positive values (zeros are floored at 1e-15 m)."""
    logs = [math.log(max(v, 1e-15)) for v in values]
    return math.exp(sum(logs) / len(logs)) if logs else math.nan


@dataclass
class Ranking:
    """Scores (m) and ranks per trajectory and overall (see the module docstring)."""

    scores: dict[str, dict[str, float]]
    ranks: dict[str, dict[str, int]]
    overall: dict[str, float]
    overall_rank: dict[str, int]

    @property
    def order(self) -> list[str]:
        """Methods, best first."""
        return sorted(self.overall, key=lambda m: (self.overall_rank[m], self.overall[m], m))


def build_ranking(plan: Plan, outputs: Mapping[RunSpec, RunOutput]) -> Ranking:
    """Rank the main runs by :func:`score`, per trajectory and by geometric mean."""
    scores: dict[str, dict[str, float]] = {}
    for spec in plan.main:
        scores.setdefault(spec.trajectory, {})[spec.method] = score(outputs[spec].summary)
    methods = list(next(iter(scores.values())))
    overall = {m: geometric_mean(scores[n][m] for n in scores) for m in methods}
    return Ranking(
        scores=scores,
        ranks={n: rank_with_ties(s) for n, s in scores.items()},
        overall=overall,
        overall_rank=rank_with_ties(overall),
    )


# -- the slides' ranking and the reasons it fails -----------------------------------------


@dataclass
class Violation:
    """On ``trajectory``, ``expected_better`` scored worse than ``expected_worse``."""

    trajectory: str
    expected_better: str
    expected_worse: str
    better_score: float
    worse_score: float


@dataclass
class SlidesCheck:
    """Whether CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS >= RR-PI holds, per trajectory."""

    chain: list[str]
    holds: dict[str, bool]
    violations: list[Violation]
    reasons: dict[tuple[str, str], list[str]]  # (trajectory, method) -> explanations

    @property
    def holds_everywhere(self) -> bool:
        """True when the chain holds on every trajectory."""
        return all(self.holds.values())


def check_slides(
    config: CompareConfig, plan: Plan, outputs: Mapping[RunSpec, RunOutput], ranking: Ranking
) -> SlidesCheck:
    """Test every pair the slides' chain implies (a before b: a at least as good as b)."""
    chain = [m for m in SLIDES_ORDER if m in config.methods]
    holds: dict[str, bool] = {}
    violations: list[Violation] = []
    reasons: dict[tuple[str, str], list[str]] = {}
    by_key = {(s.method, s.trajectory): s for s in plan.main}
    for name, scores in ranking.scores.items():
        found = [
            Violation(name, a, b, scores[a], scores[b])
            for i, a in enumerate(chain)
            for b in chain[i + 1 :]
            if not at_least_as_good(scores[a], scores[b])
        ]
        holds[name] = not found
        violations += found
        for method in dict.fromkeys(v.expected_better for v in found):
            spec = by_key[(method, name)]
            findings = diagnose(config, plan, outputs, spec)
            reasons[(name, method)] = [f.text for f in findings if f.adverse]
    return SlidesCheck(chain, holds, violations, reasons)


def singularity_onset(ts: Mapping[str, np.ndarray]) -> int | None:
    """Index of the first sample with |cos th1| < :data:`SINGULAR_COS`, or None."""
    hits = np.nonzero(np.abs(np.cos(ts["th1"])) < SINGULAR_COS)[0]
    return int(hits[0]) if len(hits) else None


def saturation_span(
    ts: Mapping[str, np.ndarray], exclude: np.ndarray | None = None
) -> tuple[int, float, float]:
    """Number of saturated steps (not in ``exclude``) and the first and last such time (s)."""
    saturated = ts["saturated"] > 0
    if exclude is not None:
        saturated &= ~exclude
    hits = np.nonzero(saturated)[0]
    if not len(hits):
        return 0, math.nan, math.nan
    return len(hits), float(ts["t"][hits[0]]), float(ts["t"][hits[-1]])


def orientation_jumps(ts: Mapping[str, np.ndarray]) -> int:
    """Number of steps of the desired orientation (> 1 rad between samples: corners)."""
    return int(np.sum(np.abs(np.diff(ts["phiE_d"])) > 1.0))


def at_joint_limit(ts: Mapping[str, np.ndarray], robot: Robot) -> np.ndarray:
    """Boolean per sample: th1 or th2 sits at one of the robot's joint limits."""
    hit = np.zeros(len(ts["t"]), dtype=bool)
    for name, (low, high) in zip(("th1", "th2"), robot.joint_limits):
        hit |= (ts[name] <= low + 1e-6) | (ts[name] >= high - 1e-6)
    return hit


def _joint_limit_reason(ts: Mapping[str, np.ndarray], limited: np.ndarray) -> str:
    first = int(np.argmax(limited))
    joint = "th2" if abs(ts["th2"][first]) >= abs(ts["th1"][first]) else "th1"
    text = (
        f"{'the elbow' if joint == 'th2' else 'the shoulder'} {joint} ran into its joint limit "
        f"({ts[joint][first]:+.2f} rad) at t = {ts['t'][first]:.1f} s and stayed there for "
        f"{int(np.sum(limited))} steps; the plant stops a joint at its limit, so the commanded "
        "motion is not produced"
    )
    if joint == "th2":
        text += " (an elbow at +-pi folds the arm back: manipulability 0)"
    return text


def saturated_after_jumps(ts: Mapping[str, np.ndarray], exclude: np.ndarray) -> bool:
    """True if every saturated step (not in ``exclude``) lies within 10 % of the run after a
    step of the desired orientation."""
    t = ts["t"]
    jumps = t[1:][np.abs(np.diff(ts["phiE_d"])) > 1.0]
    saturated = t[(ts["saturated"] > 0) & ~exclude]
    if not len(jumps) or not len(saturated):
        return False
    lag = saturated[:, None] - jumps[None, :]
    return bool(np.all(np.any((lag >= 0) & (lag <= 0.1 * t[-1]), axis=1)))


def keeps_offset(summary: Mapping[str, Any]) -> bool:
    """Final and largest position error within 10 % of the initial offset (open loop)."""
    initial = float(summary["initial_offset_m"])
    return initial > 0 and (
        abs(summary["final_position_error_m"] - initial) <= 0.1 * initial
        and summary["max_position_error_m"] <= 1.1 * initial
    )


@dataclass(frozen=True)
class Finding:
    """One data-backed sentence about a run; ``adverse`` if it explains a poor score."""

    text: str
    adverse: bool = True


def diagnose(
    config: CompareConfig, plan: Plan, outputs: Mapping[RunSpec, RunOutput], spec: RunSpec
) -> list[Finding]:
    """Why the run ``spec`` scored as it did: singularity, lost corner orientation,
    saturation, kept offset (adverse) or convergence (not adverse)."""
    ts, summary = outputs[spec].timeseries, outputs[spec].summary
    findings = []
    onset = singularity_onset(ts)
    if onset is not None:
        before = float(np.max(ts["position_error_m"][: onset + 1]))
        after = float(np.max(ts["position_error_m"][onset:]))
        if after > max(2.0 * before, SINGULAR_LOSS_M):
            findings.append(Finding(_singularity_reason(spec, ts, onset, plan, outputs)))
        else:
            findings.append(
                Finding(
                    f"it passes the singularity cos(th1) = 0 at t = {ts['t'][onset]:.1f} s "
                    f"without losing the path (largest error after it {mm(after)} mm)",
                    False,
                )
            )
            onset = None
    jumps = orientation_jumps(ts)
    if jumps and summary["rms_orientation_error_rad"] > 0.5 and onset is None:
        findings.append(Finding(_corner_reason(spec, summary, jumps)))
    limited = at_joint_limit(ts, config.robot)
    if np.any(limited):
        findings.append(Finding(_joint_limit_reason(ts, limited)))
    count, first, last = saturation_span(ts, exclude=limited)
    if count:
        where = (
            f"all within {fmt(0.1 * ts['t'][-1])} s after a corner's orientation step"
            if saturated_after_jumps(ts, limited)
            else f"t = {first:.1f} to {last:.1f} s"
        )
        more = " more" if np.any(limited) else ""
        findings.append(
            Finding(
                f"the command exceeded the wheel or joint speed limits in {count}{more} steps "
                f"({where}), so the robot could not follow it"
            )
        )
    if keeps_offset(summary):
        findings.append(
            Finding(
                "it is open loop: it keeps the initial end-effector offset "
                f"({mm(summary['initial_offset_m'])} mm) for the whole run"
            )
        )
    settle = convergence_time(ts["t"], ts["position_error_m"])
    if summary["initial_offset_m"] > 0 and not math.isnan(settle):
        findings.append(
            Finding(f"it removes the initial offset (below 5 % after {fmt(settle)} s)", False)
        )
    if not any(f.adverse for f in findings):
        findings.append(Finding("no singularity, saturation or orientation loss was detected"))
    return findings


def _singularity_reason(
    spec: RunSpec,
    ts: Mapping[str, np.ndarray],
    onset: int,
    plan: Plan,
    outputs: Mapping[RunSpec, RunOutput],
) -> str:
    t = float(ts["t"][onset])
    d_th1 = float(ts["th1"][onset] - ts["th1"][0])
    d_phi = float(ts["phi"][onset] - ts["phi"][0])
    text = (
        f"it drove the shoulder into the singularity cos(th1) = 0 at t = {t:.1f} s "
        f"(th1 moved by {d_th1:+.2f} rad while the base heading moved by {d_phi:+.2f} rad); "
        "near it the damped inverse cannot produce the commanded motion and the end effector "
        f"leaves the path (largest error {mm(np.max(ts['position_error_m'][onset:]))} mm)"
    )
    if spec.method == "pi" and abs(d_th1 - d_phi) <= 0.25 * abs(d_phi):
        text += (
            ". Why: the base-yaw and shoulder columns of J are identical, so the "
            "minimum-norm solution splits the yaw rate equally between them and th1 follows "
            "the base heading, which must turn 2 pi per loop"
        )
    variant = next(
        (v for v in plan.variants if v.method == spec.method and v.trajectory == spec.trajectory),
        None,
    )
    if spec.method == "ap" and not spec.options and variant is not None:
        run = outputs[variant]
        if singularity_onset(run.timeseries) is None:
            text += (
                ". Why: the K3 phi^2 term of the potential (K3 = 0.66, the slides' value) "
                "pushes the base heading toward 0 while the tangent heading must turn 2 pi "
                "per loop; in the null space of J, turning the base by +k turns the shoulder "
                "by -k, so the shoulder absorbs the heading the base is denied and th1 is "
                "dragged to pi/2. With K3 = 0 the same run never gets near the singularity "
                f"(RMS {mm(run.summary['rms_position_error_m'])} mm)"
            )
    return text


def _corner_reason(spec: RunSpec, summary: Mapping[str, Any], jumps: int) -> str:
    text = (
        f"it does not follow the pi/2 steps of the desired orientation at the {jumps} "
        "corners: the steps are not in Xd_dot, which is all it integrates, so phiE lags by "
        f"k pi/2 after corner k (RMS orientation error "
        f"{summary['rms_orientation_error_rad']:.2f} rad)"
    )
    if spec.method == "clrrmc-cs":
        text += (
            ". Its feedback acts on q_d - q, and the reference q_d is the augmented-Jacobian "
            "resolution integrated from Xd_dot alone, so it tracks the reference's own "
            "orientation loss faithfully"
        )
    return text


# -- studies ------------------------------------------------------------------------------


def convergence_time(
    t: np.ndarray, error: np.ndarray, fraction: float = CONVERGED_FRACTION
) -> float:
    """First time (s) after which ``error`` stays below ``fraction`` of its initial value.

    0 for a run that starts on the path; NaN if it never settles within the run.
    """
    if error[0] <= 0.0:
        return 0.0
    above = np.nonzero(error > fraction * error[0])[0]
    last = int(above[-1])
    return float(t[last + 1]) if last + 1 < len(t) else math.nan


def observed_order(values: Mapping[float, float]) -> float:
    """Median slope of log(error) vs log(dt): the integrator's observed order of accuracy.

    Pairs with an error below 1e-12 m (round-off) are skipped; NaN if none is left.
    """
    steps = sorted(values)
    slopes = [
        math.log(values[b] / values[a]) / math.log(b / a)
        for a, b in itertools.pairwise(steps)
        if values[a] > 1e-12 and values[b] > 1e-12
    ]
    return float(np.median(slopes)) if slopes else math.nan


def corner_times(trajectory: Any, duration: float) -> list[float]:
    """Times (s) of the rectangle's corners alpha = k pi/2 (k >= 1) within the run."""
    quarter = getattr(trajectory, "T", trajectory.duration) / 4.0
    return [
        k * quarter for k in range(1, int(duration / quarter + 1e-9) + 1) if k * quarter < duration
    ]


# -- number formatting --------------------------------------------------------------------


def fmt(value: Any, digits: int = 3) -> str:
    """``value`` with ``digits`` significant digits, plain notation for 1e-3 <= |v| < 1e5."""
    if value is None or value == "":
        return "n/a"
    if isinstance(value, bool | int | np.integer):
        return str(int(value))
    value = float(value)
    if math.isnan(value):
        return "n/a"
    if math.isinf(value) or value == 0.0:
        return str(value) if math.isinf(value) else "0"
    magnitude = abs(value)
    if 1e-3 <= magnitude < 1e5:
        decimals = max(0, digits - 1 - math.floor(math.log10(magnitude)))
        return f"{value:.{decimals}f}"
    return f"{value:.{digits - 1}e}"


def mm(value_m: float) -> str:
    """A length in m written in mm (3 significant digits)."""
    return fmt(1000.0 * float(value_m))


# -- the document model -------------------------------------------------------------------


class Document:
    """A small block document rendered both as Markdown and as self-contained HTML.

    Inline markup in text: ``**bold**`` and backquoted ``code`` only.
    """

    def __init__(self, title: str) -> None:
        self.title = title
        self.blocks: list[tuple[str, Any]] = []

    def heading(self, text: str, level: int = 2) -> None:
        """Section heading (level 2..4)."""
        self.blocks.append(("heading", (level, text)))

    def paragraph(self, text: str) -> None:
        """A paragraph."""
        self.blocks.append(("paragraph", text))

    def bullets(self, items: Sequence[str]) -> None:
        """A bullet list."""
        self.blocks.append(("bullets", list(items)))

    def table(self, headers: Sequence[str], rows: Sequence[Sequence[str]]) -> None:
        """A table; the first column is left aligned, the others right aligned."""
        self.blocks.append(("table", (list(headers), [list(r) for r in rows])))

    def figure(self, filename: str, caption: str) -> None:
        """A PNG figure (file in the report folder) with its caption."""
        self.blocks.append(("figure", (filename, caption)))

    def to_markdown(self) -> str:
        """Markdown text; figures are linked by relative file name."""
        parts = [f"# {self.title}"]
        for kind, data in self.blocks:
            parts.append(_MARKDOWN[kind](data))
        return "\n\n".join(parts) + "\n"

    def to_html(self, folder: Path) -> str:
        """A self-contained HTML page: figures from ``folder`` embedded as data URIs."""
        body = [f"<h1>{_inline(self.title)}</h1>"]
        for kind, data in self.blocks:
            body.append(_html_figure(data, folder) if kind == "figure" else _HTML[kind](data))
        return _HTML_PAGE.format(title=html.escape(self.title), body="\n".join(body))


def _md_table(data: tuple[list[str], list[list[str]]]) -> str:
    headers, rows = data
    lines = [
        "| " + " | ".join(headers) + " |",
        "|" + "|".join([":---"] + ["---:"] * (len(headers) - 1)) + "|",
    ]
    lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |" for row in rows]
    return "\n".join(lines)


_MARKDOWN: dict[str, Callable[[Any], str]] = {
    "heading": lambda d: "#" * d[0] + " " + d[1],
    "paragraph": lambda d: d,
    "bullets": lambda d: "\n".join(f"- {item}" for item in d),
    "table": _md_table,
    "figure": lambda d: f"![{d[1]}]({d[0]})\n\n*{d[1]}*",
}


def _inline(text: str) -> str:
    """HTML for the inline markup of :class:`Document` text."""
    text = html.escape(text, quote=False)
    text = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", text)
    return re.sub(r"`(.+?)`", r"<code>\1</code>", text)


def _html_table(data: tuple[list[str], list[list[str]]]) -> str:
    headers, rows = data
    head = "".join(f"<th>{_inline(h)}</th>" for h in headers)
    body = "".join(
        "<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in row) + "</tr>" for row in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _html_figure(data: tuple[str, str], folder: Path) -> str:
    filename, caption = data
    encoded = base64.b64encode((folder / filename).read_bytes()).decode("ascii")
    return (
        f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{encoded}">'
        f"<figcaption>{_inline(caption)}</figcaption></figure>"
    )


_HTML: dict[str, Callable[[Any], str]] = {
    "heading": lambda d: f"<h{d[0]}>{_inline(d[1])}</h{d[0]}>",
    "paragraph": lambda d: f"<p>{_inline(d)}</p>",
    "bullets": lambda d: "<ul>" + "".join(f"<li>{_inline(i)}</li>" for i in d) + "</ul>",
    "table": _html_table,
}

_HTML_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ font-family: sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em;
       line-height: 1.45; color: #222; }}
table {{ border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.55em; text-align: right; }}
th:first-child, td:first-child {{ text-align: left; }}
thead {{ background: #f0f0f0; }}
figure {{ margin: 1.5em 0; }}
img {{ max-width: 100%; }}
figcaption {{ font-style: italic; color: #555; }}
code {{ background: #f4f4f4; padding: 0 0.2em; }}
</style>
</head>
<body>
{body}
</body>
</html>
"""


# -- building the report ------------------------------------------------------------------


@dataclass
class ReportInfo:
    """What :func:`write_report` produced: ranking, slides check, file names."""

    ranking: Ranking
    check: SlidesCheck
    files: list[str]


def write_report(
    config: CompareConfig, plan: Plan, outputs: Mapping[RunSpec, RunOutput], folder: Path
) -> ReportInfo:
    """Write ``metrics.csv``, the PNG figures, ``report.md`` and ``report.html`` to ``folder``."""
    folder = Path(folder)
    write_atomic(folder / "metrics.csv", metrics_csv(metrics_rows(plan, outputs)))
    ranking = build_ranking(plan, outputs)
    check = check_slides(config, plan, outputs, ranking)
    context = _Context(config, plan, outputs, folder, Document("Method comparison"))
    _setup_section(context)
    _ranking_section(context, ranking)
    _slides_section(context, ranking, check)
    _diagnosis_section(context)
    for name in config.trajectories:
        _trajectory_section(context, name)
    for study in plan.studies:
        _STUDY_SECTIONS[study](context)
    _definitions_section(context)
    write_atomic(folder / "report.md", context.doc.to_markdown())
    write_atomic(folder / "report.html", context.doc.to_html(folder))
    files = ["report.html", "report.md", "metrics.csv", *context.figures]
    return ReportInfo(ranking, check, files)


@dataclass
class _Context:
    """Everything a report section needs."""

    config: CompareConfig
    plan: Plan
    outputs: Mapping[RunSpec, RunOutput]
    folder: Path
    doc: Document
    figures: list[str] = field(default_factory=list)

    @property
    def colors(self) -> dict[str, str]:
        methods = dict.fromkeys([*self.config.methods, *self.config.study_methods])
        return plots.method_colors(list(methods))

    def main(self, method: str, name: str) -> RunOutput:
        return self.outputs[main_spec(self.config, method, name)]

    def run(self, spec: RunSpec) -> RunOutput:
        return self.outputs[spec]

    def add_figure(self, filename: str, fig: Any, caption: str) -> None:
        plots.save(fig, self.folder / filename)
        self.figures.append(filename)
        self.doc.figure(filename, caption)


def _setup_section(c: _Context) -> None:
    config, robot = c.config, c.config.robot
    c.doc.paragraph(
        "Every registered method tracks the same trajectories from the same start "
        "configuration (the robot's home arm pose placed on the trajectory start, then the "
        "end effector moved by the same initial offset with the arm), with the same robot, "
        "integrator and step. Generated by `python -m ddwmmr.compare`."
    )
    steps = ", ".join(
        f"{n}: dt = {default_step(t):g} s, duration = {run_duration(config, n):g} s"
        for n, t in config.trajectories.items()
    )
    dx, dy = DEFAULT_INITIAL_OFFSET
    items = [
        f"robot: L1 = {robot.L1:g} m, L2 = {robot.L2:g} m, payload = {robot.payload:g} kg, "
        f"wheel speed limit = {robot.wheel_speed_limit:g} rad/s, joint speed limit = "
        f"{robot.joint_speed_limit:g} rad/s",
        f"integrator: rk4; {steps}",
        f"initial end-effector offset: ({dx:g} m, {dy:g} m), i.e. "
        f"{1000 * math.hypot(dx, dy):.1f} mm",
        "methods: "
        + "; ".join(f"`{m}`: {method_description(m).rstrip('.')}" for m in config.methods),
        f"runs: {len(c.plan.all_specs())} simulations "
        f"(studies: {', '.join(c.plan.studies) or 'none'})",
    ]
    if config.command:
        items.append(f"command: `{config.command}`")
    c.doc.heading("Setup")
    c.doc.bullets(items)


def ranking_table(ranking: Ranking) -> tuple[list[str], list[list[str]]]:
    """Headers and rows of the ranking table (RMS position error in mm, rank in brackets)."""
    names = list(ranking.scores)
    headers = ["rank", "method", *[f"{n} RMS (mm)" for n in names], "overall (mm)"]
    rows = [
        [
            str(ranking.overall_rank[m]),
            m,
            *[f"{mm(ranking.scores[n][m])} ({ranking.ranks[n][m]})" for n in names],
            mm(ranking.overall[m]),
        ]
        for m in ranking.order
    ]
    return headers, rows


def _ranking_section(c: _Context, ranking: Ranking) -> None:
    c.doc.heading("Ranking")
    c.doc.paragraph(
        "**Score**: the RMS end-effector position error over the whole run (mm), per "
        "trajectory; lower is better. All methods start with the same initial offset, so the "
        "score rewards removing it quickly and penalises drift; the orientation error is "
        "reported in the tables but not scored. Scores within 5 % (or 0.1 mm) of a better "
        "score are a tie and share its rank (the slides' `>=` allows ties). **Overall**: the "
        "geometric mean of the per-trajectory scores (errors span orders of magnitude). The "
        "per-trajectory rank is in brackets."
    )
    c.doc.table(*ranking_table(ranking))


def slides_verdict(check: SlidesCheck) -> str:
    """One sentence: does the slides' ranking hold, and where not."""
    chain = " >= ".join(slides_name(m) for m in check.chain)
    if len(check.chain) < 2:
        return "The slides' ranking was not checked (fewer than two of its methods ran)."
    if check.holds_everywhere:
        return f"The slides' ranking {chain} holds on every trajectory (ties count as >=)."
    failing = [n for n, ok in check.holds.items() if not ok]
    return f"The slides' ranking {chain} does NOT hold on: {', '.join(failing)}."


def _slides_section(c: _Context, ranking: Ranking, check: SlidesCheck) -> None:
    c.doc.heading("Does the slides' ranking hold?")
    c.doc.paragraph(
        "The slides conclude CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS (depends on the "
        "auxiliary constraint) >= RR-PI for tracking quality. Every pair the chain implies is "
        "tested with the score above. **" + slides_verdict(check) + "**"
    )
    items = []
    for name in ranking.scores:
        found = [v for v in check.violations if v.trajectory == name]
        if not found:
            items.append(f"**{name}**: holds.")
            continue
        for method in dict.fromkeys(v.expected_better for v in found):
            beaten = [v for v in found if v.expected_better == method]
            others = ", ".join(
                f"{slides_name(v.expected_worse)} ({mm(v.worse_score)} mm)" for v in beaten
            )
            reasons = "; ".join(check.reasons[(name, method)])
            items.append(
                f"**{name}**: {slides_name(method)} ({mm(beaten[0].better_score)} mm) scores "
                f"worse than {others}. Reason: {reasons}."
            )
    c.doc.bullets(items)
    _variants_table(c)
    c.doc.paragraph(" ".join(_observations(c, ranking)))


def _diagnosis_section(c: _Context) -> None:
    c.doc.heading("What happened in each run")
    c.doc.paragraph(
        "Findings computed from each main run's time series: the shoulder singularity "
        f"(|cos th1| < {SINGULAR_COS:g}), orientation lost at the rectangle's corners, "
        "saturated commands, a kept initial offset, or convergence."
    )
    for name in c.config.trajectories:
        items = []
        for m in c.config.methods:
            findings = diagnose(c.config, c.plan, c.outputs, main_spec(c.config, m, name))
            items.append(f"**{m}**: " + "; ".join(f.text for f in findings) + ".")
        c.doc.heading(name, 3)
        c.doc.bullets(items)


def _variants_table(c: _Context) -> None:
    if not c.plan.variants:
        return
    rows = []
    for spec in c.plan.variants:
        base = c.main(spec.method, spec.trajectory).summary
        variant = c.run(spec).summary
        rows.append(
            [
                spec.label(),
                spec.trajectory,
                mm(variant["rms_position_error_m"]),
                mm(base["rms_position_error_m"]),
                fmt(variant["singular_steps"]),
                fmt(variant["saturated_steps"]),
            ]
        )
    c.doc.paragraph(
        "Explanatory runs: the same comparison with one option changed (the default's score "
        "for reference). `ap` with K3 = 0 removes the pull of the base heading toward 0; "
        "`ats` with aux = sum (th1dot + th2dot = 0) is the slides' other auxiliary "
        "constraint (they note RR-ATS depends on this choice). " + _aux_finding(c)
    )
    c.doc.table(
        ["run", "trajectory", "RMS (mm)", "default RMS (mm)", "singular steps", "saturated steps"],
        rows,
    )


def _aux_finding(c: _Context) -> str:
    """Compare ats with aux = shoulder (default) and aux = sum per trajectory."""
    texts = []
    for spec in c.plan.variants:
        if spec.method != "ats":
            continue
        default = c.main("ats", spec.trajectory).summary["rms_position_error_m"]
        variant = c.run(spec).summary["rms_position_error_m"]
        onset = singularity_onset(c.run(spec).timeseries)
        where = "" if onset is None else ", reaching cos(th1) = 0"
        texts.append(
            f"on the {spec.trajectory} aux = sum gives {mm(variant)} mm{where} vs "
            f"{mm(default)} mm with aux = shoulder"
        )
    return ("For RR-ATS, " + "; ".join(texts) + ".") if texts else ""


def _observations(c: _Context, ranking: Ranking) -> list[str]:
    """Data-backed remarks on open vs closed loop and methods outside the slides' chain."""
    name = STUDY_TRAJECTORY if STUDY_TRAJECTORY in ranking.scores else next(iter(ranking.scores))
    kept = [m for m in c.config.methods if keeps_offset(c.main(m, name).summary)]
    removed = [
        m for m in c.config.methods if c.main(m, name).summary["final_position_error_m"] < 1e-4
    ]
    notes = []
    if kept:
        verb = "keeps" if len(kept) == 1 else "keep"
        notes.append(f"On the {name}, {', '.join(kept)} {verb} the initial offset (open loop).")
    if removed:
        verb = "removes" if len(removed) == 1 else "remove"
        notes.append(f"{', '.join(removed)} {verb} it (final error below 0.1 mm).")
    outside = [m for m in c.config.methods if m not in SLIDES_ORDER]
    for m in outside:
        notes.append(
            f"`{m}` is not in the slides' chain; it ranks {ranking.overall_rank[m]} overall."
        )
    return notes


METRIC_COLUMNS = (
    ("RMS pos (mm)", "rms_position_error_m", mm),
    ("max pos (mm)", "max_position_error_m", mm),
    ("final pos (mm)", "final_position_error_m", mm),
    ("RMS orient (rad)", "rms_orientation_error_rad", fmt),
    ("max nonhol. residual (m/s)", "max_nonholonomic_residual_m_s", fmt),
    ("peak wheel (rad/s)", "max_wheel_speed_rad_s", fmt),
    ("min manip.", "min_manipulability", fmt),
    ("mean manip.", "mean_manipulability", fmt),
    ("min stability S", "min_stability", fmt),
    ("singular steps", "singular_steps", fmt),
    ("saturated steps", "saturated_steps", fmt),
    ("step latency (us)", "median_step_us", fmt),
)


def _trajectory_section(c: _Context, name: str) -> None:
    c.doc.heading(f"Trajectory: {name}")
    rows = [
        [m, *[f(c.main(m, name).summary.get(key, math.nan)) for _, key, f in METRIC_COLUMNS]]
        for m in c.config.methods
    ]
    c.doc.table(["method", *[h for h, _, _ in METRIC_COLUMNS]], rows)
    series = {m: c.main(m, name).timeseries for m in c.config.methods}
    colors = c.colors
    c.add_figure(
        f"paths_{name}.png",
        plots.plot_paths(series, colors, f"{name}: end-effector paths"),
        f"{name}: end-effector paths of every method over the desired path (dashed); the "
        "frame is the desired path plus 0.5 m, so a method that drifts away leaves it.",
    )
    c.add_figure(
        f"errors_{name}.png",
        plots.plot_errors(series, colors, f"{name}: tracking errors"),
        f"{name}: position error (log scale, floored at 1e-12 m) and orientation error vs time.",
    )
    c.add_figure(
        f"wheels_{name}.png",
        plots.plot_wheels(series, colors, c.config.robot.wheel_speed_limit, f"{name}: wheels"),
        f"{name}: left (solid) and right (dashed) wheel speeds per method; dotted: the limit.",
    )
    c.add_figure(
        f"methods_{name}.png",
        plots.plot_small_multiples(series, colors, c.config.robot, name),
        f"{name}: one panel per method, with the robot drawn at six instants.",
    )


def _tau_section(c: _Context) -> None:
    c.doc.heading("Study: time constant (sluggishness)", 2)
    methods = tau_methods(c.config)
    if not methods:
        c.doc.paragraph("No selected method has a time constant `tau`.")
        return
    theory = -math.log(CONVERGED_FRACTION)
    names = [n for n in (STUDY_TRAJECTORY, CORNER_TRAJECTORY) if n in c.config.trajectories]
    runs = {
        (m, n, tau): c.run(main_spec(c.config, m, n, options=(("tau", tau),)))
        for m in methods
        for n in names
        for tau in TAUS
    }
    curves = {m: {tau: _errors(runs[(m, STUDY_TRAJECTORY, tau)]) for tau in TAUS} for m in methods}
    convergence = {m: {tau: convergence_time(*curves[m][tau]) for tau in TAUS} for m in methods}
    rows = []
    for m in methods:
        for tau in TAUS:
            row = [m, fmt(tau), fmt(convergence[m][tau]), fmt(theory * tau)]
            for n in names:
                summary = runs[(m, n, tau)].summary
                row += [mm(summary["rms_position_error_m"]), fmt(summary["saturated_steps"])]
            rows.append(row)
    c.doc.paragraph(
        f"Closed-loop methods with K = 1/tau for tau in {', '.join(f'{t:g}' for t in TAUS)} s. "
        f"Convergence time on the {STUDY_TRAJECTORY}: when the position error last exceeds "
        f"{100 * CONVERGED_FRACTION:g} % of the initial offset; a first-order decay "
        f"exp(-t/tau) needs {theory:.2f} tau. "
        + _tau_finding(convergence)
        + _tau_corner_finding(methods, runs)
    )
    headers = ["method", "tau (s)", "convergence (s)", f"{theory:.2f} tau (s)"]
    for n in names:
        headers += [f"RMS {n} (mm)", f"saturated steps {n}"]
    c.doc.table(headers, rows)
    c.add_figure(
        "study_tau.png",
        plots.plot_tau_study(curves, convergence, theory, c.colors),
        "Time-constant sweep: error vs time per tau, and convergence time vs tau.",
    )


def _tau_corner_finding(methods: Sequence[str], runs: Mapping[tuple, RunOutput]) -> str:
    """Where a small tau is worse on the rectangle (corner turns saturate), say so."""
    texts = []
    low, high = TAUS[0], TAUS[-1]
    for m in methods:
        if (m, CORNER_TRAJECTORY, low) not in runs:
            continue
        a, b = (runs[(m, CORNER_TRAJECTORY, tau)].summary for tau in (low, high))
        if a["rms_position_error_m"] > b["rms_position_error_m"] * (1 + TIE_RELATIVE):
            texts.append(
                f"{m} has RMS {mm(a['rms_position_error_m'])} mm at tau = {low:g} s "
                f"({a['saturated_steps']} saturated steps) but {mm(b['rms_position_error_m'])} "
                f"mm at tau = {high:g} s ({b['saturated_steps']})"
            )
    if not texts:
        return ""
    return (
        " On the rectangle a small tau is not better: "
        + "; ".join(texts)
        + ". A stiff loop answers the pi/2 orientation steps at the corners by asking for "
        "turns faster than the wheel or joint speed limits allow, so position tracking suffers "
        "there."
    )


def _tau_finding(convergence: Mapping[str, Mapping[float, float]]) -> str:
    texts = []
    for m, values in convergence.items():
        settled = [(tau, values[tau]) for tau in sorted(values) if not math.isnan(values[tau])]
        never = [f"{tau:g}" for tau in sorted(values) if math.isnan(values[tau])]
        if not settled:
            texts.append(f"{m} never gets below {100 * CONVERGED_FRACTION:g} % of the offset")
            continue
        text = f"{fmt(settled[0][1])} s at tau = {settled[0][0]:g} s to {fmt(settled[-1][1])} s "
        text += f"at tau = {settled[-1][0]:g} s for {m}"
        if never:
            text += (
                f" (not settled for tau = {', '.join(never)} s: its steady error exceeds "
                f"{100 * CONVERGED_FRACTION:g} % of the offset)"
            )
        texts.append(text)
    return "Convergence time: " + "; ".join(texts) + ". Larger tau is more sluggish."


def _dt_section(c: _Context) -> None:
    c.doc.heading("Study: step size and integrator (drift)", 2)
    steps = study_steps(c.config)
    if not steps:
        c.doc.paragraph("The run is too short for the step-size sweep.")
        return
    drift: dict[str, dict[str, dict[float, float]]] = {}
    rows = []
    for m in c.config.study_methods:
        for integrator in ("euler", "rk4"):
            values = {
                dt: c.run(
                    main_spec(
                        c.config,
                        m,
                        STUDY_TRAJECTORY,
                        dt=dt,
                        integrator=integrator,
                        initial_offset=(0.0, 0.0),
                    )
                ).summary["max_position_error_m"]
                for dt in steps
            }
            drift.setdefault(m, {})[integrator] = values
            kind = drift_kind(values)
            order = fmt(observed_order(values), 2) if kind == "scales" else f"no trend ({kind})"
            rows.append([m, integrator, *[mm(values[dt]) for dt in steps], order])
    c.doc.paragraph(
        f"{STUDY_TRAJECTORY}, no initial offset, so the largest position error of a run is "
        "numerical drift (or a method's own failure); the final error would hide drift that "
        "cancels over a closed loop. The observed order is the median slope of log(error) "
        "vs log(dt) (round-off below 1e-12 m excluded): about 1 for forward Euler and 4 for "
        "RK4 where the integration error dominates. " + _dt_finding(drift)
    )
    c.doc.table(
        ["method", "integrator", *[f"dt {dt:g} s (mm)" for dt in steps], "observed order"], rows
    )
    c.add_figure(
        "study_dt.png",
        plots.plot_dt_study(drift, c.colors),
        "Largest position error vs step size, Euler (solid) and RK4 (dashed), log-log.",
    )


def drift_kind(values: Mapping[float, float]) -> str:
    """``"scales"`` if the error grows with dt (monotonically, by 2x or more over the sweep),
    else ``"failure"`` (above 0.1 m) or ``"bias"`` (small, no trend: not integration drift)."""
    errors = [values[dt] for dt in sorted(values)]
    growing = all(a <= b for a, b in itertools.pairwise(errors))
    if growing and errors[-1] >= 2.0 * max(errors[0], 1e-15):
        return "scales"
    return "failure" if min(errors) > 0.1 else "bias"


def _dt_finding(drift: Mapping[str, Mapping[str, Mapping[float, float]]]) -> str:
    scaling, bias, failure = [], [], []
    for m, by_integrator in drift.items():
        for integrator, values in by_integrator.items():
            kind = drift_kind(values)
            if kind == "scales":
                scaling.append(f"{m} {integrator} {fmt(observed_order(values), 2)}")
            elif kind == "bias":
                low, high = mm(min(values.values())), mm(max(values.values()))
                bias.append(
                    f"{m} {integrator} ({low} mm)"
                    if low == high
                    else f"{m} {integrator} ({low} to {high} mm)"
                )
            elif m not in failure:
                failure.append(m)
    text = f"Observed orders: {', '.join(scaling)}." if scaling else ""
    if bias:
        text += (
            f" No trend with dt for {', '.join(bias)}: an error of the method's own "
            "tracking, not integration drift."
        )
    if failure:
        text += (
            f" {', '.join(failure)} end more than 0.1 m off whatever the step: not drift but "
            "the method's own failure (see the ranking)."
        )
    return text


def _integrator_section(c: _Context) -> None:
    c.doc.heading("Study: Euler vs RK4 at the default step", 2)
    dt = default_step(c.config.trajectories[STUDY_TRAJECTORY])
    runs = {
        (m, i): c.run(
            main_spec(c.config, m, STUDY_TRAJECTORY, integrator=i, initial_offset=(0.0, 0.0))
        )
        for m in c.config.study_methods
        for i in ("euler", "rk4")
    }
    curves = {
        m: {i: _errors(runs[(m, i)]) for i in ("euler", "rk4")} for m in c.config.study_methods
    }
    rows = []
    for m in c.config.study_methods:
        e, r = runs[(m, "euler")].summary, runs[(m, "rk4")].summary
        rows.append(
            [m]
            + [mm(x[k]) for k in ("max_position_error_m", "rms_position_error_m") for x in (e, r)]
            + [mm(e["final_position_error_m"])]
        )
    c.doc.paragraph(
        f"{STUDY_TRAJECTORY}, dt = {dt:g} s, no initial offset. Forward Euler is the "
        "first-order Runge-Kutta method: its local error is O(dt^2) per step, RK4's O(dt^5). "
        + _integrator_finding(runs)
    )
    headers = ["method", "Euler max (mm)", "RK4 max (mm)", "Euler RMS (mm)", "RK4 RMS (mm)"]
    c.doc.table([*headers, "Euler final (mm)"], rows)
    c.add_figure(
        "study_integrator.png",
        plots.plot_integrator_study(curves, c.colors, dt),
        "Position error vs time, Euler (solid) vs RK4 (dashed), no initial offset.",
    )


def _integrator_finding(runs: Mapping[tuple[str, str], RunOutput]) -> str:
    """Open loop ats vs closed loop clrrmc-ts under Euler, when both ran."""
    if ("ats", "euler") not in runs or ("clrrmc-ts", "euler") not in runs:
        return ""
    ats, ts = (runs[(m, "euler")].timeseries for m in ("ats", "clrrmc-ts"))
    ats_max, ts_max = float(np.max(ats["position_error_m"])), float(np.max(ts["position_error_m"]))
    middle = len(ats["t"]) // 2
    return (
        f"With Euler the open-loop ats drifts {mm(ats_max)} mm off at worst "
        f"({mm(ats['position_error_m'][middle])} mm half way, {mm(ats['position_error_m'][-1])} "
        "mm at the end, where the closed curve brings part of it back), while the feedback of "
        f"clrrmc-ts holds it to {mm(ts_max)} mm. RK4 makes the drift negligible for both."
        + _cs_euler_finding(runs, ts_max)
    )


def _cs_euler_finding(runs: Mapping[tuple[str, str], RunOutput], ts_max: float) -> str:
    """clrrmc-cs under Euler: sideways base error its feedback cannot remove."""
    if ("clrrmc-cs", "euler") not in runs:
        return ""
    summary = runs[("clrrmc-cs", "euler")].summary
    if summary["max_position_error_m"] < 2.0 * ts_max:
        return ""
    return (
        f" clrrmc-cs drifts more with Euler ({mm(summary['max_position_error_m'])} mm): its "
        "feedback acts on the base position in configuration space, and the sideways part of "
        "the base error can only be commanded as a sideways velocity, which the differential "
        "drive cannot produce (max nonholonomic residual "
        f"{fmt(summary['max_nonholonomic_residual_m_s'])} m/s, dropped), so that part grows "
        "step by step."
    )


def _init_section(c: _Context) -> None:
    c.doc.heading("Study: initial offset", 2)
    offsets = study_offsets(c.config)
    final: dict[str, dict[float, float]] = {}
    rows = []
    for m in c.config.study_methods:
        values = {
            math.hypot(*o): c.run(main_spec(c.config, m, STUDY_TRAJECTORY, initial_offset=o))
            for o in offsets
        }
        final[m] = {k: r.summary["final_position_error_m"] for k, r in values.items()}
        rows.append([m, *[mm(final[m][k]) for k in sorted(final[m])]])
    # The error curves show one closed-loop method: convergence depends on the offset there.
    closed = [m for m in SLIDES_ORDER if m.startswith("clrrmc") and m in c.config.study_methods]
    curve_method = (closed or list(c.config.study_methods))[0]
    curves = {
        math.hypot(*o): _errors(
            c.run(main_spec(c.config, curve_method, STUDY_TRAJECTORY, initial_offset=o))
        )
        for o in offsets
    }
    c.doc.paragraph(
        f"{STUDY_TRAJECTORY}: the end effector starts off the path by multiples of the default "
        "offset (same direction), moved with the arm; offsets the arm cannot reach are left "
        "out. Final position error per method: an "
        "open-loop method ends with its offset, a closed-loop one removes it."
    )
    headers = ["method", *[f"offset {1000 * k:.1f} mm" for k in sorted(next(iter(final.values())))]]
    c.doc.table(headers, rows)
    c.add_figure(
        "study_init.png",
        plots.plot_init_study(final, curves, curve_method, c.colors),
        "Final error vs initial offset per method, and error vs time per offset.",
    )


def _errors(run: RunOutput) -> tuple[np.ndarray, np.ndarray]:
    return run.timeseries["t"], run.timeseries["position_error_m"]


def _corners_section(c: _Context) -> None:
    c.doc.heading("Study: rectangle corners", 2)
    trajectory = c.config.trajectories[CORNER_TRAJECTORY]
    duration = run_duration(c.config, CORNER_TRAJECTORY)
    corners = corner_times(trajectory, duration)
    quarter = getattr(trajectory, "T", trajectory.duration) / 4.0
    if not corners:
        c.doc.paragraph("The run ends before the first corner.")
        return
    series = {m: c.main(m, CORNER_TRAJECTORY).timeseries for m in c.config.methods}
    peaks = {m: corner_peaks(ts, corners, quarter, duration) for m, ts in series.items()}
    c.doc.paragraph(
        "The rectangle's corners are at alpha = k pi/2 (t = k T/4). The speed drops to zero "
        "there and the tangent orientation steps by pi/2, so methods with orientation "
        "feedback must turn fast (and may saturate) while open-loop methods lose the "
        "orientation. Peak error: the largest position error within T/8 after each corner; "
        "mid-edge: the median error over the middle half of the edges. " + _corner_finding(peaks)
    )
    rows = [
        [m, mm(mid), *[mm(p) for p in values], fmt(max(values) / max(mid, 1e-15))]
        for m, (mid, values) in peaks.items()
    ]
    headers = ["method", "mid-edge (mm)"]
    headers += [f"corner {k} (mm)" for k in range(1, len(corners) + 1)] + ["max peak / mid-edge"]
    c.doc.table(headers, rows)
    c.add_figure(
        "study_corners.png",
        plots.plot_corner_study(series, c.colors, quarter, corners),
        "Rectangle: position and orientation error vs alpha/(pi/2); dotted lines are corners.",
    )


def corner_peaks(
    ts: Mapping[str, np.ndarray], corners: Sequence[float], quarter: float, duration: float
) -> tuple[float, list[float]]:
    """Mid-edge median error and the peak error within T/8 after each corner (m)."""
    t, e = ts["t"], ts["position_error_m"]
    peaks = [float(np.max(e[(t >= tc) & (t <= tc + quarter / 2)])) for tc in corners]
    return _mid_edge_error(t, e, quarter, duration), peaks


def _corner_finding(peaks: Mapping[str, tuple[float, list[float]]]) -> str:
    """Which methods peak at every corner (3x their mid-edge error or more), which do not."""
    every = [
        f"{m} ({mm(max(p))} mm vs {mm(mid)} mm mid-edge)"
        for m, (mid, p) in peaks.items()
        if min(p) >= 3.0 * mid
    ]
    others = [m for m, (mid, p) in peaks.items() if min(p) < 3.0 * mid]
    text = f"The error peaks at every corner for {', '.join(every)}." if every else ""
    if others:
        text += (
            f" Not at every corner for {', '.join(others)}: they ignore the orientation step "
            "(and lose the orientation instead) or have already left the path."
        )
    return text.strip()


def _mid_edge_error(t: np.ndarray, e: np.ndarray, quarter: float, duration: float) -> float:
    """Median error over the middle half of every edge (between corners)."""
    phase = np.mod(t, quarter) / quarter
    mask = (phase >= 0.25) & (phase <= 0.75) & (t <= duration)
    return float(np.median(e[mask])) if np.any(mask) else math.nan


_STUDY_SECTIONS: dict[str, Callable[[_Context], None]] = {
    "tau": _tau_section,
    "dt": _dt_section,
    "integrator": _integrator_section,
    "init": _init_section,
    "corners": _corners_section,
}


def _definitions_section(c: _Context) -> None:
    c.doc.heading("Definitions and files")
    c.doc.bullets(
        [
            "position error: distance between actual and desired end-effector position (m); "
            "orientation error: desired minus actual phiE, wrapped to [-pi, pi) (rad)",
            "nonholonomic residual: sideways base speed a method asked for and the "
            "differential drive cannot produce (m/s)",
            "manipulability: |sin th2| in [0, 1]; stability S: tip-over margin, S <= 1 tips",
            "singular steps: steps with damping near a singularity; saturated steps: steps "
            "where a wheel or joint speed limit was hit",
            "step latency: median wall-clock time of one controller call (us); a timing, so "
            "it varies between runs and machines",
            "`metrics.csv`: one row per method x trajectory with every `summary.json` field "
            "of the matching `python -m ddwmmr.track` run",
        ]
    )


# -- console summary ----------------------------------------------------------------------


def text_table(headers: Sequence[str], rows: Sequence[Sequence[str]], left: int = 2) -> str:
    """An aligned plain-text table: the first ``left`` columns left aligned, others right."""
    widths = [max(len(str(x)) for x in column) for column in zip(headers, *rows)]

    def line(cells: Sequence[str]) -> str:
        parts = [str(x).ljust(w) for x, w in zip(cells[:left], widths[:left])]
        parts += [str(x).rjust(w) for x, w in zip(cells[left:], widths[left:])]
        return "  ".join(parts).rstrip()

    return "\n".join([line(headers), *(line(r) for r in rows)])
