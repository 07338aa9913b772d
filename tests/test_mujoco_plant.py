"""MujocoPlant: the plant interface, measured state, command interfaces, force readout."""

import math

import mujoco
import numpy as np
import pytest

import ddwmmr.plants
from ddwmmr import ParameterError, Robot
from ddwmmr.commands import WheelForces
from ddwmmr.plants.base import Observation, PlantDivergedError
from ddwmmr.plants.mujoco import MujocoPlant
from ddwmmr.plants.mujoco.plant import (
    LIFT_TIME_S,
    TIP_TILT_RAD,
    UNLOADED_FRACTION,
    TipDetector,
    tip_time_s,
)

DT = 0.02
ROBOT = Robot().with_payload(3.0)
RNG_TILT = np.random.default_rng(3)


def fresh(q0=(0.0, 0.0, 0.0, -0.3, 0.6), robot=ROBOT, **engine) -> MujocoPlant:
    plant = MujocoPlant(robot, **engine)
    plant.reset(np.array(q0, dtype=float), DT)
    return plant


def hold(plant: MujocoPlant, command, seconds: float, t0: float = 0.0) -> float:
    steps = round(seconds / DT)
    for k in range(steps):
        plant.step(t0 + k * DT, command, DT)
    return t0 + steps * DT


def test_exported_and_shaped_like_a_plant():
    assert ddwmmr.plants.MujocoPlant is MujocoPlant
    plant = fresh()
    assert plant.name == "mujoco"
    assert set(plant.interfaces) == {"velocity", "force"}
    assert plant.robot is ROBOT
    assert len(plant.extra_values()) == len(plant.extra_columns)
    assert plant.extra_columns[0] == "min_support_force_n"
    assert "support_force_caster_back_right_n" in plant.extra_columns
    for name in ("physics_stability", "base_tilt_rad", "wheel_slip_m_s", "min_edge_load_n"):
        assert name in plant.extra_columns


def test_reset_places_the_robot_at_rest_at_q0():
    q0 = (1.5, -0.7, 2.9, 1.1, -0.4)
    observation = fresh(q0).observe()
    assert isinstance(observation, Observation)
    assert observation.q == pytest.approx(q0, abs=1e-12)
    assert (observation.v, observation.w) == (0.0, 0.0)


@pytest.mark.parametrize("pose", [(-0.3, 0.6), (1.0, 1.6), (math.pi / 2, 0.3), (2.5, -1.0)])
def test_floor_carries_the_weight_and_the_centre_of_pressure_gives_s(pose):
    """At rest: the normal forces sum to the weight and their centre of pressure is the
    centre of mass, so S_phys equals the kinematic S (docs/theory.md, "Tip-over stability")."""
    plant = fresh((0.4, 0.2, 0.9, *pose))
    values = dict(zip(plant.extra_columns, plant.extra_values()))
    forces = [values[f"support_force_{s.name}_n"] for s in plant.supports]
    assert sum(forces) == pytest.approx(plant.weight_n, rel=1e-4)
    assert values["min_support_force_n"] == min(forces)
    s = ROBOT.stability([0, 0, 0, *pose])[2]
    # the base leans into its compliant tyres (3.3 mrad at most here), which moves the centre of
    # mass by up to arm_height x tilt (1 mm) towards the loaded edge: 0.4 % of S here
    assert values["physics_stability"] == pytest.approx(s, rel=5e-3)
    assert values["base_tilt_rad"] < 4e-3
    assert values["wheel_slip_m_s"] < 1e-6


@pytest.mark.parametrize("payload", [1.0, 2.0, 2.8, 2.95])
def test_load_on_the_far_side_follows_statics(payload):
    """Arm stretched to the left: the supports on the right carry W (1 - 1/S) / 2 (moments
    about the left edge), which goes to zero as S goes to 1."""
    robot = Robot().with_payload(payload)
    plant = fresh((0.0, 0.0, 0.0, math.pi / 2, 0.0), robot=robot)
    values = dict(zip(plant.extra_columns, plant.extra_values()))
    right = sum(values[f"support_force_{s.name}_n"] for s in plant.supports if s.point[1] < 0)
    s = robot.stability([0, 0, 0, math.pi / 2, 0.0])[2]
    # The base leans into its tyres by the measured tilt, which moves the centre of mass
    # (at most arm_height up) by height x tilt towards the loaded edge: that much less on the
    # far side, W h tilt / width (0.3 N at 2.95 kg), plus 0.05 N of the contacts' own.
    lean = plant.weight_n * robot.arm_height * plant.base_tilt() / robot.base_width
    statics = 0.5 * plant.weight_n * (1.0 - 1.0 / s)
    assert statics - lean - 0.05 <= right <= statics + 0.05
    assert values["min_edge_load_n"] == pytest.approx(right, abs=1e-9)


