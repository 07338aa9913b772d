"""Formulas of the QP pieces, each checked independently (finite differences, brute force)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits import (
    INF,
    Circle,
    JointLimit,
    StabilityLimit,
    WheelSpeedLimit,
    clearance_and_rate,
    exact_stability,
    footprint_clearances,
    load_obstacles,
    safe_arm_scale,
    stability_terms_gradient,
)
from ddwmmr.qp.tasks import (
    EndEffectorTask,
    ManipulabilityTask,
    eta_squared_gradient,
    manipulability_gradient,
)
from ddwmmr.qp.tasks.manipulability import base_gradient
from footprint import outline_clearance

ROBOT = Robot().with_payload(3.0)
ARM_POSES = [(0.3, 0.4), (1.2, 0.1), (-1.4, 0.7), (2.5, -0.9), (0.05, 1.5), (-0.8, -2.0)]


def _ctx(q, pose_d=(0.0, 0.0, 0.0), velocity_d=(0.0, 0.0, 0.0), robot=ROBOT) -> StepContext:
    ctx = StepContext(robot, 0.02)
    ctx.update(0.0, np.array(q, float), np.array(pose_d, float), np.array(velocity_d, float))
    return ctx


@pytest.mark.parametrize(("th1", "th2"), ARM_POSES)
def test_stability_term_gradients_match_finite_differences(th1, th2):
    com = ROBOT.com_coefficients
    h = 1e-6
    for term in range(2):
        _, g1, g2 = stability_terms_gradient(com, th1, th2)[term]
        fd1 = (
            stability_terms_gradient(com, th1 + h, th2)[term][0]
            - stability_terms_gradient(com, th1 - h, th2)[term][0]
        ) / (2 * h)
        fd2 = (
            stability_terms_gradient(com, th1, th2 + h)[term][0]
            - stability_terms_gradient(com, th1, th2 - h)[term][0]
        ) / (2 * h)
        assert g1 == pytest.approx(fd1, rel=1e-5, abs=1e-6)
        assert g2 == pytest.approx(fd2, rel=1e-5, abs=1e-6)


@pytest.mark.parametrize(("th1", "th2"), ARM_POSES)
def test_stability_terms_agree_with_the_robot_model(th1, th2):
    q = [0.0, 0.0, 0.0, th1, th2]
    s_lon, s_lat, s = ROBOT.stability(q)
    lon, lat = stability_terms_gradient(ROBOT.com_coefficients, th1, th2)
    assert (lon[0], lat[0]) == pytest.approx((s_lon, s_lat), rel=1e-12)
    assert exact_stability(ROBOT.com_coefficients, th1, th2) == pytest.approx(s, rel=1e-12)
    active = lat if s_lat <= s_lon else lon
    assert ROBOT.stability_gradient(q)[3:] == pytest.approx(active[1:], rel=1e-12, abs=1e-15)


def test_full_sideways_stretch_with_3kg_is_exactly_tipping():
    assert exact_stability(ROBOT.com_coefficients, math.pi / 2, 0.0) == pytest.approx(1.0)


def test_stability_row_is_the_first_order_change_of_each_term():
    limit = StabilityLimit(ROBOT.com_coefficients, 1.25)
    G, lower, upper = np.zeros((2, 4)), np.zeros(2), np.zeros(2)
    ctx = _ctx([0, 0, 0, 1.1, 0.3])
    limit.compute(ctx, G, lower, upper, np.full(4, -INF), np.full(4, INF))
    rates = np.array([0.0, 0.0, 0.7, -0.4])
    dt = 1e-5
    before = stability_terms_gradient(ROBOT.com_coefficients, 1.1, 0.3)
    after = stability_terms_gradient(ROBOT.com_coefficients, 1.1 + 0.7 * dt, 0.3 - 0.4 * dt)
    for row in range(2):
        if before[row][0] < 10.0:
            assert G[row] @ rates == pytest.approx((after[row][0] - before[row][0]) / dt, rel=1e-4)
    # S_lat = 0.175 / y_com is below the floor here: the row demands an increase.
    s_lat = before[1][0]
    assert s_lat < 1.25
    assert lower[1] == pytest.approx(min(5.0 * (1.26 - s_lat), 0.5 * 2.0 * np.abs(G[1]).sum()))


def test_safe_arm_scale_never_lets_exact_stability_cross_the_floor():
    com = ROBOT.com_coefficients
    # Just above the floor, moving straight down the gradient far too fast for one step.
    th1, th2 = 0.7, 0.9
    s0, g1, g2 = stability_terms_gradient(com, th1, th2)[1]
    assert 1.25 < s0 < 1.3
    scale = safe_arm_scale(com, th1, th2, -2 * g1, -2 * g2, 0.05, 1.25)
    assert scale < 1.0
    s1 = exact_stability(com, th1 - 2 * g1 * scale * 0.05, th2 - 2 * g2 * scale * 0.05)
    assert s1 >= 1.25


def test_wheel_rows_are_the_wheel_map():
    G, lower, upper = np.zeros((2, 4)), np.zeros(2), np.zeros(2)
    WheelSpeedLimit(ROBOT).compute(_ctx([0] * 5), G, lower, upper, np.zeros(4), np.zeros(4))
    u = np.array([0.4, -1.3, 0.2, 0.1])
    assert G @ u == pytest.approx(ROBOT.wheel_speeds_from_u(0.4, -1.3), rel=1e-12)
    assert upper == pytest.approx([15.0, 15.0], rel=1e-5)
    assert lower == pytest.approx([-15.0, -15.0], rel=1e-5)


def test_joint_dampers_slow_a_joint_near_its_limit():
    robot = Robot(joint_limits=((-1.0, 1.0), (-2.0, 2.0)))
    lb, ub = np.full(4, -INF), np.full(4, INF)
    JointLimit(robot, gain=5.0, margin=0.02).compute(
        _ctx([0, 0, 0, 0.9, -1.99], robot=robot), None, None, None, lb, ub
    )
    assert ub[2] == pytest.approx(5.0 * (1.0 - 0.02 - 0.9))  # damped towards th1_max
    assert lb[2] == pytest.approx(-2.0, rel=1e-5)  # free the other way (speed limit)
    assert lb[3] > 0.0  # beyond the margin at th2_min: must move back
    assert lb[3] <= 0.5 * 2.0 + 1e-12


def _brute_clearance(hl, hw, x, y, phi, circle, n=4001):
    """Distance from densely sampled footprint outline points."""
    return outline_clearance(hl, hw, (x, y, phi), (circle.x, circle.y, circle.radius), n)


@pytest.mark.parametrize(
    ("x", "y", "phi", "circle"),
    [
        (0.0, 0.0, 0.0, Circle(1.0, 0.1, 0.3)),
        (0.2, -0.3, 0.7, Circle(-0.5, 0.6, 0.2)),
        (1.0, 1.0, -2.0, Circle(1.5, 1.3, 0.4)),
        (0.0, 0.0, 1.0, Circle(0.3, 0.4, 0.1)),
    ],
)
def test_clearance_matches_brute_force_and_its_rates_match_finite_differences(x, y, phi, circle):
    hl, hw = 0.225, 0.175
    d, a_v, a_w = clearance_and_rate(hl, hw, x, y, phi, circle)
    assert d == pytest.approx(_brute_clearance(hl, hw, x, y, phi, circle), abs=2e-4)
    assert footprint_clearances(hl, hw, [x], [y], [phi], [circle])[0] == pytest.approx(d)
    h = 1e-6  # drive forward by v h, then turn by w h: d changes by a_v v h + a_w w h
    forward = clearance_and_rate(hl, hw, x + h * math.cos(phi), y + h * math.sin(phi), phi, circle)
    turned = clearance_and_rate(hl, hw, x, y, phi + h, circle)
    assert a_v == pytest.approx((forward[0] - d) / h, abs=1e-5)
    assert a_w == pytest.approx((turned[0] - d) / h, abs=1e-5)


def test_overlap_is_negative_in_both_clearance_functions():
    circle = Circle(0.1, 0.0, 0.05)
    d, _, _ = clearance_and_rate(0.225, 0.175, 0.0, 0.0, 0.0, circle)
    assert d == pytest.approx(-(0.225 - 0.1) - 0.05)
    assert footprint_clearances(0.225, 0.175, [0.0], [0.0], [0.0], [circle])[0] == pytest.approx(d)


def test_load_obstacles_reads_circles(tmp_path):
    path = tmp_path / "obs.toml"
    path.write_text(
        "[[obstacle]]\nx = 1\ny = -2.5\nradius = 0.3\n[[obstacle]]\nx = 0\ny = 0\nradius = 1\n"
    )
    assert load_obstacles(path) == [Circle(1.0, -2.5, 0.3), Circle(0.0, 0.0, 1.0)]


@pytest.mark.parametrize(
    "text",
    [
        "[[obstacle]]\nx = 1\ny = 2\n",
        "[[obstacle]]\nx = 1\ny = 2\nradius = -1\n",
        "[[obstacle]]\nx = 'a'\ny = 2\nradius = 1\n",
        "obstacle = 3\n",
        "[[obstacle]\n",
        "[[circle]]\nx = 1\ny = 2\nradius = 1\n",
    ],
)
def test_bad_obstacle_files_raise_one_line_parameter_errors(tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match="obstacle") as info:
        load_obstacles(path)
    assert "\n" not in str(info.value)


def test_missing_obstacle_file():
    with pytest.raises(ParameterError, match="obstacles: cannot read"):
        load_obstacles("/nonexistent/obstacles.toml")


@pytest.mark.parametrize("th2", [0.3, 1.0, 2.0, -0.4, -2.8])
def test_manipulability_gradients_match_finite_differences(th2):
    h = 1e-7
    fd = (abs(math.sin(th2 + h)) - abs(math.sin(th2 - h))) / (2 * h)
    assert manipulability_gradient(th2) == pytest.approx(fd, rel=1e-6)
    fd2 = (math.sin(th2 + h) ** 2 - math.sin(th2 - h) ** 2) / (2 * h)
    assert eta_squared_gradient(th2) == pytest.approx(fd2, rel=1e-6)


@pytest.mark.parametrize(("th1", "th2"), [(0.2, 0.4), (-1.0, 2.0), (0.5, -1.2)])
def test_base_gradient_of_eta_squared_matches_finite_differences(th1, th2):
    """Move the base with the end effector fixed: eta^2 = 1 - cos(th2)^2 follows rho."""
    L1, L2 = ROBOT.L1, ROBOT.L2
    q = [0.3, -0.2, 0.4, th1, th2]
    ctx = _ctx(q)
    gx, gy = base_gradient(L1, L2, ctx)
    xe, ye, _ = ctx.pose_e

    def eta2(bx, by):
        rho2 = (xe - bx) ** 2 + (ye - by) ** 2
        c = (rho2 - L1**2 - L2**2) / (2 * L1 * L2)
        return 1.0 - c * c

    h = 1e-6
    assert gx == pytest.approx((eta2(0.3 + h, -0.2) - eta2(0.3 - h, -0.2)) / (2 * h), rel=1e-5)
    assert gy == pytest.approx((eta2(0.3, -0.2 + h) - eta2(0.3, -0.2 - h)) / (2 * h), rel=1e-5)
    assert 1.0 - math.cos(th2) ** 2 == pytest.approx(eta2(0.3, -0.2))


def test_manipulability_rows():
    task = ManipulabilityTask(weight=1.0, gain=2.0)
    jac, err = np.zeros((2, 4)), np.zeros(2)
    task.compute(_ctx([0, 0, 0, 0.0, 0.5], velocity_d=(0.3, 0.0, 0.0)), jac, err)
    assert jac[0] == pytest.approx([0, 0, 0, 2 * math.sin(0.5) * math.cos(0.5)])
    assert err[0] == pytest.approx(2.0 * (1 - math.sin(0.5) ** 2))
    assert jac[1] == pytest.approx([0, 1, 0, 0])


def test_end_effector_task_clips_feedback_and_drops_orientation():
    task = EndEffectorTask(tau=0.5, track_orientation=False, max_speed=0.5)
    jac, err = np.zeros((3, 4)), np.zeros(3)
    ctx = _ctx([0, 0, 0, 0, 0], pose_d=(10.0, 0.0, 1.0), velocity_d=(0.1, 0.0, 0.2))
    task.compute(ctx, jac, err)
    assert err[:2] == pytest.approx([0.1 + 0.5, 0.0])
    assert err[2] == 0.0 and not jac[2].any()
    assert jac[:2] == pytest.approx(ROBOT.jacobian(ctx.q)[:2] @ _input_matrix(0.0))


def _input_matrix(phi):
    from ddwmmr.model.kinematics import input_matrix

    return input_matrix(phi)


def test_end_effector_jacobian_is_j_times_b():
    ctx = _ctx([0.4, 0.1, 0.9, -0.3, 1.1])
    expected = ROBOT.jacobian(ctx.q)[:3] @ _input_matrix(0.9)
    assert ctx.jac_e == pytest.approx(expected, abs=1e-15)


def test_detour_aims_along_the_tangent_of_a_blocking_circle():
    from ddwmmr.qp.tasks import Detour

    detour = Detour([Circle(2.0, 0.1, 0.5)], inflate=0.3)
    assert detour.aim(0.0, 0.0, 4.0, 3.0) == (4.0, 3.0)  # clear way: the target itself
    ax, ay = detour.aim(0.0, 0.0, 4.0, 0.0)  # blocked; centre left of the way: pass right
    assert math.hypot(ax, ay) == pytest.approx(4.0)
    bearing = math.atan2(0.1, 2.0) - math.asin(0.8 / math.hypot(2.0, 0.1))
    assert math.atan2(ay, ax) == pytest.approx(bearing)
    # The aim ray just touches the inflated circle.
    t = 2.0 * math.cos(bearing) + 0.1 * math.sin(bearing)
    touch = (t * math.cos(bearing), t * math.sin(bearing))
    assert math.dist(touch, (2.0, 0.1)) == pytest.approx(0.8)


@pytest.mark.parametrize("th1", [0.3, 1.2, -1.4, 2.0])
def test_singularity_row_is_the_rate_of_its_margin(th1):
    from ddwmmr.qp.limits import ShoulderSingularityLimit

    limit = ShoulderSingularityLimit(margin=0.25, gain=5.0)
    G, lower, upper = np.zeros((1, 4)), np.zeros(1), np.zeros(1)
    limit.compute(_ctx([0, 0, 0, th1, 0.5]), G, lower, upper, None, None)

    def h(angle):
        return math.cos(angle) ** 2 - math.sin(0.25) ** 2

    step = 1e-6
    assert G[0, 2] == pytest.approx((h(th1 + step) - h(th1 - step)) / (2 * step), rel=1e-6)
    assert G[0, [0, 1, 3]] == pytest.approx([0, 0, 0])
    assert lower[0] == pytest.approx(min(-5.0 * h(th1), 0.5 * 2.0 * abs(G[0, 2])))
    assert h(th1) > 0 or lower[0] > 0  # inside the margin the row pushes back out


def test_a_start_pose_overlapping_an_obstacle_is_refused():
    """The footprint at the origin heading 0.3 rad: a circle centred 0.1 m ahead of its
    front edge (base_length / 2 along the heading) reaching 1 cm into it is refused with
    the overlap, one ending 1 cm short of it passes."""
    from ddwmmr.qp.limits.obstacles import Circle, check_start_clear

    robot = Robot()
    q = (0.0, 0.0, 0.3, 0.0, 1.0)
    centre = 0.5 * robot.base_length + 0.1
    x, y = centre * math.cos(0.3), centre * math.sin(0.3)
    inside = Circle(x, y, 0.11)
    clear = Circle(x, y, 0.09)
    check_start_clear(robot, [clear], q)
    with pytest.raises(
        ParameterError, match=r"obstacle 2 \(.*\) overlaps the robot's start pose by 0.01 m"
    ):
        check_start_clear(robot, [clear, inside], q)
