"""The physical limit, bracketed: docs/mpc.md's tables and docs/figures/bounds_ratios.png.

Data (committed, in docs/bounds/):

* ``bounds_seed{S}.csv``: ``python -m ddwmmr.bounds --seed S ...``'s bounds.csv;
* ``controllers_seed{S}.csv``: each controller's time per scenario on the thesis plant
  (``python -m ddwmmr.scenarios --controller X --n 100 --seed S``; the competitive arbiter
  is ``--controller thesis --arbiter competitive``), NaN where a scenario failed.

``python docs/bounds_figures.py`` redraws the figure from them and rewrites the block
between the ``bounds-table`` markers of docs/mpc.md; ``--collect SEED DIR`` first builds
``controllers_seed{SEED}.csv`` from seven scenario runs
``DIR/{thesis,competitive,qp,mpc,mpc-lookahead,mpc-plan-cold,mpc-plan}-sSEED`` (their
scenarios.csv; ``mpc-lookahead`` is ``--controller mpc --option lookahead=on``,
``mpc-plan`` that with ``--option plan=BOUNDS_DIR``, ``mpc-plan-cold`` that with
``--option plan_weight=0``), ``--bounds SEED CSV`` first copies a bounds run's
bounds.csv to ``bounds_seed{SEED}.csv``.

``--update SEED BOUNDS_DIR`` keeps, per scenario, the lower replayed best-known time of
the committed ``bounds_seed{SEED}.csv`` and of a later bounds run in ``BOUNDS_DIR`` (a
search is a multistart of a non-convex problem: a later one can find a lower optimum, or
miss one an earlier search found). Where the later run wins, its row replaces the
committed one and the two plan-following runs (``mpc-plan``, ``mpc-plan-cold``) of that
scenario are run again with its plan, through the scenarios tool's own configuration; it
prints the scenarios replaced (``docs/bounds_accounting.py --scenarios`` then redoes their
accounting rows). ``--rerun SEED BOUNDS_DIR NAMES`` runs the mpc columns NAMES (comma
separated: ``mpc``, ``mpc-lookahead``, ``mpc-plan-cold``, ``mpc-plan``) of every scenario
again, those that follow a plan with the plans in ``BOUNDS_DIR``, after a change of the
controller.
"""

from __future__ import annotations

import argparse
import csv
import math
import shutil
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ddwmmr.outputs import csv_text, line_ending, write_atomic

DOCS = Path(__file__).resolve().parent
DATA = DOCS / "bounds"
FIGURE = DOCS / "figures" / "bounds_ratios.png"
PAGE = DOCS / "mpc.md"
BEGIN, END = "<!-- bounds-table:begin -->", "<!-- bounds-table:end -->"
CONTROLLERS = {
    "thesis": "thesis controller",
    "competitive": "thesis controller, competitive arbiter",
    "qp": "qp",
    "mpc": "mpc",
    "mpc-lookahead": "mpc, lookahead",
    "mpc-plan-cold": "mpc, lookahead, offline plan as cold starts",
    "mpc-plan": "mpc, lookahead, offline plan, its arrivals",
}
SEEDS = (0, 1)


def read_bounds(seed: int) -> dict[int, tuple[float, float]]:
    """``{scenario: (lower, best)}``; best NaN where the replay failed or was not run."""
    out = {}
    with open(DATA / f"bounds_seed{seed}.csv", newline="") as handle:
        for row in csv.DictReader(handle):
            best = float(row["best_known_s"]) if row["replay_ok"] == "True" else math.nan
            out[int(row["scenario"])] = (float(row["lower_bound_s"]), best)
    return out


def read_controllers(seed: int) -> dict[str, dict[int, float]]:
    times: dict[str, dict[int, float]] = {name: {} for name in CONTROLLERS}
    with open(DATA / f"controllers_seed{seed}.csv", newline="") as handle:
        for row in csv.DictReader(handle):
            for name in CONTROLLERS:
                times[name][int(row["scenario"])] = float(row[name])
    return times


def collect(seed: int, folder: Path) -> None:
    """controllers_seed{seed}.csv from the scenario runs in ``folder``."""
    columns: dict[str, dict[int, float]] = {}
    for name in CONTROLLERS:
        with open(folder / f"{name}-s{seed}" / "scenarios.csv", newline="") as handle:
            rows = list(csv.DictReader(handle))
        columns[name] = {
            int(r["scenario"]): round(float(r["time_s"]), 3) if r["success"] == "true" else math.nan
            for r in rows
        }
    rows = {
        s: {"scenario": s, **{n: repr(columns[n][s]) for n in CONTROLLERS}}
        for s in columns["thesis"]
    }
    write_rows(DATA / f"controllers_seed{seed}.csv", ["scenario", *CONTROLLERS], rows)


def read_rows(path: Path) -> tuple[list[str], dict[int, dict[str, str]]]:
    """A CSV's header and its rows by scenario."""
    with open(path, newline="") as handle:
        reader = csv.DictReader(handle)
        return list(reader.fieldnames or []), {int(r["scenario"]): r for r in reader}


