"""``python -m ddwmmr.bounds``: the physical limit of the thesis scenarios, bracketed.

Examples::

    python -m ddwmmr.bounds --seed 0 --scenarios 1-100 --jobs 2 --out runs/bounds-seed0
    python -m ddwmmr.bounds --scenarios 1,3,7-9 --out runs/bounds-few
    python -m ddwmmr.scenarios --controller mpc --bounds runs/bounds-seed0/bounds.csv
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from collections.abc import Sequence
from concurrent.futures import as_completed
from dataclasses import asdict, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ddwmmr import provenance
from ddwmmr.bounds import batch
from ddwmmr.bounds.search import QUICK, Settings
from ddwmmr.cli.common import (
    ArgumentParser,
    Terminated,
    default_run_folder,
    integer_type,
    number_type,
    output_folder,
    output_target,
    payload_type,
    run_main,
)
from ddwmmr.cli.signals import say
from ddwmmr.errors import (
    MASS_RANGE_KG,
    MAX_JOBS,
    MAX_SCENARIOS,
    ParameterError,
    check_int_at_least,
    check_range,
    shown,
)
from ddwmmr.model.stability import STABILITY_CAP
from ddwmmr.outputs import (
    Existing,
    check_output_folder,
    check_output_path,
    check_writable,
    foreign_contents,
    inspect,
    list_in_manifest,
    write_atomic,
)
from ddwmmr.progress import ProgressBar
from ddwmmr.scenarios.executors import default_jobs
from ddwmmr.scenarios.generator import generate
from ddwmmr.scenarios.report import summary_json
from ddwmmr.sim.result import json_safe
from ddwmmr.workers import process_pool

if TYPE_CHECKING:
    from ddwmmr.scenarios.generator import Scenario

    #: Each scenario's cached (best-known, lower-bound) records, by 1-based number (None:
    #: not cached).
    Records = dict[int, tuple[dict[str, Any] | None, dict[str, Any] | None]]

PROG = "python -m ddwmmr.bounds"
TOOL = "bounds"
MARKER = "summary.json"

DESCRIPTION = """\
Bracket the minimum time of the thesis scenarios (5 waypoints, 0.01 m, the thesis plant's
force limits, S >= 1.25, start at rest in the default pose): a best-known time, a
systematic multistart of the minimum-time OCP replayed open-loop on the thesis plant, and
a true lower bound, the wheels' force budget with the base's stops priced, a relaxation
solved to global optimality (docs/mpc.md, "The physical limit, bracketed"). Writes
bounds.csv (scenario, lower_bound_s, best_known_s, starts, spread_s, replay_ok) and
summary.json into --out, and prints the means. Results are cached per scenario in
--out/cache as they come: an interrupted run started again with the same --out resumes. A
run of some --scenarios keeps the cache of the others (of the same seed and payload), and
its bounds.csv holds its own scenarios: --scenarios 1-100 again rebuilds the whole table
from the cache. A scenario takes about 55 s of CPU on average, 34 s with --quick, 19 s
with --lower-only (docs/mpc.md; the slowest took 6 minutes)."""

EPILOG = """\
Bad input prints one line and exits with status 2, leaving no output behind. The scenario
tool compares a controller with both ends: python -m ddwmmr.scenarios ... --bounds
DIR/bounds.csv."""


def build_parser() -> ArgumentParser:
    parser = ArgumentParser(
        prog=PROG,
        description=DESCRIPTION,
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--seed",
        type=integer_type(0, checked_later=True),
        default=0,
        help="generator seed, an integer >= 0 (default: 0)",
    )
    parser.add_argument(
        "--scenarios",
        default="1-100",
        metavar="LIST",
        help="scenarios, numbered from 1: '1-100', '7', '1,3,7-9' (default: 1-100)",
    )
    parser.add_argument(
        "--jobs",
        type=integer_type(1, MAX_JOBS, checked_later=True),
        metavar="N",
        help=f"worker processes, 1 to {MAX_JOBS} (default: the CPUs available)",
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default: runs/bounds-<time>/); an earlier bounds run's folder "
        "is resumed from its cache and replaced",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="accepted as the other tools accept it, and changes nothing: --out must be new, "
        "empty or an earlier bounds run's folder (the cache needs a folder of its own)",
    )
    parser.add_argument(
        "--payload",
        type=payload_type,
        default=3.0,
        metavar="KG",
        help="payload in kg (default: 3.0)",
    )
    parser.add_argument(
        "--stability-min",
        type=number_type(f"in [1, {STABILITY_CAP:g})"),
        default=1.25,
        metavar="S",
        help="floor on S of the best-known trajectories, in [1, 10) (default: 1.25; the "
        "lower bound holds for any floor)",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="a lighter multistart (46 starts instead of 59-60, about 34 s of CPU a "
        "scenario instead of 55: a coarser screening grid, the mpc's run the only "
        "controller start)",
    )
    parser.add_argument(
        "--lower-only",
        action="store_true",
        help="compute only the lower bounds (about 19 s of CPU per scenario); best-known times are "
        "taken from the cache where there (same settings), else NaN",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser


#: One item of ``--scenarios``: a number or a range of ASCII digits, as bounds.csv's
#: scenario column takes them (no sign, no underscore, no other script's digits).
_ITEM = re.compile(r"(?P<first>[0-9]+)(?:-(?P<last>[0-9]+))?")


def parse_scenarios(text: str) -> list[int]:
    """'1-100', '7', '1,3,7-9' -> sorted distinct scenario numbers (1-based); spaces
    around an item are allowed. Anything else is a one-line :class:`ParameterError`."""
    chosen: set[int] = set()
    for part in str(text).split(","):
        match = _ITEM.fullmatch(part.strip())
        if match is None:
            raise ParameterError(
                f"scenarios must be numbers or ranges like 1-100 or 1,3,7-9, in the digits "
                f"0-9 (got {shown(text)})"
            )
        first = batch.scenario_number(match["first"])
        last = batch.scenario_number(match["last"] or match["first"])
        if not 1 <= first <= last <= MAX_SCENARIOS:
            raise ParameterError(
                f"scenarios must lie in 1-{MAX_SCENARIOS} with first <= last "
                f"(got {shown(part.strip())})"
            )
        chosen.update(range(first, last + 1))
    return sorted(chosen)


def _settings(args: argparse.Namespace) -> Settings:
    check_range("payload", args.payload, *MASS_RANGE_KG, "kg")
    floor = args.stability_min
    if not (math.isfinite(floor) and 1.0 <= floor < STABILITY_CAP):
        raise ParameterError(f"stability-min must be in [1, {STABILITY_CAP:g}) (got {floor:g})")
    base = QUICK if args.quick else Settings()
    return replace(base, stability_min=floor)


def _main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    check_int_at_least("seed", args.seed, 0)
    numbers = parse_scenarios(args.scenarios)
    jobs = (
        default_jobs() if args.jobs is None else check_int_at_least("jobs", args.jobs, 1, MAX_JOBS)
    )
    settings = _settings(args)
    from ddwmmr.scenarios.protocol import check_payload

    check_payload(args.payload)  # as the scenarios tool: in range, standing at the start
    # The cache resumes in place, so the folder is written as given (not fresh).
    _, out, _ = output_target(args.out, lambda: default_run_folder("bounds"))
    target = _check_out(out, args.force)
    # Tried, not inferred from permission bits (/proc, a read-only mount): the cache is
    # written there as scenarios finish, so an unwritable --out fails before any of them.
    check_writable("out", target)
    # The seed's scenarios up to the highest number of this run or of the folder's cache:
    # this run solves its own, the cache of the others is judged by theirs.
    before = inspect(target, TOOL).listed if target.is_dir() else []
    last = max([*numbers, *batch.cached_numbers(before)])
    known = {s.index + 1: s for s in generate(last, args.seed)}
    scenarios = {i: s for i, s in known.items() if i in numbers}
    began = time.perf_counter()
    try:
        records = _solve_all(
            target, scenarios, args.payload, settings, jobs, not args.no_progress, args.lower_only
        )
    except (KeyboardInterrupt, Terminated):
        if _cached_any(target):  # before the stop line, which says the rest is removed
            say(_kept_note(target))
        raise
    rows = [batch.row(i, *records[i]) for i in numbers]
    summary = batch.summarize(rows)
    summary.update(
        seed=args.seed,
        payload=args.payload,
        settings=asdict(settings),
        wall_time_s=time.perf_counter() - began,
        run=_record(args, settings, jobs),
    )
    listed = inspect(target, TOOL).listed if target.is_dir() else []
    kept, dropped = batch.reusable_cache(target, listed, known, args.payload)
    with output_folder(target, TOOL, args.force) as staging:
        for name in kept:
            write_atomic(staging / name, (target / name).read_bytes())
        write_atomic(staging / "bounds.csv", batch.bounds_csv(rows))
        write_atomic(staging / MARKER, summary_json(summary))
    for note in _dropped_notes(target, listed, kept, args.seed, args.payload) if dropped else []:
        print(note, file=sys.stderr)
    elsewhere = _other_settings(target, scenarios, records, args.payload, settings)
    print(summary_line(len(rows), summary, elsewhere))
    print(f"wrote {out}/")  # as given (target is absolute), last on stdout as every tool
    return 0


def _cached_any(target: Path) -> bool:
    """Whether the cache in ``target`` holds a scenario's record: there is something the
    same command would resume from (a run stopped before its first scenario left none)."""
    cache = target / batch.CACHE
    if not cache.is_dir():
        return False
    names = [f"{batch.CACHE}/{path.name}" for path in cache.iterdir()]
    return bool(batch.cached_numbers(names))


def _kept_note(target: Path) -> str:
    """The line of a run stopped while solving: the finished scenarios' cache stays."""
    return (
        f"bounds: the cache of the scenarios finished so far is kept in "
        f"{target / batch.CACHE}; the same command resumes from it"
    )


