"""Edge loads of the support polygon (model/support_loads.py): at rest against the static
margin S, in motion against the moment balance of the lumped masses from first principles,
the CasADi twin against the numeric one, and (tests below) against MuJoCo's contact forces."""

import math
import sys

import casadi as ca
import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.stability import BASE_CLEARANCE_M, GRAVITY_M_S2
from ddwmmr.model.support_loads import (
    EdgeLoadModel,
    SupportPolygon,
    support_points,
    support_polygon,
)

ROBOT = Robot().with_payload(3.0)
MODEL = EdgeLoadModel.from_robot(ROBOT)
RNG = np.random.default_rng(27)
RIGHT, FRONT, LEFT, BACK = range(4)


def _motions(count: int) -> np.ndarray:
    """Random (th1, th2, rate1, rate2, acc1, acc2, a_x, a_y, w, w_dot)."""
    scale = np.array([math.pi, math.pi, 2.0, 2.0, 20.0, 20.0, 3.0, 3.0, 1.5, 5.0])
    return RNG.uniform(-1.0, 1.0, (count, 10)) * scale


def _loads(model: EdgeLoadModel, m) -> list[float]:
    th1, th2, r1, r2, a1, a2, ax, ay, w, w_dot = (float(v) for v in m)
    return model.loads(th1, th2, (r1, r2), (a1, a2), (ax, ay), w, w_dot)


def test_the_default_polygon_is_the_footprint_with_its_depths():
    polygon = support_polygon(ROBOT)
    hl, hw = 0.5 * ROBOT.base_length, 0.5 * ROBOT.base_width
    assert polygon.vertices.tolist() == [[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]]
    assert polygon.depths.tolist() == [2 * hw, 2 * hl, 2 * hw, 2 * hl]
    # the wheels lie on the side edges: off the front and back edges, not off the sides
    off = polygon.off_edge(support_points(ROBOT))
    assert off[RIGHT].tolist() == [True, False, True, False, True, False]
    assert off[FRONT].tolist() == [True, True, False, False, True, True]


def test_at_rest_the_side_loads_are_the_static_margin_in_newtons():
    """Off each side edge the far side carries W (1 - 1/S_lat) / 2 (the physics plant's
    documented statics), the two sides the weight; front and back W (1 - 1/S_lon) / 2
    as the least load off them."""
    weight = MODEL.weight
    assert weight == pytest.approx(15.0 * GRAVITY_M_S2, rel=1e-15)
    for th1, th2 in RNG.uniform(-math.pi, math.pi, (200, 2)):
        q = [0.0, 0.0, 0.0, th1, th2]
        s_lon, s_lat, _ = ROBOT.stability(q)
        loads = MODEL.static_loads(th1, th2)
        x, y = ROBOT.centre_of_mass(q)
        light_side = LEFT if y > 0 else RIGHT  # the edge the centre of mass leans towards
        if s_lat < 10.0:
            assert loads[light_side] == pytest.approx(weight * (1 - 1 / s_lat) / 2, abs=1e-9)
        light_end = FRONT if x > 0 else BACK
        if s_lon < 10.0:
            assert loads[light_end] == pytest.approx(weight * (1 - 1 / s_lon) / 2, abs=1e-9)
        assert loads[LEFT] + loads[RIGHT] == pytest.approx(weight, rel=1e-12)
        assert loads[FRONT] + loads[BACK] == pytest.approx(weight, rel=1e-12)


def test_general_motion_at_rest_gives_the_static_loads():
    for th1, th2, *_ in _motions(20):
        still = MODEL.loads(th1, th2, (0.0, 0.0), (0.0, 0.0), (0.0, 0.0), 0.0, 0.0)
        assert still == pytest.approx(MODEL.static_loads(th1, th2), abs=1e-12)


