"""The arbiter study (state machine vs competitive): statistics, tables, CLI."""

from __future__ import annotations

import json
import math

import pytest

from ddwmmr.arbiters import BEHAVIOURS
from ddwmmr.cli.scenarios import main as cli
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.scenarios.arbiter_study import (
    context_line,
    fix_entries,
    history_statistics,
    noisy_config,
    summarize,
    table_52,
)
from scenarios_cli_helpers import bad_scenarios_run


def synthetic(states, shares_of):
    """A weight history at 0.01 s: dominant states and the share each behaviour has."""
    history = {"t": [0.01 * k for k in range(len(states))], "state": list(states)}
    for name in BEHAVIOURS:
        history[f"w_{name}"] = [math.sqrt(shares_of(name, k)) for k in range(len(states))]
    return history


def test_history_statistics_count_switches_reversals_rates_and_handover():
    # objective -> stability at k = 100 (0.1 s ramp of the shares), back at k = 130
    # (0.3 s later: a fast reversal), then stability again at k = 300 (not a reversal)
    def share(name, k):
        on = 1.0 if 100 <= k < 130 or k >= 300 else 0.0
        ramp = min(1.0, max(0.0, (k - 95) / 10)) if k < 130 else on
        s = ramp if k < 130 else on
        return s if name == "stability" else (1.0 - s if name == "objective" else 0.0)

    states = ["stability" if share("stability", k) > 0.5 else "move_base" for k in range(400)]
    stats = history_statistics(synthetic(states, share))
    assert stats["switches"] == 3
    assert stats["reversals"] == 1  # 0.3 s < REVERSAL_WINDOW; the third switch is 1.7 s on
    # the share rises by 0.1 per step during the ramp: 10 /s; the jumps back: 100 /s
    assert stats["max_share_rate"] == pytest.approx(100.0)
    ramp_only = history_statistics(synthetic(states[:130], share))
    assert ramp_only["switches"] == 1
    assert ramp_only["max_share_rate"] == pytest.approx(10.0)  # 0.1 per 0.01 s step
    d_weight = max(abs(math.sqrt(0.1 * j) - math.sqrt(0.1 * (j - 1))) for j in range(1, 11))
    assert stats["max_weight_rate"] >= d_weight / 0.01


def test_summary_adds_fix_entries_and_table_has_a_column_per_arbiter():
    scenario = generate(1, 0)[0]
    config = RunConfig(stability=(1.4, 1.7), time_limit=15.0)
    sm = run_scenario(scenario, config)
    comp = run_scenario(
        scenario, RunConfig(stability=(1.4, 1.7), time_limit=15.0, arbiter="competitive")
    )
    assert fix_entries(sm) == sum(
        sm.metrics[f"transitions_{k}"] for k in ("manipulability", "stability", "obstacle")
    )
    summaries = [("state machine", summarize([sm], 1.0)), ("competitive", summarize([comp], 1.0))]
    table = table_52(summaries)
    assert table.splitlines()[0] == "| | state machine | competitive |"
    assert "| No. of failed scenarios |" in table and "| Minimum stability S |" in table
    assert "Fix-state entries per scenario" in table
    assert all(line.count("|") == 4 for line in table.splitlines())


def test_noisy_config_scales_the_default_noise_and_sets_the_seed():
    config = noisy_config(RunConfig(stability=(1.5, 1.7)), 5.0, 3)
    arbiter = config.arbiter
    assert arbiter.dynamics.noise == pytest.approx(5.0 * 0.002)
    assert arbiter.dynamics.seed == 3
    assert (arbiter.stability.enter, arbiter.stability.exit) == (1.5, 1.7)


def test_cli_competitive_run_writes_the_weights_figure(tmp_path, capsys):
    out = tmp_path / "comp"
    args = ["--n", "2", "--time-limit", "3", "--jobs", "1", "--no-progress"]
    assert cli([*args, "--arbiter", "competitive", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["config"]["arbiter"] == "competitive"
    assert (out / "weights.png").stat().st_size > 1000
    assert "competitive arbiter" in capsys.readouterr().out


def test_cli_arbiter_study_writes_tables_and_figures(tmp_path, capsys):
    out = tmp_path / "study"
    args = ["--study", "arbiters", "--n", "2", "--time-limit", "3", "--jobs", "1"]
    assert cli([*args, "--no-progress", "--out", str(out)]) == 0
    text = (out / "arbiters.md").read_text()
    for heading in ("Thesis Table 5.2", "Threshold variants", "Smoothness", "Noise seeds"):
        assert heading in text
    assert "Stability 1.50 with hysteresis 1.70" in text
    assert (
        "2 scenarios (seed 0), thesis plant, payload 3 kg, step 0.01 s, 3 s limit; "
        "competitive arbiter seed 0 (noise study: seeds 0, 1, 2, 3, 4)."
    ) in text
    for key in ("baseline", "stab-1.50-1.70", "stab-nohyst-1.50"):
        assert (out / f"competitive_weights_{key}.png").stat().st_size > 1000
    assert (out / "baseline-competitive.csv").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["study"] == "arbiters" and len(summary["weights"]) == 3
    assert "| state machine | competitive |" in capsys.readouterr().out


def test_study_context_names_scenarios_plant_limit_and_arbiter_seed():
    config = RunConfig(plant="mujoco", payload=2.5, time_limit=30.0, arbiter_seed=7)
    assert context_line(2, 0, config) == (
        "2 scenarios (seed 0), mujoco plant, payload 2.5 kg, step 0.01 s, 30 s limit; "
        "competitive arbiter seed 7 (noise study: seeds 0, 1, 2, 3, 4)."
    )
    assert context_line(1, None, RunConfig(), noise=False) == (
        "1 scenario, thesis plant, payload 3 kg, step 0.01 s, 60 s limit; "
        "competitive arbiter seed 0."
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--arbiter", "vote"], "invalid choice"),
        (["--arbiter", "competitive", "--controller", "qp"], "only the thesis controller"),
        (["--study", "arbiters", "--controller", "qp"], "arbiter study needs --controller thesis"),
        (
            ["--arbiter", "competitive", "--arbiter-seed", "-1"],
            "arbiter-seed must be an integer >= 0",
        ),
        (["--arbiter-seed", "5"], "--arbiter-seed: only used with --arbiter competitive"),
        (["--study", "arbiters", "--arbiter", "competitive"], "runs both arbiters"),
    ],
)
def test_bad_arbiter_input_one_line_exit_2(tmp_path, args, message):
    assert message in bad_scenarios_run(tmp_path, args)