def _check_out(out: Path, force: bool) -> Path:
    """:func:`check_output_folder` for this tool's ``--out``: a folder another tool or the
    user made is refused with or without ``force`` (the cache needs a folder of its own),
    in words that do not offer ``--force``."""
    path = check_output_path(out, probe=False)  # check_output_folder probes, after
    if path.is_dir():
        existing = inspect(path, TOOL)
        if existing.kind == "foreign":
            raise ParameterError(_foreign_refusal(out, existing))
    return check_output_folder(out, TOOL, force, (MARKER, "bounds.csv"))


def _foreign_refusal(out: Path, existing: Existing) -> str:
    """Why ``out`` cannot hold a bounds run, and what to do instead."""
    run = out.absolute().parent
    if out.absolute().name == batch.CACHE and inspect(run, TOOL).kind == "own":
        return (
            f"out: {out} is the cache folder of the bounds run in {run}, not a run's "
            f"folder: give --out {run} to resume or extend that run"
        )
    return (
        f"out: {out} {foreign_contents(TOOL, existing)}; the bounds cache needs a folder of "
        "its own, so --force does not help: choose another --out (a new folder or an "
        "earlier bounds run's)"
    )


#: What a dropped part of a scenario's cache is called, and the part kept beside it.
_PARTS = {
    "best": ("best-known record and trajectory", "lower bound"),
    "lower": ("lower bound", "best-known record"),
}


