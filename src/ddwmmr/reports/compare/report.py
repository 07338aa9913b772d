"""Building the report: :func:`write_report` writes ``metrics.csv``, the PNG figures,
``report.md`` and ``report.html``, with one builder per section (setup, ranking, which
method to use, the slides' settings against ours, the slides' ranking, diagnosis, one per
trajectory, one per study, definitions).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ddwmmr.commands import FORCE
from ddwmmr.controllers.base import method_description
from ddwmmr.model import Robot
from ddwmmr.outputs import write_atomic
from ddwmmr.reports import compare_plots as plots
from ddwmmr.reports import palette
from ddwmmr.reports.compare import advice, settings
from ddwmmr.reports.compare.constants import (
    CONVERGED_FRACTION,
    CORNER_TRAJECTORY,
    SINGULAR_COS,
    SLIDES_ORDER,
    STUDY_TRAJECTORY,
    TAUS,
    TIE_RELATIVE,
    slides_name,
)
from ddwmmr.reports.compare.diagnosis import (
    convergence_time,
    corner_times,
    diagnose,
    keeps_offset,
    observed_order,
    singularity_onset,
)
from ddwmmr.reports.compare.document import Document, fmt, mm
from ddwmmr.reports.compare.plan import (
    CompareConfig,
    Plan,
    RunOutput,
    RunSpec,
    default_step,
    main_spec,
    run_differences,
    run_duration,
    skipped_studies,
    study_offsets,
    study_steps,
    study_tau,
    tau_methods,
)
from ddwmmr.reports.compare.ranking import (
    NOT_TRACKED_MARK,
    NOT_TRACKED_NOTE,
    Ranking,
    SlidesCheck,
    build_ranking,
    check_slides,
    metrics_csv,
    metrics_rows,
    plant_metrics_rows,
)
from ddwmmr.reports.metrics import METRICS, Metric
from ddwmmr.reports.plots import circles_of
from ddwmmr.resolution.kernels import SINGULARITY_THRESHOLD
from ddwmmr.resolution.reference import default_offset
from ddwmmr.sim.simulate import FINAL_WINDOW_FRACTION, RATE_LIMIT_TOLERANCE
from ddwmmr.sim.verdict import explain, support_warning

# -- building the report ------------------------------------------------------------------


@dataclass
class ReportInfo:
    """What :func:`write_report` produced: ranking and slides check of the main runs, the
    same under the other preset, file names."""

    ranking: Ranking
    check: SlidesCheck
    files: list[str]
    alternative: Ranking | None = None
    alternative_check: SlidesCheck | None = None


#: The report's figures per trajectory (``<kind>_<trajectory>.png``).
TRAJECTORY_FIGURES = ("paths", "errors", "wheels", "methods")


def output_names(config: CompareConfig) -> tuple[str, ...]:
    """Every file :func:`write_report` may write for ``config`` (the CLI adds
    ``run.json``): checked against a user's files before the runs."""
    names = ["report.html", "report.md", "metrics.csv"]
    if config.plants:
        names.append(PLANT_METRICS)
    for name in config.trajectories:
        names += [f"{kind}_{name}.png" for kind in TRAJECTORY_FIGURES]
        names += [f"plant_{plant}_{name}.png" for plant in config.plants]
    names += [f"study_{study}.png" for study in config.studies]
    return tuple(names)


#: The summaries of the main runs repeated on the extra plants (``--plant``), one row per
#: run as in ``metrics.csv``, with its ``plant``.
PLANT_METRICS = "plant_metrics.csv"


def write_report(
    config: CompareConfig, plan: Plan, outputs: Mapping[RunSpec, RunOutput], folder: Path
) -> ReportInfo:
    """Write ``metrics.csv`` (and :data:`PLANT_METRICS` with extra plants), the PNG figures,
    ``report.md`` and ``report.html`` to ``folder``."""
    folder = Path(folder)
    write_atomic(folder / "metrics.csv", metrics_csv(metrics_rows(plan, outputs, config.shown)))
    tables = ["metrics.csv"]
    if plan.plants:
        rows = plant_metrics_rows(plan, outputs, config.shown)
        write_atomic(folder / PLANT_METRICS, metrics_csv(rows))
        tables.append(PLANT_METRICS)
    ranking = build_ranking(plan, outputs)
    check = check_slides(config, plan, outputs, ranking)
    alternative = build_ranking(plan, outputs, plan.alternative)
    alternative_check = check_slides(config, plan, outputs, alternative, plan.alternative)
    rankings = {
        config.preset: (ranking, check),
        config.other_preset: (alternative, alternative_check),
    }
    context = _Context(config, plan, outputs, folder, Document("Method comparison"))
    _setup_section(context)
    _ranking_section(context, ranking)
    _advice_section(context, ranking, rankings["slides"][0])
    _presets_section(context, rankings)
    _slides_section(context, ranking, check)
    _diagnosis_section(context)
    for name in config.trajectories:
        _trajectory_section(context, name)
    for plant in plan.plants:
        _plant_section(context, plant)
    for study in plan.studies:
        _STUDY_SECTIONS[study](context)
    _definitions_section(context)
    write_atomic(folder / "report.md", context.doc.to_markdown())
    write_atomic(folder / "report.html", context.doc.to_html(folder))
    files = ["report.html", "report.md", *tables, *context.figures]
    return ReportInfo(ranking, check, files, alternative, alternative_check)


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
        methods = dict.fromkeys([*self.config.methods, *self.config.studied])
        return palette.method_colors(list(methods))

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
        "integrator and step. Generated by `python -m ddwmmr.compare`. Errors are in mm "
        "unless a header says otherwise."
    )
    steps = ", ".join(
        f"{config.shown(n)}: dt = {default_step(t):g} s, duration = {run_duration(config, n):g} s"
        for n, t in config.trajectories.items()
    )
    dx, dy = default_offset(robot)
    items = [
        f"settings: preset `{config.preset}` (the report also ranks the methods under "
        f"`{config.other_preset}`, see below)",
        f"robot: L1 = {robot.L1:g} m, L2 = {robot.L2:g} m, payload = {robot.payload:g} kg, "
        f"wheel speed limit = {robot.wheel_speed_limit:g} rad/s, joint speed limit = "
        f"{robot.joint_speed_limit:g} rad/s{_other_fields(robot)}",
        f"integrator: rk4; {steps}",
        f"initial end-effector offset: ({dx:g} m, {dy:g} m) in the end effector's start "
        f"frame (x along its start orientation), i.e. {1000 * math.hypot(dx, dy):.1f} mm: "
        "the robot's default, in its length unit L1/0.35 m",
        "methods: "
        + "; ".join(f"`{m}`: {method_description(m).rstrip('.')}" for m in config.methods),
        f"runs: {len(c.plan.all_specs())} simulations "
        f"(studies: {', '.join(c.plan.studies) or 'none'}{_skipped_text(config, c.plan)})",
    ]
    items += _obstacle_items(config)
    if config.command:
        note = f" ({config.command_note})" if config.command_note else ""
        items.append(f"command: `{config.command}`{note}")
    c.doc.heading("Setup")
    c.doc.bullets(items)


