"""The compare report's plant section: the main comparison repeated on another plant."""

import re

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, simulate
from ddwmmr.reports.compare import CompareConfig, execute, plan_runs, write_report

DURATION = 4.0


def test_plant_section_matches_independent_runs(tmp_path):
    config = CompareConfig(
        methods=("ats", "clrrmc-ts"),
        trajectories={"ellipse": Ellipse()},
        duration=DURATION,
        studies=(),
        plants=("thesis",),
    )
    plan = plan_runs(config)
    assert [s.plant for s in plan.plants["thesis"]] == ["thesis", "thesis"]
    outputs = execute(config, plan.all_specs())
    write_report(config, plan, outputs, tmp_path)
    text = (tmp_path / "report.md").read_text()
    assert "## Plant: thesis next to the kinematic plant" in text
    assert (tmp_path / "plant_thesis_ellipse.png").stat().st_size > 0
    for method in config.methods:
        on_plant = simulate(Robot(), Ellipse(), method, duration=DURATION, plant="thesis")
        kinematic = simulate(Robot(), Ellipse(), method, duration=DURATION)
        ts = on_plant.timeseries
        lag = np.sqrt(np.mean((ts["v_measured"] - ts["v"]) ** 2))
        row = next(line for line in text.splitlines() if line.startswith(f"| ellipse | {method} |"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert float(cells[2]) == pytest.approx(
            1000 * kinematic.summary["rms_position_error_m"], rel=5e-3
        )
        assert float(cells[3]) == pytest.approx(
            1000 * on_plant.summary["rms_position_error_m"], rel=5e-3
        )
        assert float(cells[6]) == pytest.approx(1000 * lag, rel=5e-3)
    assert re.search(r"Where the error grows by more than 1.5x: ", text)


def test_unknown_or_kinematic_plant_is_refused():
    for plant in ("kinematic", "nope"):
        with pytest.raises(ParameterError, match="plant must be one of"):
            CompareConfig(methods=("ats",), trajectories={"ellipse": Ellipse()}, plants=(plant,))


def test_plants_may_be_comma_separated_like_the_methods():
    from ddwmmr.cli.compare import parse_plants

    assert parse_plants(["thesis,mujoco"]) == ("thesis", "mujoco")
    assert parse_plants(["mujoco", "thesis,mujoco"]) == ("mujoco", "thesis")