def test_velocity_commands_drive_the_base_and_the_arm():
    plant = fresh()
    hold(plant, np.array([0.3, 0.0, 0.2, -0.1]), 2.0)
    obs = plant.observe()
    assert obs.v == pytest.approx(0.3, abs=3e-3)
    # the swinging arm's reaction turns the base a little through the servos' compliance
    assert abs(obs.w) < 0.05
    assert abs(obs.q[2]) < 0.05
    # servo lag: the travelled distance falls short of 0.6 m by about v times the lag
    assert 0.57 < obs.q[0] < 0.6
    assert obs.q[3] == pytest.approx(-0.3 + 0.4, abs=0.01)
    assert obs.q[4] == pytest.approx(0.6 - 0.2, abs=0.01)


def test_turning_in_place_keeps_a_continuous_heading():
    plant = fresh(q0=(0.0, 0.0, 3.0, -0.3, 0.6))
    hold(plant, np.array([0.0, 1.0, 0.0, 0.0]), 4.0)
    obs = plant.observe()
    assert obs.w == pytest.approx(1.0, abs=0.02)
    # beyond pi, not wrapped; short of 4 rad by the spin-up under the torque limit
    # (yaw inertia ~2.4 kg m^2 against 2 x 20.5 N x 0.175 m: ~0.2 rad)
    assert 6.75 < obs.q[2] < 7.0
    # the offset arm needs a centripetal force the soft friction gives with a little creep
    assert math.hypot(obs.q[0], obs.q[1]) < 0.02


def test_wheel_torque_limit_saturates_the_acceleration():
    """From rest, a large speed step: the base accelerates at most at the motors' limit
    (2 F / m with F = torque / r, wheel inertia included)."""
    robot = ROBOT
    plant = fresh()
    hold(plant, np.array([1.2, 0.0, 0.0, 0.0]), 0.2)
    mass = robot.base_mass + sum(robot.link_masses) + robot.payload
    axle_inertia = 0.5 * robot.wheel_mass * robot.wheel_radius**2
    effective = mass + 2.0 * axle_inertia / robot.wheel_radius**2
    bound = 2.0 * robot.wheel_torque_limit / robot.wheel_radius / effective
    assert plant.observe().v == pytest.approx(bound * 0.2, rel=0.02)
    assert plant.observe().v < 1.2


def test_limit_applies_the_robots_speed_limits():
    plant = fresh()
    applied, saturated = plant.limit(plant.observe().q, np.array([5.0, 0.0, 3.0, 0.1]))
    assert saturated
    assert applied[0] == pytest.approx(ROBOT.wheel_speed_limit * ROBOT.wheel_radius)
    assert applied[2:] == pytest.approx([ROBOT.joint_speed_limit, 0.1])


def test_force_interface_applies_wheel_torques_and_arm_targets():
    robot = ROBOT
    plant = fresh()
    force = 5.0
    hold(plant, WheelForces(force, force, -0.3, 0.6), 0.5)  # arm held where it is
    obs = plant.observe()
    mass = robot.base_mass + sum(robot.link_masses) + robot.payload
    effective = mass + robot.wheel_mass  # two wheels' axle inertia m r^2 / 2, over r^2
    assert obs.v == pytest.approx(2.0 * force / effective * 0.5, rel=0.01)
    # the arm moves to its targets at joint_speed_limit (largest error 0.6 rad: 0.3 s)
    hold(plant, WheelForces(0.0, 0.0, 0.3, 0.2), 0.2, t0=0.5)
    assert plant.observe().q[3:] == pytest.approx([-0.3 + 0.4, 0.6 - 0.4 * 2 / 3], abs=0.02)
    hold(plant, WheelForces(0.0, 0.0, 0.3, 0.2), 0.3, t0=0.7)
    assert plant.observe().q[3:] == pytest.approx([0.3, 0.2], abs=0.01)
    # turning: opposite forces give a yaw rate, no forward speed
    plant = fresh()
    hold(plant, WheelForces(-force, force, -0.3, 0.6), 0.5)
    obs = plant.observe()
    assert obs.w > 0.2 and abs(obs.v) < 0.01
    # the velocity interface works again after force commands
    hold(plant, np.array([0.0, 0.0, 0.0, 0.0]), 1.0)
    assert abs(plant.observe().w) < 0.01


