"""Where the time goes against the force budget's bound: docs/mpc.md's accounting table and
docs/figures/bounds_accounting.png.

``python docs/bounds_accounting.py --seed S --plans DIR [--jobs N] [--scenarios LIST]``
writes ``docs/bounds/accounting_seed{S}.csv`` (``--scenarios 5,60``: only those rows, as
after ``docs/bounds_figures.py --update``): for each of the 100 scenarios, the force-budget
accounting (:func:`ddwmmr.bounds.accounting.account`) of three trajectories on the thesis
plant (3 kg):

* ``best``: the best-known trajectory, ``DIR/cache/scenario-NNN-best.npz`` of a
  ``python -m ddwmmr.bounds --seed S`` run, replayed as the search judged it (at 1 ms; a
  controller's run, ``start`` ``run-...`` in the ``.json`` beside it, at its own step);
* ``mpc``: the ``mpc``'s run (the scenario protocol's, 10 ms);
* ``mpc-plan``: the ``mpc`` with ``lookahead`` following that best-known trajectory as its
  ``plan`` (``plan_weight`` at its default).

About 10 s of CPU per scenario. Without arguments the script redraws the figure and the
table from the committed CSVs (and ``stops_seed{S}.csv`` for the force budget's bound).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ddwmmr.outputs import csv_text, line_ending, write_atomic

DOCS = Path(__file__).resolve().parent
DATA = DOCS / "bounds"
FIGURES = DOCS / "figures"
PAGE = DOCS / "mpc.md"
BEGIN, END = "<!-- accounting-table:begin -->", "<!-- accounting-table:end -->"
SEEDS = (0, 1)
PAYLOAD = 3.0
TRAJECTORIES = {
    "best": "best known",
    "mpc": "mpc",
    "mpc-plan": "mpc, lookahead, offline plan, its arrivals",
}
#: The accounting's terms (columns of the CSV, in seconds) and what the table calls them.
TERMS = {
    "path_s": "path at the bound's price",
    "turn_s": "rotation at the bound's price",
    "allowance_s": "turn allowance left",
    "momentum_s": "motion left at the end",
    "braking_s": "braking with the wheels",
    "idle_s": "force unused",
}
COLUMNS = ["scenario", "trajectory", "time_s", *TERMS, "path_m", "rotation_rad"]


def account_scenario(job: tuple[int, int, str]) -> list[dict]:
    """The three trajectories' accounting rows of one scenario (1-based ``index``)."""
    from ddwmmr.bounds.accounting import account
    from ddwmmr.bounds.batch import cache_names
    from ddwmmr.bounds.replay import REPLAY_DT, replay
    from ddwmmr.bounds.starts import controller_guess
    from ddwmmr.model import Robot
    from ddwmmr.mpc.min_time import Guess, MinimumTime
    from ddwmmr.scenarios import generate

    seed, index, plans = job
    robot = Robot().with_payload(PAYLOAD)
    scenario = generate(n=index, seed=seed)[index - 1]
    names = cache_names(index)
    path = Path(plans) / names["trajectory"]
    plan = Guess.load(path)
    best = MinimumTime(plan.arrivals[-1], plan.legs, True, plan.times, plan.states, plan.inputs, "")
    # replayed as the search judged it: a controller's run at its own step
    start = json.loads((Path(plans) / names["best"]).read_text())["start"]
    dt = float(plan.times[1] - plan.times[0]) if start.startswith("run-") else REPLAY_DT
    done = replay(robot, best, scenario.waypoints, dt=dt)
    runs = {"best": (best, done.time_s, dt)}
    for name, controller, options in (
        ("mpc", "mpc", ()),
        ("mpc-plan", "mpc-lookahead", (("plan", str(path)),)),
    ):
        run = controller_guess(scenario, controller, payload=PAYLOAD, options=options)
        if run is not None:
            runs[name] = (run, float(run.arrivals[-1]), float(run.times[1] - run.times[0]))
    rows = []
    for name, (trajectory, until, dt) in runs.items():
        terms = account(robot, trajectory, until, dt)
        rows.append({"scenario": index, "trajectory": name, **vars(terms)})
    return rows


def compute(seed: int, plans: Path, jobs: int, scenarios: list[int] | None = None) -> None:
    """accounting_seed{seed}.csv from the best-known trajectories in ``plans``: all 100
    scenarios, or only the rows of ``scenarios``, the others kept as committed."""
    target = DATA / f"accounting_seed{seed}.csv"
    work = [(seed, index, str(plans)) for index in scenarios or range(1, 101)]
    kept = []
    if scenarios:
        with open(target, newline="") as handle:
            kept = [r for r in csv.DictReader(handle) if int(r["scenario"]) not in scenarios]
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        new = [row for rows in pool.map(account_scenario, work) for row in rows]
    order = list(TRAJECTORIES)
    rows = sorted(
        [
            *kept,
            *(
                {k: row[k] if k in COLUMNS[:2] else round(row[k], 6) for k in COLUMNS}
                for row in new
            ),
        ],
        key=lambda r: (int(r["scenario"]), order.index(r["trajectory"])),
    )
    write_atomic(target, csv_text(COLUMNS, rows, line_ending(target)))


