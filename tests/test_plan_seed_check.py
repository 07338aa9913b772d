"""A ``plan`` is followed only on the problem it was made for: the waypoints and payload a
bounds run recorded beside it must be the scenario's."""

import json
from pathlib import Path

import numpy as np
import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.mpc.min_time import PLAN_FOLDER, PLAN_NAME, plan_problem
from ddwmmr.plants import ThesisPlant
from ddwmmr.scenarios.generator import generate
from ddwmmr.scenarios.protocol import RunConfig, make_scenario_controller

#: Scenario 1 of seed 0 and of seed 5: their first waypoints (m).
SEED0_FIRST = "(1.09569, -1.84171) m"
SEED5_FIRST = "(2.44002, 2.46353) m"


def bounds_folder(folder: Path, seed: int = 0, payload: float = 3.0, record: bool = True) -> Path:
    """A bounds run's output folder holding scenario 1's plan (five 1 s legs at rest): its
    record (``key``: seed ``seed``'s scenario 1's waypoints, ``payload``) when ``record``,
    and the run's summary.json (``seed``, ``payload``)."""
    cache = folder / PLAN_FOLDER
    cache.mkdir(parents=True)
    times = np.linspace(0.0, 5.0, 11)
    arrays = {"times": times, "states": np.zeros((11, 7)), "inputs": np.zeros((10, 4))}
    np.savez(cache / PLAN_NAME.format(1), legs=np.ones(5), **arrays)
    if record:
        waypoints = [list(w) for w in generate(1, seed)[0].waypoints]
        key = {"waypoints": waypoints, "payload": payload, "tolerance": 0.01}
        (cache / "scenario-001-best.json").write_text(json.dumps({"key": key}))
    (folder / "summary.json").write_text(json.dumps({"seed": seed, "payload": payload}))
    return folder


def controller_for(folder: Path, seed: int, payload: float = 3.0):
    """The mpc of scenario 1 of ``seed`` on the thesis plant with ``plan=folder``."""
    config = RunConfig(
        controller="mpc",
        plant="thesis",
        payload=payload,
        controller_options=(("plan", str(folder)),),
    )
    robot = Robot().with_payload(payload)
    return make_scenario_controller(robot, generate(1, seed)[0], config, ThesisPlant(robot))


def test_a_plan_of_the_scenario_is_followed(tmp_path):
    controller = controller_for(bounds_folder(tmp_path), seed=0)
    assert controller._plan is not None and len(controller._plan.arrivals) == 5


def test_a_plan_of_another_seeds_scenario_is_refused_naming_the_waypoint(tmp_path):
    folder = bounds_folder(tmp_path)
    with pytest.raises(ParameterError) as error:
        controller_for(folder, seed=5)
    plan, record = folder / PLAN_FOLDER / PLAN_NAME.format(1), folder / PLAN_FOLDER
    assert str(error.value) == (
        f"plan {plan} was made for other waypoints than the route's (the scenario's): "
        f"waypoint 1 is {SEED0_FIRST} in {record / 'scenario-001-best.json'}, "
        f"{SEED5_FIRST} on the route: a bounds run of the same seed and payload makes the "
        "matching plans"
    )


def test_a_plan_of_another_payload_is_refused(tmp_path):
    with pytest.raises(ParameterError, match=r"made for a payload of 3 kg \(.*scenario-001-best"):
        controller_for(bounds_folder(tmp_path), seed=0, payload=2.5)
    with pytest.raises(ParameterError, match=r"the robot carries 2\.5 kg"):
        controller_for(tmp_path, seed=0, payload=2.5)


def test_a_plan_without_its_record_is_taken_as_it_is(tmp_path):
    """Only the bounds tool's record beside the plan says what it was made for (the
    folder's summary.json names a seed, and turning that into waypoints is the scenario
    generator's, above the controllers)."""
    folder = bounds_folder(tmp_path, seed=0, record=False)
    assert plan_problem(folder / PLAN_FOLDER / PLAN_NAME.format(1)) is None
    assert controller_for(folder, seed=5)._plan is not None


def test_a_record_of_other_waypoint_count_is_refused(tmp_path):
    folder = bounds_folder(tmp_path)
    record = folder / PLAN_FOLDER / "scenario-001-best.json"
    data = json.loads(record.read_text())
    data["key"]["waypoints"] = data["key"]["waypoints"][:4]
    record.write_text(json.dumps(data))
    with pytest.raises(
        ParameterError, match=r"was made for 4 waypoints \(.*\), the route .* has 5"
    ):
        controller_for(folder, seed=0)


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("payload", float("nan"), r"made for a payload of nan kg"),
        ("waypoints", [[float("nan"), 0.0]] + [[0.0, 0.0]] * 4, r"waypoint 1 is \(nan, 0\) m"),
    ],
)
def test_a_record_holding_nan_is_refused(tmp_path, field, value, match):
    # NaN compared False with the tolerances: the plan was followed unchecked
    folder = bounds_folder(tmp_path)
    record = folder / PLAN_FOLDER / "scenario-001-best.json"
    data = json.loads(record.read_text())
    data["key"][field] = value
    record.write_text(json.dumps(data))
    with pytest.raises(ParameterError, match=match):
        controller_for(folder, seed=0)


def test_the_scenario_tool_refuses_another_seeds_plan_in_one_line(tmp_path, capsys):
    from ddwmmr.cli.scenarios import main

    folder, out = bounds_folder(tmp_path / "bounds"), tmp_path / "out"
    args = ["--controller", "mpc", "--n", "1", "--seed", "5", "--jobs", "1", "--no-progress"]
    assert main([*args, "--option", f"plan={folder}", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: plan {folder / PLAN_FOLDER / PLAN_NAME.format(1)} was made")
    assert SEED5_FIRST in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


def test_the_scenario_tool_follows_a_plan_of_its_own_seed(tmp_path):
    """Seed 5's plan in a seed-5 run passes the check made before the batch."""
    from ddwmmr.cli.scenarios import main

    folder, out = bounds_folder(tmp_path / "bounds", seed=5), tmp_path / "out"
    args = ["--controller", "mpc", "--n", "1", "--seed", "5", "--jobs", "1", "--no-progress"]
    assert (
        main([*args, "--time-limit", "0.1", "--option", f"plan={folder}", "--out", str(out)]) == 0
    )
    assert (out / "scenarios.csv").exists()