def test_runs_are_deterministic():
    def run():
        plant = fresh()
        rows = []
        for k in range(60):
            u = np.array([0.3 * math.sin(0.1 * k), 0.5, 0.2, -0.3])
            plant.step(k * DT, u, DT)
            rows.append([*plant.observe().q, *plant.extra_values()])
        return np.array(rows)

    assert np.array_equal(run(), run())


def test_dt_must_be_a_multiple_of_the_engine_step():
    plant = MujocoPlant(ROBOT)
    with pytest.raises(ParameterError) as info:
        plant.reset(np.zeros(5), 0.005)
    message = str(info.value)
    assert message.startswith("dt must be a whole multiple of the MuJoCo timestep 0.002 s")
    assert "0.002, 0.004, 0.006" in message and "0.005" in message
    plant.reset(np.zeros(5), 0.004)
    with pytest.raises(ParameterError, match="dt must be a whole multiple"):
        plant.step(0.0, np.zeros(4), 0.003)
    MujocoPlant(ROBOT, timestep=0.005, contact_time_constant=0.01).reset(np.zeros(5), 0.005)
    for text in ("abc", None, "0.004", True):  # no number: the message naming the steps
        with pytest.raises(ParameterError, match=r"whole multiple .*0\.002, 0\.004.* \(got"):
            plant.reset(np.zeros(5), text)


def test_bad_start_configurations_are_parameter_errors():
    plant = MujocoPlant(ROBOT)
    with pytest.raises(ParameterError, match="q0 must be 5 finite numbers"):
        plant.reset(np.array([0.0, 0.0, np.nan, 0.0, 0.0]), DT)
    with pytest.raises(
        ParameterError, match=r"^q0: joint th2 = 4 rad is outside joint_limits\[2\]"
    ):
        plant.reset(np.array([0.0, 0.0, 0.0, 0.0, 4.0]), DT)


