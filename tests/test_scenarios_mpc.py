"""The mpc controller in the thesis protocol: the one loop, wheel forces on the thesis plant."""

import functools

import pytest

from ddwmmr import ParameterError
from ddwmmr.scenarios import Outcome, RunConfig, generate, run_scenario

SCENARIO = generate(5, 0)[4]  # the shortest of the first five (about 14 s for mpc)


@functools.cache
def default_mpc_run() -> Outcome:
    """SCENARIO run by the mpc with its default options (read only by the tests, which
    share it: the run is deterministic)."""
    return run_scenario(SCENARIO, RunConfig(controller="mpc"))


def test_mpc_on_the_thesis_plant_beats_the_thesis_controller_and_holds_its_floor():
    mpc = default_mpc_run()
    thesis = run_scenario(SCENARIO, RunConfig(controller="thesis"))
    m = mpc.metrics
    assert m["success"] and thesis.metrics["success"]
    assert m["time_s"] <= 0.85 * thesis.metrics["time_s"]
    # The hard floor holds at every step (1.25, with the 0.01 damper margin rounded).
    assert m["min_stability"] >= 1.25 - 1e-6
    assert mpc.median_step_us is not None and mpc.median_step_us > 0.0


def test_controller_options_reach_the_controller():
    """A 2 s horizon (default 5 s) sees the next waypoint later: a different, slower run."""
    default = default_mpc_run().metrics["time_s"]
    short = RunConfig(controller="mpc", controller_options=(("horizon", 2.0),))
    assert run_scenario(SCENARIO, short).metrics["time_s"] > default + 1.0
    with pytest.raises(ParameterError, match="horizon"):
        run_scenario(SCENARIO, RunConfig(controller="mpc", controller_options=(("horizon", -1.0),)))


def test_fallback_steps_are_counted_in_the_scenario_metrics(monkeypatch):
    """Every 25th solve fails (as HPIPM's 'minimum step' does on the physics plant): the
    scenario says how many commands were the qp fallback's, and the summary adds them up."""
    import math

    from ddwmmr.mpc import solvers
    from ddwmmr.scenarios import report

    real = solvers.GaussNewtonSQP.solve
    calls = {"n": 0}

    def failing(self, *args):
        calls["n"] += 1
        if calls["n"] % 25 == 0:
            raise solvers.SolverFailure("hpipm: return status 2")
        return real(self, *args)

    monkeypatch.setattr(solvers.GaussNewtonSQP, "solve", failing)
    config = RunConfig(controller="mpc", time_limit=2.0)
    metrics = run_scenario(SCENARIO, config).metrics
    assert metrics["sim_steps"] == 200 and metrics["fallback_steps"] == 200 // 25
    thesis = run_scenario(SCENARIO, RunConfig(time_limit=0.5)).metrics
    assert math.isnan(thesis["fallback_steps"])  # the state machine has no fallback
    summary = report.summarize([run_scenario(SCENARIO, config)] * 2, 1.0)
    assert summary["fallback_steps"] == 16 and summary["fallback_share"] == 16 / 400
    assert "Steps with a fallback command" in report.format_table(summary, "t")
