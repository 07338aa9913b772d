"""The bench table says what each line times, the machine's load, and judges a p99 only
over enough samples."""

from __future__ import annotations

import pytest

from ddwmmr.bench.mpc_floor import FLOOR_TARGETS, floor_verdicts, format_floor_lines
from ddwmmr.bench.qp_classes import QP_TARGETS, qp_target_verdict
from ddwmmr.bench.report import format_load, format_qp_verdict, format_table
from ddwmmr.bench.timing import P99_MIN_SAMPLES


def _config(**fields) -> dict:
    config = {
        "trajectory": "ellipse",
        "calls": 50,
        "run_duration_s": 2.0,
        "integrator": "rk4",
        "repeats": 2,
        "state_source": "clrrmc-ts",
        "cpus": 2,
        "load_average": [4.1, 3.0, 2.0],
    }
    return {**config, **fields}


def _qp_class(name: str, states: int, median: float, p99: float) -> dict:
    return {
        "name": name,
        "states": states,
        "rows": {"qp": {"median_us": median, "p90_us": median, "p99_us": p99}},
        "ratios": {},
        "phases": {"build": 1.0, "solve": 1.0, "check": 0.5, "rest": 0.5},
        "exact_check_fraction": 0.06,
    }


def _report(classes: list[dict], floor: list[dict] | None = None) -> dict:
    row = {"label": "qp", "step_us": 20.4, "step_p90_us": 24.8, "step_p99_us": 84.4}
    row.update(step_ratio=0.5, steps_per_s=5572.0, run_speedup=1.5, meets_target=True)
    return {
        "config": _config(state_spacing_s=0.816, load_average_start=[3.5, 3.0, 2.0]),
        "rows": [row],
        "target_step_ratio": 0.25,
        "baseline": "naive-pinv",
        "step_budgets_us": {"qp": 60.0, "mpc": 2000.0},
        "pairs": [],
        "skipped": {},
        "qp_classes": classes,
        "qp_targets": dict(QP_TARGETS),
        "mpc_floor": floor or [],
    }


def test_p99_threshold_is_a_hundred_samples() -> None:
    assert P99_MIN_SAMPLES == 100


@pytest.mark.parametrize(
    ("states", "expected"), [(50, None), (99, None), (100, False), (500, False)]
)
def test_a_p99_over_too_few_states_is_not_judged(states: int, expected) -> None:
    qp = {"median_us": 15.0, "p99_us": 1100.0}
    assert qp_target_verdict(qp, states) is expected
    # a median that misses misses, however few the states
    assert qp_target_verdict({"median_us": 25.0, "p99_us": 30.0}, states) is False
    assert qp_target_verdict({"median_us": 15.0, "p99_us": 30.0}, states) is (
        None if states < 100 else True
    )


def test_qp_verdict_line_says_p99_needs_100_states_instead_of_miss() -> None:
    few = [_qp_class("tracking", 50, 15.0, 1100.0), _qp_class("obstacles", 50, 18.0, 90.0)]
    line = format_qp_verdict(_report(few))
    assert "MISS" not in line
    assert "in every class: not judged (worst 18.00 / -); p99 needs >= 100 states, " in line
    assert "not judged in 2 of 2 classes" in line
    assert "stricter than the table's 60 us budget" in line
    # a judgeable class's p99 is judged, the other's still is not
    mixed = [_qp_class("tracking", 500, 15.0, 41.0), _qp_class("obstacles", 50, 18.0, 900.0)]
    line = format_qp_verdict(_report(mixed))
    assert "in every class: MISS (worst 18.00 / 41.00); p99 needs >= 100" in line
    assert "not judged in 1 of 2 classes" in line
    enough = [_qp_class("tracking", 100, 15.0, 39.5)]
    line = format_qp_verdict(_report(enough))
    assert "in every class: ok (worst 15.00 / 39.50); rtb-holistic" in line


def test_class_line_explains_the_exact_look_ahead() -> None:
    table = format_table(_report([_qp_class("obstacles", 50, 18.0, 90.0)]))
    assert (
        "  obstacles (50 states; exact stability look-ahead needed in 6.0 %, else the cheap "
        "bound sufficed)"
    ) in table.splitlines()


def test_table_says_what_it_times_and_the_load() -> None:
    lines = format_table(_report([])).splitlines()
    assert lines[1].startswith(
        "step: wall time (us) of one command call on states replayed from a clrrmc-ts run, "
        "0.82 s apart (a warm-started method such as mpc did not predict them)"
    )
    assert lines[1].endswith("(p99 of fewer than 100 states: about their maximum)")
    assert lines[2] == (
        "load average (1 min) 3.5 at the start, 4.1 at the end on 2 CPUs: more than the CPUs, "
        "so these latencies are unreliable (other jobs preempt the timed calls)"
    )
    assert "target for qp: step <= 60 us (absolute budget on the median above)" in lines


@pytest.mark.parametrize(
    ("start", "end", "warned"),
    [(None, [0.6], False), ([1.9], [2.0], False), ([2.1], [1.0], True), (None, [2.01], True)],
)
def test_load_warning_only_above_the_cpu_count(start, end, warned) -> None:
    line = format_load(_config(load_average=end, load_average_start=start))
    assert ("latencies are unreliable" in line) is warned
    assert line.startswith("load average (1 min) ") and " on 2 CPUs" in line
    assert format_load(_config(load_average=None)) == "load average unknown on 2 CPUs"


def _floor_row(steps: int, p99_over_median: float) -> dict:
    return {
        "case": "tracking ellipse (kinematic plant)",
        "steps": steps,
        "median_us": 570.0,
        "p99_us": 570.0 * p99_over_median,
        "max_us": 3000.0,
        "hpipm_median_us": 300.0,
        "step_over_hpipm": 1.9,
        "p99_over_median": p99_over_median,
    }


def test_floor_p99_over_too_few_steps_is_not_judged() -> None:
    few, enough = _floor_row(21, 3.0), _floor_row(101, 3.0)
    assert floor_verdicts(few)["p99_over_median"] is None
    assert floor_verdicts(enough)["p99_over_median"] is False
    assert floor_verdicts(dict(FLOOR_TARGETS))["p99_over_median"] is True  # no "steps"
    lines = format_floor_lines([few])
    assert "MISS" not in lines[2] and lines[2].split()[-3:] == ["3.00", "-", "ok"]
    assert lines[3] == (
        "  -: p99 needs >= 100 steps, not judged (tracking ellipse (kinematic plant) has 21)"
    )
    lines = format_floor_lines([enough])
    assert lines[2].split()[-3:] == ["3.00", "MISS", "ok"] and len(lines) == 3
    assert lines[0].startswith(
        "mpc step against its HPIPM solve in mpc's own closed-loop runs (thread CPU time, "
        "not the method table's wall time on replayed states;"
    )


def test_report_records_the_load_at_the_start_and_the_state_spacing() -> None:
    from ddwmmr.bench import run_benchmark

    report = run_benchmark(repeats=1, calls=5, duration=0.1, methods=["ats"])
    config = report["config"]
    # five states spread over the ellipse's 40 s period (2001 states at 0.02 s)
    assert config["state_spacing_s"] == pytest.approx(10.0, abs=1e-9)
    assert len(config["load_average_start"]) == 3
    assert all(v >= 0.0 for v in config["load_average_start"])
    assert "load average (1 min) " in format_table(report).splitlines()[2]
