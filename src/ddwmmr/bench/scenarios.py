"""The scenario section: simulated seconds per wall-clock second of the thesis benchmark's
scenarios."""

from __future__ import annotations

import time
from typing import Any

from ddwmmr.errors import (
    MAX_JOBS,
    MAX_SCENARIOS,
    check_int_at_least,
)

#: Controllers of the scenario-throughput section and its default size.
SCENARIO_CONTROLLERS = ("thesis", "qp", "mpc")
SCENARIO_COUNT = 100
#: What the scenario section takes from the scenarios tool's summary.
SCENARIO_KEYS = ("failed", "sim_time_s", "wall_time_s", "sim_seconds_per_wall_second")


def scenario_workers(count: int, jobs: int | None = None) -> int:
    """Worker processes for ``count`` scenarios: ``jobs`` (default: the CPUs available),
    never more than the scenarios (an idle worker only adds start-up time to the wall time)."""
    from ddwmmr.scenarios.executors import default_jobs

    jobs = default_jobs() if jobs is None else check_int_at_least("jobs", jobs, 1, MAX_JOBS)
    return max(1, min(jobs, count))


def time_scenarios(count: int, jobs: int | None = None) -> list[dict[str, Any]]:
    """Simulated seconds per wall-clock second of the first ``count`` scenarios (seed 0,
    the defaults of ``python -m ddwmmr.scenarios``) for each controller of
    :data:`SCENARIO_CONTROLLERS`, on ``jobs`` worker processes (default: the CPUs; at
    most ``count``, see :func:`scenario_workers`)."""
    from ddwmmr.scenarios.executors import run_many
    from ddwmmr.scenarios.generator import generate
    from ddwmmr.scenarios.protocol import RunConfig
    from ddwmmr.scenarios.report import summarize

    check_int_at_least("scenarios", count, 1, MAX_SCENARIOS)
    jobs = scenario_workers(count, jobs)
    batch = generate(count, 0)
    rows = []
    for controller in SCENARIO_CONTROLLERS:
        start = time.perf_counter()
        outcomes = run_many(batch, RunConfig(controller=controller), jobs=jobs)
        # The numbers the scenarios tool writes to its summary.json.
        summary = summarize(outcomes, time.perf_counter() - start)
        rows.append(
            {
                "controller": controller,
                "scenarios": count,
                "jobs": jobs,
                **{key: summary[key] for key in SCENARIO_KEYS},
            }
        )
    return rows
