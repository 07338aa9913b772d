"""Refactors must not change results: replay the runs recorded by tests/golden/make_golden.py.

The reference file holds time series recorded before the loop/plant refactor and the QP
speed work; every column must agree to 1e-12 (absolute, in the column's SI unit). A
deliberate behaviour change regenerates the file (see its script).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

GOLDEN = Path(__file__).parent / "golden"
TOLERANCE = 1e-12

_spec = importlib.util.spec_from_file_location("make_golden", GOLDEN / "make_golden.py")
make_golden = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_golden)


@pytest.fixture(scope="module")
def reference() -> dict[str, np.ndarray]:
    with np.load(GOLDEN / "loops.npz") as data:
        return {key: data[key] for key in data.files}


def _compare(reference: dict[str, np.ndarray], prefix: str, values: dict[str, np.ndarray]):
    expected = {k[len(prefix) + 1 :]: v for k, v in reference.items() if k.startswith(prefix + "/")}
    assert expected, f"no reference for {prefix}"
    for column, want in expected.items():
        assert column in values, f"{prefix}: column {column} missing"
        got = np.asarray(values[column], dtype=float)
        assert got.shape == want.shape, f"{prefix}/{column}: shape {got.shape} != {want.shape}"
        np.testing.assert_allclose(got, want, rtol=0, atol=TOLERANCE, err_msg=f"{prefix}/{column}")


@pytest.mark.parametrize(
    "case", list(make_golden.tracking_cases()), ids=lambda c: c[0] if isinstance(c, tuple) else c
)
def test_tracking_runs_unchanged(reference, case):
    key, trajectory, method, integrator, robot = case
    result = make_golden.simulate(
        robot, trajectory, method, duration=make_golden.TRACK_DURATION, integrator=integrator
    )
    _compare(reference, key, result.timeseries)


@pytest.mark.parametrize("name", list(make_golden.SCENARIO_CASES))
def test_scenario_runs_unchanged(reference, name):
    config = make_golden.SCENARIO_CASES[name]
    scenarios = make_golden.generate(max(make_golden.SCENARIOS) + 1, 0)
    for index in make_golden.SCENARIOS:
        outcome = make_golden.run_scenario(scenarios[index], config)
        prefix = f"scenario/{name}/{index}"
        _compare(reference, f"{prefix}/trace", outcome.trace or {})
        metrics = {k: v for k, v in outcome.metrics.items() if isinstance(v, bool | int | float)}
        _compare(reference, f"{prefix}/metric", metrics)