def _masses(robot: Robot, th1: float, th2: float) -> list[tuple[float, np.ndarray]]:
    """(mass kg, base-frame position (x, y, z) m) of every lumped mass, from the robot."""
    m1, m2 = robot.link_masses
    elbow = np.array([robot.L1 * math.cos(th1), robot.L1 * math.sin(th1)])
    tip = elbow + robot.L2 * np.array([math.cos(th1 + th2), math.sin(th1 + th2)])
    h, t = robot.arm_height, 0.5 * robot.track_width
    box = BASE_CLEARANCE_M + robot.base_height / 2
    return [
        (robot.base_mass - 2 * robot.wheel_mass, np.array([0.0, 0.0, box])),
        (robot.wheel_mass, np.array([0.0, t, robot.wheel_radius])),
        (robot.wheel_mass, np.array([0.0, -t, robot.wheel_radius])),
        (m1, np.array([*(0.5 * elbow), h])),
        (m2, np.array([*(0.5 * (elbow + tip)), h])),
        (robot.payload, np.array([*tip, h])),
    ]  # fmt: skip


def _path(m: np.ndarray):
    """A motion through t = 0 with the state ``m``: base origin, heading and joints as
    quadratics in t, the base sliding sideways as the acceleration (a_x, a_y) says."""
    th1, th2, r1, r2, a1, a2, ax, ay, w, w_dot = m
    velocity = np.array([0.4, -0.3])  # base frame at t = 0: the base also slides sideways

    def state(t: float):
        heading = 0.2 + w * t + 0.5 * w_dot * t * t
        c0, s0 = math.cos(0.2), math.sin(0.2)
        rot0 = np.array([[c0, -s0], [s0, c0]])
        a_world = rot0 @ np.array([ax, ay])  # the origin's acceleration, held constant
        origin = rot0 @ velocity * t + 0.5 * a_world * t * t
        joints = (th1 + r1 * t + 0.5 * a1 * t * t, th2 + r2 * t + 0.5 * a2 * t * t)
        return origin, heading, joints

    return state


def _world_positions(state, t: float) -> list[tuple[float, np.ndarray]]:
    origin, heading, joints = state(t)
    c, s = math.cos(heading), math.sin(heading)
    out = []
    for mass, p in _masses(ROBOT, *joints):
        x, y = origin + np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])
        out.append((mass, np.array([x, y, p[2]])))
    return out


def test_loads_are_the_moment_balance_of_the_lumped_masses():
    """First principles: each mass's world acceleration by central differences of its
    path, then the floor's normal forces' moment about each edge line (on the floor) is
    ``u . sum r_i x m_i (a_i - g)`` (u the edge's direction, counter-clockwise): friction
    acts in the floor and has no moment about a line in it. Over the polygon's depth it
    is the edge load."""
    polygon = MODEL.polygon
    h = 1e-3
    gravity = np.array([0.0, 0.0, -GRAVITY_M_S2])
    for m in _motions(30):
        state = _path(m)
        before, now, after = (_world_positions(state, t) for t in (-h, 0.0, h))
        origin, heading, _ = state(0.0)
        c, s = math.cos(heading), math.sin(heading)
        expected = []
        for e in range(4):
            start = polygon.vertices[e]
            direction = polygon.vertices[(e + 1) % 4] - start
            direction = direction / np.linalg.norm(direction)
            point = origin + np.array([c * start[0] - s * start[1], s * start[0] + c * start[1]])
            u = np.array(
                [c * direction[0] - s * direction[1], s * direction[0] + c * direction[1], 0]
            )
            moment = 0.0
            for (mass, p0), (_, p1), (_, p2) in zip(before, now, after):
                acceleration = (p0 - 2 * p1 + p2) / (h * h)
                r = p1 - np.array([*point, 0.0])
                moment += u @ np.cross(r, mass * (acceleration - gravity))
            expected.append(moment / polygon.depths[e])
        # quadratic paths: central differences are exact up to rounding (and the
        # heading's rotation, whose error is O(h^2 w^4))
        assert _loads(MODEL, m) == pytest.approx(expected, abs=2e-5 * MODEL.weight)


