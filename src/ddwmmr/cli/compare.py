"""``python -m ddwmmr.compare``: every method on the same trajectories, one report.

Examples::

    python -m ddwmmr.compare --out report
    python -m ddwmmr.compare --methods ats clrrmc-ts --study tau --jobs 2 --out tau-report
    python -m ddwmmr.compare --traj figure8 --study none --duration 20 --out quick
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ddwmmr.cli.common import (
    ArgumentParser,
    add_robot_arguments,
    atomic_output_dir,
    robot_from_arguments,
    run_main,
)
from ddwmmr.controllers.base import available_methods, method_description
from ddwmmr.controllers.presets import PRESETS
from ddwmmr.errors import ParameterError, check_int_at_least, check_positive
from ddwmmr.reports.compare import (
    DEFAULT_TRAJECTORIES,
    MARKER,
    OFFSET_SCALES,
    STEP_SIZES,
    STUDIES,
    TAUS,
    CompareConfig,
    ReportInfo,
    default_step,
    execute,
    plan_runs,
    ranking_table,
    slides_name,
    slides_verdict,
    text_table,
    write_report,
)
from ddwmmr.trajectories import available_trajectories, load_trajectory, trajectory_name

PROG = "python -m ddwmmr.compare"
DEFAULT_OUT = "runs/compare"
#: Default number of worker processes: the CPUs, at most 8.
DEFAULT_JOBS = min(os.cpu_count() or 1, 8)

EPILOG_TEXT = f"""\
outputs (in --out):
  report.html   self-contained report (figures embedded, no external files)
  report.md     the same report as Markdown, linking the PNG figures next to it
  metrics.csv   one row per method x trajectory: method, trajectory and every field of
                the summary.json that `python -m ddwmmr.track` writes for that run
  *.png         paths, errors, wheel speeds and per-method panels per trajectory; one
                figure per study
  The folder is built next to --out and renamed into place when complete; an existing
  --out is replaced only if it is an earlier compare report (it holds {MARKER}).

ranking:
  score = RMS end-effector position error over the whole run (mm), per trajectory; lower
  is better; within 5 % (or 0.1 mm) counts as a tie. Overall = geometric mean over the
  trajectories. The report states whether the slides' ranking
  CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS >= RR-PI holds, and why not where it fails.

studies (--study, default all):
  tau         closed-loop time constants {", ".join(f"{t:g}" for t in TAUS)} s: convergence
              time vs tau (sluggishness), on the ellipse and the rectangle
  dt          steps {", ".join(f"{s:g}" for s in STEP_SIZES)} s with Euler and RK4, no
              initial offset: final error = drift, observed order of accuracy
  integrator  Euler vs RK4 at the default step, error vs time
  init        initial offsets {", ".join(f"{s:g}" for s in OFFSET_SCALES)} x the default
              (30 mm, -30 mm): open loop keeps the offset, closed loop removes it
  corners     rectangle: error peaks at the corners alpha = k pi/2 (no extra runs)
  all | none  every study | only the comparison

