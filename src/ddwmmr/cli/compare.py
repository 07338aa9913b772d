"""``python -m ddwmmr.compare``: every method on the same trajectories, one report.

Examples::

    python -m ddwmmr.compare --out report
    python -m ddwmmr.compare --methods ats clrrmc-ts --study tau --jobs 2 --out tau-report
    python -m ddwmmr.compare --traj figure8 --study none --duration 20 --out quick
    python -m ddwmmr.compare --only figure8 --study none --out figure8-only
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import textwrap
import time
from collections.abc import Callable, Collection, Sequence
from pathlib import Path
from typing import Any

from ddwmmr import provenance
from ddwmmr.cli.common import (
    ArgumentParser,
    add_force_argument,
    add_option_argument,
    add_robot_arguments,
    add_traj_scale_argument,
    check_output_folder,
    console_text,
    default_run_folder,
    horizon_defaults,
    horizon_range,
    integer_type,
    method_options_text,
    number_type,
    option_target,
    output_folder,
    output_target,
    refuse_plant_option_argument,
    robot_from_arguments,
    run_main,
    scaled_trajectory,
    split_names,
)
from ddwmmr.controllers.base import available_methods, method_description
from ddwmmr.controllers.option_specs import option_names, parse_options
from ddwmmr.controllers.presets import PRESETS, preset_options
from ddwmmr.errors import (
    MAX_JOBS,
    ParameterError,
    check_int_at_least,
    check_positive,
    check_step_count,
    did_you_mean,
)
from ddwmmr.outputs import write_atomic
from ddwmmr.plants import available_plants
from ddwmmr.progress import phase
from ddwmmr.registry import unknown_hint, used_plugins
from ddwmmr.reports.compare import (
    DEFAULT_TRAJECTORIES,
    OFFSET_SCALES,
    STEP_SIZES,
    STUDIES,
    TAUS,
    CompareConfig,
    ReportInfo,
    default_step,
    execute,
    output_names,
    plan_runs,
    ranking_footnote,
    ranking_table,
    slides_name,
    slides_verdict,
    text_table,
    write_report,
)
from ddwmmr.reports.compare.constants import TIE_ABSOLUTE_M, TIE_RELATIVE
from ddwmmr.reports.compare.plan import main_spec, report_name, run_duration, skipped_studies
from ddwmmr.resolution.reference import default_offset, initial_configuration
from ddwmmr.sim.result import json_safe
from ddwmmr.sim.simulate import check_start
from ddwmmr.sim.verdict import explain
from ddwmmr.trajectories import available_trajectories, load_trajectory, trajectory_name
from ddwmmr.trajectories.files import find_obstacle_file, find_trajectory_file

PROG = "python -m ddwmmr.compare"
#: Default number of worker processes: the CPUs, at most 8.
DEFAULT_JOBS = min(os.cpu_count() or 1, 8)

EPILOG_TEXT = f"""\
outputs (in --out):
  report.html   self-contained report (figures embedded, no external files)
  report.md     the same report as Markdown, linking the PNG figures next to it
  metrics.csv   one row per method x trajectory: method, trajectory and every metric of
                the summary.json that `python -m ddwmmr.track` writes for that run
  plant_metrics.csv  with --plant: the same for the runs on each plant (column plant)
  run.json      everything needed to repeat the comparison by hand: methods and
                their options with defaults, robot, trajectories (parameters, and a
                file's path and SHA-256), step per trajectory, integrator, initial
                offset, studies, version, git commit, libraries, BLAS, CPU and a
                command that repeats it
  *.png         paths, errors, wheel speeds and per-method panels per trajectory; one
                figure per study
  The folder is built next to --out and renamed into place when complete; an existing
  --out is replaced only if it is an earlier compare report holding nothing else (its
  .ddwmmr-manifest.json lists every file); --force writes into another folder and still
  deletes only files a manifest lists.

ranking:
  score = RMS end-effector position error over the whole run (mm), per trajectory; lower
  is better; within 5 % plus 0.1 mm counts as a tie. Overall = geometric mean over the
  trajectories. The report states whether the slides' ranking
  CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS >= RR-PI holds, and why not where it fails.

studies (--study, default all):
  tau         closed-loop time constants {", ".join(f"{t:g}" for t in TAUS)} s: convergence
              time vs tau (sluggishness), on the ellipse and the rectangle
  dt          steps {", ".join(f"{s:g}" for s in STEP_SIZES)} s with Euler and RK4, no
              initial offset: the error is the drift; its observed order of accuracy
  integrator  Euler vs RK4 at the default step, error vs time
  init        initial offsets {", ".join(f"{s:g}" for s in OFFSET_SCALES)} x the robot's
              default: open loop keeps the offset, closed loop removes it
  corners     rectangle: error peaks at the corners alpha = k pi/2 (no extra runs)
  all | none  every study | only the comparison

All runs use the same robot, start configuration (home arm pose on the trajectory start,
end effector moved with the arm by the robot's default offset: -0.03, -0.03 times its
length unit L1/0.35 m in its start frame, (-30, -30) mm for the default robot; for
another offset run python -m ddwmmr.track --offset), integrator (rk4) and step (the
trajectory's own: T/N, or a CSV's row spacing made no coarser than 0.02 s, as
python -m ddwmmr.track takes it). Results do not depend on --jobs; only the step latency
(a wall-clock timing) varies. Bad input prints one line on stderr and exits with status 2.
"""


def epilog() -> str:
    """The ``--help`` text after the options: outputs, ranking, studies, methods and their
    options."""
    methods = "\n".join(f"  {m:<10}  {method_description(m)}" for m in available_methods())
    options = "\n".join(
        textwrap.fill(line, 88, subsequent_indent="    ")
        for line in method_options_text(available_methods()).splitlines()
    )
    return f"{EPILOG_TEXT}\nmethods:\n{methods}\n\n{options}"


def build_parser() -> ArgumentParser:
    """The argument parser (``--help`` documents every option, output and study)."""
    parser = ArgumentParser(
        prog=PROG,
        description=(  # wrapped by hand: the raw formatter keeps the epilog's columns
            "Compare redundancy-resolution and control methods of the differential-drive\n"
            "mobile manipulator: run every registered method (or --methods) on the ellipse\n"
            "and the rectangle (plus any --traj) and write a report with metrics tables,\n"
            "figures, a ranking and optional studies."
        ),
        epilog=epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--traj",
        nargs="+",
        action="extend",
        default=[],
        metavar="NAME|FILE",
        help="extra trajectories besides ellipse and rectangle: a name "
        f"({', '.join(available_trajectories())}) or a .toml/.csv path",
    )
    parser.add_argument(
        "--only",
        nargs="+",
        action="extend",
        default=[],
        metavar="NAME|FILE",
        help="compare on these trajectories instead of ellipse and rectangle (the studies "
        "need the ellipse, the corner study the rectangle: others are skipped)",
    )
    add_traj_scale_argument(
        parser, "every compared trajectory (--only and --traj too; the studies run on them)"
    )
    parser.add_argument(
        "--methods",
        nargs="+",
        action="extend",
        metavar="METHOD",
        help=f"methods to compare (space or comma separated; default all: "
        f"{', '.join(available_methods())})",
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default runs/compare-<time>/, never replacing anything: -2, "
        "-3... when taken)",
    )
    parser.add_argument(
        "--jobs",
        type=integer_type(1, MAX_JOBS, checked_later=True),
        default=DEFAULT_JOBS,
        metavar="N",
        help=f"parallel worker processes, 1 to {MAX_JOBS} (default {DEFAULT_JOBS}: the "
        "CPUs, at most 8)",
    )
    parser.add_argument(
        "--study",
        nargs="+",
        action="extend",
        metavar="NAME",
        help=f"studies to add: {', '.join(STUDIES)}, all or none (space or comma separated; "
        "default all; see below)",
    )
    parser.add_argument(
        "--study-methods",
        nargs="+",
        action="extend",
        metavar="METHOD",
        help="methods the studies run (default: the compared methods; list fewer to save time "
        "when a method is slow)",
    )
    parser.add_argument(
        "--duration",
        type=number_type("> 0 s"),
        metavar="S",
        help="simulated time of every run, studies included, in s (default: one period of "
        "each trajectory)",
    )
    parser.add_argument(
        "--preset",
        choices=PRESETS,
        default="default",
        help="settings of the main comparison and the studies: default (the library's) or "
        "slides (the slides' auxiliary row and gains); the report ranks both either way",
    )
    parser.add_argument(
        "--plant",
        nargs="+",
        action="extend",
        default=[],
        metavar="PLANT",
        help="also run the main comparison on these plants (space or comma separated; "
        f"{', '.join(extra_plants())}; thesis: force-limited base; "
        "mujoco: rigid-body physics) and report their errors next to the kinematic plant's, "
        "with the reasons (lag, torque limits, slip)",
    )
    refuse_plant_option_argument(parser, "compare")
    add_option_argument(
        parser,
        "an option of the compared methods: NAME=VALUE for every method taking NAME, "
        "METHOD:NAME=VALUE for that one; over the preset in every run of the method, except "
        "where a study sets it (the swept tau)",
    )
    parser.add_argument(
        "--horizon",
        type=number_type(horizon_range()),
        metavar="S",
        help="prediction horizon in s of the methods taking one (mpc; docs/mpc.md); the same "
        f"as --option horizon=S (default {horizon_defaults()[0]:g} s, the mpc's tracking one)",
    )
    add_robot_arguments(parser)
    add_force_argument(parser)
    parser.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    return parser


def parse_method_options(
    texts: Sequence[str] | None, methods: Sequence[str], horizon: float | None = None
) -> dict[str, dict[str, Any]]:
    """The user's options per compared method, from ``--option [METHOD:]NAME=VALUE`` and
    ``--horizon`` (checked as the simulator's fields are; values made hashable)."""
    texts = [*(texts or ()), *(() if horizon is None else (f"horizon={horizon!r}",))]
    chosen: dict[str, list[str]] = {m: [] for m in methods}
    for text in texts:
        target, rest = option_target(text)
        if target is not None:  # METHOD:NAME=VALUE
            if target not in chosen:
                raise ParameterError(
                    f"option: {target!r} is not a compared method{did_you_mean(target, chosen)}"
                    f" (compared: {', '.join(methods)}; got {text!r})"
                )
            chosen[target].append(rest)
            continue
        name = text.partition("=")[0].strip()
        takers = [m for m in methods if name in option_names(m)]
        if not takers:
            if "=" not in text:
                raise ParameterError(f"option must be [METHOD:]NAME=VALUE (got {text!r})")
            known = sorted({n for m in methods for n in option_names(m)})
            taken = "; ".join(f"{m}: {', '.join(option_names(m))}" for m in methods)
            raise ParameterError(
                f"option: no compared method takes {name!r}{did_you_mean(name, known)} ({taken})"
            )
        for method in takers:
            chosen[method].append(text)
    options = {}
    for method, given in chosen.items():
        parsed = parse_options(method, given)
        if "obstacles" in parsed and parsed["obstacles"] is not None:
            from ddwmmr.qp.limits.obstacles import load_obstacles

            circles = load_obstacles(find_obstacle_file(parsed["obstacles"]))
            parsed["obstacles"] = tuple((c.x, c.y, c.radius) for c in circles)
        if parsed:
            options[method] = parsed
    return options


def extra_plants() -> list[str]:
    """The plants ``--plant`` may add next to the kinematic one."""
    return [p for p in available_plants() if p != "kinematic"]


def parse_plants(values: Sequence[str] | None) -> tuple[str, ...]:
    """Validated ``--plant`` names (repeated and/or comma separated)."""
    plants = split_names(values, "plant")
    for name in plants:
        if name == "kinematic":
            raise ParameterError("plant: the kinematic plant always runs; --plant adds others")
        if name not in extra_plants():
            raise ParameterError(
                f"plant: unknown plant {name!r} (one of {', '.join(extra_plants())})"
                + unknown_hint(name, extra_plants())
            )
    return tuple(plants)


def parse_methods(values: Sequence[str] | None, option: str = "methods") -> tuple[str, ...]:
    """Validated method names (default: every registered method)."""
    known = available_methods()
    methods = split_names(values, option) or known
    for method in methods:
        if method not in known:
            raise ParameterError(
                f"{option}: unknown method {method!r} (known: {', '.join(known)})"
                + unknown_hint(method, known)
            )
    return tuple(methods)


def parse_studies(values: Sequence[str] | None) -> tuple[str, ...]:
    """Validated study names; ``all`` (default) and ``none`` expand."""
    names = split_names(values, "study") or ["all"]
    for name in names:
        if name not in (*STUDIES, "all", "none"):
            raise ParameterError(
                f"study: unknown study {name!r} (known: {', '.join(STUDIES)}, all, none)"
            )
    if len(set(names)) > 1 and {"all", "none"} & set(names):
        word = "none" if "none" in names else "all"
        raise ParameterError(
            f"study: {word!r} cannot be combined with other studies (got {' '.join(names)})"
        )
    if "all" in names:
        return STUDIES
    return tuple(s for s in STUDIES if s in names)


def load_trajectories(
    extra: Sequence[str],
    only: Sequence[str] = (),
    sources: dict[str, Any] | None = None,
    shown: dict[str, str] | None = None,
    scale: Callable[[Any], Any] | None = None,
) -> dict[str, Any]:
    """Ellipse, rectangle (or the ``--only`` ones) and the ``--traj`` ones, by unique
    file-safe name (:func:`report_name`, the stem of their figure files), each passed
    through ``scale`` if given (``--traj-scale``: :func:`scaled_trajectory`).

    ``sources`` (if given) receives each key's file (None for a built-in default);
    ``shown`` (if given) each key's shown name: the trajectory's own name on one line (a
    line break becomes a space, as the reports show it), ``-2``, ``-3``... appended to a
    repeated one. The key is the loaded trajectory's name (a scaled ellipse is still the
    ``ellipse`` the studies run on), the shown name the scaled one's (``ellipse x10``).
    """
    chosen = _trajectory_values(only, "only")
    # each value with the option that gave it first, for the messages
    values = {v: "only" for v in chosen or DEFAULT_TRAJECTORIES}
    values.update({v: "traj" for v in _trajectory_values(extra, "traj") if v not in values})
    trajectories: dict[str, Any] = {}
    files: dict[str, Any] = {}
    names: dict[str, str] = {}
    for value, option in values.items():
        trajectory = _load(value, option)
        name = unique_name(report_name(trajectory_name(trajectory)), trajectories)  # file-safe
        if scale is not None:
            trajectory = scale(trajectory)
        own = trajectory_name(trajectory)
        trajectories[name] = trajectory
        files[name] = _load(value, option, find_trajectory_file)
        names[name] = unique_name(" ".join(str(own).splitlines()), names.values())
    if sources is not None:
        sources.update(files)
    if shown is not None:
        shown.update(names)
    return trajectories


def _trajectory_values(values: Sequence[str] | None, option: str) -> list[str]:
    """The trajectories of ``--traj`` or ``--only``: comma-separated lists
    (:func:`split_names`), except a value that is a file's whole name, a comma in it
    (``run 3,4.csv``), which is that one file."""
    items: list[str] = []
    for value in values or []:
        whole = "," in value and os.path.isfile(value)
        items.extend([value] if whole else split_names([value], option))
    return list(dict.fromkeys(items))


def _load(value: str, option: str, read: Callable[[str], Any] = load_trajectory) -> Any:
    """``read(value)``; its refusal names ``option`` (``only: unknown trajectory ...``), not
    ``traj``, for a value of ``--only``."""
    try:
        return read(value)
    except ParameterError as exc:
        text = str(exc)
        if option == "traj" or not text.startswith("traj: "):
            raise
        raise ParameterError(f"{option}: {text.removeprefix('traj: ')}") from None


def unique_name(base: str, taken: Collection[str]) -> str:
    """``base``, or ``base-2``, ``base-3``... the first not in ``taken`` (two trajectories
    of one name: keep both)."""
    name, suffix = base, 2
    while name in taken:
        name, suffix = f"{base}-{suffix}", suffix + 1
    return name


def check_duration(duration: float | None, trajectories: dict[str, Any]) -> float | None:
    """The ``--duration`` value, checked against every trajectory's default step (s)."""
    if duration is None:
        return None
    duration = check_positive("duration", duration)
    for name, trajectory in trajectories.items():
        step = default_step(trajectory)
        if step > duration:
            raise ParameterError(
                f"duration must be >= the step of {name} ({step:g} s) (got {duration:g})"
            )
    return duration


def check_runs(config: CompareConfig, specs: Sequence[Any]) -> None:
    """Every planned run within the step cap (:data:`ddwmmr.errors.MAX_STEPS`), and
    starting upright and clear of its obstacles (:func:`ddwmmr.sim.simulate.check_start`,
    as ``track`` refuses it), before any run."""
    for spec in specs:
        try:
            check_step_count(run_duration(config, spec.trajectory), spec.dt)
            trajectory = config.trajectories[spec.trajectory]
            own = default_offset(config.robot)
            offset = own if spec.initial_offset is None else spec.initial_offset
            name = "the robot's default offset" if offset == own else "the study's offset"
            start = initial_configuration(config.robot, trajectory, offset, name=name)
            obstacles = dict(spec.options).get("obstacles") or ()
            check_start(config.robot, start, obstacles, "payload", None)
        except ParameterError as exc:
            where = config.shown(spec.trajectory)
            raise ParameterError(f"{exc} (run {spec.label()} on {where})") from None


def compared_plugins(config: CompareConfig) -> dict[str, dict[str, str]]:
    """The plug-ins a comparison runs (:func:`ddwmmr.registry.used_plugins`): its
    methods, those of its studies, and its plants."""
    methods = [*config.methods, *config.studied]
    return used_plugins(method=list(dict.fromkeys(methods)), plant=list(config.plants))


def run_record(
    config: CompareConfig, sources: dict[str, Any], argv: Sequence[str] | None, jobs: int
) -> dict[str, Any]:
    """run.json: everything needed to repeat the comparison. ``dt`` (s, per trajectory),
    ``integrator`` and ``initial_offset`` (m, in the end effector's start frame) are the
    main comparison's on the kinematic plant, encoded as in track's record (the studies
    sweep them; a physics plant rounds the step to its engine's)."""
    record = provenance.header("compare", PROG, argv, compared_plugins(config))
    runs = {name: main_spec(config, config.methods[0], name) for name in config.trajectories}
    first = next(iter(runs.values()))
    record.update(
        methods=list(config.methods),
        study_methods=list(config.studied),
        preset=config.preset,
        options={
            m: provenance.options_record(
                m, {**preset_options(m, config.preset), **config.options.get(m, {})}
            )
            for m in config.methods
        },
        robot=provenance.robot_record(config.robot),
        trajectories={
            name: provenance.trajectory_record(t, sources.get(name))
            for name, t in config.trajectories.items()
        },
        dt={name: spec.dt for name, spec in runs.items()},
        duration=config.duration,
        integrator=first.integrator,
        initial_offset=list(first.initial_offset or ()),
        studies=list(config.studies),
        jobs=jobs,
        plant={"name": "kinematic"},  # the main comparison; ``plants`` adds sections
        plants=["kinematic", *config.plants],
        seed=None,  # nothing random in a comparison
    )
    return record


def config_from_arguments(
    args: argparse.Namespace, argv: Sequence[str] | None, sources: dict[str, Any] | None = None
) -> CompareConfig:
    """Validated :class:`CompareConfig` from the parsed arguments (``sources``: see
    :func:`load_trajectories`)."""
    shown: dict[str, str] = {}
    plants = parse_plants(args.plant)
    robot = robot_from_arguments(args, plants)
    trajectories = load_trajectories(
        args.traj,
        args.only,
        sources,
        shown,
        lambda trajectory: scaled_trajectory(trajectory, args.traj_scale, robot),
    )
    methods = parse_methods(args.methods)
    study_methods = (
        parse_methods(args.study_methods, "study-methods") if args.study_methods else None
    )
    studies = parse_studies(args.study)
    if study_methods is not None and not studies:
        raise ParameterError("study-methods: only used with a study (got --study none)")
    config = CompareConfig(
        methods=methods,
        study_methods=study_methods,
        trajectories=trajectories,
        robot=robot,
        duration=check_duration(args.duration, trajectories),
        studies=studies,
        preset=args.preset,
        plants=plants,
        options=parse_method_options(args.option, methods, args.horizon),
        shown_names=shown,
    )
    # quoted as the run record quotes it (with the plug-ins' DDWMMR_PLUGINS): the report's
    # line repeats the run when pasted, or says what else it needs
    command = provenance.command_record(PROG, argv, compared_plugins(config))
    config.command, config.command_note = command["command"], command.get("command_note", "")
    return config


def judged_runs(plan: Any) -> list[tuple[Any, str, str]]:
    """The runs the console judges (:func:`not_tracked`): the main runs, then their
    repetitions on each ``--plant``, each as ``(spec, who, where)``: the method (with the
    plant off the kinematic one) for the likely-cause lines, and ``" (thesis plant)"`` or
    ``""`` for the run's line. The comparison's other runs (the other preset, variants,
    studies) feed the report's sections and are not judged on the console."""
    judged = [(spec, spec.method, "") for spec in plan.main]
    # a plan may leave out ``plants`` when no extra plant runs
    for plant, specs in getattr(plan, "plants", {}).items():
        judged += [
            (spec, f"{spec.method} on the {plant} plant", f" ({plant} plant)") for spec in specs
        ]
    return judged


def runs_text(plan: Any, runs: int) -> str:
    """``"14 runs (the 12 judged below: ...; 2 for the report's other sections)"``: the
    ``runs`` simulated, and of them the :func:`judged_runs` where they are fewer, so the
    console's counts agree."""
    judged = len(judged_runs(plan))
    if judged >= runs:
        return f"{runs} runs"
    plants = ["kinematic", *getattr(plan, "plants", {})]
    where = " and ".join([", ".join(plants[:-1]), plants[-1]] if len(plants) > 1 else plants)
    return (
        f"{runs} runs (the {judged} main runs on the {where} plant{'s' * (len(plants) > 1)}, "
        f"judged below, and {runs - judged} for the report's other sections)"
    )


def not_tracked(plan: Any, outputs: dict[Any, Any], shown: Callable[[str], str] = str) -> list[str]:
    """Console lines for the runs that did not track (:mod:`ddwmmr.sim.verdict`), the main
    runs and their repetitions on each ``--plant`` (named): one per run saying what went
    wrong, then each likely cause once; ``shown`` gives a trajectory key's shown name
    (:meth:`CompareConfig.shown`)."""
    judged = judged_runs(plan)
    lines: list[str] = []
    causes: dict[str, list[str]] = {}
    for spec, who, where in judged:
        found, what, cause = explain(outputs[spec].summary)
        if found:
            lines.append(f"  {spec.method} on {shown(spec.trajectory)}{where}: {what}")
            causes.setdefault(cause, []).append(who)
    if not lines:
        return ['Every run tracked (see docs/cli.md, "Verdict").']
    head = f'Did not track ({len(lines)} of {len(judged)} runs; see docs/cli.md, "Verdict"):'
    tail = [
        f"  likely cause ({', '.join(dict.fromkeys(methods))}): {cause}"
        for cause, methods in causes.items()
    ]
    return [head, *lines, *tail]


def format_summary(
    info: ReportInfo,
    out: Path,
    runs: int | str,
    seconds: float,
    jobs: int,
    failures: Sequence[str] = (),
    shown: Callable[[str], str] = str,
) -> str:
    """The short console summary: ranking table, slides verdict, the runs that did not
    track (``failures``, from :func:`not_tracked`), where the files went; ``runs``: how
    many ran, a number or :func:`runs_text`; ``shown`` gives a trajectory key's shown name
    (:meth:`CompareConfig.shown`)."""
    ranking, check = info.ranking, info.check
    lines = [
        f"Compared {len(ranking.overall)} methods on {', '.join(map(shown, ranking.scores))}: "
        f"{runs if isinstance(runs, str) else f'{runs} runs'} "
        f"in {seconds:.1f} s ({jobs} job{'s' if jobs > 1 else ''}).",
        "",
        "Ranking: RMS end-effector position error over the run (mm), lower is better; "
        "per-trajectory rank in brackets; overall = geometric mean; scores within "
        f"{100 * TIE_RELATIVE:g} % plus {1000 * TIE_ABSOLUTE_M:g} mm of a better one share "
        "its rank.",
        text_table(*ranking_table(ranking, shown)),
        *([footnote] if (footnote := ranking_footnote(ranking)) else []),
        "",
        slides_verdict(check),
    ]
    for name in ranking.scores:
        found = [v for v in check.violations if v.trajectory == name]
        for method in dict.fromkeys(v.expected_better for v in found):
            worse = [slides_name(v.expected_worse) for v in found if v.expected_better == method]
            lines.append(
                f"  {shown(name)}: {slides_name(method)} scores worse than {', '.join(worse)}"
            )
    if failures:
        lines += ["", *failures]
    figures = sum(name.endswith(".png") for name in info.files)
    lines += [
        "",
        f"Report: {out / 'report.html'} (also report.md, "
        f"{', '.join(n for n in info.files if n.endswith('.csv'))} and {figures} PNG "
        f"figures in {out}/); the reasons are in the report.",
    ]
    return "\n".join(lines)


def default_out() -> Path:
    """``runs/compare-<YYYYmmdd-HHMMSS>`` (:func:`default_run_folder`, as track's)."""
    return default_run_folder("compare")


def skipped_notes(config: CompareConfig, plan: Any) -> list[str]:
    """One stderr note per requested study the plan leaves out (every study is requested
    by default): the trajectory it needs is not among the compared ones (``--only``/``--traj``)."""
    compared = ", ".join(map(config.shown, config.trajectories))
    return [
        f"note: study {study} skipped: it needs the {needed} trajectory, which is not "
        f"compared (trajectories: {compared})"
        for study, needed in skipped_studies(config, plan).items()
    ]


def _main(argv: Sequence[str] | None) -> int:
    args = build_parser().parse_args(argv)
    jobs = check_int_at_least("jobs", args.jobs, 1, MAX_JOBS)
    base, out, fresh = output_target(args.out, default_out)
    check_output_folder(out, "compare", args.force)  # the path, before anything is loaded
    sources: dict[str, Any] = {}
    config = config_from_arguments(args, argv, sources)
    check_output_folder(out, "compare", args.force, ("run.json", *output_names(config)))
    plan = plan_runs(config)
    for line in skipped_notes(config, plan):  # the default studies too: say which cannot run
        print(line, file=sys.stderr)
    specs = plan.all_specs()
    check_runs(config, specs)
    record = run_record(config, sources, argv, jobs)
    progress = not args.no_progress
    start = time.perf_counter()
    writer = output_folder(base, "compare", args.force, fresh)  # numbers from base if fresh
    with writer as staging:
        outputs = execute(config, specs, jobs=jobs, progress=progress)
        with phase("compare: writing the report (figures, HTML, Markdown)", enabled=progress):
            info = write_report(config, plan, outputs, staging)
            write_atomic(staging / "run.json", json.dumps(json_safe(record), indent=2) + "\n")
    seconds = time.perf_counter() - start
    failures = not_tracked(plan, outputs, config.shown)
    runs = runs_text(plan, len(specs))
    out = out.with_name(writer.path.name)  # fresh: the next free name if out was taken
    print(console_text(format_summary(info, out, runs, seconds, jobs, failures, config.shown)))
    print(f"wrote {out}/")  # last on stdout, as every tool
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; bad input prints one line on stderr and returns 2."""
    return run_main(_main, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
