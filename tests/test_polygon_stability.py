"""The stability margin S on support polygons other than the footprint.

S is measured on the convex hull of the wheels and casters (docs/theory.md, "Tip-over
stability"): the factor by which the centre of mass could move away from the base centre
before it leaves that polygon. These tests check it against an independent computation from
the layouts' own vertices (a bisection on that factor), through every consumer: the model's
S and gradient, the QP's terms and look-ahead, the MPC's symbolic S and rows, the arrays of
the summaries and the physics plant's S_phys.
"""

import math

import numpy as np
import pytest

from ddwmmr import load_trajectory, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.stability import (
    STABILITY_CAP,
    centre_of_mass,
    max_payload,
    stability_arrays,
    stability_gradient,
    stability_terms,
)
from ddwmmr.model.support_loads import edge_loads_at, support_polygon
from ddwmmr.qp.limits import full_step_is_safe, safe_arm_scale, stability_terms_gradient

A, B = 0.225, 0.175
#: Layouts: caster positions and the support polygon's vertices as drawn by hand (CCW),
#: wheels at (0, +-0.175).
LAYOUTS = {
    "diamond": (((A, 0.0), (-A, 0.0)), [(A, 0.0), (0.0, B), (-A, 0.0), (0.0, -B)]),
    "tricycle": (
        ((A, B), (A, -B), (-A, 0.0)),
        [(A, -B), (A, B), (0.0, B), (-A, 0.0), (0.0, -B)],
    ),
    "outriggers": (
        ((0.3, 0.2), (0.3, -0.2), (-0.3, 0.2), (-0.3, -0.2)),
        [(0.3, -0.2), (0.3, 0.2), (-0.3, 0.2), (-0.3, -0.2)],
    ),
    "trapezoid": (
        ((0.35, 0.25), (0.35, -0.25), (-0.2, 0.2), (-0.2, -0.2)),
        [(0.35, -0.25), (0.35, 0.25), (-0.2, 0.2), (-0.2, -0.2)],
    ),
}


def inside(vertices, x: float, y: float) -> bool:
    """Whether (x, y) is strictly inside the CCW convex polygon ``vertices``."""
    for (x0, y0), (x1, y1) in zip(vertices, vertices[1:] + vertices[:1]):
        if (x1 - x0) * (y - y0) - (y1 - y0) * (x - x0) <= 0.0:
            return False
    return True


def tipping_factor(vertices, x: float, y: float) -> float:
    """The largest factor s (capped) with ``s c`` still inside, by bisection."""
    if inside(vertices, STABILITY_CAP * x, STABILITY_CAP * y):
        return STABILITY_CAP
    low, high = 0.0, STABILITY_CAP
    for _ in range(200):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if inside(vertices, middle * x, middle * y) else (low, middle)
    return low


def reference_s(vertices, x: float, y: float) -> float:
    """S from the vertices: ``min d / (n . c)`` over the edges the point moves towards."""
    least = STABILITY_CAP
    for (x0, y0), (x1, y1) in zip(vertices, vertices[1:] + vertices[:1]):
        length = math.hypot(x1 - x0, y1 - y0)
        n_x, n_y = (y1 - y0) / length, -(x1 - x0) / length  # outward for CCW
        reach = n_x * x + n_y * y
        if reach > 0.0:
            least = min(least, (n_x * x0 + n_y * y0) / reach)
    return least


def random_poses(count: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-math.pi, math.pi, size=(count, 2))


@pytest.mark.parametrize("name", LAYOUTS)
@pytest.mark.parametrize("payload", [1.25, 3.0, 8.0])
def test_s_is_the_tipping_factor_of_the_polygon(name, payload):
    """S is the factor by which the centre of mass can move out before it leaves the
    polygon (bisection), and the load on the edge it reaches vanishes there."""
    casters, vertices = LAYOUTS[name]
    robot = Robot(caster_positions=casters, payload=payload)
    polygon = support_polygon(robot)
    for th1, th2 in random_poses(60, seed=len(name)):
        x, y = centre_of_mass(robot.com_coefficients, th1, th2)
        s = robot.stability([0.0, 0.0, 0.0, th1, th2])[2]
        assert s == pytest.approx(tipping_factor(vertices, x, y), abs=1e-9)
        if s < STABILITY_CAP:  # the least edge load is zero at s c
            loads = edge_loads_at(polygon, 1.0, s * x, s * y)
            assert min(loads) == pytest.approx(0.0, abs=1e-9)


