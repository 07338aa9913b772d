"""The model in CasADi: an independent second formulation (this file's ``symbolic_model``)
checks the numeric model, and both check the library's ``ddwmmr.model.symbolic`` (values and
derivatives at many random states, and the thesis plant's force-level dynamics)."""

import math

import casadi as ca
import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.model import kinematics
from ddwmmr.model import symbolic as sym
from ddwmmr.plants.thesis import ThesisPlant, ThesisState


def symbolic_model(robot: Robot):
    """CasADi functions of q: FK (3), J_E = dFK/dq (3x5), S_lon, S_lat and their gradients."""
    q = ca.SX.sym("q", 5)
    x, y, phi, th1, th2 = (q[i] for i in range(5))
    L1, L2 = robot.L1, robot.L2
    fk = ca.vertcat(
        x + L1 * ca.cos(phi + th1) + L2 * ca.cos(phi + th1 + th2),
        y + L1 * ca.sin(phi + th1) + L2 * ca.sin(phi + th1 + th2),
        phi + th1 + th2,
    )
    m1, m2 = robot.link_masses
    total = robot.base_mass + m1 + m2 + robot.payload
    # Moments of each body's centre of mass in the base frame (written out independently).
    com = (
        m1 * ca.vertcat(L1 / 2 * ca.cos(th1), L1 / 2 * ca.sin(th1))
        + m2
        * ca.vertcat(
            L1 * ca.cos(th1) + L2 / 2 * ca.cos(th1 + th2),
            L1 * ca.sin(th1) + L2 / 2 * ca.sin(th1 + th2),
        )
        + robot.payload
        * ca.vertcat(
            L1 * ca.cos(th1) + L2 * ca.cos(th1 + th2), L1 * ca.sin(th1) + L2 * ca.sin(th1 + th2)
        )
    ) / total
    s_lon = (robot.base_length / 2) / ca.fabs(com[0])
    s_lat = (robot.base_width / 2) / ca.fabs(com[1])
    return ca.Function(
        "model",
        [q],
        [fk, ca.jacobian(fk, q), s_lon, s_lat, ca.gradient(s_lon, q), ca.gradient(s_lat, q)],
    )


def test_jacobian_matches_casadi_autodiff(rng):
    robot = Robot()
    model = symbolic_model(robot)
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, 5)
        fk, jac, *_ = (np.array(v, dtype=float) for v in model(q))
        np.testing.assert_allclose(robot.fk(q), fk.ravel(), atol=1e-12)
        np.testing.assert_allclose(robot.jacobian(q)[:3], jac, atol=1e-12)


@pytest.mark.parametrize("payload", [1.25, 3.0])
def test_stability_and_gradient_match_casadi_autodiff(rng, payload):
    robot = Robot().with_payload(payload)
    model = symbolic_model(robot)
    checked = 0
    while checked < 25:
        q = rng.uniform(-math.pi, math.pi, 5)
        _, _, s_lon, s_lat, g_lon, g_lat = (np.array(v, dtype=float) for v in model(q))
        s_lon, s_lat = s_lon.item(), s_lat.item()
        s = min(s_lon, s_lat)
        if s >= 10.0 or abs(s_lon - s_lat) < 1e-6:
            continue  # capped or at the kink of min(): the library reports a zero/one-sided slope
        ours = robot.stability(q)
        assert ours[0] == pytest.approx(min(s_lon, 10.0), rel=1e-12)
        assert ours[1] == pytest.approx(min(s_lat, 10.0), rel=1e-12)
        expected = (g_lon if s_lon < s_lat else g_lat).ravel()
        np.testing.assert_allclose(robot.stability_gradient(q), expected, rtol=1e-10, atol=1e-12)
        checked += 1


# -- the library's symbolic model (ddwmmr.model.symbolic) against the numeric one -------------


STATES = 200


def random_configurations(rng, count=STATES):
    return rng.uniform(-math.pi, math.pi, (count, 5)) * np.array([2.0, 2.0, 1.0, 1.0, 1.0])


