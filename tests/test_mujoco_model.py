"""The MuJoCo model generated from a Robot: masses, lengths, inertia, supports, bad input."""

import math

import mujoco
import numpy as np
import pytest

from ddwmmr import ParameterError, Robot
from ddwmmr.plants.mujoco import EngineOptions, build_model, mjcf, support_polygon, supports
from ddwmmr.plants.mujoco.model import CASTER_RADIUS, WHEEL_PRELOAD_DEPTH, convex_hull
from ddwmmr.plants.thesis import ThesisPlant

ROBOTS = [
    Robot(),
    Robot().with_payload(3.0),
    Robot(L1=0.5, L2=0.2, link_masses=(2.0, 0.5), payload=0.0, base_mass=20.0, base_inertia=1.2),
]


def body_id(model, name: str) -> int:
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)


def posed(model, q) -> mujoco.MjData:
    """Data with the base at (x, y, heading) on the floor and the arm at (th1, th2)."""
    data = mujoco.MjData(model)
    x, y, phi, th1, th2 = q
    data.qpos[0:3] = (x, y, 0.1)
    data.qpos[3:7] = (math.cos(phi / 2), 0.0, 0.0, math.sin(phi / 2))
    data.qpos[model.joint("shoulder").qposadr[0]] = th1
    data.qpos[model.joint("elbow").qposadr[0]] = th2
    mujoco.mj_forward(model, data)
    return data


@pytest.mark.parametrize("robot", ROBOTS)
def test_masses_match_the_robot(robot):
    model = build_model(robot)
    mass = {name: model.body_mass[body_id(model, name)] for name in ("base", "link1", "link2")}
    wheels = [model.body_mass[body_id(model, n)] for n in ("wheel_left", "wheel_right")]
    assert wheels == pytest.approx([robot.wheel_mass] * 2, abs=1e-12)
    assert mass["base"] + sum(wheels) == pytest.approx(robot.base_mass, abs=1e-12)
    assert mass["link1"] == pytest.approx(robot.link_masses[0], abs=1e-12)
    # the payload is a point mass at the end effector, folded into link 2's inertial
    assert mass["link2"] == pytest.approx(robot.link_masses[1] + robot.payload, abs=1e-12)
    total = robot.base_mass + sum(robot.link_masses) + robot.payload
    assert float(np.sum(model.body_mass)) == pytest.approx(total, abs=1e-9)


@pytest.mark.parametrize("robot", ROBOTS)
def test_end_effector_and_link_lengths_follow_forward_kinematics(robot, rng):
    model = build_model(robot)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "end_effector")
    for _ in range(5):
        q = np.array([*rng.uniform(-2, 2, 2), *rng.uniform(-3, 3, 3)])
        data = posed(model, q)
        xe, ye, _ = robot.fk(q)
        assert data.site_xpos[site][:2] == pytest.approx([xe, ye], abs=1e-9)
        elbow = data.xpos[body_id(model, "link2")]
        shoulder = data.xpos[body_id(model, "link1")]
        assert np.linalg.norm(elbow - shoulder) == pytest.approx(robot.L1, abs=1e-12)
        assert shoulder[:2] == pytest.approx(q[:2], abs=1e-12)  # arm at the axle midpoint
        # the base frame sits on the floor (its damping acts there): the arm at arm_height
        assert shoulder[2] - data.xpos[body_id(model, "base")][2] == pytest.approx(
            robot.arm_height, abs=1e-12
        )


@pytest.mark.parametrize("robot", ROBOTS)
def test_centre_of_mass_matches_the_stability_model(robot, rng):
    """The horizontal centre of mass MuJoCo computes is the one S is built on."""
    model = build_model(robot)
    for _ in range(5):
        q = np.array([0.0, 0.0, 0.0, *rng.uniform(-3, 3, 2)])
        data = posed(model, q)
        com = data.subtree_com[body_id(model, "base")][:2]
        assert com == pytest.approx(robot.centre_of_mass(q), abs=1e-12)


@pytest.mark.parametrize("robot", ROBOTS)
def test_yaw_inertia_is_the_thesis_plants(robot, rng):
    """Whole-robot yaw inertia about the axle midpoint against ThesisPlant.inertia (links as
    rods, payload a point mass, base + wheels = base_inertia): an independent formula."""
    model = build_model(robot)
    for _ in range(4):
        th1, th2 = rng.uniform(-3, 3, 2)
        data = posed(model, (0.3, -0.2, 0.7, th1, th2))
        centre = data.xpos[body_id(model, "base")]
        total = 0.0
        for b in range(1, model.nbody):
            rotation = data.ximat[b].reshape(3, 3)
            inertia = rotation @ np.diag(model.body_inertia[b]) @ rotation.T
            offset = data.xipos[b][:2] - centre[:2]
            total += inertia[2, 2] + model.body_mass[b] * float(offset @ offset)
        assert total == pytest.approx(ThesisPlant(robot).inertia(th1, th2), rel=1e-9)


