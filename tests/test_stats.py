"""The scenario benchmark's statistics and its configuration's checks: Student's t for the
mean time's confidence interval, an undefined sd of one scenario, summary.json's undefined
numbers as null, and RunConfig refusing what the command line refuses, in its words."""

from __future__ import annotations

import dataclasses
import json
import math
import statistics

import numpy as np
import pytest

from ddwmmr.cli.scenarios import main as cli
from ddwmmr.errors import ParameterError
from ddwmmr.scenarios import report
from ddwmmr.scenarios.generator import generate
from ddwmmr.scenarios.protocol import RunConfig, check_dt, max_start_payload, run_scenario

#: Published two-sided 95 % quantiles of Student's t (degrees of freedom: quantile).
T_TABLE = {1: 12.706, 2: 4.303, 5: 2.571, 10: 2.228, 23: 2.069, 99: 1.984}


@pytest.mark.parametrize(("dof", "quantile"), T_TABLE.items())
def test_the_t_quantile_matches_the_published_table(dof, quantile):
    assert report.t_quantile_95(dof) == pytest.approx(quantile, abs=1e-3)


def _t_mass(dof: int, half_width: float, intervals: int = 20_000) -> float:
    """P(|T| <= half_width) for Student's t with ``dof`` degrees of freedom, by Simpson's
    rule on its density (math only: independent of scipy)."""
    log_c = math.lgamma((dof + 1) / 2) - math.lgamma(dof / 2) - 0.5 * math.log(dof * math.pi)
    x = np.linspace(0.0, half_width, intervals + 1)
    density = np.exp(log_c - (dof + 1) / 2 * np.log1p(x * x / dof))
    h = half_width / intervals
    simpson = (
        h / 3 * (density[0] + density[-1] + 4 * density[1:-1:2].sum() + 2 * density[2:-1:2].sum())
    )
    return 2.0 * simpson


@pytest.mark.parametrize("dof", [1, 2, 3, 5, 10, 23, 99, 1000])
def test_the_t_quantile_holds_95_percent_of_the_density(dof):
    assert _t_mass(dof, report.t_quantile_95(dof)) == pytest.approx(0.95, abs=1e-9)


def test_the_t_quantile_has_the_closed_forms_of_one_and_two_degrees():
    p = 0.975
    assert report.t_quantile_95(1) == pytest.approx(math.tan(math.pi * (p - 0.5)), rel=1e-12)
    assert report.t_quantile_95(2) == pytest.approx((2 * p - 1) / math.sqrt(2 * p * (1 - p)))
    assert report.t_quantile_95(10**6) == pytest.approx(1.959964, abs=1e-5)  # the normal's


@pytest.mark.parametrize("dof", [0, -1, 2.5, True])
def test_the_t_quantile_refuses_what_is_no_degree_of_freedom(dof):
    with pytest.raises(ParameterError, match=r"^dof must be an integer >= 1 \(got "):
        report.t_quantile_95(dof)


@pytest.fixture(scope="module")
def base_outcome():
    return run_scenario(generate(1, 0)[0], RunConfig(time_limit=0.3))


def _with_times(base, times):
    return [dataclasses.replace(base, metrics={**base.metrics, "time_s": t}) for t in times]


def test_the_ci_of_three_scenarios_uses_t_with_two_degrees(base_outcome):
    """At n = 3 the t interval is 4.303 / 1.960 = 2.2 times the normal one."""
    times = [20.0, 25.0, 33.0]
    summary = report.summarize(_with_times(base_outcome, times), 1.0)
    sd = statistics.stdev(times)  # 6.557 s
    assert summary["sd_time_s"] == pytest.approx(sd, rel=1e-12)
    assert summary["ci95_time_s"] == pytest.approx(4.302653 * sd / math.sqrt(3), rel=1e-6)
    assert summary["ci95_time_s"] == pytest.approx(16.289, abs=1e-3)
    assert summary["mean_time_s"] == pytest.approx(26.0, rel=1e-12)


def test_the_sd_of_one_scenario_is_undefined(base_outcome):
    summary = report.summarize([base_outcome], 1.0)
    sds = {k: v for k, v in summary.items() if k.startswith("sd_")}
    assert len(sds) == len(report.AVERAGED)
    assert all(math.isnan(v) for v in sds.values()), sds
    assert math.isnan(summary["ci95_time_s"])
    assert summary["mean_time_s"] == pytest.approx(base_outcome.metrics["time_s"])
    rows = dict(report.table_rows(summary))
    assert rows["Simulation time (s)"].endswith("(n/a)")
    two = report.summarize([base_outcome, base_outcome], 1.0)
    assert two["sd_time_s"] == 0.0 and two["ci95_time_s"] == 0.0  # defined, and nil


def _strict(text: str):
    """json.loads refusing the NaN/Infinity tokens that are not JSON."""

    def refuse(token: str):
        raise ValueError(f"not JSON: {token}")

    return json.loads(text, parse_constant=refuse)


