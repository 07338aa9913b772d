"""The scenario benchmark's Python API refuses what ``python -m ddwmmr.scenarios``
refuses, in the same one-line words (the command line builds its configuration with
:class:`RunConfig`, whose checks are the only ones)."""

from __future__ import annotations

import pytest

from ddwmmr.cli.scenarios import _title
from ddwmmr.cli.scenarios import main as cli
from ddwmmr.errors import ParameterError
from ddwmmr.scenarios import RunConfig, generate
from ddwmmr.scenarios.executors import run_many

#: (RunConfig keywords, the command line's options, the message both give).
REFUSED = [
    ({"dt": 0.5}, ["--dt", "0.5"], "dt must be in (0, 0.1] s (got 0.5)"),
    (
        {"stability": (11.0, 12.0)},
        ["--stability", "11", "12"],
        "stability thresholds must be in (0, 10] (got 11, 12)",
    ),
    (
        {"stability": (0.0, 1.0)},
        ["--stability", "0", "1"],
        "stability thresholds must be in (0, 10] (got 0, 1)",
    ),
    (
        {"manipulability": (1.5, 2.0)},
        ["--manipulability", "1.5", "2"],
        "manipulability thresholds must be in (0, 1] (got 1.5, 2)",
    ),
    (
        {"stability": (1.6, 1.2)},
        ["--stability", "1.6", "1.2"],
        "stability thresholds: ENTER must be <= EXIT, both in (0, 10] (got 1.6, 1.2)",
    ),
    (
        {"arbiter": "competitive", "arbiter_seed": -1},
        ["--arbiter", "competitive", "--arbiter-seed", "-1"],
        "arbiter_seed must be an integer >= 0 (got -1)",
    ),
    (
        {"controller": "qp", "plant": "kinematic", "qp_stability_min": 10.0},
        ["--controller", "qp", "--plant", "kinematic", "--qp-stability-min", "10"],
        "qp_stability_min must be in (0, 10) (got 10)",
    ),
    (
        {"controller": "qp", "plant": "kinematic", "qp_max_speed": 11.0},
        ["--controller", "qp", "--plant", "kinematic", "--qp-max-speed", "11"],
        "qp_max_speed must be in (0, 10] m/s (got 11)",
    ),
    (
        {"time_limit": 10001.0},
        ["--time-limit", "10001"],
        # the step count spelt apart from the cap, not "= 1e+06" against 1000000
        "time_limit / dt must be <= 1000000 steps per run (got 10001 s / 0.01 s = "
        "1.0001e+06); use a larger dt or a shorter time_limit",
    ),
]


@pytest.mark.parametrize(("options", "argv", "message"), REFUSED)
def test_run_config_refuses_what_the_command_line_refuses(tmp_path, capsys, options, argv, message):
    with pytest.raises(ParameterError) as caught:
        RunConfig(**options)
    assert str(caught.value) == message
    assert cli(["--n", "1", "--no-progress", "--out", str(tmp_path / "r"), *argv]) == 2
    # the same words, the fields spelt as the options are
    cli_message = message
    for field in ("time_limit", "arbiter_seed", "qp_stability_min", "qp_max_speed"):
        cli_message = cli_message.replace(field, field.replace("_", "-"))
    assert capsys.readouterr().err == f"error: {cli_message}\n"
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"arbiter_seed": 1.5}, "arbiter_seed must be an integer >= 0 (got 1.5)"),
        ({"stability": "ab"}, "stability thresholds must be two numbers (ENTER, EXIT) in (0, "),
        ({"manipulability": (0.5,)}, "manipulability thresholds must be two numbers"),
        ({"qp_max_speed": float("nan")}, "qp_max_speed must be a finite number in (0, 10]"),
    ],
)
def test_run_config_refuses_values_no_command_line_can_give(options, message):
    with pytest.raises(ParameterError) as caught:
        RunConfig(**options)
    assert str(caught.value).startswith(message)


@pytest.mark.parametrize(
    ("jobs", "message"),
    [
        (0, "jobs must be an integer in [1, 256] (got 0)"),
        (257, "jobs must be an integer in [1, 256] (got 257)"),
        (1.5, "jobs must be an integer in [1, 256] (got 1.5)"),
    ],
)
def test_run_many_refuses_a_job_count_the_command_line_refuses(jobs, message):
    with pytest.raises(ParameterError) as caught:
        run_many(generate(2, 0), RunConfig(time_limit=0.1), jobs=jobs)
    assert str(caught.value) == message