def test_loads_of_motion_is_the_rolling_base():
    for th1, th2, r1, r2, a1, a2, v_dot, _, w, w_dot in _motions(20):
        v = 0.7
        rolling = MODEL.loads_of_motion(th1, th2, (r1, r2), (a1, a2), v, w, v_dot, w_dot)
        general = MODEL.loads(th1, th2, (r1, r2), (a1, a2), (v_dot, v * w), w, w_dot)
        assert rolling == pytest.approx(general, abs=1e-12)


def test_the_casadi_twin_is_the_same_formula():
    q, rates, accelerations = ca.SX.sym("q", 5), ca.SX.sym("r", 2), ca.SX.sym("a", 2)
    base, w, w_dot = ca.SX.sym("b", 2), ca.SX.sym("w"), ca.SX.sym("wd")
    loads = sym.edge_loads(ROBOT, q, rates, accelerations, base, w, w_dot)
    arguments = [q, rates, accelerations, base, w, w_dot]
    function = ca.Function("loads", arguments, [loads])
    jacobian = ca.Function("jacobian", arguments, [ca.jacobian(loads, ca.vertcat(*arguments))])
    for m in _motions(200):
        th1, th2, r1, r2, a1, a2, ax, ay, wz, wz_dot = m
        values = [[0.3, -0.2, 0.1, th1, th2], [r1, r2], [a1, a2], [ax, ay], wz, wz_dot]
        symbolic = np.array(function(*values)).ravel()
        assert np.max(np.abs(symbolic - _loads(MODEL, m))) <= 1e-12
    # derivatives against central differences of the numeric model
    m = _motions(1)[0]
    values = [[0.3, -0.2, 0.1, m[0], m[1]], m[2:4], m[4:6], m[6:8], m[8], m[9]]
    exact = np.array(jacobian(*values))
    step = 1e-6
    for index in range(10):  # th1, th2, rates, accelerations, a_x, a_y, w, w_dot
        plus, minus = m.copy(), m.copy()
        plus[index] += step
        minus[index] -= step
        numeric = (np.array(_loads(MODEL, plus)) - np.array(_loads(MODEL, minus))) / (2 * step)
        assert exact[:, 3 + index] == pytest.approx(numeric, abs=1e-5 * MODEL.weight)
    assert np.all(exact[:, :3] == 0.0)  # the base's place and heading do not enter


def test_a_caster_triangle_has_its_own_depths():
    points = [(0.0, 0.2), (0.0, -0.2), (0.3, 0.0), (-0.25, 0.1)]
    polygon = SupportPolygon.from_points(points)
    distances = polygon.distances(points)
    assert np.allclose(polygon.depths, distances.max(axis=0))
    assert np.all(distances >= -1e-12)
    # a point on a hull edge (not a vertex) is dropped from the hull but counts as on it
    on_edge = SupportPolygon.from_points([*points, (0.15, 0.1)])
    assert len(on_edge.vertices) == len(polygon.vertices)
    with pytest.raises(ValueError, match="span a polygon"):
        SupportPolygon.from_points([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)])


@pytest.mark.parametrize("length", [1e-6, 1e-3, 1e3])  # the allowed range's ends and between
def test_a_robot_of_any_allowed_size_has_the_scale_free_margin(length):
    """S is a ratio of lengths: a robot whose every length is ``length`` has the margin of
    the one whose every length is 1 m, down to the smallest allowed (its supports 5e-7 m
    from the centre: a fixed collinearity threshold took them for one line)."""
    keys = ("L1", "L2", "wheel_radius", "track_width", "base_length", "base_width")
    keys += ("base_height", "arm_height")
    small = Robot(**dict.fromkeys(keys, length))
    unit = Robot(**dict.fromkeys(keys, 1.0))
    for q in ([0.0, 0.0, 0.0, 0.5, -0.7], [1.0, 2.0, 0.3, 2.0, 1.0]):
        np.testing.assert_allclose(small.stability(q), unit.stability(q), rtol=1e-12)
    assert len(support_polygon(small).vertices) == len(support_polygon(unit).vertices) == 4


