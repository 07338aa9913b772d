"""The lower bound's parts per scenario: docs/bounds/stops_seed{S}.csv, and the lower
bound of docs/bounds/bounds_seed{S}.csv as their greatest.

``python docs/bounds_stops.py --seed S [--jobs N]`` computes, for each of the 100
scenarios (3 kg), what :func:`ddwmmr.bounds.lower.lower_bound` takes the greatest of: the
force budget alone (``budget_bound_s``, on ``BUDGET_GRID``) and the bound with the stops
priced at each weight of ``STOP_WEIGHTS`` (``stops_<weight>_s``, on ``STOP_GRID``). It
writes them to ``stops_seed{S}.csv`` and sets ``lower_bound_s`` in ``bounds_seed{S}.csv``
to their greatest, as ``python -m ddwmmr.bounds`` computes it. About 25 s of CPU per
scenario. Without arguments it prints the means of the committed CSVs.
"""

from __future__ import annotations

import argparse
import csv
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "bounds"
SEEDS = (0, 1)
PAYLOAD = 3.0


def columns() -> list[str]:
    from ddwmmr.bounds.lower import STOP_WEIGHTS

    return ["scenario", "budget_bound_s", *(f"stops_{w:g}_s" for w in STOP_WEIGHTS)]


def parts(job: tuple[int, int]) -> dict[str, float]:
    """One scenario's bounds (s), named as the CSV's columns."""
    from ddwmmr.bounds.lower import BUDGET_GRID, STOP_GRID, STOP_WEIGHTS, budget_bound
    from ddwmmr.model import Robot
    from ddwmmr.scenarios import generate

    seed, index = job
    robot = Robot().with_payload(PAYLOAD)
    waypoints = generate(n=index, seed=seed)[index - 1].waypoints
    row = {"scenario": index}
    row["budget_bound_s"] = budget_bound(
        robot, waypoints, cell=BUDGET_GRID[0], arcs=BUDGET_GRID[1]
    ).value
    for weight in STOP_WEIGHTS:
        row[f"stops_{weight:g}_s"] = budget_bound(
            robot, waypoints, cell=STOP_GRID[0], arcs=STOP_GRID[1], rotation_weight=weight
        ).value
    return row


def write_csv(path: Path, header: list[str], rows: list[dict]) -> None:
    """Write ``rows`` to ``path`` atomically, with the line ending the file had."""
    from ddwmmr.outputs import csv_text, line_ending, write_atomic

    write_atomic(path, csv_text(header, rows, line_ending(path)))


def set_lower_bounds(seed: int, rows: list[dict]) -> None:
    """``lower_bound_s`` of bounds_seed{seed}.csv := the greatest of each row's parts."""
    greatest = {r["scenario"]: max(v for k, v in r.items() if k != "scenario") for r in rows}
    path = DATA / f"bounds_seed{seed}.csv"
    with open(path, newline="") as handle:
        reader = csv.DictReader(handle)
        header, bounds = list(reader.fieldnames), list(reader)
    for row in bounds:
        row["lower_bound_s"] = repr(float(greatest[int(row["scenario"])]))
    write_csv(path, header, bounds)


def compute(seed: int, jobs: int) -> None:
    work = [(seed, index) for index in range(1, 101)]
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        rows = list(pool.map(parts, work))
    write_csv(DATA / f"stops_seed{seed}.csv", columns(), rows)
    set_lower_bounds(seed, rows)


def summary() -> list[str]:
    lines = []
    for seed in SEEDS:
        path = DATA / f"stops_seed{seed}.csv"
        if not path.exists():
            continue
        with open(path, newline="") as handle:
            rows = list(csv.DictReader(handle))
        names = [c for c in rows[0] if c != "scenario"]
        values = np.array([[float(r[c]) for c in names] for r in rows])
        best = values.max(axis=1)
        means = ", ".join(f"{n} {m:.2f} s" for n, m in zip(names, values.mean(axis=0)))
        wins = ", ".join(
            f"{n} {int(c)}"
            for n, c in zip(names, np.bincount(values.argmax(axis=1), minlength=len(names)))
        )
        lines.append(f"seed {seed}: {means}; greatest {best.mean():.2f} s (wins: {wins})")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, choices=SEEDS)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    if args.seed is not None:
        compute(args.seed, args.jobs)
    print("\n".join(summary()))


if __name__ == "__main__":
    main()