@pytest.mark.parametrize("robot", ROBOTS)
def test_support_polygon_is_the_footprint(robot):
    model = build_model(robot)
    data = posed(model, (0.0, 0.0, 0.0, 0.0, 0.0))
    base_z = data.xpos[body_id(model, "base")][2]
    lowest, points = {}, []
    for support in supports(robot):
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, support.name)
        assert model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_SPHERE
        centre = data.geom_xpos[geom]
        lowest[support.name] = centre[2] - model.geom_size[geom][0]
        assert centre[:2] == pytest.approx(support.point, abs=1e-12)
        points.append(centre[:2])
    # the casters touch the floor plane when the base frame is on it, the wheels (their
    # tyres at the nominal deflection) reach WHEEL_PRELOAD_DEPTH below it
    for name, z in lowest.items():
        expected = -WHEEL_PRELOAD_DEPTH if name.startswith("wheel") else 0.0
        assert z - base_z == pytest.approx(expected, abs=1e-12)
    hl, hw = robot.base_length / 2, robot.base_width / 2
    corners = sorted([(hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw)])
    compiled = sorted(tuple(p) for p in convex_hull(points).tolist())  # from the model
    assert np.array(compiled) == pytest.approx(np.array(corners), abs=1e-12)
    assert sorted(tuple(p) for p in support_polygon(robot).tolist()) == corners


def test_casters_are_frictionless_and_the_wheels_grip():
    model = build_model(Robot(), EngineOptions(friction=0.8))
    for support in supports(Robot()):
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, support.name)
        if support.kind == "caster":
            assert model.geom_condim[geom] == 1 and model.geom_priority[geom] == 1
            assert model.geom_size[geom][0] == CASTER_RADIUS
        else:
            assert model.geom_condim[geom] == 3
            assert model.geom_friction[geom][0] == 0.8  # MuJoCo uses the larger of the two
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    assert model.geom_friction[floor][0] == 0.8


def test_motor_limits_and_options_reach_the_model():
    robot = Robot(wheel_torque_limit=3.5, joint_torque_limits=(12.0, 7.0))
    model = build_model(robot, EngineOptions(timestep=0.004, contact_time_constant=0.02))
    limits = [tuple(model.actuator_forcerange[i]) for i in range(model.nu)]
    assert limits == [(-3.5, 3.5), (-3.5, 3.5), (-12.0, 12.0), (-7.0, 7.0)]
    assert model.opt.timestep == 0.004
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST


def test_custom_casters_define_the_polygon():
    robot = Robot(caster_positions=[(0.3, 0.0), (-0.3, 0.0)])
    hull = support_polygon(robot)
    assert {tuple(p) for p in hull.tolist()} == {
        (0.3, 0.0),
        (0.0, 0.175),
        (-0.3, 0.0),
        (0.0, -0.175),
    }
    assert [s.name for s in supports(robot)][2:] == ["caster_1", "caster_2"]
    build_model(robot)


def test_convex_hull_drops_inner_and_edge_points():
    points = [(0, 0), (2, 0), (2, 2), (0, 2), (1, 1), (1, 0), (0, 1)]
    assert convex_hull(points).tolist() == [[0, 0], [2, 0], [2, 2], [0, 2]]


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"link_masses": (0.0, 1.0)}, "link_masses[1] must be > 0 for the MuJoCo plant"),
        ({"link_masses": (1.0, 0.0), "payload": 0.0}, "link_masses[2] must be > 0"),
        ({"caster_positions": [(0.2, 0.0)]}, "caster_positions: the base centre must lie"),
        ({"base_inertia": 0.01}, "base_inertia must be >"),
    ],
)
def test_robots_mujoco_cannot_build_give_one_line(options, message):
    with pytest.raises(ParameterError) as info:
        build_model(Robot(**options))
    assert message in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"wheel_radius": 0.0}, "wheel_radius must be in [1e-06, 1000] m (got 0)"),
        ({"base_mass": 0.0}, "base_mass must be in (0, 100000] kg (got 0)"),
        ({"wheel_mass": 6.0}, "wheel_mass must be < base_mass / 2"),
        (
            {"joint_torque_limits": (5.0, -1.0)},
            "joint_torque_limits[2] must be in [1e-06, 1e+06] N m (got -1)",
        ),
        (
            {"caster_positions": []},
            "caster_positions must be a non-empty list of (x, y) pairs in m (got [])",
        ),
        ({"arm_height": float("nan")}, "arm_height must be a finite number"),
    ],
)
def test_robot_validates_the_physical_fields(options, message):
    with pytest.raises(ParameterError) as info:
        Robot(**options)
    assert message in str(info.value)


def test_engine_options_are_validated():
    with pytest.raises(ParameterError, match="contact_time_constant must be >= 2 timesteps"):
        EngineOptions(timestep=0.01, contact_time_constant=0.01)
    with pytest.raises(ParameterError, match="cone must be one of"):
        EngineOptions(cone="round")
    with pytest.raises(ParameterError, match="timestep must be > 0"):
        EngineOptions(timestep=0.0)


def test_the_model_is_generated_not_kept():
    """Changing the robot changes the MJCF: nothing is cached or hand-kept."""
    assert mjcf(Robot()) != mjcf(Robot(L1=0.4))
    assert mjcf(Robot()) == mjcf(Robot())


def test_mujoco_builds_a_robot_with_a_tiny_track():
    """Raising the base's roll and pitch inertia to the triangle bound was rounded below
    it for a 1 mm track, and MuJoCo refused the model ('A + B >= C')."""
    from ddwmmr.plants.mujoco.model import _base_inertia_diagonal

    robot = Robot(track_width=0.001)
    ixx, iyy, izz = _base_inertia_diagonal(robot)
    assert ixx + iyy >= izz and izz == pytest.approx(0.49749, abs=1e-5)
    assert build_model(robot).nbody > 1


def test_a_wheel_heavier_in_yaw_than_the_base_names_the_parameters():
    with pytest.raises(ParameterError, match=r"base_inertia must be > the wheels' own yaw"):
        build_model(Robot(wheel_radius=10.0))
