"""The physical limit of the thesis scenarios: minimum time under the thesis plant's force
limits and S >= 1.25 (docs/mpc.md, "The physical limit").

    python docs/mpc_min_time.py [--n 100] [--seed 0] [--jobs 2]

For each scenario, :func:`ddwmmr.mpc.min_time.solve_minimum_time` solves the free-final-time
OCP from four straight-line starts (forwards / minimal turn, both elbow branches) and keeps
the best; :func:`ddwmmr.mpc.min_time.verify` re-integrates the winner on a 10x finer grid
(waypoint miss, S between the nodes). Writes ``docs/mpc_min_time.json`` (one row per
scenario) and the summary block between the ``mpc-min-time`` markers of docs/mpc.md.
Takes ~15-20 s per scenario on one core.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from ddwmmr import Robot
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.mpc.min_time import MinimumTimeProblem, solve_minimum_time, verify
from ddwmmr.scenarios import generate
from ddwmmr.sim.result import write_atomic

DOCS = Path(__file__).parent
BEGIN, END = "<!-- mpc-min-time:begin -->", "<!-- mpc-min-time:end -->"


def solve_one(task: tuple[int, int, float]) -> dict:
    index, seed, payload = task
    robot = Robot().with_payload(payload)
    scenario = generate(index + 1, seed)[index]
    start = [0.0, 0.0, 0.0, *default_pose(robot), 0.0, 0.0]
    began = time.perf_counter()
    problem = MinimumTimeProblem(robot, scenario.waypoints, start)
    result = solve_minimum_time(problem)
    check = verify(problem, result)
    return {
        "scenario": index + 1,
        "min_time_s": result.total,
        "legs_s": [float(v) for v in result.legs],
        "start": result.start,
        "solve_s": time.perf_counter() - began,
        **check,
    }


def summary_block(rows: list[dict], seed: int) -> str:
    times = np.array([r["min_time_s"] for r in rows])
    lowest_s = min(r["min_stability"] for r in rows)
    miss = max(r["max_miss_m"] for r in rows)
    return "\n".join(
        [
            BEGIN,
            f"Minimum-time bound, {len(rows)} scenarios, seed {seed}, 3 kg (written by "
            "`docs/mpc_min_time.py`): mean **{:.2f} s** (sd {:.2f}, min {:.2f}, max {:.2f}); "
            "re-integrated on a 10x finer grid: smallest S {:.4f}, largest waypoint miss "
            "{:.4f} m.".format(
                times.mean(), times.std(ddof=1), times.min(), times.max(), lowest_s, miss
            ),
            END,
        ]
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--payload", type=float, default=3.0)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    tasks = [(i, args.seed, args.payload) for i in range(args.n)]
    rows: list[dict] = []
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        for done, row in enumerate(pool.map(solve_one, tasks), start=1):
            rows.append(row)
            print(
                f"[{done}/{len(tasks)}] scenario {row['scenario']}: {row['min_time_s']:.2f} s "
                f"({row['start']}, {row['solve_s']:.0f} s)",
                file=sys.stderr,
                flush=True,
            )
    out = DOCS / f"mpc_min_time_seed{args.seed}.json"
    write_atomic(out, json.dumps(rows, indent=1) + "\n")
    block = summary_block(rows, args.seed)
    page = DOCS / "mpc.md"
    if page.exists() and args.seed == 0 and args.n == 100:
        text = page.read_text()
        if BEGIN in text and END in text:
            head, rest = text.split(BEGIN, 1)
            _, tail = rest.split(END, 1)
            write_atomic(page, head + block + tail)
    print(block)
    print(f"mean {np.mean([r['min_time_s'] for r in rows]):.3f} s; wrote {out}")
    return 0 if all(math.isfinite(r["min_time_s"]) for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