def seeds() -> list[int]:
    """The seeds with an accounting CSV."""
    return [seed for seed in SEEDS if (DATA / f"accounting_seed{seed}.csv").exists()]


def read(seed: int) -> tuple[dict[str, dict[str, float]], float]:
    """Mean of every column per trajectory, over the scenarios all three finished; and
    the mean force-budget bound over the same scenarios."""
    with open(DATA / f"accounting_seed{seed}.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    # the accounting splits the time against the force budget's own terms, so against its
    # bound (docs/bounds_stops.py), not the stop-pricing bounds that may exceed it
    with open(DATA / f"stops_seed{seed}.csv", newline="") as handle:
        lower = {int(r["scenario"]): float(r["budget_bound_s"]) for r in csv.DictReader(handle)}
    done = {
        s
        for s in {int(r["scenario"]) for r in rows}
        if sum(int(r["scenario"]) == s for r in rows) == len(TRAJECTORIES)
    }
    means = {}
    for name in TRAJECTORIES:
        mine = [r for r in rows if r["trajectory"] == name and int(r["scenario"]) in done]
        means[name] = {k: float(np.mean([float(r[k]) for r in mine])) for k in COLUMNS[2:]}
        means[name]["count"] = len(mine)
    return means, float(np.mean([lower[s] for s in done]))


def stop_priced_bound(seed: int) -> float:
    """The mean lower bound (s) of bounds_seed{seed}.csv: the force budget's or, where
    greater, the bound with the stops priced (docs/bounds_stops.py)."""
    with open(DATA / f"bounds_seed{seed}.csv", newline="") as handle:
        return float(np.mean([float(r["lower_bound_s"]) for r in csv.DictReader(handle)]))


def table() -> list[str]:
    lines = [
        "| seed, trajectory | time (s) | force-budget bound | path and rotation above it "
        "| turn allowance left | motion left at the end | braking with the wheels "
        "| force unused | path (m), rotation (rad) |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for seed in seeds():
        means, lower = read(seed)
        for name, label in TRAJECTORIES.items():
            m = means[name]
            above = m["path_s"] + m["turn_s"] - lower
            lines.append(
                f"| {seed}, {label} | {m['time_s']:.2f} | {lower:.2f} | {above:.2f} "
                f"| {m['allowance_s']:.2f} | {m['momentum_s']:.2f} | {m['braking_s']:.2f} "
                f"| {m['idle_s']:.2f} | {m['path_m']:.2f}, {m['rotation_rad']:.2f} |"
            )
    return lines


def figure() -> None:
    parts = [
        ("force-budget bound", "lightgrey"),
        ("path and rotation above it", "tab:blue"),
        ("turn allowance left", "tab:cyan"),
        ("motion left at the end", "tab:green"),
        ("braking with the wheels", "tab:red"),
        ("force unused", "black"),
    ]
    labels, stacks, bounds = [], [], []
    for seed in seeds():
        means, lower = read(seed)
        priced = stop_priced_bound(seed)
        for name, label in TRAJECTORIES.items():
            m = means[name]
            labels.append(f"seed {seed}: {label}")
            bounds.append(priced)
            stacks.append(
                [
                    lower,
                    m["path_s"] + m["turn_s"] - lower,
                    m["allowance_s"],
                    m["momentum_s"],
                    m["braking_s"],
                    m["idle_s"],
                ]
            )
    fig, ax = plt.subplots(figsize=(10, 4.2))
    rows = np.arange(len(labels))[::-1]
    left = np.zeros(len(labels))
    for k, (name, color) in enumerate(parts):
        widths = np.array([s[k] for s in stacks])
        ax.barh(rows, widths, left=left, color=color, label=name, height=0.6)
        left += widths
    ax.plot(bounds, rows, "|", color="black", ms=22, mew=2, label="lower bound, stops priced")
    for row, total in zip(rows, left):
        ax.text(total + 0.15, row, f"{total:.2f} s", va="center", fontsize=8)
    ax.set_yticks(rows, labels, fontsize=8)
    ax.set_xlabel("mean time over 100 scenarios (s), thesis plant, 3 kg")
    ax.set_xlim(0, math.ceil(left.max() + 2.0))
    ax.grid(axis="x", alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, 1.22), ncol=4, fontsize=8, frameon=False)
    fig.tight_layout()
    fig.savefig(FIGURES / "bounds_accounting.png", dpi=110)
    plt.close(fig)


def rewrite_page() -> None:
    text = PAGE.read_text()
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    PAGE.write_text(head + "\n".join([BEGIN, *table(), END]) + tail)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, choices=SEEDS)
    parser.add_argument("--plans", type=Path, help="a python -m ddwmmr.bounds output folder")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument(
        "--scenarios", help="with --plans: redo only these rows, e.g. 5,60 (default: all 100)"
    )
    args = parser.parse_args()
    if (args.seed is None) != (args.plans is None):
        parser.error("--seed and --plans go together")
    if args.scenarios and args.plans is None:
        parser.error("--scenarios needs --seed and --plans")
    if args.seed is not None:
        chosen = [int(s) for s in args.scenarios.split(",")] if args.scenarios else None
        compute(args.seed, args.plans, args.jobs, chosen)
    figure()
    rewrite_page()
    print("\n".join(table()))


if __name__ == "__main__":
    main()
