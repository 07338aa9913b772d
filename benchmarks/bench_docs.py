"""Regenerate the benchmark tables of docs/api.md and docs/qp.md from a bench report.

    .venv/bin/python -m ddwmmr.bench --out benchmarks/bench.json
    .venv/bin/python benchmarks/bench_docs.py benchmarks/bench.json

Each document keeps its generated part between two marker comments (``<!-- bench:NAME
begin -->`` and ``<!-- bench:NAME end -->``): docs/api.md the full text table
(``api-table``), docs/qp.md the qp step by state class and by phase (``qp-classes``).
Everything outside the markers is left as it is; each file is replaced atomically.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path
from typing import Any

from ddwmmr.bench import PHASES, REFERENCE_LABEL, TOOL, format_table
from ddwmmr.sim.result import write_atomic

ROOT = Path(__file__).resolve().parents[1]


def conditions(report: dict[str, Any]) -> str:
    """One line: when, where and on what the report was measured."""
    config = report["config"]
    load = config.get("load_average")
    load_text = f", load average {load[0]:.1f}" if load else ""
    return (
        f"Measured {config.get('timestamp', '?')} (commit {config.get('git_commit') or '?'}), "
        f"Python {config['python']}, numpy {config['numpy']}, {config['machine']}, "
        f"{config.get('cpus', '?')} CPUs shared with other jobs{load_text}; "
        f"{config['repeats']} repeats of {config['calls']} states."
    )


def api_table(report: dict[str, Any]) -> str:
    """The docs/api.md block: the conditions and the bench's own text table."""
    return f"{conditions(report)}\n\n```text\n{format_table(report)}\n```"


def qp_tables(report: dict[str, Any]) -> str:
    """The docs/qp.md block: latency by state class, then the phases of a qp step."""
    classes = [e for e in report["qp_classes"] if "rows" in e]
    latency = [
        "| state class | states | qp median / p90 / p99 (us) | generic path | + user task, limit "
        f"| qp-naive | {REFERENCE_LABEL} |",
        "|---|---|---|---|---|---|---|",
    ]
    for entry in classes:
        rows, ratios = entry["rows"], entry["ratios"]
        qp = rows["qp"]

        def versus(label: str, rows=rows, ratios=ratios) -> str:
            if label not in rows:
                return "not measured"
            return f"{rows[label]['median_us']:.1f} us ({ratios[label]['median']:.1f}x)"

        latency.append(
            f"| {entry['name']} | {entry['states']} | {qp['median_us']:.1f} / {qp['p90_us']:.1f}"
            f" / {qp['p99_us']:.1f} | {versus('qp (generic path)')} "
            f"| {versus('qp + user task, limit')} | {versus('qp-naive')} "
            f"| {versus(REFERENCE_LABEL)} |"
        )
    phases = [
        "| state class | "
        + " | ".join(f"{name} (us)" for name in PHASES)
        + " | exact look-ahead ran |",
        "|---|" + "---|" * (len(PHASES) + 1),
    ]
    for entry in classes:
        values = " | ".join(f"{entry['phases'][name]:.2f}" for name in PHASES)
        phases.append(
            f"| {entry['name']} | {values} | {100 * entry['exact_check_fraction']:.1f} % |"
        )
    return "\n".join([conditions(report), "", *latency, "", *phases])


def replace_block(text: str, name: str, body: str) -> str:
    """``text`` with the part between the ``name`` markers replaced by ``body``."""
    pattern = re.compile(
        rf"(<!-- bench:{name} begin -->\n)(?:.*?\n)?(<!-- bench:{name} end -->)", re.DOTALL
    )
    if not pattern.search(text):
        raise SystemExit(f"bench_docs: no <!-- bench:{name} begin/end --> markers")
    return pattern.sub(lambda m: m.group(1) + body + "\n" + m.group(2), text, count=1)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Regenerate the docs' benchmark tables.")
    parser.add_argument("report", nargs="?", default=str(ROOT / "benchmarks" / "bench.json"))
    parser.add_argument("--docs", default=str(ROOT / "docs"), help="docs folder")
    args = parser.parse_args(argv)
    report = json.loads(Path(args.report).read_text(encoding="utf-8"))
    if report.get("tool") != TOOL:
        print(f"bench_docs: {args.report} is not a {TOOL} report", file=sys.stderr)
        return 2
    docs = Path(args.docs)
    for name, block, document in (
        ("api-table", api_table(report), docs / "api.md"),
        ("qp-classes", qp_tables(report), docs / "qp.md"),
    ):
        text = document.read_text(encoding="utf-8")
        write_atomic(document, replace_block(text, name, block))
        print(f"updated {document} ({name})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