def test_run_many_runs_no_more_workers_than_scenarios():
    outcomes = run_many(generate(1, 0), RunConfig(time_limit=0.1), jobs=8)
    assert [o.metrics["scenario"] for o in outcomes] == [1]


def test_valid_settings_are_kept_as_given():
    config = RunConfig(stability=(1.3, 1.3), manipulability=(0.6, 1.0), dt=0.1, arbiter_seed=3)
    assert (config.stability, config.manipulability, config.dt) == ((1.3, 1.3), (0.6, 1.0), 0.1)


def test_a_qp_or_mpc_table_states_the_settings_they_use_not_the_thesis_thresholds():
    """The qp's title gave the thesis controller's thresholds, which it does not read,
    and neither its stability floor nor its speed limit."""
    qp = RunConfig(controller="qp", plant="kinematic", qp_stability_min=1.5, qp_max_speed=0.5)
    assert _title(qp) == (
        "qp controller, kinematic plant, payload 3 kg, S_min 1.5, max speed 0.5 m/s"
    )
    assert _title(RunConfig(controller="mpc")) == (
        "mpc controller, thesis plant, payload 3 kg, S_min 1.25"
    )
    # the thesis controller's titles as before
    assert (
        _title(RunConfig())
        == "thesis controller, thesis plant, payload 3 kg, S 1.25/1.6, eta 0.75/0.9"
    )
    assert _title(RunConfig(arbiter="competitive", stability=(1.4, 1.7))) == (
        "thesis controller, thesis plant, payload 3 kg, S 1.4/1.7, eta 0.75/0.9, "
        "competitive arbiter"
    )


def test_the_default_worker_count_is_within_what_run_many_accepts(monkeypatch):
    """On a machine with more CPUs than MAX_JOBS the default was refused by run_many."""
    import os

    from ddwmmr.errors import MAX_JOBS
    from ddwmmr.scenarios.executors import default_jobs

    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(300)), raising=False)
    assert default_jobs() == MAX_JOBS == 256
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    assert default_jobs() == 2


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"index": None}, r"^scenario index must be an integer >= 0 \(got None\)$"),
        ({"waypoints": None}, r"^scenario waypoints must be a non-empty list of \(x, y\) "),
        ({"waypoints": ()}, r"^scenario waypoints must be .* \(got \(\)\)$"),
        ({"waypoints": ((1, 2), (1, "a"))}, r"^scenario waypoints\[2\] y must be a finite "),
        ({"waypoints": ((1, 2), (1, 2, 3))}, r"^scenario waypoints\[2\] must be an \(x, y\) pair"),
        ({"waypoints": ((float("nan"), 0),)}, r"^scenario waypoints\[1\] x must be a finite "),
        (
            {"obstacles": ((1, 2),)},
            r"^scenario obstacles must be Circle\(x, y, radius\) or \(x, y, radius\)",
        ),
        (
            {"obstacles": ((1, 2, -0.3),)},
            r"^scenario obstacles: obstacle radius must be > 0 \(got -0.3\)$",
        ),
        ({"obstacles": 5}, r"^scenario obstacles must be circles, \(x, y, radius\) triples "),
    ],
)
def test_run_scenario_refuses_a_hand_made_scenario_naming_its_field(fields, message):
    """A Scenario built by hand was run unchecked: a waypoint list of None raised
    TypeError (len), an index of None TypeError (+ 1) after the run, a text coordinate
    TypeError (float - str). Bad obstacles were named ``obstacles`` only (the message of
    ``as_circles``), not ``scenario obstacles`` as the index and waypoints are."""
    from ddwmmr.scenarios import run_scenario
    from ddwmmr.scenarios.generator import Scenario

    scenario = Scenario(**{"index": 0, "waypoints": ((1.0, 1.0),), **fields})
    with pytest.raises(ParameterError, match=message) as info:
        run_scenario(scenario, RunConfig(time_limit=0.1))
    assert "\n" not in str(info.value)
