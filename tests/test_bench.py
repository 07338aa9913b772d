"""The benchmark runs, reports every method against the naive baseline, and stays honest."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, available_methods, make_controller
from ddwmmr.bench import (
    EXTRA_CASES,
    NAIVE_LABEL,
    ExtraCase,
    NaivePseudoinverseController,
    benchmark_cases,
    format_table,
    main,
    record_states,
    run_benchmark,
)

TINY = {"repeats": 1, "calls": 20, "duration": 0.4}


@pytest.fixture(scope="module")
def report() -> dict:
    extras = (
        *EXTRA_CASES,
        ExtraCase("naive-again", "ddwmmr.bench:NaivePseudoinverseController", pair="pi"),
        ExtraCase("missing", "ddwmmr.no_such_module:Thing", pair="pi"),
    )
    return run_benchmark(**TINY, extras=extras)


def test_rows_cover_baseline_and_every_registered_method(report: dict) -> None:
    rows = {row["label"]: row for row in report["rows"]}
    labels = list(rows)
    assert labels[0] == NAIVE_LABEL and rows[NAIVE_LABEL]["kind"] == "baseline"
    assert set(available_methods()) <= set(labels)  # every method measured exactly once
    assert len(labels) == len(set(labels))
    assert labels[-1] == "naive-again" and rows["naive-again"]["kind"] == "extra"
    for row in report["rows"]:
        assert (row["meets_target"] is None) == (row["kind"] != "method")
    assert "missing" in report["skipped"]
    assert "ddwmmr.no_such_module" in report["skipped"]["missing"]


def test_numbers_are_positive_and_ratios_consistent(report: dict) -> None:
    naive = report["rows"][0]
    assert naive["step_ratio"] == pytest.approx(1.0)
    for row in report["rows"]:
        assert row["step_us"] > 0 and math.isfinite(row["step_us"])
        assert row["steps_per_s"] > 0 and math.isfinite(row["steps_per_s"])
        assert row["step_ratio"] == pytest.approx(row["step_us"] / naive["step_us"])
        assert row["run_speedup"] == pytest.approx(row["steps_per_s"] / naive["steps_per_s"])
        assert row["meets_target"] in (True, False, None)
    pairs = {pair["naive"]: pair for pair in report["pairs"]}
    assert pairs["naive-again"]["method"] == "pi"
    steps = {row["label"]: row["step_us"] for row in report["rows"]}
    for pair in pairs.values():
        assert pair["step_ratio"] == pytest.approx(steps[pair["method"]] / steps[pair["naive"]])


def test_table_lists_every_row(report: dict) -> None:
    table = format_table(report)
    for row in report["rows"]:
        assert row["label"] in table
    assert "skipped missing" in table


def test_cli_json(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(
        ["--json", "--repeats", "1", "--calls", "10", "--duration", "0.2", "--method", "ats"]
    )
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert [row["label"] for row in data["rows"]][:2] == [NAIVE_LABEL, "ats"]
    assert data["config"]["repeats"] == 1


def test_cli_rejects_unknown_method(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--method", "nope", "--repeats", "1"]) == 2
    assert "nope" in capsys.readouterr().err


def test_extra_case_replaces_the_registered_method_of_the_same_name() -> None:
    extra = ExtraCase("ats", "ddwmmr.bench:NaivePseudoinverseController", pair="pi")
    cases, skipped = benchmark_cases(methods=["pi", "ats"], extras=(extra,))
    assert [(c.label, c.kind) for c in cases] == [
        (NAIVE_LABEL, "baseline"),
        ("pi", "method"),
        ("ats", "extra"),
    ]
    assert skipped == {}
    assert isinstance(cases[-1].make(Robot()), NaivePseudoinverseController)


def test_selected_methods_keep_only_their_extra_cases() -> None:
    extras = (
        ExtraCase("pi-twin", "ddwmmr.bench:NaivePseudoinverseController", pair="pi"),
        ExtraCase("ats-twin", "ddwmmr.bench:NaivePseudoinverseController", pair="ats"),
    )
    cases, _ = benchmark_cases(methods=["pi"], extras=extras)
    assert [c.label for c in cases] == [NAIVE_LABEL, "pi", "pi-twin"]


def test_default_extra_cases_are_well_formed() -> None:
    for extra in EXTRA_CASES:
        module, _, attribute = extra.factory.partition(":")
        assert module and attribute and extra.label


def test_naive_baseline_equals_closed_form_pseudoinverse() -> None:
    """Away from cos(th1) = 0 the SVD pseudoinverse and the closed-form kernel agree."""
    robot, trajectory = Robot(), Ellipse()
    states = record_states(robot, trajectory, 25)
    naive = NaivePseudoinverseController(robot)
    closed = make_controller("pi", robot)
    for t, q, pose, velocity in zip(
        states.times, states.configurations, states.poses, states.velocities
    ):
        assert abs(math.cos(q[3])) > 0.1
        np.testing.assert_allclose(
            naive.command(t, q, pose, velocity), closed.command(t, q, pose, velocity), atol=1e-10
        )
        assert abs(naive.last.nonholonomic_residual) < 1e-12
