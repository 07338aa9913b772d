"""Check a controller's run of one scenario as the best-known search checks its candidates.

The run (thesis plant, 3 kg, 10 ms) is recorded, its wheel forces and joint rates are
replayed open loop at the run's own step (``ddwmmr.bounds.search.replay_run``), and the
replay must bring the end effector within 0.01 m of every waypoint in order with S >= 1.25
at every step. docs/mpc.md uses it for the two best-known times of seed 1 that came from
the plan-guided ``mpc`` (scenarios 32 and 58)::

    python docs/replay_run.py --seed 1 --scenario 32 --option lookahead=on \\
        --option plan=BOUNDS_DIR
    python docs/replay_run.py --seed 1 --scenario 58 --option lookahead=on \\
        --option plan=BOUNDS_DIR --option stability_margin=0.001 --option input_weight=0.001

(``BOUNDS_DIR``: ``python -m ddwmmr.bounds --seed 1 --out BOUNDS_DIR``'s output folder.)
"""

from __future__ import annotations

import argparse
import json

from ddwmmr import Robot
from ddwmmr.bounds.search import Settings, replay_run
from ddwmmr.bounds.starts import controller_guess
from ddwmmr.scenarios import generate


def parse_option(text: str) -> tuple[str, object]:
    """``NAME=VALUE``: the value as JSON where it parses (numbers, true/false), else text;
    ``on``/``off`` as booleans."""
    name, _, value = text.partition("=")
    words = {"on": True, "off": False}
    if value in words:
        return name, words[value]
    try:
        return name, json.loads(value)
    except json.JSONDecodeError:
        return name, value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--scenario", type=int, required=True, help="numbered from 1")
    parser.add_argument("--controller", default="mpc")
    parser.add_argument("--option", action="append", default=[], metavar="NAME=VALUE")
    args = parser.parse_args()
    scenario = generate(args.scenario, args.seed)[args.scenario - 1]
    options = tuple(parse_option(text) for text in args.option)
    run = controller_guess(scenario, args.controller, options=options)
    if run is None:
        print("the run did not reach every waypoint")
        return
    _, check = replay_run(
        Robot().with_payload(3.0), args.controller, run, scenario.waypoints, Settings()
    )
    print(f"run {run.arrivals[-1]:.2f} s; replay ok: {check.ok}, {check.time_s:.2f} s")
    print(f"closest approach to each waypoint (mm): {[round(1e3 * d, 1) for d in check.closest_m]}")
    print(f"least S over the replay: {check.min_stability:.4f}")


if __name__ == "__main__":
    main()