def _skipped_text(config: CompareConfig, plan: Plan) -> str:
    skipped = skipped_studies(config, plan)
    return "".join(
        f"; {study} skipped: it needs the {needed} trajectory, which is not compared"
        for study, needed in skipped.items()
    )


#: Caption sentence of the figures that draw the runs' obstacles.
OBSTACLES_CAPTION = " Grey discs: the obstacles given with `--option obstacles`."


def _given_obstacles(config: CompareConfig) -> dict[str, tuple[tuple[float, float, float], ...]]:
    """method -> the obstacles (x, y, radius) (m, world frame) it was given (``--option
    obstacles``), for the compared methods that were given any."""
    given = {
        m: tuple(circles_of(config.options.get(m, {}).get("obstacles"))) for m in config.methods
    }
    return {m: circles for m, circles in given.items() if circles}


def run_obstacles(config: CompareConfig) -> list[tuple[float, float, float]]:
    """Every obstacle (x, y, radius) (m, world frame) any compared method was given
    (``--option obstacles``), each once, sorted."""
    return sorted({o for circles in _given_obstacles(config).values() for o in circles})


def _obstacle_items(config: CompareConfig) -> list[str]:
    """One Setup line per set of obstacles (``--option obstacles``) and the methods that
    avoid it: circles (x, y, radius) in m in the world frame; none without obstacles."""
    methods: dict[tuple[tuple[float, float, float], ...], list[str]] = {}
    for method, circles in _given_obstacles(config).items():
        methods.setdefault(circles, []).append(method)
    others = [m for m in config.methods if not any(m in v for v in methods.values())]
    verb = "ignores" if len(others) == 1 else "ignore"
    ignore = f"; {', '.join(f'`{m}`' for m in others)} {verb} them" if others else ""
    return [
        "obstacles (world frame, m): "
        + ", ".join(f"circle at ({x:g}, {y:g}) of radius {r:g}" for x, y, r in key)
        + f", given to {', '.join(f'`{m}`' for m in names)}{ignore}"
        for key, names in methods.items()
    ]


def ranking_table(
    ranking: Ranking, shown: Callable[[str], str] = str
) -> tuple[list[str], list[list[str]]]:
    """Headers and rows of the ranking table (RMS position error in mm, rank in brackets,
    :data:`NOT_TRACKED_MARK` after the score of a run that did not track: see
    :func:`ranking_footnote`); ``shown`` gives a trajectory key's shown name
    (:meth:`CompareConfig.shown`)."""
    names = list(ranking.scores)
    headers = ["rank", "method", *[f"{shown(n)} RMS (mm)" for n in names], "overall (mm)"]
    rows = [
        [
            str(ranking.overall_rank[m]),
            m,
            *[
                f"{mm(ranking.scores[n][m])}{_mark(ranking.tracked(n, m))} ({ranking.ranks[n][m]})"
                for n in names
            ],
            mm(ranking.overall[m]),
        ]
        for m in ranking.order
    ]
    return headers, rows


def _mark(tracked: bool) -> str:
    """:data:`NOT_TRACKED_MARK` for a run that did not track, else nothing."""
    return "" if tracked else NOT_TRACKED_MARK


def ranking_footnote(ranking: Ranking) -> str:
    """The footnote under :func:`ranking_table`: :data:`NOT_TRACKED_NOTE` when a score is
    marked, ``""`` when every ranked run tracked."""
    return NOT_TRACKED_NOTE if any(ranking.untracked.values()) else ""


def _ranking_table(c: _Context, ranking: Ranking) -> None:
    """The ranking table with its footnote, if any."""
    c.doc.table(*ranking_table(ranking, c.config.shown))
    note = ranking_footnote(ranking)
    if note:
        c.doc.paragraph(note + ".")


def _ranking_section(c: _Context, ranking: Ranking) -> None:
    c.doc.heading("Ranking")
    c.doc.paragraph(
        "**Score**: the RMS end-effector position error over the whole run (mm), per "
        "trajectory; lower is better. All methods start with the same initial offset, so the "
        "score rewards removing it quickly and penalises drift; the orientation error is "
        "reported in the tables but not scored. Scores within 5 % plus 0.1 mm of a better "
        "score are a tie and share its rank (the slides' `>=` allows ties). **Overall**: the "
        "geometric mean of the per-trajectory scores (errors span orders of magnitude). The "
        f"per-trajectory rank is in brackets. Settings: preset `{c.config.preset}`."
    )
    _ranking_table(c, ranking)


def _advice_section(c: _Context, ranking: Ranking, slides_ranking: Ranking) -> None:
    c.doc.heading("Which method should I use?")
    items = advice.profiles(c.config, c.outputs, ranking, c.plan.plants)
    c.doc.paragraph(
        "From the main runs above: accuracy (the score), the controller step on this "
        "machine (the median over the trajectories of each run's median step; a timing: it "
        "varies between runs and machines), whether the initial offset is removed, whether "
        "tip-over stability is a hard constraint, and what the shoulder singularity "
        f"cos th1 = 0 does to the run ({REACHED_TEXT})." + _plant_scope(list(c.plan.plants))
    )
    c.doc.table(advice.ADVICE_HEADERS, advice.advice_rows(items), left=advice.ADVICE_TEXT)
    if advice.marked(items):
        c.doc.paragraph(NOT_TRACKED_NOTE + ".")
    c.doc.bullets(advice.recommendations(items, slides_ranking, _corners_reached(c.config)))