def test_a_diverged_engine_state_names_the_step(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    plant = fresh()
    hold(plant, np.zeros(4), 3 * DT)
    plant.data.qvel[0] = 1e20  # far beyond what MuJoCo accepts: it flags a bad state
    with pytest.raises(PlantDivergedError, match=r"in control step 4 \(t = 0.06 to 0.08 s\)"):
        plant.step(3 * DT, np.zeros(4), DT)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()  # the warning went to logging


LIGHT = Robot(base_mass=1e-3, wheel_mass=1e-4, link_masses=(1e-3, 1e-3), payload=0.0)


def test_a_robot_too_light_for_the_timestep_is_refused_at_reset(capsys):
    """On tyres as stiff as the default robot's (not scaled to its mass)."""
    with pytest.raises(ParameterError, match=r"^MuJoCo cannot settle this robot at timestep ") as e:
        fresh(robot=LIGHT, tyre_stiffness=5e4)
    assert str(e.value).endswith(
        "give it heavier parts, or a smaller MujocoPlant(robot, timestep=...) in "
        "[1e-05, 0.01] s (track: --plant-option)"
    )
    assert capsys.readouterr().err == ""  # the engine's own warning stays in logging
    # the message's remedy works: a shorter engine step settles the same robot
    settled = fresh(robot=LIGHT, timestep=5e-4, tyre_stiffness=5e4)
    assert settled.observe().q[3:] == pytest.approx((-0.3, 0.6))


def test_cli_refuses_a_robot_too_light_for_the_engine_in_one_line(tmp_path, capsys):
    from ddwmmr.cli.track import main

    robot = tmp_path / "light.toml"
    robot.write_text(
        "base_mass = 1e-3\nwheel_mass = 1e-4\nlink_masses = [1e-3, 1e-3]\npayload = 0.0\n"
    )
    argv = ["--method", "clrrmc-ts", "--traj", "ellipse", "--robot", str(robot)]
    out = tmp_path / "run"
    stiff = ["--plant-option", "tyre_stiffness=50000"]  # the default robot's tyres
    status = main([*argv, "--plant", "mujoco", *stiff, "--duration", "0.2", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2
    assert len(err) == 1 and "base_mass 0.001 kg" in err[0] and "timestep" in err[0]
    assert not out.exists()


def test_non_finite_commands_are_refused():
    plant = fresh()
    with pytest.raises(ParameterError, match=r"^command must be "):
        plant.step(0.0, np.array([np.nan, 0.0, 0.0, 0.0]), DT)
    with pytest.raises(ParameterError, match=r"^command must be "):
        plant.step(0.0, WheelForces(np.inf, 0.0, 0.0, 0.0), DT)


def test_slip_is_measured_on_a_slippery_floor():
    grip = fresh()
    hold(grip, np.array([1.0, 0.0, 0.0, 0.0]), 0.3)
    ice = fresh(friction=0.02)
    hold(ice, np.array([1.0, 0.0, 0.0, 0.0]), 0.3)
    slip = grip.extra_columns.index("wheel_slip_m_s")
    assert grip.extra_values()[slip] < 0.01
    assert ice.extra_values()[slip] > 0.5  # the wheels spin, the base barely moves
    assert ice.observe().v < 0.1


def test_tipping_criterion_on_recorded_series():
    weight = 100.0
    unloaded = 0.5 * UNLOADED_FRACTION * weight
    t = np.arange(0.0, 1.0, DT)
    tilt = 1e-3 * t  # pivoting: the tilt grows 2e-5 rad per sample, 1e-4 per 0.1 s
    needed = math.ceil(LIFT_TIME_S / DT)
    load = np.full_like(t, 10.0)
    load[10 : 10 + needed - 1] = unloaded  # one sample too short
    assert tip_time_s(t, load, tilt, weight) is None
    load[10 : 10 + needed] = unloaded
    assert tip_time_s(t, load, tilt, weight) == pytest.approx(t[10 + needed - 1])
    assert tip_time_s(t, load, 0.5 * tilt, weight) is None  # tilting, but too little
    tilt[5] = 1.01 * TIP_TILT_RAD
    assert tip_time_s(t, load, tilt, weight) == pytest.approx(t[5])


def test_summary_of_a_stable_and_of_a_tipping_hold():
    stable = fresh((0.0, 0.0, 0.0, math.pi / 2, 0.0), robot=Robot().with_payload(2.5))
    tipping = fresh((0.0, 0.0, 0.0, math.pi / 2, 0.0), robot=Robot().with_payload(3.5))
    for plant in (stable, tipping):
        rows = []
        for k in range(40):
            rows.append([k * DT, *plant.extra_values()])
            plant.step(k * DT, np.zeros(4), DT)
        data = np.array(rows)
        plant.result = plant.summarize(
            {c: data[:, i] for i, c in enumerate(("t", *plant.extra_columns))}
        )
    assert not stable.result["tipped"] and not stable.result["support_lost"]
    assert stable.result["tip_time_s"] is None
    assert stable.result["min_edge_load_n"] > 5.0
    assert tipping.result["tipped"] and tipping.result["support_lost"]
    assert tipping.result["tip_time_s"] == pytest.approx(LIFT_TIME_S - DT, abs=1e-9)
    assert tipping.result["min_edge_load_n"] == 0.0
    assert tipping.result["max_base_tilt_rad"] > 0.01
    # the plant's own verdict during the run is the recorded series' verdict
    assert stable.tip_time is None and stable.unloaded_time_s == 0.0
    assert tipping.tip_time == pytest.approx(tipping.result["tip_time_s"], abs=1e-12)
    assert tipping.unloaded_time_s == pytest.approx(tipping.result["unloaded_time_s"], abs=1e-9)
    for key in ("min_support_force_n", "max_wheel_slip_m_s", "min_physics_stability"):
        assert math.isfinite(tipping.result[key])


def test_torque_use_reaches_one_when_a_motor_saturates():
    """Asking 1 m/s from rest saturates the wheel motors (2 N m each); holding still does
    not use the motors beyond the arm's static load."""
    plant = fresh()
    use = plant.extra_columns.index("torque_use")
    hold(plant, np.zeros(4), 0.1)
    assert plant.extra_values()[use] < 0.5
    plant.step(0.0, np.array([1.0, 0.0, 0.0, 0.0]), DT)
    assert plant.extra_values()[use] == pytest.approx(1.0, abs=1e-9)


def test_a_lifted_edge_tips_only_while_the_base_pivots_on():
    """Chatter (an edge unloaded, the tilt flat) and rocking (up, then back) are not
    tipping; a tilt growing all the while an edge is unloaded is, after LIFT_TIME_S."""
    weight, needed = 100.0, math.ceil(LIFT_TIME_S / DT)
    unloaded = 0.5 * UNLOADED_FRACTION * weight
    t = np.arange(0.0, 1.0, DT)
    load = np.full_like(t, 10.0)
    load[10 : 10 + 3 * needed] = unloaded
    flat = np.full_like(t, 3e-4)  # exactly flat: balanced on the edge, not pivoting
    assert tip_time_s(t, load, flat, weight) is None
    noisy = flat + RNG_TILT.normal(0.0, 1e-6, len(t))  # contact noise on a flat tilt
    assert tip_time_s(t, load, noisy, weight) is None
    wobble = flat.copy()
    wobble[10 : 10 + 3 * needed : 2] = 2.9e-4
    assert tip_time_s(t, load, wobble, weight) is None
    rocking = np.concatenate([np.linspace(0.0, 3e-3, 10 + needed // 2), np.full(len(t), 3e-3)])
    rocking = rocking[: len(t)].copy()
    rocking[10 + needed // 2 :] = np.linspace(3e-3, 0.0, len(t) - 10 - needed // 2)
    assert tip_time_s(t, load, rocking, weight) is None
    growing = np.linspace(6e-4, 0.05, len(t))
    assert tip_time_s(t, load, growing, weight) == pytest.approx(t[10 + needed - 1])
    detector = TipDetector(weight, DT)
    for k in range(len(t)):
        detector.update(t[k], load[k], flat[k])
    assert detector.tip_time is None
    assert detector.unloaded(unloaded) and not detector.unloaded(UNLOADED_FRACTION * weight)


def test_support_forces_match_a_contact_by_contact_readout():
    """The vectorised readout against MuJoCo's contacts one at a time, while moving."""
    plant = fresh()
    hold(plant, np.array([0.4, 0.6, 1.0, -1.0]), 0.5)
    model, data = plant.model, plant.data
    names = [s.name for s in plant.supports]
    origin = data.xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")][:2]
    c, s = math.cos(plant.observe().q[2]), math.sin(plant.observe().q[2])
    forces, moments, buffer = np.zeros(len(names)), np.zeros((len(names), 2)), np.zeros(6)
    for i in range(data.ncon):
        contact = data.contact[i]
        geoms = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in
                 (contact.geom1, contact.geom2)]  # fmt: skip
        touching = [names.index(g) for g in geoms if g in names]
        if not touching:
            continue
        mujoco.mj_contactForce(model, data, i, buffer)
        dx, dy = contact.pos[0] - origin[0], contact.pos[1] - origin[1]
        forces[touching[0]] += buffer[0]
        moments[touching[0]] += buffer[0] * np.array([c * dx + s * dy, -s * dx + c * dy])
    measured, points = plant.support_forces()
    assert data.ncon >= 4 and np.sum(forces) > 100.0
    np.testing.assert_allclose(measured, forces, rtol=0, atol=1e-9)
    loaded = forces > 1e-12
    np.testing.assert_allclose(points[loaded], moments[loaded] / forces[loaded, None], atol=1e-12)
    # the tip criterion's lean reading is the geometry's edge loads of those forces
    edge_loads = plant.geometry.edge_loads(forces)
    assert plant._min_edge_load() == pytest.approx(float(np.min(edge_loads)), abs=1e-9)


def test_the_lift_time_is_time_not_a_sample_count():
    """A detector made for 0.02 s samples and fed 0.002 s ones still needs 0.1 s of
    pivoting (not five samples), as when a run changes its step after the reset."""
    weight = 100.0
    detector = TipDetector(weight, 0.02)
    t = np.arange(0.0, 0.3, 0.002)
    for time, tilt in zip(t, 1e-3 + 1e-2 * t):
        if detector.update(float(time), 0.0, float(tilt)) is not None:
            break
    assert detector.tip_time == pytest.approx(LIFT_TIME_S - 0.02, abs=1e-9)