def _dropped_notes(
    target: Path, listed: list[str], kept: list[str], seed: int, payload: float
) -> list[str]:
    """The lines saying which cache files of ``listed`` a run dropped (not in ``kept``):
    whole scenarios, or the one part of a scenario whose other part was kept."""
    kept_numbers = batch.cached_numbers(kept)
    groups: dict[str, set[int]] = {}
    for name in set(listed) - set(kept):
        entry = batch.cache_entry(name)
        if entry is None:
            continue
        index, part = entry
        part = "whole" if index not in kept_numbers else "lower" if part == "lower" else "best"
        groups.setdefault(part, set()).add(index)
    why = f"made for another seed or payload than seed {seed}, payload {payload:g} kg"
    notes = []
    for part in ("whole", "best", "lower"):
        if part in groups:
            notes.append(_dropped_note(target, sorted(groups[part]), part, why))
    return notes


def _dropped_note(target: Path, dropped: list[int], part: str, why: str) -> str:
    """One line of :func:`_dropped_notes`: ``part`` (``whole``, ``best``, ``lower``) of
    the cache of scenarios ``dropped`` removed from ``target``, and ``why``."""
    shown_numbers = ", ".join(str(i) for i in dropped[:5]) + (", ..." if len(dropped) > 5 else "")
    scenarios = "scenario" + "s" * (len(dropped) > 1)
    where = f"{len(dropped)} {scenarios} ({shown_numbers}) from {target / batch.CACHE}"
    if part == "whole":
        return f"note: removed the cache of {where}: {why} (or unreadable)"
    removed, other = _PARTS[part]
    them = "them" if len(dropped) > 1 else "it"
    if part == "best":
        why += ", unreadable, or its trajectory missing or damaged"
        again = f"a run of {them} without --lower-only searches again"
    else:
        why += " (or unreadable)"
        again = f"a run of {them} computes {them} again"
    return f"note: removed the {removed} of {where}, keeping the {other}: {why}; {again}"