def _plant_scope(plants: Sequence[str]) -> str:
    """The advice's sentence on the runs on the extra ``plants`` (``--plant``); ``""``
    without any."""
    if not plants:
        return ""
    several = "s" * (len(plants) > 1)
    titles = ", ".join(f'"{_plant_title(p)}"' for p in plants)
    return (
        " The lines below are judged on the kinematic plant; each also names the runs of its "
        f"methods that did not track, there and on the {' and '.join(plants)} plant{several} "
        f"(section{several} {titles})."
    )


def _sentence(text: str) -> str:
    """``text`` with its first letter capitalised and a full stop."""
    return text[:1].upper() + text[1:] + "."


def _corners_reached(config: CompareConfig) -> bool:
    """The runs of the corner trajectory reach one of its corners; True when it is not
    compared or does not say where its corners are (nothing to hold against its score)."""
    trajectory = config.trajectories.get(CORNER_TRAJECTORY)
    if getattr(trajectory, "corner_times", None) is None:
        return True
    return bool(corner_times(trajectory, run_duration(config, CORNER_TRAJECTORY)))


def _presets_section(c: _Context, rankings: Mapping[str, tuple[Ranking, SlidesCheck]]) -> None:
    c.doc.heading("The slides' settings and ours")
    rows = settings.setting_rows(c.config.methods, c.config.options)
    c.doc.paragraph(
        "The slides configure some methods differently from the library's defaults. Every "
        "main run is repeated with the slides' settings (`--preset slides`, "
        '`make_controller(name, robot, preset="slides")`); a method whose settings are the '
        "same runs once and counts in both rankings. Settings that differ:"
        if rows
        else "None of the compared methods is configured differently by the slides."
    )
    if rows:
        c.doc.table(settings.SETTING_HEADERS, rows)
    c.doc.paragraph("The same in both: " + "; ".join(settings.same_in_both(c.config.options)) + ".")
    if rows:
        c.doc.paragraph(
            "Results under both (errors in mm; the difference is what our setting buys). "
            + _aux_finding(c)
        )
        c.doc.table(settings.RESULT_HEADERS, settings.result_rows(c.config, c.plan, c.outputs))
    effects = settings.effect_rows(c.config, c.plan, c.outputs)
    if effects:
        c.doc.paragraph(
            "Each slides setting on its own (our settings with that one changed), for the "
            "methods where the presets differ in more than one setting:"
        )
        c.doc.table(settings.EFFECT_HEADERS, effects)
    for preset in ("slides", "default"):
        ranking, check = rankings[preset]
        label = "the slides' settings" if preset == "slides" else "our settings"
        c.doc.heading(f"Ranking under {label} (preset `{preset}`)", 3)
        _ranking_table(c, ranking)
        shown = c.config.shown
        c.doc.paragraph(" ".join([slides_verdict(check, shown), *failing_pairs(check, shown)]))


def slides_verdict(check: SlidesCheck, shown: Callable[[str], str] = str) -> str:
    """One sentence: does the slides' ranking hold, and where not (trajectories by their
    shown names, :meth:`CompareConfig.shown`)."""
    chain = " >= ".join(slides_name(m) for m in check.chain)
    if len(check.chain) < 2:
        return "The slides' ranking was not checked (fewer than two of its methods ran)."
    if check.holds_everywhere:
        return f"The slides' ranking {chain} holds on every trajectory (ties count as >=)."
    failing = [n for n, ok in check.holds.items() if not ok]
    return f"The slides' ranking {chain} does NOT hold on: {', '.join(map(shown, failing))}."


def failing_pairs(check: SlidesCheck, shown: Callable[[str], str] = str) -> list[str]:
    """One sentence per trajectory (by its shown name) and method that breaks the slides'
    chain."""
    lines = []
    for name in check.holds:
        found = [v for v in check.violations if v.trajectory == name]
        for method in dict.fromkeys(v.expected_better for v in found):
            worse = [
                f"{slides_name(v.expected_worse)} ({mm(v.worse_score)} mm)"
                for v in found
                if v.expected_better == method
            ]
            score = next(v.better_score for v in found if v.expected_better == method)
            lines.append(
                f"On the {shown(name)}, {slides_name(method)} ({mm(score)} mm) scores worse "
                "than "
                f"{', '.join(worse)}."
            )
    return lines


def _slides_section(c: _Context, ranking: Ranking, check: SlidesCheck) -> None:
    c.doc.heading("Does the slides' ranking hold?")
    c.doc.paragraph(
        "The slides conclude CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS (depends on the "
        "auxiliary constraint) >= RR-PI for tracking quality. Every pair the chain implies is "
        "tested with the score above. **" + slides_verdict(check, c.config.shown) + "**"
    )
    items = []
    for name in ranking.scores:
        found = [v for v in check.violations if v.trajectory == name]
        if not found:
            items.append(f"**{c.config.shown(name)}**: holds.")
            continue
        for method in dict.fromkeys(v.expected_better for v in found):
            beaten = [v for v in found if v.expected_better == method]
            others = ", ".join(
                f"{slides_name(v.expected_worse)} ({mm(v.worse_score)} mm)" for v in beaten
            )
            reasons = "; ".join(check.reasons[(name, method)])
            items.append(
                f"**{c.config.shown(name)}**: {slides_name(method)} "
                f"({mm(beaten[0].better_score)} mm) scores "
                f"worse than {others}. Reason: {reasons}."
            )
    c.doc.bullets(items)
    _variants_table(c)
    c.doc.paragraph(" ".join(_observations(c, ranking)))


