"""Record reference time series of the simulation loops (run by hand, not by pytest).

    .venv/bin/python tests/golden/make_golden.py

writes ``tests/golden/loops.npz``: tracking runs of every built-in method on the default
ellipse and rectangle (first 4 s, RK4 and Euler) and traced thesis-protocol scenarios (the
thesis controller and ``qp`` on the thesis plant, ``qp`` on the kinematic plant).
``tests/test_golden.py`` replays them and requires agreement to 1e-12: refactors of the
loop, the plants or the controllers must not change results. Regenerate only when a
behaviour change is intended, and say so in the commit message.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ddwmmr import Ellipse, Rectangle, Robot, simulate
from ddwmmr.scenarios.generator import generate
from ddwmmr.scenarios.protocol import RunConfig, run_scenario

OUT = Path(__file__).with_name("loops.npz")
METHODS = ("pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs", "qp")
TRACK_DURATION = 4.0
#: Columns compared (wall-clock timings excluded).
SKIP = {"step_us"}
SCENARIOS = (0, 1, 5)
SCENARIO_CASES = {
    "thesis": RunConfig(controller="thesis", plant="thesis", record=True, time_limit=20.0),
    "qp_thesis": RunConfig(controller="qp", plant="thesis", record=True, time_limit=20.0),
    "qp_kinematic": RunConfig(controller="qp", plant="kinematic", record=True, time_limit=20.0),
}


def tracking_cases():
    """(key, trajectory, method, integrator, robot) of every recorded tracking run."""
    for traj in (Ellipse(), Rectangle()):
        for method in METHODS:
            for integrator in ("rk4", "euler"):
                robot = Robot().with_payload(3.0) if method == "qp" else Robot()
                yield f"track/{traj.name}/{method}/{integrator}", traj, method, integrator, robot


def main() -> None:
    arrays: dict[str, np.ndarray] = {}
    for key, traj, method, integrator, robot in tracking_cases():
        result = simulate(robot, traj, method, duration=TRACK_DURATION, integrator=integrator)
        for column, values in result.timeseries.items():
            if column not in SKIP:
                arrays[f"{key}/{column}"] = np.asarray(values, dtype=float)
    scenarios = generate(max(SCENARIOS) + 1, 0)
    for name, config in SCENARIO_CASES.items():
        for index in SCENARIOS:
            outcome = run_scenario(scenarios[index], config)
            prefix = f"scenario/{name}/{index}"
            for column, values in (outcome.trace or {}).items():
                arrays[f"{prefix}/trace/{column}"] = np.asarray(values, dtype=float)
            for column, value in outcome.metrics.items():
                if isinstance(value, bool | int | float):
                    arrays[f"{prefix}/metric/{column}"] = np.asarray(float(value))
    np.savez_compressed(OUT, **arrays)
    print(f"wrote {OUT} ({len(arrays)} arrays, {OUT.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
