"""``python -m ddwmmr.bench`` (console script ``ddwmmr-bench``): the benchmark's command
line (:mod:`ddwmmr.bench` measures; docs/api.md, "Benchmark", explains the method)."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path

from ddwmmr.bench.baseline import NAIVE_LABEL
from ddwmmr.bench.methods import EXTRA_CASES
from ddwmmr.bench.report import (
    check_out,
    format_comparison,
    format_table,
    probe_out,
    read_report,
    write_report,
)
from ddwmmr.bench.run import MAX_CALLS, MAX_REPEATS, check_duration, run_benchmark
from ddwmmr.bench.scenarios import SCENARIO_CONTROLLERS, SCENARIO_COUNT
from ddwmmr.bench.timing import P99_MIN_SAMPLES
from ddwmmr.cli.common import (
    ArgumentParser,
    RefusedOption,
    given_text,
    integer_type,
    number_type,
    run_main,
    split_names,
)
from ddwmmr.controllers.base import available_methods
from ddwmmr.errors import MAX_JOBS, MAX_SCENARIOS, MAX_STEPS, ParameterError
from ddwmmr.registry import unknown_hint
from ddwmmr.trajectories import Ellipse
from ddwmmr.trajectories.base import resolution_step

DESCRIPTION = """\
Time every control method step by step and in full runs, the qp step by state class
and phase against its naive twin and roboticstoolbox-python's holistic QP step (install
with pip install 'ddwmmr[bench]', or -e '.[bench]' in a checkout), and the mpc step
against the HPIPM solve inside it (tracking and the first scenarios). Prints a table and
writes the report to --out.
"""


_repeat_count = integer_type(1, MAX_REPEATS)
_call_count = integer_type(1, MAX_CALLS)
_job_count = integer_type(1, MAX_JOBS)
_scenario_count = integer_type(0, MAX_SCENARIOS)


def method_names() -> list[str]:
    """What ``--method`` accepts: the registered methods and the extra rows."""
    return sorted(set(available_methods()) | {extra.label for extra in EXTRA_CASES})


def build_parser() -> argparse.ArgumentParser:
    """The ``python -m ddwmmr.bench`` argument parser."""
    parser = ArgumentParser(
        prog="python -m ddwmmr.bench",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ellipse = Ellipse()
    dt = resolution_step(ellipse)
    parser.add_argument(
        "--repeats",
        type=_repeat_count,
        default=5,
        metavar="N",
        help="times every timing is repeated (the --calls states and the full runs); each "
        f"state's median over the repeats counts (default 5, at most {MAX_REPEATS})",
    )
    parser.add_argument(
        "--calls",
        type=_call_count,
        default=500,
        metavar="N",
        help=f"states per timing (default 500, at most {MAX_CALLS}; a p99 is judged only "
        f"over >= {P99_MIN_SAMPLES})",
    )
    parser.add_argument(
        "--duration",
        # check_duration checks the range itself
        type=number_type(f"in [{dt:g}, {MAX_STEPS * dt:g}] s", finite=True),
        default=None,
        metavar="S",
        help=f"simulated time of each full run in s (default: one trajectory period, "
        f"{ellipse.duration:g}; {dt:g} to {MAX_STEPS * dt:g}: 1 to {MAX_STEPS} steps of {dt:g} s)",
    )
    parser.add_argument(
        "--method",
        action="append",
        dest="methods",
        metavar="NAME",
        help=f"measure only this method (and its extra rows; the {NAIVE_LABEL} baseline is "
        f"always measured); repeatable or comma separated; one of "
        f"{', '.join(method_names())} (default: all)",
    )
    parser.add_argument(
        "--out", default="bench.json", metavar="FILE", help="report file (default bench.json)"
    )
    parser.add_argument(
        "--force", action="store_true", help="replace --out even if it is not a bench report"
    )
    parser.add_argument(
        "--compare",
        metavar="FILE",
        help="also print medians against an earlier report (read and checked before the run)",
    )
    parser.add_argument(
        "--scenarios",
        type=_scenario_count,
        default=None,
        metavar="N",
        help=f"also time the first N benchmark scenarios with {', '.join(SCENARIO_CONTROLLERS)} "
        f"(simulated s per wall s; default {SCENARIO_COUNT} without --method, else 0; 0: skip; "
        f"at most {MAX_SCENARIOS})",
    )
    parser.add_argument(
        "--jobs",
        type=_job_count,
        default=None,
        metavar="N",
        help=f"worker processes of the scenario timing, only with --scenarios N >= 1 (default: "
        f"the CPUs available; at most {MAX_JOBS}, and never more than the scenarios)",
    )
    parser.add_argument(
        "--robot",
        action=RefusedOption,
        reason="the benchmark times the thesis robot only, as the scenario benchmark runs "
        'it (docs/thesis.md, "What is simulated")',
    )
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    parser.add_argument("--no-progress", action="store_true", help="no progress output on stderr")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point: print the table (or JSON) and write the report.

    Ctrl-C and SIGTERM stop it with one line (exit 130 / 143), as for every tool."""
    return run_main(_main, argv)


def _main(argv: Sequence[str] | None = None) -> int:
    """The tool; bad input raises :class:`ParameterError` (one line, status 2, as every
    tool: :func:`~ddwmmr.cli.common.run_main`)."""
    args = build_parser().parse_args(argv)
    if args.methods is not None:  # repeated and/or comma separated, as compare's --methods
        args.methods = split_names(args.methods, "--method")
    unknown = sorted(set(args.methods or ()) - set(method_names()))
    if unknown:
        choices = ", ".join(method_names())
        raise ParameterError(
            f"method: unknown method {unknown[0]!r} (choose from {choices})"
            + unknown_hint(unknown[0], method_names())
        )
    scenarios = args.scenarios
    if scenarios is None:
        scenarios = SCENARIO_COUNT if args.methods is None else 0
    if args.jobs is not None and scenarios == 0:  # nothing else runs in workers
        given = "got 0" if args.scenarios is not None else "0 by default with --method"
        raise ParameterError(f"--jobs: only used with --scenarios N >= 1 ({given})")
    # Everything that can be checked is checked before a minute-long run.
    previous = read_report(args.compare) if args.compare is not None else None
    out = Path(given_text("out", args.out, "a report file"))
    check_out(out, force=args.force)
    check_duration(Ellipse(), args.duration)
    probe_out(out)
    report = run_benchmark(
        args.repeats,
        args.calls,
        args.duration,
        args.methods,
        progress=not args.no_progress,
        scenarios=scenarios,
        scenario_jobs=args.jobs,
    )
    write_report(report, out, force=args.force)
    print(json.dumps(report, indent=2) if args.json else format_table(report))
    if previous is not None:
        print(format_comparison(report, previous))
    # Last, as every tool: where the report went. With --json on stderr, so that the
    # printed report stays one JSON document (bench --json > copy.json).
    print(f"wrote {out}", file=sys.stderr if args.json else sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
