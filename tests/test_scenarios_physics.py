"""The thesis protocol on the MuJoCo plant: same loop, same controllers, physics judged."""

import math

import pytest

from ddwmmr import ParameterError, Robot
from ddwmmr.plants import MujocoPlant, ThesisPlant
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.scenarios.protocol import make_scenario_plant

SCENARIO = generate(2, 0)[1]  # 25 s on the thesis plant


@pytest.mark.parametrize("controller", ["thesis", "qp"])
def test_one_scenario_on_the_physics_plant(controller):
    on_thesis = run_scenario(SCENARIO, RunConfig(controller=controller)).metrics
    physics = run_scenario(SCENARIO, RunConfig(controller=controller, plant="mujoco")).metrics
    assert physics["success"], physics["reason"]
    assert physics["min_stability"] > 1.0
    # Same base damping and the same controller: the times agree to within a few seconds
    # (physics adds servo lag, contact and motor limits).
    assert abs(physics["time_s"] - on_thesis["time_s"]) < 8.0


def test_scenario_physics_plant_carries_the_thesis_damping():
    plant = make_scenario_plant(Robot().with_payload(3.0), RunConfig(plant="mujoco"))
    assert isinstance(plant, MujocoPlant)
    assert plant.base_damping == (15.0, 4.0)
    envelope = plant.velocity_envelope()
    robot = plant.robot
    force = robot.wheel_torque_limit / robot.wheel_radius  # per wheel (N)
    assert envelope["max_base_speed"] == pytest.approx(0.8 * 2 * force / 15.0)
    assert envelope["max_yaw_rate"] == pytest.approx(0.8 * 2 * force * 0.175 / 4.0)
    stretched = ThesisPlant(robot).inertia(0.0, 0.0)
    assert envelope["max_yaw_acceleration"] == pytest.approx(0.8 * 2 * force * 0.175 / stretched)
    assert MujocoPlant(robot).velocity_envelope() is None  # no damping, no drag envelope


@pytest.mark.parametrize("bad", [(1.0,), (-1.0, 2.0), (1.0, math.nan), "x"])
def test_base_damping_is_validated(bad):
    with pytest.raises(ParameterError, match="base_damping"):
        MujocoPlant(Robot(), base_damping=bad)


def test_thesis_controller_still_refuses_the_kinematic_plant():
    with pytest.raises(ParameterError, match="thesis or mujoco"):
        RunConfig(controller="thesis", plant="kinematic")