def _diagnosis_section(c: _Context) -> None:
    c.doc.heading("What happened in each run")
    c.doc.paragraph(
        "Findings computed from each main run's time series: the shoulder singularity "
        f"({REACHED_TEXT}; the steps a finding calls damped are the singular steps, a wider "
        "test: see the Definitions), orientation lost at the rectangle's corners, "
        "commands the plant clipped at a speed limit (saturated), speed limits a method held "
        "inside its own bounds, a kept initial offset, or convergence."
    )
    for name in c.config.trajectories:
        items = []
        for m in c.config.methods:
            findings = diagnose(c.config, c.plan, c.outputs, main_spec(c.config, m, name))
            items.append(f"**{m}**: " + "; ".join(f.text for f in findings) + ".")
        c.doc.heading(c.config.shown(name), 3)
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
                c.config.shown(spec.trajectory),
                mm(variant["rms_position_error_m"]),
                mm(base["rms_position_error_m"]),
                fmt(variant["singular_steps"]),
                limit_steps(variant),
            ]
        )
    c.doc.paragraph(
        "Explanatory runs: the same comparison with one option changed (the main run's score "
        "for reference). `ap` with K3 = 0 removes the pull of the base heading toward 0. "
        "(The slides' auxiliary row aux = sum, on which they note RR-ATS depends, is in the "
        "section on the slides' settings.)"
    )
    c.doc.table(
        ["run", "trajectory", "RMS (mm)", "main run RMS (mm)", "singular steps", LIMIT_STEPS],
        rows,
    )


def _aux_finding(c: _Context) -> str:
    """Compare ats with aux = shoulder (ours) and aux = sum (the slides') per trajectory."""
    ats_options = c.config.options.get("ats", {})
    if "ats" not in c.config.methods or "aux" not in run_differences("ats", ats_options):
        return ""
    runs = settings.runs_by_preset(c.config, c.plan)
    texts = []
    for name in c.config.trajectories:
        slides = c.run(runs["slides"][("ats", name)])
        ours = c.run(runs["default"][("ats", name)]).summary["rms_position_error_m"]
        onset = singularity_onset(slides.timeseries)
        where = "" if onset is None else ", reaching cos(th1) = 0"
        texts.append(
            f"on the {c.config.shown(name)} aux = sum gives "
            f"{mm(slides.summary['rms_position_error_m'])} mm"
            f"{where} vs {mm(ours)} mm with aux = shoulder"
        )
    return "For RR-ATS, " + "; ".join(texts) + "."


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
        notes.append(
            f"On the {c.config.shown(name)}, {', '.join(kept)} {verb} the initial offset "
            "(open loop)."
        )
    if removed:
        verb = "removes" if len(removed) == 1 else "remove"
        notes.append(f"{', '.join(removed)} {verb} it (settled-end RMS error below 0.1 mm).")
    outside = [m for m in c.config.methods if m not in SLIDES_ORDER]
    for m in outside:
        notes.append(
            f"`{m}` is not in the slides' chain; it ranks {ranking.overall_rank[m]} overall."
        )
    return notes


#: When the report counts the shoulder singularity reached (its diagnosis and advice):
#: a narrower test than the damping that ``singular_steps`` counts.
REACHED_TEXT = f"reached where |cos th1| < {SINGULAR_COS:g}"

#: Header of a cell of :func:`limit_steps`.
LIMIT_STEPS = "saturated / wheel-limit / joint-rate-limit steps"


def limit_steps(summary: Mapping[str, Any]) -> str:
    """Table cell ``"saturated / wheel-limit / joint-rate-limit"`` of a run's step counts
    (``saturated_steps``: clipped by the plant; the others: at the limit, clipped or held
    by the method's own bounds; see the Definitions)."""
    keys = ("saturated_steps", "wheel_limit_steps", "joint_rate_limit_steps")
    return " / ".join(fmt(summary.get(k, math.nan)) for k in keys)


def tracked(reasons: Any) -> str:
    """Table cell of a run's ``verdict_reasons``: yes, or no with the reason codes."""
    if not isinstance(reasons, list | tuple):
        return "n/a"
    return "yes" if not reasons else "no: " + ", ".join(reasons)


def metric_cell(metric: Metric) -> Callable[[Any], str]:
    """The table cell of ``metric``: its value in the display unit, 3 significant digits."""
    return lambda value: fmt(metric.shown(value))


#: The summary metrics of a trajectory's table, as summary keys (labels, units and scales:
#: :data:`~ddwmmr.reports.metrics.METRICS`).
METRIC_KEYS = (
    "rms_position_error_m",
    "max_position_error_m",
    "final_position_error_m",
    "rms_orientation_error_rad",
    "max_nonholonomic_residual_m_s",
    "max_wheel_speed_rad_s",
    "min_manipulability",
    "mean_manipulability",
    "min_stability",
    "singular_steps",
    "saturated_steps",
    "wheel_limit_steps",
    "joint_rate_limit_steps",
    "median_step_us",
)
#: A trajectory's table: (header, summary key, cell writer) per column after the method's.
METRIC_COLUMNS: tuple[tuple[str, str, Callable[[Any], str]], ...] = (
    *((METRICS[key].label, key, metric_cell(METRICS[key])) for key in METRIC_KEYS),
    ("tracked? (docs/cli.md, Verdict)", "verdict_reasons", tracked),
)