def test_a_robot_with_its_own_casters():
    robot = Robot(caster_positions=((0.3, 0.0), (-0.3, 0.1), (-0.3, -0.1))).with_payload(1.0)
    model = EdgeLoadModel.from_robot(robot)
    for th1, th2 in RNG.uniform(-math.pi, math.pi, (50, 2)):
        loads = model.static_loads(th1, th2)
        x, y = robot.centre_of_mass([0, 0, 0, th1, th2])
        polygon = model.polygon
        distances = polygon.distances([(x, y)])[0]
        assert loads == pytest.approx(model.weight * distances / polygon.depths, abs=1e-9)


# -- against MuJoCo's contact forces -------------------------------------------------------
def _study():
    import importlib.util
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "docs" / "support_loads.py"
    spec = importlib.util.spec_from_file_location("support_loads_study", script)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def study():
    return _study()


@pytest.fixture(scope="module")
def turn(study):
    return study.fast_turn()


def test_the_recording_plant_runs_as_the_plant_does(study):
    from ddwmmr.plants.mujoco import MujocoPlant

    plants = [
        MujocoPlant(ROBOT, base_damping=study.DAMPING, **study.PHASE_A_ENGINE),
        study.RecordingPlant(ROBOT, base_damping=study.DAMPING),
    ]
    for plant in plants:
        plant.reset(np.array([0.0, 0.0, 0.0, *study.TURN_POSE]), study.TURN_DT)
        for k in range(200):
            t = k * study.TURN_DT
            applied, _ = plant.limit(plant.observe().q, study.turn_command(t))
            plant.step(t, applied, study.TURN_DT)
    assert np.array_equal(plants[0].data.qpos, plants[1].data.qpos)
    assert plants[0].unloaded_time_s == plants[1].unloaded_time_s


def test_replays_repeat_the_run(study, turn):
    """The recorded actuator controls replayed open loop give the same run bit for bit; a
    stretch replayed from the recorded engine state gives the same contact forces (the
    solver's warm start aside, to 1e-9 N)."""
    run = {"record": turn, "mode": "velocity"}
    again = study.replay(run, q0=np.array([0.0, 0.0, 0.0, *study.TURN_POSE]))
    assert np.array_equal(again["off"], turn["off"])
    assert np.array_equal(again["measured_inside"], turn["measured_inside"])
    stretch = study.replay_from(turn, 300, 50, "velocity")
    assert np.max(np.abs(stretch["measured_inside"] - turn["measured_inside"][300:350])) < 1e-9


def test_the_model_predicts_mujocos_edge_loads_in_a_fast_turn(study, turn):
    """The fast turn with the payload out (docs/physics.md, "Support loads while moving"):
    per edge, the model with the measured motion against the contact forces, both
    averaged over each control step. Measured: median 0.6-1.4 N, 95th percentile 6-9 N
    (the weight is 147 N); the static model (the weight at the centre of mass) is off by
    3-4.5 N in the median and 12-17 N at the 95th percentile."""
    errors = study.prediction_errors(turn)
    model, static = np.abs(errors["mean"]), np.abs(errors["static"])
    assert np.all(np.median(model, axis=0) <= 2.0), np.median(model, axis=0)
    assert np.all(np.percentile(model, 95, axis=0) <= 11.0), np.percentile(model, 95, axis=0)
    assert np.all(np.median(model, axis=0) <= 0.5 * np.median(static, axis=0))
    # the run is dynamic: the light side's measured load swings by more than 40 N, and the
    # model sees it unloaded where the static load never falls below the S floor's 14.7 N
    light = study.EDGES.index("left")
    measured = turn["measured_inside"].mean(axis=1)[:, light]
    assert measured.max() - measured.min() > 40.0
    assert study.static_loads(turn["motion"])[:, light].min() > 14.0
    assert study.predicted_loads(turn["motion"])[:, light].min() < 2.0