def write_rows(path: Path, header: list[str], rows: dict[int, dict[str, str]]) -> None:
    """Write ``rows`` (by scenario, in order) under ``header``, atomically, with the line
    ending the file had (the committed bounds CSVs end their lines in CRLF)."""
    ordered = (rows[scenario] for scenario in sorted(rows))
    write_atomic(path, csv_text(header, ordered, line_ending(path)))


def replayed_best(row: dict[str, str]) -> float:
    """A bounds row's best-known time (s), inf unless its replay passed."""
    return float(row["best_known_s"]) if row["replay_ok"] == "True" else math.inf


#: The mpc columns, as the scenarios tool's options (BOUNDS_DIR filled in): the mpc, with
#: lookahead, and with lookahead following the plan, or with the plan as cold starts only.
_LOOKAHEAD = ("--option", "lookahead=on")
_FOLLOW = (*_LOOKAHEAD, "--option", "plan={}")
MPC_RUNS = {
    "mpc": (),
    "mpc-lookahead": _LOOKAHEAD,
    "mpc-plan-cold": (*_FOLLOW, "--option", "plan_weight=0"),
    "mpc-plan": _FOLLOW,
}
#: The columns that follow a bounds run's plans.
PLAN_RUNS = ("mpc-plan", "mpc-plan-cold")


def mpc_run(job: tuple[int, int, str, str]) -> tuple[int, str, float]:
    """``(scenario, run name, time)``: one run of an mpc column (:data:`MPC_RUNS`) in a
    scenario (1-based), configured as ``python -m ddwmmr.scenarios --controller mpc ...``
    would, rounded as :func:`collect` rounds; NaN where it failed."""
    from ddwmmr.cli.scenarios import build_parser, config_from_arguments
    from ddwmmr.scenarios import generate, run_scenario

    seed, index, name, folder = job
    options = [part.format(folder) for part in MPC_RUNS[name]]
    args = build_parser().parse_args(["--controller", "mpc", "--seed", str(seed), *options])
    scenario = generate(n=index, seed=seed)[index - 1]
    metrics = run_scenario(scenario, config_from_arguments(args)).metrics
    return index, name, round(metrics["time_s"], 3) if metrics["success"] else math.nan


#: A later best-known time replaces the committed one only if lower by more than this (s):
#: closer, the two searches found the same optimum, and replacing it would only run the
#: plan-following closed loop again, whose times move by tenths of a second with the
#: plan's last digits.
SAME_OPTIMUM_S = 1e-6


def update(seed: int, folder: Path, jobs: int) -> list[int]:
    """Keep the lower replayed best-known time per scenario (module docstring); returns
    the scenarios whose row came from ``folder``."""
    target = DATA / f"bounds_seed{seed}.csv"
    header, committed = read_rows(target)
    _, later = read_rows(folder / "bounds.csv")
    replaced = sorted(
        s
        for s, row in later.items()
        if s in committed and replayed_best(row) < replayed_best(committed[s]) - SAME_OPTIMUM_S
    )
    if not replaced:
        return []
    for s in replaced:
        committed[s] = {key: later[s][key] for key in header}
    rerun(seed, folder, PLAN_RUNS, jobs, replaced)
    write_rows(target, header, committed)
    return replaced


def rerun(
    seed: int, folder: Path, names: tuple[str, ...], jobs: int, scenarios: list[int] | None = None
) -> None:
    """Run the mpc columns ``names`` (:data:`MPC_RUNS`) of ``scenarios`` (default: every
    scenario of controllers_seed{seed}.csv) again, the plans from the bounds run in
    ``folder``, and write their times into that file."""
    controllers = DATA / f"controllers_seed{seed}.csv"
    header, times = read_rows(controllers)
    work = [(seed, s, name, str(folder.resolve())) for s in scenarios or times for name in names]
    if jobs == 1:
        runs = [mpc_run(job) for job in work]
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            runs = list(pool.map(mpc_run, work))
    for index, name, time_s in runs:
        times[index][name] = repr(time_s)
    write_rows(controllers, header, times)