def summary_line(count: int, summary: dict[str, Any], elsewhere: str | None = None) -> str:
    """The one line the tool prints: the means, and the bracket where both ends are known
    (``--lower-only`` leaves the best-known times to a later run). Each mean says the
    scenarios it is over when not all ``count``: the lower bound's over every scenario,
    beside the best known and the width over the bracketed ones, with the lower bound's
    mean over those too. ``elsewhere``: the options of other settings the cache holds
    best-known times for (:func:`_other_settings`), named when the run has none."""
    scenarios = "1 scenario" if count == 1 else f"{count} scenarios"
    line = f"{scenarios}: lower bound {summary['mean_lower_bound_s']:.2f} s"
    bracketed = summary.get("bracketed", summary["replay_ok"])
    if bracketed == 0 or not math.isfinite(summary["mean_best_known_s"]):
        if elsewhere is not None:
            return line + (
                f", no best-known time with these settings (the cache holds ones of other "
                f"settings: {elsewhere}; run with those to use them, or without --lower-only "
                "to search)"
            )
        return line + ", no best-known time yet (run without --lower-only for them)"
    width = f"bracket width {summary['mean_width']:.3f} (mean of best known / lower bound)"
    if bracketed == count:
        return line + (
            f", best known {summary['mean_best_known_s']:.2f} s (replayed "
            f"{summary['replay_ok']}), {width}"
        )
    return line + (
        f" (mean of all {count}); over the {bracketed} with a replayed best-known time: "
        f"lower bound {summary['mean_lower_bound_bracketed_s']:.2f} s, best known "
        f"{summary['mean_best_known_s']:.2f} s, {width}"
    )


def _other_settings(
    folder: Path,
    scenarios: dict[int, Scenario],
    records: Records,
    payload: float,
    settings: Settings,
) -> str | None:
    """The options (``--quick``, ``--stability-min S``) of the settings of the cached
    best-known records of other settings than ``settings`` for the ``scenarios`` without
    one of their own in ``records``; None when there are none. The first such record
    speaks for the rest."""
    for index, scenario in scenarios.items():
        if records[index][0] is not None:
            continue
        recorded = batch.other_settings(folder, scenario, payload, settings)
        if recorded is not None:
            return _settings_options(recorded, settings)
    return None


def _settings_options(recorded: dict[str, Any], settings: Settings) -> str:
    """The options that make the method settings ``recorded`` (as a cache key holds them)
    out of a run's ``settings`` (``--quick``, ``without --quick``, ``--stability-min S``),
    or "other method settings" if no options do."""
    floor = recorded.get("stability_min")
    if not isinstance(floor, float):
        return "other method settings"
    for option, base in (("--quick", QUICK), ("without --quick", Settings())):
        if json_safe(asdict(replace(base, stability_min=floor))) != recorded:
            continue
        same_method = replace(settings, stability_min=floor) == replace(base, stability_min=floor)
        options = [] if same_method else [option]
        if floor != settings.stability_min:
            options.append(f"--stability-min {floor:g}")
        return ", ".join(options)
    return "other method settings"


def _solve_all(
    folder: Path,
    scenarios: dict[int, Scenario],
    payload: float,
    settings: Settings,
    jobs: int,
    progress: bool,
    lower_only: bool = False,
) -> Records:
    """Every scenario's (best, lower) records: cached ones read, the others solved (in
    ``jobs`` processes) and cached as they finish (``lower_only``: no best-known search)."""
    records, pending = {}, []
    for index, scenario in scenarios.items():
        best, lower = batch.read_cached(folder, scenario, payload, settings)
        records[index] = (best, lower)
        need_best = best is None and not lower_only
        if need_best or lower is None:
            pending.append(batch.Job(scenario, payload, settings, need_best, lower is None))
    with ProgressBar(len(scenarios), "bounds: scenarios", enabled=progress, unit="scenario") as bar:
        bar.advance(len(scenarios) - len(pending))
        if jobs == 1 or len(pending) <= 1:
            for job in pending:
                _keep(folder, records, batch.solve(job))
                bar.advance()
        else:
            with process_pool(min(jobs, len(pending))) as pool:
                futures = [pool.submit(batch.solve, job) for job in pending]
                for future in as_completed(futures):
                    _keep(folder, records, future.result())
                    bar.advance()
    return records


def _keep(folder: Path, records: Records, result: dict[str, Any]) -> None:
    """Cache a solved scenario (listed in the folder's manifest: the folder stays this
    tool's own, so a later run resumes from it)."""
    written = batch.store(folder, result)
    list_in_manifest(folder, TOOL, written)
    index = result["index"]
    best, lower = records[index]
    records[index] = (result.get("best", best), result.get("lower", lower))


def _record(args: argparse.Namespace, settings: Settings, jobs: int) -> dict[str, Any]:
    record = provenance.header(TOOL, PROG, args.argv if hasattr(args, "argv") else None)
    record.update(
        seed=args.seed,
        scenarios=args.scenarios,
        payload=args.payload,
        settings=provenance.encode(settings),
        jobs=jobs,
    )
    return record


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; bad input prints one line on stderr and returns 2."""
    return run_main(_main, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
