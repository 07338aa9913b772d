"""Where an mpc step's time goes: HPIPM's solve against everything around it, in one run.

Runs the default rectangle and ellipse (kinematic plant) and the first scenarios of the
thesis benchmark (thesis plant) with ``mpc``, times every step by phase
(:mod:`ddwmmr.bench.mpc_floor`) and prints the table of docs/mpc.md ("Where an MPC step's
time goes")::

    .venv/bin/python benchmarks/mpc_floor.py                 # thread CPU time
    .venv/bin/python benchmarks/mpc_floor.py --wall --json floor.json
"""

from __future__ import annotations

import argparse
import json
import time

from ddwmmr.bench.mpc_floor import (
    FLOOR_SCENARIOS,
    FLOOR_TRACKING,
    format_floor_table,
    measure_mpc_floor,
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, default=FLOOR_SCENARIOS, metavar="N")
    parser.add_argument("--wall", action="store_true", help="wall time (default: CPU time)")
    parser.add_argument("--json", metavar="PATH", help="also write the rows as JSON")
    args = parser.parse_args()
    clock = time.perf_counter_ns if args.wall else time.thread_time_ns
    rows = measure_mpc_floor(FLOOR_TRACKING, max(0, args.scenarios), clock)
    print(format_floor_table(rows))
    for row in rows:
        print(
            f"{row['case']}: {row['qps_per_step']:.3f} QPs a step, "
            f"{row['hpipm_iterations_per_qp']:.1f} HPIPM iterations a QP, "
            f"{row['cold_steps']} cold steps (max {row['cold_max_us']:.0f} us), "
            f"warm max {row['warm_max_us']:.0f} us, {row['gc_steps']} steps with GC, "
            f"phases over {row['split_steps']} steps"
        )
    if args.json:
        with open(args.json, "w") as file:
            json.dump(rows, file, indent=1)


if __name__ == "__main__":
    main()
