"""A seed is any integer >= 0 (numpy's SeedSequence takes any size, as generate() does):
the scenarios and bounds tools refused one of 1000 digits with "seed must be a finite
number >= 0 (got an integer of about 1e999)", a range it lies in, and RunConfig its
arbiter_seed alike."""

from __future__ import annotations

import pytest

from ddwmmr.cli.scenarios import build_parser, config_from_arguments
from ddwmmr.errors import ParameterError
from ddwmmr.scenarios import RunConfig

HUGE = 10**999


def test_the_scenarios_tool_takes_a_seed_of_any_size():
    argv = ["--n", "1", "--seed", str(HUGE), "--arbiter", "competitive"]
    config_from_arguments(build_parser().parse_args([*argv, "--arbiter-seed", str(HUGE)]))
    with pytest.raises(ParameterError, match=r"^seed must be an integer >= 0 \(got -1\)$"):
        config_from_arguments(build_parser().parse_args(["--seed", "-1"]))


def test_a_run_config_takes_an_arbiter_seed_of_any_size():
    assert RunConfig(arbiter="competitive", arbiter_seed=HUGE).arbiter_seed == HUGE
    with pytest.raises(ParameterError, match=r"^arbiter_seed must be an integer >= 0"):
        RunConfig(arbiter="competitive", arbiter_seed=-1)


def test_the_bounds_tool_takes_a_seed_of_any_size(tmp_path, capsys):
    """Refused before any work: a bad seed ends the tool at once; a huge one reaches the
    scenario list's check (given bad here, so that nothing runs)."""
    from ddwmmr.cli.bounds import main as bounds

    out = str(tmp_path / "out")
    assert bounds(["--seed", str(HUGE), "--scenarios", "0", "--out", out]) == 2
    assert "error: scenarios must lie in" in capsys.readouterr().err