@pytest.mark.parametrize("payload", [1.25, 3.0])
def test_library_model_equals_numeric_model_and_independent_formulation(rng, payload):
    robot = Robot().with_payload(payload)
    lib = sym.casadi_functions(robot)
    reference = symbolic_model(robot)
    q_sym = ca.SX.sym("q", 5)
    jac_fk = ca.Function("J", [q_sym], [ca.jacobian(sym.forward_kinematics(robot, q_sym), q_sym)])
    for q in random_configurations(rng):
        fk = np.array(lib["fk"](q)).ravel()
        np.testing.assert_allclose(fk, robot.fk(q), atol=1e-12)
        np.testing.assert_allclose(np.array(jac_fk(q)), robot.jacobian(q)[:3], atol=1e-12)
        com = np.array(lib["com"](q)).ravel()
        np.testing.assert_allclose(com, robot.centre_of_mass(q), atol=1e-13)
        s_lon, s_lat = np.array(lib["stability"](q)).ravel()
        ref = [float(v) for v in reference(q)[2:4]]
        assert s_lon == pytest.approx(ref[0], rel=1e-12)
        assert s_lat == pytest.approx(ref[1], rel=1e-12)
        numeric = robot.stability(q)
        assert numeric[0] == pytest.approx(min(s_lon, 10.0), rel=1e-12)
        assert numeric[1] == pytest.approx(min(s_lat, 10.0), rel=1e-12)
        assert float(lib["eta"](q)) == pytest.approx(robot.manipulability(q), abs=1e-15)


def test_stability_gradient_of_the_library_expression(rng):
    robot = Robot().with_payload(3.0)
    q_sym = ca.SX.sym("q", 5)
    terms = sym.stability_terms(robot, q_sym)
    grad = ca.Function("g", [q_sym], [ca.jacobian(terms, q_sym)])
    checked = 0
    for q in random_configurations(rng):
        s_lon, s_lat, s = robot.stability(q)
        if s >= 10.0 or abs(s_lon - s_lat) < 1e-6:
            continue
        rows = np.array(grad(q))
        expected = rows[0] if s_lon < s_lat else rows[1]
        np.testing.assert_allclose(robot.stability_gradient(q), expected, rtol=1e-10, atol=1e-12)
        checked += 1
    assert checked > 100


@pytest.mark.parametrize("s_min", [1.25, 1.4, 1.6])
def test_centre_of_mass_box_is_exactly_the_stability_condition(rng, s_min):
    """|x_com| <= hl/S and |y_com| <= hw/S  <=>  S_lon, S_lat >= S (the OCP's hard row)."""
    robot = Robot().with_payload(3.0)
    x_max, y_max = sym.stability_bounds(robot, s_min)
    inside = outside = 0
    for q in random_configurations(rng, 2000):
        com = robot.centre_of_mass(q)
        in_box = abs(com[0]) <= x_max and abs(com[1]) <= y_max
        assert in_box == (robot.stability(q)[2] >= s_min)
        inside += in_box
        outside += not in_box
    assert inside > 100 and outside > 100


def test_kinematic_model_and_wheel_map(rng):
    robot = Robot()
    lib = sym.casadi_functions(robot)
    q_sym = ca.SX.sym("q", 5)
    g = ca.Function("G", [q_sym], [sym.input_matrix(q_sym)])
    for q in random_configurations(rng, 50):
        u = rng.normal(size=4)
        qdot = np.array(lib["kinematic"](q, u)).ravel()
        np.testing.assert_allclose(qdot, kinematics.qdot_from_u(q[2], u), atol=1e-14)
        np.testing.assert_allclose(np.array(g(q)), kinematics.input_matrix(q[2]), atol=1e-15)
        wheels = np.array(sym.wheel_speeds(robot, u[0], u[1])).ravel()
        np.testing.assert_allclose(wheels, robot.wheel_speeds_from_u(u[0], u[1]), rtol=1e-14)
        eta2 = ca.Function("e", [q_sym], [ca.gradient(sym.manipulability_squared(q_sym), q_sym)])
        assert float(eta2(q)[4]) == pytest.approx(math.sin(2.0 * q[4]), abs=1e-14)


@pytest.mark.parametrize("payload", [1.25, 3.0])
def test_thesis_dynamics_parameters_equal_the_plant(rng, payload):
    robot = Robot().with_payload(payload)
    plant = ThesisPlant(robot)
    model = sym.ThesisDynamics.from_robot(robot)
    assert model.mass == pytest.approx(plant.mass, rel=1e-15)
    for th1, th2 in rng.uniform(-math.pi, math.pi, (50, 2)):
        assert model.inertia(th2) == pytest.approx(plant.inertia(th1, th2), rel=1e-14)
        assert float(model.inertia(ca.DM(th2))) == pytest.approx(plant.inertia(th1, th2), rel=1e-14)
    assert model.velocity_envelope() == pytest.approx(plant.velocity_envelope())
    assert model.top_speed == pytest.approx(20.0 / 15.0)
    assert model.top_yaw_rate == pytest.approx(0.875)