def _trajectory_section(c: _Context, name: str) -> None:
    title = c.config.shown(name)  # shown; ``name`` (file-safe) names the figure files
    c.doc.heading(f"Trajectory: {title}")
    rows = [
        [m, *[f(c.main(m, name).summary.get(key, math.nan)) for _, key, f in METRIC_COLUMNS]]
        for m in c.config.methods
    ]
    c.doc.table(["method", *[h for h, _, _ in METRIC_COLUMNS]], rows)
    series = {m: c.main(m, name).timeseries for m in c.config.methods}
    colors = c.colors
    trajectory = c.config.trajectories[name]
    quarter = getattr(trajectory, "T", trajectory.duration) / 4.0
    obstacles = run_obstacles(c.config)
    offset = math.hypot(*default_offset(c.config.robot))
    zooms: list[tuple[str, float, float | None]] = [("A", 0.0, 3.0 * offset)]
    if quarter < run_duration(c.config, name):
        zooms.append(("B", quarter, None))
    c.add_figure(
        f"paths_{name}.png",
        plots.plot_paths(
            series, colors, f"{title}: end-effector paths", zooms, obstacles=obstacles
        ),
        f"{title}: end-effector paths and the desired path (thin dashed, drawn over the "
        "methods, which go from wide to thin lines so that coinciding ones stay visible). "
        "The main "
        "frame holds the desired path plus 0.5 m and every method's whole path (a method "
        "that drifts away widens it). Zoom "
        "A: the start, where the closed-loop methods remove the initial offset and the "
        "open-loop ones keep it"
        + (
            f"; zoom B: around t = T/4 = {quarter:g} s"
            + (" (the first corner)" if name == CORNER_TRAJECTORY else "")
            + ", dots mark where each method is at that time"
            if len(zooms) > 1
            else ""
        )
        + "."
        + OBSTACLES_CAPTION * bool(obstacles),
    )
    c.add_figure(
        f"errors_{name}.png",
        plots.plot_errors(series, colors, f"{title}: tracking errors"),
        f"{title}: position error (log scale, floored at 1e-12 m) and orientation error vs "
        "time (wrapped to [-pi, pi); the line is broken where it crosses +-pi instead of "
        "jumping across the plot).",
    )
    c.add_figure(
        f"wheels_{name}.png",
        plots.plot_wheels(series, colors, c.config.robot.wheel_speed_limit, f"{title}: wheels"),
        f"{title}: left (solid) and right (dashed) wheel speeds per method; dotted: the limit "
        f"+-{c.config.robot.wheel_speed_limit:g} rad/s.",
    )
    c.add_figure(
        f"methods_{name}.png",
        plots.plot_small_multiples(series, colors, c.config.robot, title, obstacles=obstacles),
        f"{title}: one panel per method (axes in m): desired path dashed, end effector in the "
        "method's colour, base path grey, the robot (footprint and arm) at six instants, one "
        "grey per instant from light (start) to dark (the final pose), named in the legend. "
        "Each panel holds everything it draws: a method that leaves the desired path gets a "
        "wider frame." + OBSTACLES_CAPTION * bool(obstacles),
    )


#: A tracking error this many times the kinematic plant's is explained (section "Plants").
PLANT_GAP = 1.5
#: Thresholds naming a cause: RMS velocity lag (m/s), wheel slip (m/s), torque-limited time.
LAG_M_S, SLIP_M_S, SATURATED_SHARE = 0.005, 0.05, 0.01


def _plant_title(plant: str) -> str:
    """The heading of ``plant``'s section."""
    return f"Plant: {plant} next to the kinematic plant"


def _plant_section(c: _Context, plant: str) -> None:
    """The main comparison repeated on ``plant``, next to the kinematic plant, with the
    measured reasons for the difference (velocity lag, torque saturation, wheel slip)."""
    c.doc.heading(_plant_title(plant))
    runs = dict(zip(c.plan.main, c.plan.plants[plant]))
    # the support columns where the plant reports its support loads (MuJoCo)
    support = any(SUPPORT_KEY in c.run(spec).summary for spec in runs.values())
    rows, reasons = [], []
    for base_spec, spec in runs.items():
        base, run = c.run(base_spec), c.run(spec)
        s, k, ts = run.summary, base.summary, run.timeseries
        forces = s["command_interface"] == FORCE  # wheel forces command no speed
        lag = math.nan if forces else float(np.sqrt(np.mean((ts["v_measured"] - ts["v"]) ** 2)))
        duration = max(float(ts["t"][-1]), 1e-12)
        saturated = s.get("actuator_saturated_time_s", math.nan) / duration
        slip = s.get("max_wheel_slip_m_s", math.nan)
        ratio = s["rms_position_error_m"] / max(k["rms_position_error_m"], 1e-12)
        rows.append(
            [
                c.config.shown(spec.trajectory),
                spec.method,
                mm(k["rms_position_error_m"]),
                mm(s["rms_position_error_m"]),
                fmt(ratio),
                mm(s["final_position_error_m"]),
                fmt(1000.0 * lag) if math.isfinite(lag) else "-",
                f"{100.0 * saturated:.1f} %" if math.isfinite(saturated) else "-",
                fmt(1000.0 * slip) if math.isfinite(slip) else "-",
                fmt(k["min_stability"]),
                fmt(s.get("min_physics_stability", math.nan)),
                _tipped_text(s),
                *(_support_cells(s) if support else []),
                tracked(s.get("verdict_reasons")),
            ]
        )
        if ratio > PLANT_GAP:
            where = c.config.shown(spec.trajectory)
            reasons.append(_plant_reason(spec, where, ratio, lag, saturated, slip))
    headers = [
        "trajectory", "method", "RMS kinematic (mm)", f"RMS {plant} (mm)", RATIO_HEADER,
        f"settled-end RMS {plant} (mm)", "lag (mm/s)", "actuator-limited", "slip (mm/s)",
        METRICS["min_stability"].label, METRICS["min_physics_stability"].label, "tipped",
        *(SUPPORT_HEADERS if support else ()),
        "tracked? (docs/cli.md, Verdict)",
    ]  # fmt: skip
    headers, rows = _filled_columns(headers, rows)
    notes = [text.format(plant=plant) for h, text in PLANT_COLUMN_NOTES.items() if h in headers]
    c.doc.paragraph(
        f"Every method of the comparison, same trajectories, robot and start, on the {plant} "
        "plant (its own dynamics: velocity commands go to velocity servos, so the base lags "
        "and may saturate or slip; a method that sends wheel forces there, as mpc does on a "
        "plant that judges tipping by its physics, drives the motors itself) and on the "
        "kinematic plant (the command is the motion). " + _sentence("; ".join(notes))
    )
    c.doc.table(headers, rows)
    c.doc.paragraph(
        "Where the error grows by more than "
        f"{PLANT_GAP:g}x: " + ("; ".join(reasons) if reasons else "nowhere.")
    )
    _plant_verdicts(c, plant)
    for name in c.config.trajectories:
        kinematic = {s.method: c.run(s).timeseries for s in runs if s.trajectory == name}
        on_plant = {s.method: c.run(r).timeseries for s, r in runs.items() if s.trajectory == name}
        c.add_figure(
            f"plant_{plant}_{name}.png",
            plots.plot_plant_errors(
                kinematic,
                on_plant,
                c.colors,
                plant,
                f"{c.config.shown(name)}: kinematic vs {plant} plant",
            ),
            f"{c.config.shown(name)}: position error per method on the {plant} plant (solid) "
            "and on the kinematic plant (dashed).",
        )


