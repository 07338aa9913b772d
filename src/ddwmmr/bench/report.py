"""The report: its text tables, its comparison with an earlier report, its file (written
atomically, read back and checked)."""

from __future__ import annotations

import json
import math
import os
from datetime import datetime
from pathlib import Path
from typing import Any

from ddwmmr.bench.methods import REFERENCE_LABEL
from ddwmmr.bench.mpc_floor import format_floor_lines
from ddwmmr.bench.qp_classes import qp_target_verdict
from ddwmmr.bench.timing import P99_MIN_SAMPLES, p99_judgeable
from ddwmmr.errors import (
    ParameterError,
    printable_line,
    read_text_file,
    shown,
)
from ddwmmr.outputs import check_output_file, check_writable, write_atomic

#: Marker of a report written by this tool (an existing ``--out`` file must carry it).
TOOL = "ddwmmr.bench"
#: Version of the report layout (3: ``config`` names the code by ``package_version``,
#: ``git`` and ``git_note`` as run records do; 2 had ``git_commit``).
REPORT_VERSION = 3


def format_table(report: dict[str, Any]) -> str:
    """A readable text table of :func:`run_benchmark`'s report."""
    config = report["config"]
    lines = [
        f"ddwmmr bench: {config['trajectory']}, {config['calls']} states per timing, "
        f"{config['run_duration_s']:g} s runs ({config['integrator']}), {config['repeats']} "
        "repeats",
        format_step_clause(config),
        format_load(config),
        f"{'method':<14} {'median':>8} {'p90':>8} {'p99':>8} {'vs naive':>9} {'steps/s':>9} "
        f"{'run x naive':>11}  target",
    ]
    for row in report["rows"]:
        verdict = {True: "ok", False: "MISS", None: "-"}[row["meets_target"]]
        lines.append(
            f"{row['label']:<14} {row['step_us']:>8.2f} {row['step_p90_us']:>8.2f} "
            f"{row['step_p99_us']:>8.2f} {row['step_ratio']:>9.3f} {row['steps_per_s']:>9.0f} "
            f"{row['run_speedup']:>11.2f}  {verdict}"
        )
    lines.append(
        f"target: step <= {report['target_step_ratio']:g} x {report['baseline']} step "
        "('vs naive' = step / naive step; 'run x naive' = steps/s / naive steps/s)"
    )
    measured = {row["label"] for row in report["rows"]}
    for label, budget in report["step_budgets_us"].items():
        if label not in measured:  # a budget of a method this run did not time
            continue
        lines.append(
            f"target for {label}: step <= {budget:g} us (absolute budget on the median above)"
        )
    for pair in report["pairs"]:
        lines.append(f"{pair['method']} / {pair['naive']} step ratio: {pair['step_ratio']:.3f}")
    for label, reason in report["skipped"].items():
        lines.append(f"skipped {label}: {reason}")
    if report.get("qp_classes"):
        lines += ["", *format_qp_classes(report)]
    if report.get("mpc_floor"):
        lines += ["", *format_floor_lines(report["mpc_floor"])]
    if report.get("scenarios"):
        lines += ["", *format_scenarios(report)]
    return "\n".join(lines)


def format_step_clause(config: dict[str, Any]) -> str:
    """One line: what the method table's step times (wall time on replayed states), and
    that its p99 is about the maximum when the states are too few for one."""
    source = config.get("state_source", "recorded")
    spacing = config.get("state_spacing_s")
    apart = f", {spacing:.2f} s apart" if spacing else ""
    text = (
        f"step: wall time (us) of one command call on states replayed from a {source} run"
        f"{apart} (a warm-started method such as mpc did not predict them); per state the "
        "median of its repeats, then median / p90 / p99 over states"
    )
    if not p99_judgeable(int(config["calls"])):
        text += f" (p99 of fewer than {P99_MIN_SAMPLES} states: about their maximum)"
    return text


def format_load(config: dict[str, Any]) -> str:
    """One line: the machine's 1-minute load average (at the start, when the report has
    it, and at the end of the run) against its CPUs, and a warning when it exceeds them."""
    cpus, end, start = (
        config.get("cpus"),
        config.get("load_average"),
        config.get("load_average_start"),
    )
    if not end:
        return f"load average unknown on {cpus or '?'} CPUs"
    text = f"load average (1 min) {end[0]:.1f} at the end"
    if start:
        text = f"load average (1 min) {start[0]:.1f} at the start, {end[0]:.1f} at the end"
    text += f" on {cpus or '?'} CPUs"
    if cpus and max(end[0], start[0] if start else 0.0) > cpus:
        text += (
            ": more than the CPUs, so these latencies are unreliable (other jobs preempt the "
            "timed calls)"
        )
    return text