def test_thesis_dynamics_rate_equals_the_plant_over_a_short_step(rng):
    """xdot of the model = (plant state after h - before) / h for h -> 0 (forward and
    rotational equations, kinematics, arm servo), at random states and forces."""
    robot = Robot().with_payload(3.0)
    plant = ThesisPlant(robot)
    model = sym.ThesisDynamics.from_robot(robot)
    rhs = sym.casadi_functions(robot, model)["thesis"]
    h = 1e-6
    for _ in range(100):
        q = rng.uniform(-math.pi, math.pi, 5)
        v, w = rng.uniform(-1.2, 1.2), rng.uniform(-0.8, 0.8)
        forces = rng.uniform(-10.0, 10.0, 2)
        rates = rng.uniform(-1.9, 1.9, 2)
        state = ThesisState(*q, v, w)
        before = np.array([*state.q, state.v, state.w])
        plant.advance(state, *forces, (q[3] + rates[0] * h, q[4] + rates[1] * h), h)
        after = np.array([*state.q, state.v, state.w])
        expected = np.array(rhs(before, [*forces, *rates])).ravel()
        np.testing.assert_allclose((after - before) / h, expected, rtol=1e-4, atol=1e-5)


@pytest.mark.parametrize("arm_moves", [False, True])
def test_thesis_dynamics_integrated_over_a_control_step_matches_the_plant(rng, arm_moves):
    """RK4 of the model over dt = 0.01 s equals ThesisPlant.advance (which integrates v, w
    exactly and moves along the mean heading) to the plant's own approximation error.

    Positions: the plant moves the travelled distance along the mean heading, the model
    integrates the arc (difference ~ v dt (w dt)^2 < 2e-6 m here). With the arm moving the
    yaw rate differs by up to ~1e-4 rad/s: the plant holds the yaw inertia at the
    start-of-step pose (dI/I up to ~1 % over the step), the model lets it follow th2."""
    robot = Robot().with_payload(3.0)
    plant = ThesisPlant(robot)
    model = sym.ThesisDynamics.from_robot(robot)
    x, u = ca.SX.sym("x", 7), ca.SX.sym("u", 4)
    discrete = sym.rk4_step(model.rhs, x, u, 0.01)
    step = ca.Function("s", [x, u], [discrete])
    jac = ca.Function("j", [x, u], [ca.jacobian(discrete, ca.vertcat(x, u))])
    for _ in range(50):
        q = rng.uniform(-math.pi, math.pi, 5)
        v, w = rng.uniform(-1.2, 1.2), rng.uniform(-0.8, 0.8)
        rates = rng.uniform(-1.9, 1.9, 2) if arm_moves else np.zeros(2)
        command = np.concatenate([rng.uniform(-10, 10, 2), rates])
        state = ThesisState(*q, v, w)
        before = np.array([*state.q, state.v, state.w])
        plant.advance(state, command[0], command[1], tuple(q[3:5] + 0.01 * command[2:]), 0.01)
        after = np.array([*state.q, state.v, state.w])
        tolerance = np.array([2e-6, 2e-6, 1e-8, 1e-12, 1e-12, 1e-9, 1e-7])  # RK4 vs exact
        if arm_moves:
            tolerance[2], tolerance[6] = 2e-6, 2e-4
        assert np.all(np.abs(np.array(step(before, command)).ravel() - after) <= tolerance)
        # derivatives of the discrete step against central differences of the plant
        analytic = np.array(jac(before, command))
        for j in (2, 5, 6, 7, 8):  # heading, v, w, both forces
            delta = np.zeros(11)
            delta[j] = 1e-6
            point = np.concatenate([before, command])
            outs = []
            for z in (point + delta, point - delta):
                s = ThesisState(*z[:7])
                plant.advance(s, z[7], z[8], tuple(z[3:5] + 0.01 * z[9:11]), 0.01)
                outs.append(np.array([*s.q, s.v, s.w]))
            np.testing.assert_allclose(
                (outs[0] - outs[1]) / 2e-6,
                analytic[:, j],
                atol=2e-5,
                rtol=5e-4 if arm_moves else 1e-7,
            )


def test_velocity_tracking_forces_equal_the_scenario_velocity_loop(rng):
    from ddwmmr.plants.thesis import VelocityServo as VelocityLoop

    robot = Robot().with_payload(3.0)
    plant = ThesisPlant(robot)
    loop = VelocityLoop(plant)
    model = sym.ThesisDynamics.from_robot(robot)
    for _ in range(100):
        q = rng.uniform(-math.pi, math.pi, 5)
        state = ThesisState(*q, rng.uniform(-1.3, 1.3), rng.uniform(-0.9, 0.9))
        v_d, w_d = rng.uniform(-1.5, 1.5), rng.uniform(-1.0, 1.0)
        expected = loop.forces(state, v_d, w_d)
        got = model.velocity_tracking_forces(state.v, state.w, v_d, w_d, state.th2)
        np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-13)
