"""``python -m ddwmmr.bounds`` run on some --scenarios into the folder of an earlier run
keeps the cache of the other scenarios (same seed and payload), and drops, saying so, the
cache made for another seed or payload. The solves are replaced by records with known
numbers (a real scenario takes minutes)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import ddwmmr.cli.bounds as tool
from ddwmmr.bounds import batch
from ddwmmr.outputs import MANIFEST


def _solved(job: batch.Job) -> dict:
    """What :func:`batch.solve` returns, with times made from the scenario number."""
    index = job.scenario.index + 1
    wanted = batch.keys(job.scenario, job.payload, job.settings)
    out: dict = {"index": index}
    if job.need_lower:
        out["lower"] = {"key": wanted["lower"], "lower_bound_s": 10.0 + index, "cells": 4}
    if job.need_best:
        out["best"] = {
            "key": wanted["best"],
            "best_known_s": 12.5 + index,
            "starts": 3,
            "spread_s": 0.25,
            "replay_ok": True,
        }
        out["trajectory"] = {"times": np.arange(3.0), "legs": np.array([1.0, 2.0])}
    return out


@pytest.fixture
def solved(monkeypatch) -> list[int]:
    """The scenario numbers solved (not read from the cache), in order."""
    calls: list[int] = []

    def solve(job: batch.Job) -> dict:
        calls.append(job.scenario.index + 1)
        return _solved(job)

    monkeypatch.setattr(batch, "solve", solve)
    return calls


def _run(out: Path, scenarios: str, *extra: str) -> None:
    argv = ["--scenarios", scenarios, "--jobs", "1", "--no-progress", "--out", str(out)]
    assert tool.main([*argv, "--quick", *extra]) == 0


def _rows(out: Path) -> list[tuple[str, str, str]]:
    lines = (out / "bounds.csv").read_text().splitlines()[1:]
    return [tuple(line.split(",")[:3]) for line in lines]


def _cache(out: Path) -> list[str]:
    return sorted(p.name for p in (out / "cache").iterdir())


def test_a_run_of_other_scenarios_keeps_the_cache_of_the_earlier_ones(tmp_path, solved):
    out = tmp_path / "b"
    _run(out, "1")
    _run(out, "2", "--lower-only")
    assert _cache(out) == [
        "scenario-001-best.json",
        "scenario-001-best.npz",
        "scenario-001-lower.json",
        "scenario-002-lower.json",
    ]
    listed = json.loads((out / MANIFEST).read_text())["files"]
    assert [f"cache/{name}" for name in _cache(out)] == [f for f in listed if f.startswith("cache")]
    assert _rows(out) == [("2", "12.0", "nan")]  # bounds.csv: this run's scenarios
    _run(out, "1-2")  # only scenario 2's best-known search is left
    assert solved == [1, 2, 2]
    assert _rows(out) == [("1", "11.0", "13.5"), ("2", "12.0", "14.5")]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["mean_lower_bound_s"] == 11.5 and summary["scenarios"] == 2


def test_the_cache_of_another_seed_is_dropped_with_a_note(tmp_path, solved, capsys):
    out = tmp_path / "b"
    _run(out, "1,2", "--lower-only")
    _run(out, "3", "--lower-only", "--seed", "1")
    assert _cache(out) == ["scenario-003-lower.json"]
    err = capsys.readouterr().err
    assert "note: removed the cache of 2 scenarios (1, 2) from " in err
    assert "made for another seed or payload than seed 1, payload 3 kg" in err
    _run(out, "1", "--lower-only", "--seed", "1")
    assert solved == [1, 2, 3, 1]  # seed 0's record was not taken for seed 1's scenario 1


def test_a_record_of_other_method_settings_is_kept_and_not_used(tmp_path, solved):
    """--quick's best-known record stays for a --quick run; a full search recomputes it."""
    out = tmp_path / "b"
    _run(out, "1")
    assert tool.main(["--scenarios", "2", "--lower-only", "--jobs", "1", "--no-progress",
                      "--out", str(out)]) == 0  # fmt: skip
    assert "scenario-001-best.json" in _cache(out)
    assert _rows(out) == [("2", "12.0", "nan")]
    assert tool.main(["--scenarios", "1", "--jobs", "1", "--no-progress",
                      "--out", str(out)]) == 0  # fmt: skip
    assert solved == [1, 2, 1]  # the full search of 1 ran: the --quick record does not match
