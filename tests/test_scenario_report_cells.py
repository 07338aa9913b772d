"""The scenario tool's table says what each row holds, and its scenarios.csv writes a
metric that does not apply as compare's metrics.csv does (an empty cell; null in
summary.json)."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest

from ddwmmr.cli.scenarios import main as cli
from ddwmmr.scenarios import report


@pytest.fixture(scope="module")
def batch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("h186") / "s"
    args = ["--n", "2", "--seed", "0", "--jobs", "1", "--no-progress"]
    assert cli([*args, "--out", str(out)]) == 0
    return out


def rows(batch: Path) -> list[dict[str, str]]:
    with (batch / "scenarios.csv").open(newline="") as handle:
        return list(csv.DictReader(handle))


def test_the_minimum_stability_row_is_the_lowest_run_and_says_so(batch: Path) -> None:
    table = (batch / "table.txt").read_text()
    lowest = min(float(r["min_stability"]) for r in rows(batch))
    assert lowest == pytest.approx(1.3696348930755882, abs=1e-12)  # seed 0, scenario 2
    (line,) = [line for line in table.splitlines() if line.startswith("Minimum stability S")]
    label, value = line.rsplit(None, 1)
    assert float(value) == pytest.approx(lowest, abs=5e-3)  # 1.37, not the mean 1.38
    assert label.strip() == "Minimum stability S (lowest run)"
    legend = " ".join(table.splitlines()[2:8])
    assert "the minimum stability S (the lowest of all the scenarios' runs)" in legend


def test_a_metric_that_does_not_apply_is_an_empty_cell_and_null(batch: Path) -> None:
    summary = json.loads((batch / "summary.json").read_text())
    assert summary["fallback_steps"] is None and summary["mean_unloaded_time_s"] is None
    for row in rows(batch):
        assert row["fallback_steps"] == ""  # the thesis controller has no fallback
        assert row["unloaded_time_s"] == ""  # not a physics plant
        assert float(row["min_stability"]) > 1.3  # the numbers are written as before


def test_an_undefined_number_stays_nan_and_none_is_empty() -> None:
    assert report._cell(float("nan")) == "nan"  # e.g. the speed of an unfinished scenario
    assert report._cell(float("nan"), nan_not_applicable=True) == ""
    assert report._cell(None) == ""
    assert report._cell(0.1) == "0.1" and report._cell(True) == "true"


def documented_names(heading: str) -> set[str]:
    """The backquoted names of the first column of the table after ``heading`` in
    docs/thesis.md (``time_<state>_s`` expanded over the fix states)."""
    text = (Path(__file__).parent.parent / "docs" / "thesis.md").read_text()
    lines = text[text.index(heading) :].splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("| "))
    names: set[str] = set()
    for line in lines[start + 2 :]:
        if not line.startswith("|"):
            break
        for name in re.findall(r"`([^`]+)`", line.split("|")[1]):
            states = ("manipulability", "stability", "obstacle")
            expanded = [name.replace("<state>", s) for s in states] if "<" in name else [name]
            names.update(expanded)
    return names


def test_the_thesis_page_names_every_column_and_key(batch: Path) -> None:
    assert documented_names("`scenarios.csv` has one row") == set(rows(batch)[0])
    summary = json.loads((batch / "summary.json").read_text())
    documented = documented_names("`summary.json` of a batch")
    # the sd of each mean is named with it, "each with its sd_ key"
    assert {k for k in documented if not k.startswith("sd_")} == {
        k for k in summary if not k.startswith("sd_")
    }
    assert {f"sd_{k}" for k in ("time_s", "speed_m_s")} <= documented