def test_the_diamond_at_the_pose_that_tipped_it():
    """A pose the QP reached on MuJoCo (S 1.78 on the footprint): 1.07 on the diamond, in
    the robot's S, the arrays of the summaries and the max payload."""
    casters, vertices = LAYOUTS["diamond"]
    robot = Robot(caster_positions=casters, payload=2.5)
    th1, th2 = -0.839, 0.948
    x, y = centre_of_mass(robot.com_coefficients, th1, th2)
    s = robot.stability([0.0, 0.0, 0.0, th1, th2])
    assert s[2] == pytest.approx(tipping_factor(vertices, x, y), abs=1e-9)
    assert s[2] == pytest.approx(1.0720, abs=1e-4)
    assert Robot(payload=2.5).stability([0, 0, 0, th1, th2])[2] == pytest.approx(1.7826, abs=1e-4)
    arrays = stability_arrays(robot.com_coefficients, np.array([th1]), np.array([th2]))
    assert [float(a[0]) for a in arrays] == pytest.approx(list(s), abs=1e-12)
    # the heaviest payload that stands there: S = 1 at its centre of mass
    held = max_payload(robot, th1, th2)
    assert 2.5 < held < 3.0
    assert robot.with_payload(held).stability([0, 0, 0, th1, th2])[2] > 1.0
    assert robot.with_payload(held + 0.002).stability([0, 0, 0, th1, th2])[2] <= 1.0


@pytest.mark.parametrize("name", LAYOUTS)
def test_the_arrays_are_the_scalar_terms(name):
    robot = Robot(caster_positions=LAYOUTS[name][0], payload=3.0)
    poses = random_poses(200, seed=3)
    arrays = stability_arrays(robot.com_coefficients, poses[:, 0], poses[:, 1])
    for i, (th1, th2) in enumerate(poses):
        expected = stability_terms(robot.com_coefficients, th1, th2)
        assert [float(a[i]) for a in arrays] == pytest.approx(list(expected), abs=1e-12)


@pytest.mark.parametrize("name", ["diamond", "tricycle", "trapezoid"])
def test_the_gradient_is_the_polygon_margins(name):
    """``stability_gradient`` and the QP's active-edge rows against central differences of
    the reference S, where one edge has the minimum (no kink within 1e-5 rad)."""
    casters, vertices = LAYOUTS[name]
    robot = Robot(caster_positions=casters, payload=3.0)
    k = robot.com_coefficients
    h, checked = 1e-6, 0

    def s_of(th1, th2):
        return reference_s(vertices, *centre_of_mass(k, th1, th2))

    for th1, th2 in random_poses(200, seed=7):
        s = s_of(th1, th2)
        if s >= STABILITY_CAP - 1e-3:
            continue
        d1 = (s_of(th1 + h, th2) - s_of(th1 - h, th2)) / (2 * h)
        d2 = (s_of(th1, th2 + h) - s_of(th1, th2 - h)) / (2 * h)
        kinked = max(
            abs(s_of(th1 + e1, th2 + e2) - s - d1 * e1 - d2 * e2)
            for e1, e2 in ((1e-5, 0.0), (-1e-5, 0.0), (0.0, 1e-5), (0.0, -1e-5))
        )
        if kinked > 1e-7:
            continue
        checked += 1
        value, g1, g2 = stability_gradient(k, th1, th2)
        assert value == pytest.approx(s, abs=1e-12)
        assert (g1, g2) == pytest.approx((d1, d2), rel=1e-5, abs=1e-6)
        assert robot.stability_gradient([0, 0, 0, th1, th2])[3:] == pytest.approx([g1, g2])
        terms = stability_terms_gradient(k, th1, th2)
        least = min(terms, key=lambda t: t[0])
        assert least[0] == pytest.approx(s, abs=1e-12)
        assert least[1:] == pytest.approx((d1, d2), rel=1e-5, abs=1e-6)
    assert checked > 100


def test_the_qp_look_ahead_holds_the_polygon():
    """``full_step_is_safe`` proves no step that takes the polygon's S below the floor,
    and ``safe_arm_scale`` scales every step to keep it there."""
    casters, vertices = LAYOUTS["diamond"]
    robot = Robot(caster_positions=casters, payload=2.5)
    k = robot.com_coefficients
    rng = np.random.default_rng(11)
    dt, floor, proven = 0.05, 1.25, 0
    for th1, th2 in random_poses(400, seed=5):
        r1, r2 = rng.uniform(-2.0, 2.0, size=2)
        trig = (math.sin(th1), math.cos(th1), math.sin(th1 + th2), math.cos(th1 + th2))
        after = reference_s(vertices, *centre_of_mass(k, th1 + dt * r1, th2 + dt * r2))
        if full_step_is_safe(k, trig, th1, th2, r1, r2, dt, floor):
            proven += 1
            assert after >= floor
        now = reference_s(vertices, *centre_of_mass(k, th1, th2))
        scale = safe_arm_scale(k, th1, th2, r1, r2, dt, floor)
        moved = centre_of_mass(k, th1 + scale * dt * r1, th2 + scale * dt * r2)
        assert reference_s(vertices, *moved) >= min(floor, now) - 1e-12
    assert proven > 50


