"""The thesis protocol on the MuJoCo plant: same loop, same controllers, physics judged."""

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.plants import MujocoPlant, ThesisPlant
from ddwmmr.plants.mujoco import plant as mujoco_plant
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.scenarios.protocol import make_scenario_plant
from ddwmmr.scenarios.report import format_table, summarize

SCENARIO = generate(2, 0)[1]  # 25 s on the thesis plant


@pytest.mark.parametrize("controller", ["thesis", "qp"])
def test_one_scenario_on_the_physics_plant(controller):
    on_thesis = run_scenario(SCENARIO, RunConfig(controller=controller)).metrics
    physics = run_scenario(SCENARIO, RunConfig(controller=controller, plant="mujoco")).metrics
    assert physics["success"], physics["reason"]
    assert physics["min_stability"] > 1.0
    # judged by the contact forces too: it stayed up, and the time a lightly loaded
    # wheel spent off the floor is reported (the thesis plant has no contacts: NaN)
    assert 0.0 <= physics["unloaded_time_s"] < 0.5 * physics["time_s"]
    assert math.isnan(on_thesis["unloaded_time_s"])
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


def test_the_velocity_servos_feed_the_base_damping_forward():
    """With base damping a straight drive settles at the commanded speed: the wheel-speed
    targets lead by the damping force's wheel torque over the servo gain, so the wheels'
    rims turn at the commanded speed. (A proportional servo without the lead settled 2 %
    short, at 0.784 of 0.8 m/s.) The base itself goes slower by the tyres' creep under the
    traction they give (the contacts' slip, 3 mm/s here: a tyre's slip ratio of 0.4 %)."""
    robot = Robot().with_payload(3.0)
    q0 = np.array([0.0, 0.0, 0.0, *default_pose(robot)])
    damped = MujocoPlant(robot, base_damping=(15.0, 4.0))
    damped.reset(q0, 0.01)
    for k in range(300):
        damped.step(0.01 * k, np.array([0.8, 0.0, 0.0, 0.0]), 0.01)
    wheels = [damped.model.joint(n).dofadr[0] for n in ("wheel_left", "wheel_right")]
    rims = damped.data.qvel[wheels] * robot.wheel_radius
    assert rims == pytest.approx([0.8, 0.8], abs=1e-3)
    creep = damped.wheel_slip()
    assert creep < 5e-3
    assert damped.observe().v == pytest.approx(0.8 - creep, abs=1e-3)
    damped.reset(q0, 0.01)
    for k in range(300):  # turning in place: the couple of the yaw damping
        damped.step(0.01 * k, np.array([0.0, 1.0, 0.0, 0.0]), 0.01)
    # 0.85 without the lead; 0.978 with it, the rest the tyres' creep under the couple
    assert damped.observe().w == pytest.approx(1.0, abs=0.03)
    narrow = Robot(track_width=0.3).with_payload(3.0)  # wheels inside the 0.35 m footprint
    plant = MujocoPlant(narrow, base_damping=(15.0, 4.0))
    kv = float(plant.model.actuator_gainprm[0, 0])  # the wheel servo's gain (N m s/rad)
    r = narrow.wheel_radius
    left, right = plant._damping_lead(0.8, 0.0)  # each wheel pulls half of c1 v
    assert left == right == pytest.approx(0.5 * 15.0 * 0.8 * r / kv, rel=1e-12)
    left, right = plant._damping_lead(0.0, 1.0)  # the wheels' couple (lever track/2) of c2 w
    assert right == pytest.approx(-left) == pytest.approx(4.0 / 0.3 * r / kv, rel=1e-12)
    assert MujocoPlant(robot)._damping_lead(0.8, 1.0) == (0.0, 0.0)  # no damping, no lead


@pytest.mark.parametrize("bad", [(1.0,), (-1.0, 2.0), (1.0, math.nan), "x"])
def test_base_damping_is_validated(bad):
    with pytest.raises(ParameterError, match="base_damping"):
        MujocoPlant(Robot(), base_damping=bad)


@pytest.mark.parametrize("damping", [(0.0, 0.0), (0.0, 4.0), (15.0, 0.0)])
def test_a_zero_damping_has_no_velocity_envelope(damping):
    """base_damping accepts 0 per axis (no drag); the envelope divided by it
    (ZeroDivisionError). No drag on an axis: no top speed, as without damping."""
    assert MujocoPlant(Robot(), base_damping=damping).velocity_envelope() is None
    assert MujocoPlant(Robot(), base_damping=(15.0, 4.0)).velocity_envelope() is not None


def test_thesis_controller_still_refuses_the_kinematic_plant():
    with pytest.raises(ParameterError, match="thesis or mujoco"):
        RunConfig(controller="thesis", plant="kinematic")


def test_the_physics_plant_fails_a_run_that_tips_by_its_contact_forces(monkeypatch):
    """With a tilt threshold below the resting lean the plant says "tipped" at once:
    the protocol stops the run on the plant's word, whatever the formula's S says."""
    monkeypatch.setattr(mujoco_plant, "TIP_TILT_RAD", 0.0)
    outcome = run_scenario(SCENARIO, RunConfig(plant="mujoco"))
    metrics = outcome.metrics
    assert not metrics["success"] and metrics["reason"] == "tipped (physics)"
    assert metrics["sim_steps"] == 1 and metrics["min_stability"] > 1.3
    summary = summarize([outcome], wall_time_s=1.0)
    assert summary["tipped_physics"] == 1
    assert "Tipped over (physics)" in format_table(summary, "t")


def test_plants_without_physics_report_no_physics_verdict():
    outcome = run_scenario(generate(1, 0)[0], RunConfig(time_limit=1.0))
    summary = summarize([outcome], wall_time_s=1.0)
    assert summary["tipped_physics"] is None and summary["mean_unloaded_time_s"] is None
    assert "physics" not in format_table(summary, "t")