def ratios(seed: int) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per controller: scenarios, time / best known, time / lower bound."""
    bounds = read_bounds(seed)
    times = read_controllers(seed)
    out = {}
    for name, by_scenario in times.items():
        scenarios = np.array([s for s in sorted(by_scenario) if s in bounds])
        t = np.array([by_scenario[s] for s in scenarios])
        lower = np.array([bounds[s][0] for s in scenarios])
        best = np.array([bounds[s][1] for s in scenarios])
        out[name] = (scenarios, t / best, t / lower)
    return out


def table(seed: int) -> list[str]:
    bounds = read_bounds(seed)
    with open(DATA / f"bounds_seed{seed}.csv", newline="") as handle:
        starts = sorted({int(row["starts"]) for row in csv.DictReader(handle)})
    lower = np.array([v[0] for v in bounds.values()])
    best = np.array([v[1] for v in bounds.values()])
    both = np.isfinite(best)
    width = best[both] / lower[both]
    count = str(starts[0]) if len(starts) == 1 else f"{starts[0]}-{starts[-1]}"
    lines = [
        f"**Seed {seed}**: scenarios {min(bounds)}-{max(bounds)} ({len(bounds)} of 100; "
        f"{count} starts each, best-known times replayed for {int(both.sum())}): lower bound "
        f"{lower.mean():.2f} s, best known {np.nanmean(best):.2f} s, bracket width (best known "
        f"/ lower bound) mean **{width.mean():.3f}** (min {width.min():.3f}, max "
        f"{width.max():.3f}).",
        "",
        "| controller (thesis plant) | mean time (s) | / best known: mean (least) "
        "| / lower bound: mean (least) |",
        "| --- | --- | --- | --- |",
    ]
    times = read_controllers(seed)
    for name, (scenarios, to_best, to_lower) in ratios(seed).items():
        t = np.array([times[name][s] for s in scenarios])
        lines.append(
            f"| {CONTROLLERS[name]} | {np.nanmean(t):.2f} | {np.nanmean(to_best):.3f} "
            f"({np.nanmin(to_best):.3f}) | {np.nanmean(to_lower):.3f} ({np.nanmin(to_lower):.3f}) |"
        )
    return lines


def figure() -> None:
    fig, axes = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    style = {
        "thesis": ("tab:blue", "o"),
        "competitive": ("tab:cyan", "v"),
        "qp": ("tab:orange", "s"),
        "mpc": ("tab:green", "D"),
        "mpc-lookahead": ("tab:red", "^"),
        "mpc-plan-cold": ("tab:pink", "+"),
        "mpc-plan": ("tab:purple", "x"),
    }
    data = ratios(0)
    bounds = read_bounds(0)
    for name, (scenarios, to_best, to_lower) in data.items():
        color, marker = style[name]
        for ax, values in zip(axes, (to_best, to_lower)):
            ax.plot(scenarios, values, marker, color=color, ms=3.5, label=CONTROLLERS[name])
    scenarios = np.array(sorted(bounds))
    width = np.array([bounds[s][1] / bounds[s][0] for s in scenarios])
    axes[1].plot(scenarios, width, "-", color="black", lw=1.0, label="best known / lower bound")
    for ax, title in zip(
        axes, ("time / best-known minimum time", "time / lower bound (the physical limit)")
    ):
        ax.axhline(1.0, color="grey", lw=0.8)
        ax.set_ylabel(title)
        ax.grid(alpha=0.3)
        top = max(
            np.nanmax(np.concatenate([v[1 if ax is axes[0] else 2] for v in data.values()])), 1.0
        )
        ax.set_ylim(0.9, 1.05 * top)
    axes[1].set_xlabel("scenario (seed 0)")
    axes[1].set_xlim(0, scenarios.max() + 1)
    handles, labels = axes[1].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


def rewrite_page() -> None:
    block = [BEGIN, *[line for seed in SEEDS for line in [*table(seed), ""]][:-1], END]
    text = PAGE.read_text()
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    PAGE.write_text(head + "\n".join(block) + tail)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collect", nargs=2, metavar=("SEED", "DIR"), action="append")
    parser.add_argument("--bounds", nargs=2, metavar=("SEED", "CSV"), action="append")
    parser.add_argument("--update", nargs=2, metavar=("SEED", "BOUNDS_DIR"), action="append")
    parser.add_argument(
        "--rerun",
        nargs=3,
        metavar=("SEED", "BOUNDS_DIR", "NAMES"),
        action="append",
        help=f"run the comma-separated mpc columns NAMES (of {', '.join(MPC_RUNS)}) of every "
        "scenario again, the plans from BOUNDS_DIR",
    )
    parser.add_argument("--jobs", type=int, default=2, help="processes for the runs")
    args = parser.parse_args()
    for seed, path in args.bounds or []:
        shutil.copyfile(path, DATA / f"bounds_seed{int(seed)}.csv")
    for seed, folder in args.update or []:
        replaced = update(int(seed), Path(folder), args.jobs)
        print(f"seed {seed}: replaced {','.join(map(str, replaced)) or 'none'}")
    for seed, folder, names in args.rerun or []:
        columns = tuple(name.strip() for name in names.split(","))
        unknown = [name for name in columns if name not in MPC_RUNS]
        if unknown:  # before a hundred runs, not inside the first of them
            parser.error(f"--rerun: unknown column {unknown[0]!r} (of {', '.join(MPC_RUNS)})")
        rerun(int(seed), Path(folder), columns, args.jobs)
    for seed, folder in args.collect or []:
        collect(int(seed), Path(folder))
    figure()
    rewrite_page()
    for seed in SEEDS:
        print("\n".join(table(seed)) + "\n")


if __name__ == "__main__":
    main()