def test_the_mpcs_s_is_the_models():
    """The symbolic terms (uncapped) are the model's below the cap, and the OCP's rows
    (``stability_edges``) hold exactly where S >= the floor."""
    casters, _ = LAYOUTS["diamond"]
    robot = Robot(caster_positions=casters, payload=2.5)
    function = sym.casadi_functions(robot)["stability"]
    rows = sym.stability_edges(robot, 1.25)
    depth = A * B / math.hypot(A, B)  # each edge's line from the base centre
    assert [bound for *_, bound, _ in rows] == pytest.approx([depth / 1.25] * 4, abs=1e-15)
    assert sym.stability_edges(Robot(), 1.25) is None  # the rectangle keeps its box
    for th1, th2 in random_poses(300, seed=13):
        q = [0.0, 0.0, 0.0, th1, th2]
        s_lon, s_lat, s = robot.stability(q)
        symbolic = np.asarray(function(q), dtype=float).ravel()
        assert np.minimum(symbolic, STABILITY_CAP) == pytest.approx([s_lon, s_lat], abs=1e-12)
        x, y = centre_of_mass(robot.com_coefficients, th1, th2)
        held = all(n_x * x + n_y * y <= bound for n_x, n_y, bound, _ in rows)
        if abs(s - 1.25) > 1e-9:
            assert held == (s >= 1.25)


@pytest.mark.parametrize("method", ["qp", "mpc"])
def test_the_controllers_on_the_diamond_hold_the_polygons_floor(method):
    """The run that tipped on MuJoCo, on the kinematic plant: S on the polygon (the
    reference, from the vertices) never goes below the controller's floor, which binds
    (the footprint's S would have let the arm go further out)."""
    casters, vertices = LAYOUTS["diamond"]
    robot = Robot(caster_positions=casters, payload=2.5)
    result = simulate(robot, load_trajectory("sideways_reach"), method)
    ts = result.timeseries
    k = robot.com_coefficients
    polygon_s = [
        reference_s(vertices, *centre_of_mass(k, th1, th2))
        for th1, th2 in zip(ts["th1"], ts["th2"])
    ]
    assert min(polygon_s) >= 1.25 - 1e-6
    assert min(polygon_s) < 1.3
    assert np.asarray(ts["stability"]) == pytest.approx(polygon_s, abs=1e-9)


def test_the_default_robot_s_is_the_closed_form_to_the_bit():
    """The default support polygon is the footprint: S, its terms, the arrays and the
    gradient are the footprint's closed form, bit for bit."""
    robot = Robot()
    k = robot.com_coefficients
    assert k.edges is None and (k.half_length, k.half_width) == (0.225, 0.175)
    poses = random_poses(500, seed=17)
    arrays = stability_arrays(k, poses[:, 0], poses[:, 1])
    for i, (th1, th2) in enumerate(poses):
        x = k.A * math.cos(th1) + k.B * math.cos(th1 + th2)
        y = k.A * math.sin(th1) + k.B * math.sin(th1 + th2)
        s_lon = STABILITY_CAP if abs(x) * STABILITY_CAP <= 0.225 else 0.225 / abs(x)
        s_lat = STABILITY_CAP if abs(y) * STABILITY_CAP <= 0.175 else 0.175 / abs(y)
        expected = (s_lon, s_lat, min(s_lon, s_lat))
        assert robot.stability([0.0, 0.0, 0.0, th1, th2]) == expected
        assert tuple(float(a[i]) for a in arrays) == expected


def test_a_polygon_without_the_base_centre_is_refused():
    """S is a ratio of offsets from the base centre: a layout whose polygon does not hold
    it strictly inside has none (docs/theory.md, "Tip-over stability")."""
    for casters in ([(0.2, 0.0)], [(0.3, 0.1), (0.3, -0.1)], [(-0.1, 0.5), (-0.1, -0.5)]):
        with pytest.raises(ParameterError, match=r"^caster_positions: the base centre must"):
            Robot(caster_positions=casters)


def test_the_physics_plants_margin_is_the_models():
    """S_phys of a centre of pressure is the model's S there, on the polygon."""
    pytest.importorskip("mujoco")
    from ddwmmr.plants.mujoco.support import SupportGeometry

    for name, (casters, vertices) in LAYOUTS.items():
        robot = Robot(caster_positions=casters)
        geometry = SupportGeometry(support_polygon(robot).vertices)
        for x, y in np.random.default_rng(1).uniform(-0.3, 0.3, size=(50, 2)):
            assert geometry.stability((x, y)) == pytest.approx(
                tipping_factor(vertices, x, y), abs=1e-9
            ), name
    default = SupportGeometry(support_polygon(Robot()).vertices)
    assert default.edges.rectangle == (0.225, 0.175)


def test_the_diamond_no_longer_tips_on_mujoco():
    """The qp on the sideways reach with 2.5 kg fell over on the physics plant while S was
    measured on the footprint; with S on the diamond it tracks, no edge unloaded."""
    pytest.importorskip("mujoco")
    robot = Robot(caster_positions=LAYOUTS["diamond"][0], payload=2.5)
    summary = simulate(robot, load_trajectory("sideways_reach"), "qp", plant="mujoco").summary
    assert not summary["tipped"] and summary["verdict"] == "tracked"
    assert summary["min_stability"] >= 1.25
    assert summary["min_edge_load_n"] > 10.0  # 13.2 N measured
    assert summary["rms_position_error_m"] < 0.015  # 8.6 mm measured
