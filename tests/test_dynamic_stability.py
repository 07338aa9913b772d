"""The dynamic tip-over margin: the zero moment point (model/stability.py) against first
principles, its symbolic twin, and the centre of pressure MuJoCo measures."""

import math

import casadi as ca
import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.stability import (
    BASE_CLEARANCE_M,
    GRAVITY_M_S2,
    centre_of_mass,
    dynamic_stability,
    inertial_terms,
    stability_terms,
    zero_moment_point,
)

ROBOT = Robot().with_payload(3.0)
RNG = np.random.default_rng(7)


def _states(count: int):
    """Random (th1, th2, rate1, rate2, v, w, v_dot, w_dot, acc1, acc2)."""
    scale = np.array([math.pi, math.pi, 2.0, 2.0, 1.0, 1.5, 1.0, 3.0, 20.0, 20.0])
    return RNG.uniform(-1.0, 1.0, (count, 10)) * scale


def test_at_rest_the_zero_moment_point_is_the_centre_of_mass():
    k, terms = ROBOT.com_coefficients, inertial_terms(ROBOT)
    for th1, th2, *_ in _states(20):
        point = zero_moment_point(k, terms, th1, th2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        assert point == pytest.approx(centre_of_mass(k, th1, th2), abs=1e-15)
        still = dynamic_stability(k, terms, th1, th2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        assert still == pytest.approx(stability_terms(k, th1, th2), abs=1e-12)


def _lumped_masses(robot: Robot, th1: float, th2: float):
    """(mass kg, base-frame x, y m, height m) of every lumped mass, from the robot's fields."""
    m1, m2 = robot.link_masses
    a1, a12 = th1, th1 + th2
    elbow = (robot.L1 * math.cos(a1), robot.L1 * math.sin(a1))
    tip = (elbow[0] + robot.L2 * math.cos(a12), elbow[1] + robot.L2 * math.sin(a12))
    half_track = 0.5 * robot.track_width
    box_height = BASE_CLEARANCE_M + robot.base_height / 2
    return [
        (robot.base_mass - 2 * robot.wheel_mass, 0.0, 0.0, box_height),
        (robot.wheel_mass, 0.0, half_track, robot.wheel_radius),
        (robot.wheel_mass, 0.0, -half_track, robot.wheel_radius),
        (m1, 0.5 * elbow[0], 0.5 * elbow[1], robot.arm_height),
        (m2, 0.5 * (elbow[0] + tip[0]), 0.5 * (elbow[1] + tip[1]), robot.arm_height),
        (robot.payload, tip[0], tip[1], robot.arm_height),
    ]  # fmt: skip


def _world_masses(robot, state, t: float):
    """World (mass, X, Y, height) at time t of a motion with constant accelerations."""
    th1, th2, r1, r2, v0, w0, a, alpha, acc1, acc2 = state
    s = np.linspace(0.0, t, 2001)  # the base's path: Simpson's rule on the exact rates
    heading = 0.3 + w0 * s + 0.5 * alpha * s**2
    speed = v0 + a * s
    weights = np.ones_like(s)
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    x0 = np.sum(weights * speed * np.cos(heading)) * (t / 2000) / 3.0
    y0 = np.sum(weights * speed * np.sin(heading)) * (t / 2000) / 3.0
    phi = heading[-1]
    q1 = th1 + r1 * t + 0.5 * acc1 * t**2
    q2 = th2 + r2 * t + 0.5 * acc2 * t**2
    c, si = math.cos(phi), math.sin(phi)
    return [
        (m, x0 + c * bx - si * by, y0 + si * bx + c * by, h)
        for m, bx, by, h in _lumped_masses(robot, q1, q2)
    ]


def test_the_formula_is_the_zero_moment_point_of_the_lumped_masses():
    """First principles: second differences of each mass's world path, then
    sum m (g X - h Xddot) / (M g), rotated into the base frame at t = 0 (heading 0.3)."""
    k, terms = ROBOT.com_coefficients, inertial_terms(ROBOT)
    h = 1e-3
    for state in _states(10):
        before, now, after = (_world_masses(ROBOT, state, t) for t in (-h, 0.0, h))
        total = sum(m for m, *_ in now)
        zx = zy = 0.0
        for (m, xb, yb, z), (_, x, y, _), (_, xa, ya, _) in zip(before, now, after):
            zx += m * (GRAVITY_M_S2 * x - z * (xa - 2 * x + xb) / h**2)
            zy += m * (GRAVITY_M_S2 * y - z * (ya - 2 * y + yb) / h**2)
        zx, zy = zx / (total * GRAVITY_M_S2), zy / (total * GRAVITY_M_S2)
        c, s = math.cos(0.3), math.sin(0.3)
        expected = (c * zx + s * zy, -s * zx + c * zy)  # base frame, origin at the axle
        assert zero_moment_point(k, terms, *state) == pytest.approx(expected, abs=2e-6)


def test_the_symbolic_twin_builds_the_same_expression():
    q, rates, acc = ca.SX.sym("q", 5), ca.SX.sym("r", 2), ca.SX.sym("a", 2)
    v, w, v_dot, w_dot = ca.SX.sym("v"), ca.SX.sym("w"), ca.SX.sym("vd"), ca.SX.sym("wd")
    point = sym.zero_moment_point(ROBOT, q, rates, v, w, v_dot, w_dot, (acc[0], acc[1]))
    f = ca.Function("zmp", [q, rates, v, w, v_dot, w_dot, acc], [point])
    k, terms = ROBOT.com_coefficients, inertial_terms(ROBOT)
    for th1, th2, r1, r2, vv, ww, vd, wd, a1, a2 in _states(10):
        value = f([0.0, 0.0, 0.0, th1, th2], [r1, r2], vv, ww, vd, wd, [a1, a2])
        numeric = zero_moment_point(k, terms, th1, th2, r1, r2, vv, ww, vd, wd, a1, a2)
        np.testing.assert_allclose(np.asarray(value).ravel(), numeric, rtol=0, atol=1e-14)


@pytest.mark.parametrize(
    ("u", "q0"),
    [
        ((0.5, 1.0, 0.0, 0.0), (-math.pi / 2, 0.0)),  # a steady turn, arm out to the right
        ((0.3, -1.5, 0.0, 0.0), (math.pi / 2, 0.3)),
        ((0.0, 2.0, 0.0, 0.0), (0.0, 0.0)),  # spinning on the spot, arm forward
        ((0.0, 0.0, 1.5, 0.0), (-1.0, 0.5)),  # the base still, the arm swinging
    ],
)
def test_mujoco_measures_the_zero_moment_point_not_the_centre_of_mass(u, q0):
    """The centre of pressure of MuJoCo's floor forces, in steady motion, is the zero
    moment point to 1 mm; the static centre of mass is centimetres off."""
    from ddwmmr.plants.mujoco import MujocoPlant
    from ddwmmr.plants.mujoco.support import centre_of_pressure

    robot = Robot().with_payload(2.0)
    k, terms = robot.com_coefficients, inertial_terms(robot)
    plant = MujocoPlant(robot)
    plant.reset(np.array([0.0, 0.0, 0.0, *q0]), 0.01)
    steps = 90 if u[2] else 300  # the arm sweeps 1.35 rad; the turns settle
    for step in range(steps):
        plant.step(step * 0.01, np.array(u), 0.01)
    obs = plant.observe()
    forces, points = plant.support_forces()
    measured = centre_of_pressure(points, forces)
    th1, th2 = obs.q[3], obs.q[4]
    predicted = zero_moment_point(k, terms, th1, th2, u[2], u[3], obs.v, obs.w, 0.0, 0.0)
    assert np.hypot(*(measured - predicted)) < 1e-3
    assert np.hypot(*(measured - centre_of_mass(k, th1, th2))) > 8e-3