#: The plant table's column of the RMS error on the plant over the kinematic plant's.
RATIO_HEADER = "RMS ratio to kinematic"
#: The plant section's note on each column it explains, written when the table has it.
PLANT_COLUMN_NOTES = {
    RATIO_HEADER: "the RMS ratio to kinematic is the RMS error on the {plant} plant over the "
    "RMS error of the same run on the kinematic plant",
    "lag (mm/s)": "lag the RMS difference between the commanded and the measured forward "
    "speed ('-' for wheel-force commands, which command no speed)",
    "actuator-limited": "'actuator-limited' the share of the run with a motor at its torque "
    "limit (or a wheel at its force limit)",
    "slip (mm/s)": "slip the peak speed of a wheel's contact point over the floor (physics only)",
}
#: A table cell that holds no value (:func:`fmt` of a missing one, or a column's own '-').
EMPTY_CELLS = ("-", "n/a")


def _filled_columns(
    headers: Sequence[str], rows: Sequence[Sequence[str]]
) -> tuple[list[str], list[list[str]]]:
    """``headers`` and ``rows`` without the columns that no row fills (every cell one of
    :data:`EMPTY_CELLS`: the plant does not measure it, e.g. slip on the thesis plant)."""
    if not rows:
        return list(headers), []
    keep = [i for i in range(len(headers)) if any(r[i] not in EMPTY_CELLS for r in rows)]
    return [headers[i] for i in keep], [[r[i] for i in keep] for r in rows]


def _plant_verdicts(c: _Context, plant: str) -> None:
    """List the runs on ``plant`` that did not track, with what went wrong and its likely
    cause (:func:`ddwmmr.sim.verdict.explain`), or say that every run tracked; then the
    runs that unloaded an edge of the support polygon, with the verdict's warning
    (:func:`ddwmmr.sim.verdict.support_warning`)."""
    specs = c.plan.plants[plant]
    items, warnings = [], []
    for spec in specs:
        summary = c.run(spec).summary
        found, what, cause = explain(summary)
        who = f"**{spec.method} on {c.config.shown(spec.trajectory)}**"
        if found:
            items.append(f"{who}: {what}; likely cause: {cause}")
        warning = support_warning(summary)
        if warning:
            warnings.append(f"{who}: {warning.removeprefix('warning: ')}")
    if not items:
        c.doc.paragraph(f'Every run on the {plant} plant tracked (docs/cli.md, "Verdict").')
    else:
        c.doc.paragraph(
            f"Did not track on the {plant} plant ({len(items)} of {len(specs)} runs; "
            'docs/cli.md, "Verdict"):'
        )
        c.doc.bullets(items)
    if warnings:
        c.doc.paragraph(
            f"Lost support on the {plant} plant, tracked or not ({len(warnings)} of "
            f'{len(specs)} runs; a warning, not a failure: docs/cli.md, "Verdict"):'
        )
        c.doc.bullets(warnings)


#: The summary key whose presence says the plant reports its support loads (MuJoCo).
SUPPORT_KEY = "unloaded_time_s"
#: The plant table's support columns (:func:`_support_cells`).
SUPPORT_HEADERS = ("edge unloaded (s)", "min predicted edge load / floor (N)")


def _support_cells(summary: Mapping[str, Any]) -> list[str]:
    """The cells of :data:`SUPPORT_HEADERS`: the time with an edge of the support polygon
    unloaded (``unloaded_time_s``), and the least edge load the controller predicted with
    the floor it held (``min_predicted_edge_load_n``, ``min_edge_load_floor_n``; ``-``
    where its edge-load limit is off)."""
    least = summary.get("min_predicted_edge_load_n")
    floor = summary.get("min_edge_load_floor_n")
    predicted = "-" if least is None else f"{fmt(least)} / {fmt(floor)}"
    return [fmt(summary.get(SUPPORT_KEY, math.nan)), predicted]


def _tipped_text(summary: Mapping[str, Any]) -> str:
    """``yes (at t s)`` / ``no`` for a physics run, ``-`` where the plant cannot tip."""
    if "tipped" not in summary:
        return "-"
    return f"yes (at {summary['tip_time_s']:.2f} s)" if summary["tipped"] else "no"


def _plant_reason(
    spec: RunSpec, where: str, ratio: float, lag: float, saturated: float, slip: float
) -> str:
    """One clause: which measured effect explains a method's larger error on the plant
    (``where``: the run's trajectory by its shown name)."""
    causes = []
    if math.isfinite(saturated) and saturated >= SATURATED_SHARE:
        causes.append(f"actuators at their limit {100 * saturated:.1f} % of the time")
    if lag >= LAG_M_S:
        causes.append(f"the servos lag the command by {1000 * lag:.0f} mm/s RMS")
    if math.isfinite(slip) and slip >= SLIP_M_S:
        causes.append(f"the wheels slip up to {1000 * slip:.0f} mm/s")
    because = ", ".join(causes) if causes else "no single measured cause above its threshold"
    return f"{spec.method} on {where} ({fmt(ratio)}x): {because}"


