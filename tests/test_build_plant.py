"""``build_plant`` builds the plant ``simulate`` would build from a name, so that a tool
that needs the run's plant before the run (track refuses a control step the plant will
refuse) passes that object on and ``simulate`` builds no second one, with the same run."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import ddwmmr.plants as plants
from ddwmmr.model import Robot
from ddwmmr.sim.simulate import build_plant, simulate
from ddwmmr.trajectories import Ellipse


@pytest.mark.parametrize(
    ("plant", "integrator", "options"),
    [
        ("kinematic", None, None),
        ("kinematic", "euler", None),
        ("thesis", None, {"c1": 20.0}),
        ("mujoco", None, {"timestep": 0.001}),
    ],
)
def test_a_built_plant_runs_as_its_name_does_and_nothing_else_is_built(
    plant, integrator, options, monkeypatch
):
    robot = Robot()
    run = {"dt": 0.02, "duration": 0.4}
    named = simulate(
        robot, Ellipse(), "pi", plant=plant, integrator=integrator, plant_options=options, **run
    )
    built = build_plant(plant, robot, integrator, options)
    assert built.name == plant and getattr(built, "integrator", None) == named.summary["integrator"]
    made = []
    original = plants.make_plant
    module = sys.modules["ddwmmr.sim.simulate"]  # ddwmmr.sim.simulate is also a function
    monkeypatch.setattr(module, "make_plant", lambda *a, **k: made.append(a) or original(*a, **k))
    passed = simulate(robot, Ellipse(), "pi", plant=built, **run)
    assert made == []  # the object is run as it is
    timing = {"median_step_us"}
    assert {k: v for k, v in passed.summary.items() if k not in timing} == {
        k: v for k, v in named.summary.items() if k not in timing
    }
    for column, values in named.timeseries.items():
        if column != "step_us":
            np.testing.assert_array_equal(passed.timeseries[column], values, err_msg=column)