def test_summary_json_writes_every_undefined_number_as_null():
    summary = {
        "a": math.nan,
        "b": np.float64("nan"),
        "c": np.float32("inf"),
        "d": [1.5, -math.inf, (np.int64(3), math.nan)],
        "e": {"f": None, "g": "inf", "h": np.float64(2.5)},
    }
    data = _strict(report.summary_json(summary))
    assert data == {
        "a": None,
        "b": None,
        "c": None,
        "d": [1.5, None, [3, None]],
        "e": {"f": None, "g": "inf", "h": 2.5},  # strings (the run record's) kept
    }


CLI_RUN = ["--n", "1", "--time-limit", "0.3", "--jobs", "1", "--no-progress"]


def test_the_written_summary_has_null_for_undefined_numbers(tmp_path):
    out = tmp_path / "qp"
    argv = [*CLI_RUN, "--controller", "qp", "--plant", "kinematic", "--out", str(out)]
    assert cli(argv) == 0
    text = (out / "summary.json").read_text()
    summary = _strict(text)
    assert '"nan"' not in text and "NaN" not in text
    for key in ("sd_time_s", "ci95_time_s", "time_stability_s", "transitions_manipulability"):
        assert summary[key] is None, key
    assert summary["mean_time_s"] == pytest.approx(0.3)
    assert summary["fallback_steps"] == 0


def test_the_threshold_study_summary_has_null_for_undefined_numbers(tmp_path):
    out = tmp_path / "thr"
    assert cli([*CLI_RUN, "--study", "thresholds", "--out", str(out)]) == 0
    text = (out / "summary.json").read_text()
    variants = _strict(text)["variants"]
    assert '"nan"' not in text and len(variants) == 18
    assert all(v["sd_time_s"] is None and v["ci95_time_s"] is None for v in variants)
    assert all(v["mean_time_s"] == pytest.approx(0.3) for v in variants)


#: (RunConfig keywords, the command line's options): each refused in the same words.
SAME_WORDS = [
    ({"dt": 0.0}, ["--dt", "0"]),
    ({"dt": -0.01}, ["--dt", "-0.01"]),
    ({"dt": 1.0, "time_limit": 0.5}, ["--dt", "1", "--time-limit", "0.5"]),
    ({"dt": 100.0}, ["--dt", "100"]),
    ({"dt": 0.1, "time_limit": 0.05}, ["--dt", "0.1", "--time-limit", "0.05"]),
    ({"time_limit": 0.0}, ["--time-limit", "0"]),
    ({"time_limit": math.inf}, ["--time-limit", "inf"]),
    ({"payload": 20.0}, ["--payload", "20"]),
    ({"payload": 1e300}, ["--payload", "1e300"]),
    ({"payload": -1.0}, ["--payload", "-1"]),
]


@pytest.mark.parametrize(("options", "argv"), SAME_WORDS)
def test_run_config_refuses_in_the_command_line_s_words(tmp_path, capsys, options, argv):
    with pytest.raises(ParameterError) as caught:
        RunConfig(**options)
    assert cli(["--n", "1", "--no-progress", "--out", str(tmp_path / "r"), *argv]) == 2
    expected = str(caught.value).replace("time_limit", "time-limit")
    assert capsys.readouterr().err == f"error: {expected}\n"
    assert not (tmp_path / "r").exists()


def test_run_config_gives_the_dt_range_and_the_payload_limit():
    with pytest.raises(ParameterError) as caught:
        RunConfig(dt=0.0)
    assert str(caught.value) == "dt must be in (0, 0.1] s (got 0)"
    with pytest.raises(ParameterError) as caught:
        RunConfig(payload=20.0)
    assert str(caught.value) == (
        "payload: 20 kg tips the robot over in the start pose (S = 0.741 <= 1); the start "
        "pose holds at most 9.338 kg"
    )


def test_run_config_takes_payloads_up_to_what_the_start_pose_holds():
    limit = max_start_payload()
    assert limit == pytest.approx(9.338, abs=1e-3)
    assert RunConfig(payload=0.99 * limit).payload == pytest.approx(0.99 * limit)
    with pytest.raises(ParameterError, match=r"^payload: .* tips the robot over"):
        RunConfig(payload=1.01 * limit)


@pytest.mark.parametrize(
    ("dt", "got"),
    [("abc", "'abc'"), (None, "None"), (True, "True"), (10**400, "an integer of about 1e400")],
)
def test_check_dt_refuses_what_is_no_number_in_one_line(dt, got):
    with pytest.raises(ParameterError) as caught:
        check_dt(dt)
    assert str(caught.value) == f"dt must be in (0, 0.1] s (got {got})"


def test_the_arbiter_studys_sd_of_one_scenario_is_undefined(base_outcome):
    """The arbiter study's own sd (fix-state entries) follows report.summarize's rule."""
    from ddwmmr.scenarios import arbiter_study

    one = arbiter_study.summarize([base_outcome], 1.0)
    assert math.isnan(one["sd_fix_entries"])
    two = arbiter_study.summarize([base_outcome, base_outcome], 1.0)
    assert two["sd_fix_entries"] == 0.0