def _tau_section(c: _Context) -> None:
    c.doc.heading("Study: time constant (sluggishness)", 2)
    methods = tau_methods(c.config)
    if not methods:
        c.doc.paragraph("No selected method has a time constant `tau`.")
        return
    theory = -math.log(CONVERGED_FRACTION)
    names = [n for n in (STUDY_TRAJECTORY, CORNER_TRAJECTORY) if n in c.config.trajectories]
    runs = {
        (m, n, tau): c.run(
            main_spec(c.config, m, n, options=(("tau", study_tau(c.config, m, tau)),))
        )
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
                row += [mm(summary["rms_position_error_m"]), limit_steps(summary)]
            rows.append(row)
    c.doc.paragraph(
        f"Closed-loop methods with K = 1/tau for tau in {', '.join(f'{t:g}' for t in TAUS)} s. "
        f"Convergence time on the {STUDY_TRAJECTORY}: when the position error last exceeds "
        f"{100 * CONVERGED_FRACTION:g} % of the initial offset; a first-order decay "
        f"exp(-t/tau) needs {first_order(theory)}. "
        + _tau_finding(convergence, run_duration(c.config, STUDY_TRAJECTORY), theory)
        + _tau_corner_finding(methods, runs)
    )
    headers = ["method", "tau (s)", "convergence (s)", f"{first_order(theory)} (s)"]
    for n in names:
        headers += [f"RMS {c.config.shown(n)} (mm)", f"{LIMIT_STEPS} {c.config.shown(n)}"]
    c.doc.table(headers, rows)
    c.add_figure(
        "study_tau.png",
        plots.plot_tau_study(curves, convergence, theory, c.colors),
        "Time-constant sweep: error vs time per tau (left), convergence time / tau per method "
        f"(right; dotted: the first-order {theory:.3f}). " + _tau_overlap(convergence),
    )


def first_order(theory: float) -> str:
    """``"2.996 tau"``: the time a first-order decay needs to fall below the convergence
    threshold, as a multiple of tau (``theory`` = -ln of the threshold fraction), with
    enough digits that the table's values (``theory * tau``) agree with it."""
    return f"{theory:.3f} tau"


def _tau_overlap(convergence: Mapping[str, Mapping[float, float]]) -> str:
    """Say which methods have the same convergence times (their markers overlap)."""
    methods = list(convergence)
    same = [
        m
        for m in methods[1:]
        if all(
            math.isclose(convergence[m][tau], convergence[methods[0]][tau], rel_tol=0.02)
            for tau in convergence[m]
        )
    ]
    if not same:
        return "The methods are offset by a few per cent in tau so no marker hides another."
    names = ", ".join([methods[0], *same])
    return (
        f"{names} converge in the same time (within 2 %) at every tau: their markers would "
        "coincide, so the methods are offset by a few per cent in tau."
    )


def _tau_corner_finding(
    methods: Sequence[str], runs: Mapping[tuple[str, str, float], RunOutput]
) -> str:
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


def _tau_finding(
    convergence: Mapping[str, Mapping[float, float]], duration: float, theory: float
) -> str:
    """Each method's range of convergence times over tau. A tau it did not settle for is
    put down to the run's ``duration`` (s) when that is shorter than a first-order decay
    needs (``theory`` tau), else to a steady error above the threshold."""
    texts = []
    for m, values in convergence.items():
        settled = [(tau, values[tau]) for tau in sorted(values) if not math.isnan(values[tau])]
        unsettled = [tau for tau in sorted(values) if math.isnan(values[tau])]
        short = [f"{tau:g}" for tau in unsettled if duration < theory * tau]
        never = [f"{tau:g}" for tau in unsettled if duration >= theory * tau]
        notes = []
        if never:
            notes.append(
                f"not settled for tau = {', '.join(never)} s: its steady error exceeds "
                f"{100 * CONVERGED_FRACTION:g} % of the offset"
            )
        if short:
            notes.append(
                f"the {duration:g} s run is too short to settle for tau = {', '.join(short)} s: "
                f"it ends before {first_order(theory)}"
            )
        if not settled:
            what = "never gets" if not short else "does not get"
            text = f"{m} {what} below {100 * CONVERGED_FRACTION:g} % of the offset"
            texts.append(text + (f" ({'; '.join(notes)})" if short else ""))
            continue
        text = f"{fmt(settled[0][1])} s at tau = {settled[0][0]:g} s"
        if len(settled) > 1:
            text += f" to {fmt(settled[-1][1])} s at tau = {settled[-1][0]:g} s"
        text += f" for {m}"
        if notes:
            text += f" ({'; '.join(notes)})"
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
    for m in c.config.studied:
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
        "numerical drift (or a method's own failure); the error at the end would hide drift that "
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
        "Largest position error vs step size, Euler (solid) and RK4 (dashed), log-log. "
        "Lines within 15 % of each other at every step lie on each other: they are drawn "
        "from wide to thin with open markers, and the legend's title names them.",
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
        for m in c.config.studied
        for i in ("euler", "rk4")
    }
    curves = {m: {i: _errors(runs[(m, i)]) for i in ("euler", "rk4")} for m in c.config.studied}
    summaries = {key: run.summary for key, run in runs.items()}
    rows = [
        [m]
        + [
            mm(summaries[(m, i)][k])
            for k in ("max_position_error_m", "rms_position_error_m")
            for i in ("euler", "rk4")
        ]
        + [mm(summaries[(m, "euler")]["end_position_error_m"])]
        for m in c.config.studied
    ]
    c.doc.paragraph(
        f"{STUDY_TRAJECTORY}, dt = {dt:g} s, no initial offset. Forward Euler is the "
        "first-order Runge-Kutta method: its local error is O(dt^2) per step, RK4's O(dt^5). "
        + _integrator_finding(runs)
    )
    headers = ["method", "Euler max (mm)", "RK4 max (mm)", "Euler RMS (mm)", "RK4 RMS (mm)"]
    c.doc.table([*headers, "Euler at the end (mm)"], rows)
    c.add_figure(
        "study_integrator.png",
        plots.plot_integrator_study(curves, c.colors, dt),
        "Position error vs time, Euler (solid) vs RK4 (dashed), no initial offset.",
    )


def _integrator_finding(runs: Mapping[tuple[str, str], RunOutput]) -> str:
    """Open loop ats vs closed loop clrrmc-ts under Euler, when both ran: each one's
    largest error (``max_position_error_m``), and ats's half way and at the last sample
    (``end_position_error_m``, the table's "at the end"; not the settled-end RMS)."""
    summaries = {key: run.summary for key, run in runs.items()}
    if ("ats", "euler") not in summaries or ("clrrmc-ts", "euler") not in summaries:
        return ""
    largest = {k: float(v["max_position_error_m"]) for k, v in summaries.items()}
    ats_max, ts_max = largest[("ats", "euler")], largest[("clrrmc-ts", "euler")]
    ats = runs[("ats", "euler")].timeseries
    end = float(summaries[("ats", "euler")]["end_position_error_m"])
    # only a clear return below the worst drift is put down to the closed curve
    back = ", where the closed curve brings part of it back" if end < 0.9 * ats_max else ""
    return (
        f"With Euler the open-loop ats drifts {mm(ats_max)} mm off at worst "
        f"({mm(ats['position_error_m'][len(ats['t']) // 2])} mm half way, {mm(end)} "
        f"mm at the end{back}), while the feedback of "
        f"clrrmc-ts holds it to {mm(ts_max)} mm. "
        + _rk4_finding(
            {m: largest[(m, "rk4")] for m in ("ats", "clrrmc-ts")},
            {"ats": ats_max, "clrrmc-ts": ts_max},
        )
        + _cs_euler_finding(summaries, ts_max)
    )


