"""compare names what it shows as track does: the plant table's settled-end RMS column,
the two tests of the shoulder singularity (reached: |cos th1| < 0.05; damped: the
``singular_steps``), the studies' wording of the settled end and the error at the end;
and its run.json records the step, integrator and initial offset as track's record does.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Robot, simulate
from ddwmmr.cli.compare import main, run_record
from ddwmmr.reports.compare.document import mm
from ddwmmr.reports.compare.plan import CompareConfig, plan_runs
from ddwmmr.trajectories import Ellipse, load_trajectory


def _compare(out: Path, *argv: str) -> Path:
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        assert main([*argv, "--jobs", "1", "--no-progress", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def plants(tmp_path_factory) -> Path:
    """pi and qp on the ellipse and the rectangle, also on the thesis plant, no study."""
    out = tmp_path_factory.mktemp("h188") / "plants"
    return _compare(out, "--methods", "pi,qp", "--study", "none", "--plant", "thesis")


@pytest.fixture(scope="module")
def studies(tmp_path_factory) -> str:
    """report.md of a 2 s comparison of ats on the ellipse with the dt and init studies."""
    out = tmp_path_factory.mktemp("h188") / "studies"
    argv = ["--methods", "ats", "--only", "ellipse", "--duration", "2", "--study", "dt,init"]
    return (_compare(out, *argv) / "report.md").read_text()


def _section(text: str, heading: str) -> str:
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return text[start : end if end >= 0 else None]


def _table(section: str) -> list[dict[str, str]]:
    lines = [x for x in section.splitlines() if x.startswith("|")]
    cells = [[c.strip() for c in x.strip("|").split("|")] for x in lines]
    return [dict(zip(cells[0], row)) for row in cells[2:]]


def test_the_plant_table_names_the_settled_end_rms_as_track_does(plants: Path) -> None:
    section = _section((plants / "report.md").read_text(), "## Plant: thesis")
    rows = _table(section)
    assert "settled-end RMS thesis (mm)" in rows[0]
    assert not [h for h in rows[0] if h.startswith("final")]
    with (plants / "plant_metrics.csv").open() as f:
        summary = next(
            r for r in csv.DictReader(f) if r["method"] == "qp" and r["trajectory"] == "ellipse"
        )
    settled, end = float(summary["final_position_error_m"]), float(summary["end_position_error_m"])
    assert settled == pytest.approx(1.60e-3, rel=0.01) and end < 0.9 * settled
    qp = next(r for r in rows if r["method"] == "qp" and r["trajectory"] == "ellipse")
    assert qp["settled-end RMS thesis (mm)"] == mm(settled) == "1.60"


def test_the_report_says_which_test_of_the_singularity_each_statement_uses(plants: Path) -> None:
    """pi on the rectangle damps from 14.58 s on (singular_steps) and reaches |cos th1| < 0.05
    at 20.5 s (the diagnosis): the report names both tests."""
    ts = simulate(Robot(), load_trajectory("rectangle"), "pi").timeseries
    damped = np.nonzero(ts["singular"])[0]
    reached = np.nonzero(np.abs(np.cos(ts["th1"])) < 0.05)[0]
    assert ts["t"][damped[0]] == pytest.approx(14.58, abs=1e-9)
    assert ts["t"][reached[0]] == pytest.approx(20.5, abs=0.05)
    text = (plants / "report.md").read_text()
    advice = _section(text, "## Which method should I use?")
    assert (
        "what the shoulder singularity cos th1 = 0 does to the run (reached where "
        "|cos th1| < 0.05)." in advice
    )
    assert "rectangle: reaches it at 20.5 s and loses the path" in advice
    happened = _section(text, "## What happened in each run")
    assert (
        "the shoulder singularity (reached where |cos th1| < 0.05; the steps a finding calls "
        "damped are the singular steps, a wider test: see the Definitions)" in happened
    )
    assert "singularity cos(th1) = 0 at t = 20.5 s" in happened
    definitions = _section(text, "## Definitions and files")
    assert (
        "singular steps: steps where the method damped its inverse, the smallest singular "
        "value of the matrix inverted below its `singularity_threshold` (default 0.05 in the "
        "robot's length unit: on `Robot()` |cos th1| < 0.15 to 0.25, so they begin before "
        "the singularity counts as reached, |cos th1| < 0.05;" in definitions
    )
    pi = next(r for r in _table(_section(text, "## Trajectory: rectangle")) if r["method"] == "pi")
    assert pi["singular steps"] == "1271"


def test_the_studies_name_the_settled_end_and_the_error_at_the_end(studies: str) -> None:
    dt = _section(studies, "## Study: step size")
    assert "the error at the end would hide drift" in dt and "final error" not in dt
    init = _section(studies, "## Study: initial offset")
    assert "*Settled-end RMS position error vs initial offset per method" in init
    assert "Final error" not in init


def test_run_json_records_step_integrator_and_offset_as_track_does(plants: Path) -> None:
    record = json.loads((plants / "run.json").read_text())
    assert record["dt"] == {"ellipse": 0.02, "rectangle": 0.02}
    assert record["integrator"] == "rk4"
    assert record["initial_offset"] == [-0.03, -0.03]


def test_run_record_takes_each_trajectory_s_step_and_the_robot_s_offset() -> None:
    """The steps the plan runs, per trajectory; the offset in the robot's length unit."""
    trajectories = {"ellipse": Ellipse(), "slow": Ellipse(T=20.0, N=400, name="slow")}
    config = CompareConfig(("ats",), trajectories, robot=Robot(L1=0.7, L2=0.6), studies=())
    record = run_record(config, {}, [], jobs=1)
    planned = {spec.trajectory: spec.dt for spec in plan_runs(config).main}
    assert record["dt"] == planned == {"ellipse": 0.02, "slow": 0.05}
    assert record["initial_offset"] == [-0.06, -0.06]
    assert record["integrator"] == "rk4"