def format_scenarios(report: dict[str, Any]) -> list[str]:
    """The scenario-throughput section of the table."""
    first = report["scenarios"][0]
    scenarios, jobs = first["scenarios"], first["jobs"]
    lines = [
        f"scenario benchmark ({scenarios} scenario{'s' if scenarios != 1 else ''}, seed 0, "
        f"{jobs} worker{'s' if jobs != 1 else ''}; simulated s per wall s, wall time "
        "includes the worker pool)"
    ]
    for row in report["scenarios"]:
        lines.append(
            f"  {row['controller']:<8} {row['sim_seconds_per_wall_second']:>8.0f}   "
            f"({row['sim_time_s']:.0f} simulated s in {row['wall_time_s']:.2f} s, "
            f"{row['failed']} failed)"
        )
    return lines


def format_qp_classes(report: dict[str, Any]) -> list[str]:
    """The qp state-class section of the table."""
    lines = [
        "qp step by state class (3 kg payload; states recorded from qp runs; us: "
        "median / p90 / p99 over states)"
    ]
    for entry in report["qp_classes"]:
        if "skipped" in entry:
            lines.append(f"  {entry['name']}: skipped ({entry['skipped']})")
            continue
        lines.append(
            f"  {entry['name']} ({entry['states']} states; exact stability look-ahead needed "
            f"in {100 * entry['exact_check_fraction']:.1f} %, else the cheap bound sufficed)"
        )
        for label, stats in entry["rows"].items():
            ratio = entry["ratios"].get(label)
            versus = (
                ""
                if ratio is None
                else (
                    f"  {ratio['median']:7.1f}x qp (repeats {ratio['min_over_repeats']:.1f}"
                    f"-{ratio['max_over_repeats']:.1f})"
                )
            )
            lines.append(
                f"    {label:<22} {stats['median_us']:>8.2f} {stats['p90_us']:>8.2f} "
                f"{stats['p99_us']:>8.2f}{versus}"
            )
        lines.append(format_qp_phases(entry))
    lines.append(format_qp_verdict(report))
    return lines


def format_qp_phases(entry: dict[str, Any]) -> str:
    """One line: the median of each qp phase (us) and the rest of the step, its median
    minus theirs. Medians do not add: when the phases' exceed the step's, the rest is
    shown negative and said so, not as the report's ``rest`` (clamped at 0)."""
    phases = entry["phases"]
    step = entry["rows"]["qp"]["median_us"]
    rest = step - sum(phases[name] for name in ("build", "solve", "check"))
    text = "    qp phases (median): " + ", ".join(
        f"{name} {phases[name]:.2f}" for name in ("build", "solve", "check")
    )
    if rest >= 0.0:
        return f"{text}, rest {rest:.2f}"
    return (
        f"{text}, rest {rest:.2f} (the phase medians add up to more than the step median "
        f"{step:.2f}: medians do not add)"
    )


def format_qp_verdict(report: dict[str, Any]) -> str:
    """One line: the qp step's targets (``report["qp_targets"]``), met or missed, per class."""
    targets = report["qp_targets"]
    measured = [e for e in report["qp_classes"] if "skipped" not in e]
    if not measured:
        return "qp targets: no class measured"
    verdicts = [qp_target_verdict(e["rows"]["qp"], e["states"]) for e in measured]
    worst_median = max(e["rows"]["qp"]["median_us"] for e in measured)
    judged = [e["rows"]["qp"]["p99_us"] for e in measured if p99_judgeable(e["states"])]
    worst_p99 = f"{max(judged):.2f}" if judged else "-"
    verdict = "MISS" if False in verdicts else ("not judged" if None in verdicts else "ok")
    budget = report.get("step_budgets_us", {}).get("qp")
    scope = "qp's own states by class" + (
        f", stricter than the table's {budget:g} us budget" if budget is not None else ""
    )
    text = (
        f"qp targets ({scope}): median <= {targets['median_us']:g} us and p99 <= "
        f"{targets['p99_us']:g} us in every class: {verdict} (worst {worst_median:.2f} / "
        f"{worst_p99})"
    )
    if len(judged) < len(measured):
        text += (
            f"; p99 needs >= {P99_MIN_SAMPLES} states, not judged in "
            f"{len(measured) - len(judged)} of {len(measured)} classes"
        )
    ratios = [e["ratios"][REFERENCE_LABEL] for e in measured if REFERENCE_LABEL in e["ratios"]]
    if ratios:
        lowest = min(r["min_over_repeats"] for r in ratios)
        verdict = "ok" if lowest >= targets["reference_ratio"] else "MISS"
        text += (
            f"; {REFERENCE_LABEL} / qp >= {targets['reference_ratio']:g}: {verdict} "
            f"(lowest over classes and repeats {lowest:.1f})"
        )
    else:
        text += f"; {REFERENCE_LABEL}: not measured"
    return text