All runs use the same robot, start configuration (home arm pose on the trajectory start,
end effector offset by 30 mm, -30 mm with the arm), integrator (rk4) and step (the
trajectory's T/N). Results do not depend on --jobs; only the step latency (a wall-clock
timing) varies. Bad input prints one line on stderr and exits with status 2.
"""


def epilog() -> str:
    """The ``--help`` text after the options: outputs, ranking, studies, methods."""
    methods = "\n".join(f"  {m:<10}  {method_description(m)}" for m in available_methods())
    return f"{EPILOG_TEXT}\nmethods:\n{methods}"


def build_parser() -> ArgumentParser:
    """The argument parser (``--help`` documents every option, output and study)."""
    parser = ArgumentParser(
        prog=PROG,
        description=(
            "Compare redundancy-resolution and control methods of the differential-drive "
            "mobile manipulator: run every registered method (or --methods) on the ellipse "
            "and the rectangle (plus any --traj) and write a report with metrics tables, "
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
        "--methods",
        nargs="+",
        action="extend",
        metavar="METHOD",
        help=f"methods to compare (space or comma separated; default all: "
        f"{', '.join(available_methods())})",
    )
    parser.add_argument(
        "--out", default=DEFAULT_OUT, metavar="DIR", help=f"output folder (default {DEFAULT_OUT})"
    )
    parser.add_argument(
        "--jobs",
        type=int,
        default=DEFAULT_JOBS,
        metavar="N",
        help=f"parallel worker processes (default {DEFAULT_JOBS}: the CPUs, at most 8)",
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
        type=float,
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
    add_robot_arguments(parser)
    parser.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    return parser


def split_list(values: Sequence[str] | None) -> list[str]:
    """Items of repeated and/or comma-separated option values, in order, without repeats."""
    items = [item.strip() for value in values or [] for item in value.split(",")]
    return list(dict.fromkeys(item for item in items if item))


def parse_methods(values: Sequence[str] | None, option: str = "methods") -> tuple[str, ...]:
    """Validated method names (default: every registered method)."""
    known = available_methods()
    methods = split_list(values) or known
    for method in methods:
        if method not in known:
            raise ParameterError(f"{option}: unknown method {method!r} (known: {', '.join(known)})")
    return tuple(methods)


def parse_studies(values: Sequence[str] | None) -> tuple[str, ...]:
    """Validated study names; ``all`` (default) and ``none`` expand."""
    names = split_list(values) or ["all"]
    for name in names:
        if name not in (*STUDIES, "all", "none"):
            raise ParameterError(
                f"study: unknown study {name!r} (known: {', '.join(STUDIES)}, all, none)"
            )
    if "all" in names:
        return STUDIES
    return tuple(s for s in STUDIES if s in names)


def load_trajectories(extra: Sequence[str]) -> dict[str, Any]:
    """Ellipse, rectangle and the ``--traj`` trajectories, keyed by unique name."""
    trajectories = {name: load_trajectory(name) for name in DEFAULT_TRAJECTORIES}
    for value in split_list(extra):
        if value in DEFAULT_TRAJECTORIES:
            continue
        trajectory = load_trajectory(value)
        name = base = trajectory_name(trajectory)
        suffix = 2
        while name in trajectories:  # two files with the same stem: keep both
            name, suffix = f"{base}-{suffix}", suffix + 1
        trajectories[name] = trajectory
    return trajectories


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


def check_out(path: Path) -> Path:
    """Fail early (before any simulation) if ``--out`` may not be written or replaced."""
    if path.exists() and (
        not path.is_dir() or (any(path.iterdir()) and not (path / MARKER).exists())
    ):
        raise ParameterError(
            f"out: {path} exists and is not a compare report folder (no {MARKER}); "
            "choose another --out"
        )
    return path


def config_from_arguments(args: argparse.Namespace, argv: Sequence[str] | None) -> CompareConfig:
    """Validated :class:`CompareConfig` from the parsed arguments."""
    trajectories = load_trajectories(args.traj)
    command = " ".join([PROG, *(argv if argv is not None else sys.argv[1:])])
    methods = parse_methods(args.methods)
    study_methods = (
        parse_methods(args.study_methods, "study-methods") if args.study_methods else None
    )
    return CompareConfig(
        methods=methods,
        study_methods=study_methods,
        trajectories=trajectories,
        robot=robot_from_arguments(args),
        duration=check_duration(args.duration, trajectories),
        studies=parse_studies(args.study),
        command=command,
        preset=args.preset,
    )


def format_summary(info: ReportInfo, out: Path, runs: int, seconds: float, jobs: int) -> str:
    """The short console summary: ranking table, slides verdict, where the files went."""
    ranking, check = info.ranking, info.check
    lines = [
        f"Compared {len(ranking.overall)} methods on {', '.join(ranking.scores)}: {runs} runs "
        f"in {seconds:.1f} s ({jobs} job{'s' if jobs > 1 else ''}).",
        "",
        "Ranking: RMS end-effector position error over the run (mm), lower is better; "
        "per-trajectory rank in brackets; overall = geometric mean.",
        text_table(*ranking_table(ranking)),
        "",
        slides_verdict(check),
    ]
    for name in ranking.scores:
        found = [v for v in check.violations if v.trajectory == name]
        for method in dict.fromkeys(v.expected_better for v in found):
            worse = [slides_name(v.expected_worse) for v in found if v.expected_better == method]
            lines.append(f"  {name}: {slides_name(method)} scores worse than {', '.join(worse)}")
    figures = sum(name.endswith(".png") for name in info.files)
    lines += [
        "",
        f"Report: {out / 'report.html'} (also report.md, metrics.csv and {figures} PNG "
        f"figures in {out}/); the reasons are in the report.",
    ]
    return "\n".join(lines)


def _main(argv: Sequence[str] | None) -> int:
    args = build_parser().parse_args(argv)
    jobs = check_int_at_least("jobs", args.jobs, 1)
    out = check_out(Path(args.out))
    config = config_from_arguments(args, argv)
    plan = plan_runs(config)
    specs = plan.all_specs()
    start = time.perf_counter()
    outputs = execute(config, specs, jobs=jobs, progress=not args.no_progress)
    with atomic_output_dir(out, marker=MARKER) as staging:
        info = write_report(config, plan, outputs, staging)
    seconds = time.perf_counter() - start
    print(format_summary(info, out, len(specs), seconds, jobs))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; bad input prints one line on stderr and returns 2."""
    return run_main(_main, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