def test_the_base_damping_acts_on_the_floor_and_pitches_nothing(study, turn):
    """The plant applies the base damping c1 v on the floor (its base frame sits there):
    the front and back edges' model error does not grow with the speed. Applied at the
    axle's height r, as it was, it put a pitch moment c1 v r on the base, ``c1 r /
    base_length`` = 3.25 N per m/s on those edges (3.0 measured then)."""
    errors = study.prediction_errors(turn)["mean"]
    v = turn["v"]
    at_the_axle = study.DAMPING[0] * ROBOT.wheel_radius / ROBOT.base_length
    for edge in ("front", "back"):
        slope = np.polyfit(v, errors[:, study.EDGES.index(edge)], 1)[0]
        assert abs(slope) < 0.15 * at_the_axle


def test_the_load_parts_sum_to_the_dynamic_loads(study):
    motions = _motions(50)
    parts = study.load_parts(motions)
    total = sum(parts.values())
    dynamic = study.predicted_loads(motions) - study.static_loads(motions)
    assert np.max(np.abs(total - dynamic)) <= 1e-9 * MODEL.weight
    # each part alone: a pure forward acceleration is all "forward acceleration"
    still = np.zeros((1, 10))
    still[0, :2] = (0.4, 1.1)
    pushed = still.copy()
    pushed[0, 6] = 2.0
    alone = study.load_parts(pushed)
    expected = study.predicted_loads(pushed) - study.predicted_loads(still)
    assert alone["forward acceleration"] == pytest.approx(expected, abs=1e-12)
    assert all(np.all(alone[p] == 0.0) for p in study.PARTS if p != "forward acceleration")


def test_each_unloaded_step_gets_one_cause(study):
    """Four unloaded steps built to be static, inertial (the arm), a lift and chatter, and
    one loaded step that is not counted."""
    weight, substeps = MODEL.weight, 5
    right = study.EDGES.index("right")

    def step(th2, acc1, measured_mean):
        motion = np.zeros((substeps, 10))
        motion[:, 0], motion[:, 1], motion[:, 4] = -0.5 * math.pi, th2, acc1
        measured = np.full((substeps, 4), 70.0)
        measured[:, right] = measured_mean
        off = np.full(4, 70.0)
        off[right] = 0.0  # the plant's reading at the step's end: unloaded
        return motion, measured, off

    rows = [
        step(0.0, 0.0, 0.0),  # arm stretched to the right: static S = 1
        step(1.2, 60.0, 0.0),  # folded, S 1.34, but the shoulder accelerates hard
        step(1.2, 0.0, 0.0),  # folded, still: the side carried nothing all step
        step(1.2, 0.0, 20.0),  # folded, still: 20 N on average, nothing at the end
    ]
    loaded = step(1.2, 0.0, 20.0)
    rows.append((loaded[0], loaded[1], np.full(4, 70.0)))
    record = {
        "motion_inside": np.array([r[0] for r in rows]),
        "measured_inside": np.array([r[1] for r in rows]),
        "off": np.array([r[2] for r in rows]),
        "motion": np.array([r[0][-1] for r in rows]),
    }
    attribution = study.Attribution()
    study.classify(record, study.DELTA_SHARE * weight, attribution)
    dt = study.SCENARIO_DT
    assert attribution.steps == 5
    assert attribution.unloaded == pytest.approx(
        {"static": dt, "inertial": dt, "lift": dt, "chatter": dt}
    )
    assert attribution.parts["arm acceleration"] == pytest.approx(dt)
    assert attribution.edges["right"] == pytest.approx(4 * dt)