#: RK4's largest error counts as negligible below this fraction of Euler's at the same step.
NEGLIGIBLE_RK4_FRACTION = 0.1


def _rk4_finding(rk4: Mapping[str, float], euler_max: Mapping[str, float]) -> str:
    """What RK4 measured: ``rk4`` and ``euler_max`` map each method to its largest
    position error (m, ``max_position_error_m``) with RK4 and with Euler. The RK4 errors in
    mm, called negligible only where each is below :data:`NEGLIGIBLE_RK4_FRACTION` of the
    method's Euler error."""
    measured = " and ".join(f"{mm(v)} mm for {m}" for m, v in rk4.items())
    small = [m for m, v in rk4.items() if v < NEGLIGIBLE_RK4_FRACTION * euler_max[m]]
    below = f"below {NEGLIGIBLE_RK4_FRACTION:g} x the method's Euler drift"
    if len(small) == len(rk4):
        return f"With RK4 the largest errors are {measured}: negligible (each {below})."
    large = ", ".join(m for m in rk4 if m not in small)
    return f"With RK4 the largest errors are {measured}: not {below} for {large}."


def _cs_euler_finding(summaries: Mapping[tuple[str, str], Mapping[str, Any]], ts_max: float) -> str:
    """clrrmc-cs under Euler: sideways base error its feedback cannot remove."""
    if ("clrrmc-cs", "euler") not in summaries:
        return ""
    summary = summaries[("clrrmc-cs", "euler")]
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
    for m in c.config.studied:
        values = {
            math.hypot(*o): c.run(main_spec(c.config, m, STUDY_TRAJECTORY, initial_offset=o))
            for o in offsets
        }
        final[m] = {k: r.summary["final_position_error_m"] for k, r in values.items()}
        rows.append([m, *[mm(final[m][k]) for k in sorted(final[m])]])
    # The error curves show one closed-loop method: convergence depends on the offset there.
    closed = [m for m in SLIDES_ORDER if m.startswith("clrrmc") and m in c.config.studied]
    curve_method = (closed or list(c.config.studied))[0]
    curves = {
        math.hypot(*o): _errors(
            c.run(main_spec(c.config, curve_method, STUDY_TRAJECTORY, initial_offset=o))
        )
        for o in offsets
    }
    c.doc.paragraph(
        f"{STUDY_TRAJECTORY}: the end effector starts off the path by multiples of the default "
        "offset (same direction in the end effector's frame), moved with the arm; offsets the "
        "arm cannot reach are left out. Settled-end RMS position error per method: an "
        "open-loop method ends with its offset, a closed-loop one removes it."
    )
    headers = ["method", *[f"offset {1000 * k:.1f} mm" for k in sorted(next(iter(final.values())))]]
    c.doc.table(headers, rows)
    c.add_figure(
        "study_init.png",
        plots.plot_init_study(final, curves, curve_method, c.colors),
        "Settled-end RMS position error vs initial offset per method, and error vs time per "
        "offset.",
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
        c.doc.paragraph("No corner of the trajectory falls within the run.")
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
            'settled-end RMS position error (`final_position_error_m`; "final" in the '
            "verdict): RMS of the position error over the settled end of the run, the last "
            f"{100 * FINAL_WINDOW_FRACTION:g} % of the samples outside the rectangle's corner "
            "windows; position error at the end (`end_position_error_m`): at the last sample",
            "manipulability: |sin th2| in [0, 1]; stability S: tip-over margin, S <= 1 tips",
            "singular steps: steps where the method damped its inverse, the smallest "
            "singular value of the matrix inverted below its `singularity_threshold` "
            f"(default {SINGULARITY_THRESHOLD:g} in the robot's length unit: on `Robot()` "
            "|cos th1| < 0.15 to 0.25, so they begin before the singularity counts as "
            f"reached, |cos th1| < {SINGULAR_COS:g}; for `clrrmc-cs`: steps whose reference "
            "segment was integrated with damping); saturated steps: steps "
            "whose command the plant clipped at a wheel or joint speed limit (or stopped at "
            "a joint limit); wheel-limit steps, joint-rate-limit steps: steps with a wheel "
            "speed or a joint rate within "
            f"{100 * RATE_LIMIT_TOLERANCE:g} % of its limit, whether the plant clipped it "
            "or the method held it inside its own bounds (`qp` and `mpc` bound their "
            "commands a hair inside the limits: their limits show here, not as saturated)",
            f"{METRICS['median_step_us'].name}: median wall-clock time of one controller "
            "call (us); a timing, so it varies between runs and machines",
            "`metrics.csv`: one row per method x trajectory with every `summary.json` field "
            "of the matching `python -m ddwmmr.track` run"
            + (
                f"; `{PLANT_METRICS}`: the same for the runs on the other plants (`plant` names it)"
                if c.plan.plants
                else ""
            ),
        ]
    )


#: The robot fields the report's robot line always shows.
_SHOWN_FIELDS = ("L1", "L2", "payload", "wheel_speed_limit", "joint_speed_limit")


def _other_fields(robot: Robot) -> str:
    """The robot's other fields that differ from ``Robot()``'s (a caster layout, a base
    size...), for the report's robot line: ``""`` for the default robot."""
    default = Robot()
    differ = [
        f"{entry.name} = {getattr(robot, entry.name)!r}"
        for entry in dataclasses.fields(Robot)
        if entry.init
        and entry.name not in _SHOWN_FIELDS
        and getattr(robot, entry.name) != getattr(default, entry.name)
    ]
    return f"; other fields than Robot()'s: {', '.join(differ)}" if differ else ""
