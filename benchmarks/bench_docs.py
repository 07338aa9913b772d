"""Regenerate the benchmark tables of docs/api.md and docs/qp.md from a bench report.

    .venv/bin/python -m ddwmmr.bench --out benchmarks/bench.json
    .venv/bin/python benchmarks/bench_docs.py benchmarks/bench.json

Each document keeps its generated part between two marker comments (``<!-- bench:NAME
begin -->`` and ``<!-- bench:NAME end -->``): docs/api.md the full text table
(``api-table``), docs/qp.md the qp step by state class and by phase (``qp-classes``).
Everything outside the markers is left as it is; each file is replaced atomically. The
figure docs/figures/bench.png (step latency, full-run throughput, the phases of a qp step)
is drawn from the same report.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path
from typing import Any

from ddwmmr.bench import PHASES, REFERENCE_LABEL, TOOL, format_table
from ddwmmr.bench.report import format_source
from ddwmmr.sim.result import write_atomic

#: The simulate-throughput target, steps/s of a closed-form method's full run
#: (docs/api.md, "Benchmark").
RUN_TARGET = 60_000

ROOT = Path(__file__).resolve().parents[1]


def conditions(report: dict[str, Any]) -> str:
    """One line: when, where and on what the report was measured."""
    config = report["config"]
    load = config.get("load_average")
    load_text = f", load average {load[0]:.1f}" if load else ""
    return (
        f"Measured {config.get('timestamp', '?')} ({format_source(config)}), "
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


def plot_report(report: dict[str, Any], path: Path) -> Path:
    """docs/figures/bench.png: control-step latency per row (median, p90 and p99 over
    states, log scale), full-run throughput of every method, and the phases of a qp step
    in each state class next to the reference step."""
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = report["rows"]
    labels = [row["label"] for row in rows]
    figure, (latency, runs, phases) = plt.subplots(
        1, 3, figsize=(15, 4.8), gridspec_kw={"width_ratios": [1.2, 1.0, 1.1]}
    )
    y = range(len(rows))
    colours = ["0.55" if row["kind"] != "method" else "tab:blue" for row in rows]
    latency.barh(y, [row["step_us"] for row in rows], color=colours)
    latency.scatter([row["step_p90_us"] for row in rows], y, marker="|", color="k", label="p90")
    latency.scatter([row["step_p99_us"] for row in rows], y, marker="x", color="k", label="p99")
    latency.set(xscale="log", xlabel="control step (us), median over states", title="Step")
    latency.set_yticks(list(y), labels)
    latency.invert_yaxis()
    latency.legend(loc="upper right", fontsize=8)
    methods = [row for row in rows if row["kind"] != "extra"]
    runs.barh(
        range(len(methods)), [row["steps_per_s"] / 1000 for row in methods], color="tab:green"
    )
    runs.axvline(RUN_TARGET / 1000, color="tab:red", ls="--")
    runs.set_yticks(range(len(methods)), [row["label"] for row in methods])
    runs.invert_yaxis()
    # The target named in the axis label: a legend inside would sit on the bars or the line.
    runs.set(
        xlabel=f"full simulate run (1000 steps/s); red dashed: {RUN_TARGET / 1000:g}k target",
        title="Run (RK4, 2000 steps)",
    )
    classes = [entry for entry in report.get("qp_classes", []) if "phases" in entry]
    left = [0.0] * len(classes)
    for phase in PHASES:
        widths = [entry["phases"][phase] for entry in classes]
        phases.barh(range(len(classes)), widths, left=left, label=phase)
        left = [a + b for a, b in zip(left, widths)]
    phases.set_yticks(range(len(classes)), [entry["name"] for entry in classes])
    phases.invert_yaxis()
    title = "qp step by state class"
    reference = [entry["rows"].get(REFERENCE_LABEL, {}).get("median_us") for entry in classes]
    if classes and all(value is not None for value in reference):
        title += f"\n({REFERENCE_LABEL}: {min(reference):.0f}-{max(reference):.0f} us)"
    phases.set(xlabel="qp step (us), median of each phase", title=title)
    phases.set_xlim(0.0, 1.45 * max(left, default=1.0))
    phases.legend(loc="center right", fontsize=8)
    figure.suptitle(conditions(report), fontsize=8)
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=90, metadata={"Software": None})
    plt.close(figure)
    write_atomic(path, buffer.getvalue())
    return path


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
    figure = plot_report(report, docs / "figures" / "bench.png")
    print(f"drew {figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