def format_comparison(report: dict[str, Any], previous: dict[str, Any]) -> str:
    """Median step of each row and qp class against a previous report (new / old)."""
    config = previous["config"]
    lines = [
        f"against {config.get('timestamp', '?')} ({format_source(config)}): median step new / old"
    ]
    old_rows = {row["label"]: row for row in previous.get("rows", [])}
    for row in report["rows"]:
        old = old_rows.get(row["label"])
        if old:
            lines.append(
                f"  {row['label']:<14} {old['step_us']:>8.2f} -> {row['step_us']:>8.2f} us "
                f"({_ratio(row['step_us'], old['step_us'])})"
            )
    old_classes = {e["name"]: e for e in previous.get("qp_classes", []) if "rows" in e}
    for entry in report.get("qp_classes", []):
        old = old_classes.get(entry["name"])
        if old and "rows" in entry:
            new_us, old_us = entry["rows"]["qp"]["median_us"], old["rows"]["qp"]["median_us"]
            lines.append(
                f"  qp, {entry['name']:<20} {old_us:>8.2f} -> {new_us:>8.2f} us "
                f"({_ratio(new_us, old_us)})"
            )
    old_scenarios = {row["controller"]: row for row in previous.get("scenarios", [])}
    for row in report.get("scenarios", []):
        old = old_scenarios.get(row["controller"])
        if old:
            new_rate, old_rate = (
                row["sim_seconds_per_wall_second"],
                old["sim_seconds_per_wall_second"],
            )
            lines.append(
                f"  scenarios, {row['controller']:<14} {old_rate:>8.0f} -> {new_rate:>8.0f} "
                f"simulated s per wall s ({_ratio(new_rate, old_rate)})"
            )
    return "\n".join(lines)


def _ratio(new: float, old: float) -> str:
    """``new / old`` (both > 0) as ``1.23x``; a ratio beyond floats (an edited report's
    tiny or huge number) as ``>1e308x`` or ``<1e-308x`` instead of ``infx`` or ``0.00x``."""
    try:
        ratio = new / old
    except OverflowError:  # integers beyond float
        ratio = math.inf
    if ratio == math.inf:
        return ">1e308x"
    if ratio == 0.0:  # both are > 0: the quotient underflowed
        return "<1e-308x"
    return f"{ratio:.2f}x"


def format_source(config: dict[str, Any]) -> str:
    """What code a report's ``config`` was measured with: ``ddwmmr 0.1.0, commit
    0123456789ab`` (``, dirty`` with modified tracked files; ``no commit`` from an
    installed package, :func:`ddwmmr.provenance.git_record`), or ``commit b697be4`` from
    a report of layout 2, whose ``git_commit`` was the short commit of any git repository
    above the installed package (the user's own, outside a checkout)."""
    if "git" not in config:  # layout 2
        return f"commit {config.get('git_commit') or '?'}"
    git = config["git"]
    commit = git.get("commit") if isinstance(git, dict) else None
    if isinstance(commit, str) and commit:
        source = f"commit {commit[:12]}" + (", dirty" if git.get("dirty") else "")
    else:
        source = "no commit"
    return f"ddwmmr {config.get('package_version') or '?'}, {source}"


def write_report(report: dict[str, Any], path: str | Path, force: bool = False) -> None:
    """Write ``report`` to ``path`` atomically; an existing file is replaced only when it
    is a report of this tool (or with ``force``)."""
    path = Path(path)
    check_out(path, force)
    try:
        write_atomic(path, json.dumps(report, indent=2) + "\n")
    except OSError as exc:
        raise ParameterError(f"out: cannot write {path} ({exc.strerror or exc})") from None


def check_out(path: Path, force: bool = False) -> None:
    """Refuse, before the run, an output path that cannot be written or that is not a
    report of this tool (unless ``force``): :func:`ddwmmr.outputs.check_output_file`."""
    check_output_file(path, TOOL, _is_report, force)


def probe_out(path: str | Path) -> None:
    """Create and remove a temporary file where the report will go (the first existing
    folder on the way to ``path``, missing parents are created when the report is
    written): catches what permission bits do not show (``/proc``, a read-only mount, a
    full disk of inodes) before a long run rather than after it."""
    check_writable("out", Path(os.path.abspath(path)).parent)


def read_report(path: str | Path) -> dict[str, Any]:
    """A report written by :func:`write_report` (for ``--compare``), checked to hold every
    field :func:`format_comparison` reads; else one-line :class:`ParameterError`s naming
    ``compare`` and what is wrong (missing, unreadable, not JSON, nested too deeply, not
    a report of this tool, a field of the wrong type)."""
    if not str(path):
        raise ParameterError("compare: no file name given")
    path = Path(path)
    text = read_text_file(path, "compare")  # missing, permission, FIFO, size, UTF-8
    try:
        data = json.loads(text)
    except RecursionError:
        raise ParameterError(f"compare: {path} is not valid JSON (nested too deeply)") from None
    except ValueError as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ParameterError(f"compare: {path} is not valid JSON ({message})") from None
    if not isinstance(data, dict) or data.get("tool") != TOOL:
        raise ParameterError(f'compare: {path} is not a {TOOL} report (no "tool": "{TOOL}")')
    problem = _layout_problem(data)
    if problem:
        raise ParameterError(f"compare: {path} is not a usable {TOOL} report: {problem}")
    return data


def _type_name(value: Any) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean"}.get(
        type(value), "null" if value is None else "a number"
    )


def _positive_number(value: Any) -> bool:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(float(value)) and value > 0
    except OverflowError:  # an integer beyond float
        return False


def _entries_problem(data: dict[str, Any], key: str, fields: dict[str, str]) -> str | None:
    """What is wrong with ``data[key]`` as a list of objects with ``fields`` (name ->
    "text" or "number"; a number must be finite and > 0; the first field, the entry's name,
    given once: a comparison looks entries up by it); None if nothing."""
    entries = data.get(key, [])
    if not isinstance(entries, list):
        return f'"{key}" must be a list (got {_type_name(entries)})'
    names: set[str] = set()
    for i, entry in enumerate(entries, start=1):
        if not isinstance(entry, dict):
            return f'"{key}"[{i}] must be an object (got {_type_name(entry)})'
        for name, kind in fields.items():
            value = entry.get(name)
            if kind == "text" and not isinstance(value, str):
                return f'"{key}"[{i}].{name} must be a string (got {_type_name(value)})'
            if kind == "number" and not _positive_number(value):
                got = shown(value) if isinstance(value, int | float) else _type_name(value)
                return f'"{key}"[{i}].{name} must be a number > 0 (got {got})'
        name = next(iter(fields))
        if entry[name] in names:
            return f'"{key}"[{i}].{name} {shown(entry[name])} is given twice'
        names.add(entry[name])
    return None


def _config_problem(config: dict[str, Any]) -> str | None:
    """What is wrong with the fields of ``config`` the comparison's header prints (each
    may be missing): ``timestamp`` must be an ISO 8601 date and time, the code's names
    (``package_version``, ``git_commit``, ``git.commit``; null too) text on one line. An
    edited newline would split the header; None if nothing is wrong."""
    if "timestamp" in config and not _iso_timestamp(config["timestamp"]):
        got = shown(config["timestamp"])
        return f'"config".timestamp must be an ISO 8601 date and time (got {got})'
    git = config.get("git")
    texts = {
        "package_version": config.get("package_version"),
        "git_commit": config.get("git_commit"),
        "git.commit": git.get("commit") if isinstance(git, dict) else None,
    }
    for name, value in texts.items():
        if value is not None and not (isinstance(value, str) and printable_line(value)):
            return (
                f'"config".{name} must be text on one line, without control characters '
                f"(got {shown(value)})"
            )
    return None


def _iso_timestamp(value: Any) -> bool:
    if not isinstance(value, str):
        return False
    try:
        datetime.fromisoformat(value)
    except ValueError:
        return False
    return True


def _layout_problem(data: dict[str, Any]) -> str | None:
    """The first field :func:`format_comparison` would trip over, or None."""
    if not isinstance(data.get("config"), dict):
        return f'"config" must be an object (got {_type_name(data.get("config"))})'
    problem = _config_problem(data["config"])
    if problem:
        return problem
    if "rows" not in data:
        return 'no "rows"'
    problem = _entries_problem(data, "rows", {"label": "text", "step_us": "number"})
    problem = problem or _entries_problem(data, "qp_classes", {"name": "text"})
    problem = problem or _entries_problem(
        data, "scenarios", {"controller": "text", "sim_seconds_per_wall_second": "number"}
    )
    if problem:
        return problem
    for i, entry in enumerate(data.get("qp_classes", []), start=1):
        if "rows" in entry:
            rows = entry["rows"]
            qp = rows.get("qp") if isinstance(rows, dict) else None
            if not isinstance(qp, dict) or not _positive_number(qp.get("median_us")):
                return f'"qp_classes"[{i}].rows.qp.median_us must be a number > 0'
    return None


def _is_report(path: Path) -> bool:
    """Whether ``path`` is a report of this tool (a regular file of at most
    :data:`ddwmmr.errors.MAX_INPUT_BYTES` is read; a device such as /dev/zero never)."""
    try:
        data = json.loads(read_text_file(path, "out"))
    except (ParameterError, ValueError, RecursionError):
        return False
    return isinstance(data, dict) and data.get("tool") == TOOL
