"""Every limit of the qp controller holds for every finite state.

Found before: at |x| = 1e12 the QP answer broke the joint-speed limit (the huge tracking
demand swamped the solver's tolerances), and the fallback could drive a joint further past
its limit. The property test below drives the controller with extreme but finite inputs
(positions up to 1e300, angles far outside [-pi, pi], joints at and over their limits,
stability far below the floor, absurd desired velocities) in every configuration, and
checks each command against the limits computed independently from the robot model.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddwmmr import Robot, make_controller
from ddwmmr.qp.limits import clearance_and_rate, exact_stability
from ddwmmr.qp.limits.obstacles import Circle

ROBOT = Robot().with_payload(3.0)
FLOOR = 1.25
#: Slew limits of the base-motion configuration (m/s^2, rad/s^2) and its caps.
ACCELERATION, YAW_ACCELERATION, BASE_SPEED, YAW_RATE = 1.5, 4.0, 0.8, 2.0
#: Joint damper gain (JointLimit default): one step of dt <= 1/gain never crosses a limit.
JOINT_GAIN = 5.0


def magnitude(low: float, high: float) -> st.SearchStrategy[float]:
    """Signed floats whose magnitude spans 10**low .. 10**high (and zero)."""
    return st.builds(
        lambda sign, exponent: sign * 10.0**exponent,
        st.sampled_from([-1.0, 1.0]),
        st.floats(low, high),
    ) | st.just(0.0)


def joint_angle(limits: tuple[float, float]) -> st.SearchStrategy[float]:
    """Angles inside, at, just beyond and far beyond a joint's limits."""
    low, high = limits
    return st.one_of(
        st.floats(low, high),
        st.sampled_from([low, high, low - 1e-9, high + 1e-9, low + 0.01, high - 0.01]),
        st.floats(high, high + 0.5),
        st.floats(low - 0.5, low),
        magnitude(0.0, 12.0),
    )


def configurations() -> st.SearchStrategy[dict]:
    return st.sampled_from(
        [
            {},
            {"mode": "hierarchical"},
            {"track_orientation": False, "max_speed": 1.0},
            {"singularity_margin": None, "manipulability_weight": 2.0},
            {
                "max_base_speed": BASE_SPEED,
                "max_yaw_rate": YAW_RATE,
                "max_acceleration": ACCELERATION,
                "max_yaw_acceleration": YAW_ACCELERATION,
            },
            {"obstacles": "near"},
        ]
    )


def _check_command(controller, q, u, dt, previous, circles) -> None:
    """Each limit, from the robot model (not from the controller's own rows)."""
    assert u.shape == (4,) and np.all(np.isfinite(u)), u
    v, w, r1, r2 = (float(value) for value in u)
    speed = ROBOT.joint_speed_limit
    assert abs(r1) <= speed and abs(r2) <= speed, (r1, r2)
    left, right = ROBOT.wheel_speeds_from_u(v, w)
    assert max(abs(left), abs(right)) <= ROBOT.wheel_speed_limit, (left, right)
    for angle, rate, (low, high) in zip(q[3:], (r1, r2), ROBOT.joint_limits):
        if angle >= high:
            assert rate <= 1e-9, ("further past the upper limit", angle, rate)
        if angle <= low:
            assert rate >= -1e-9, ("further past the lower limit", angle, rate)
        if low <= angle <= high:
            assert low - 1e-9 <= angle + dt * rate <= high + 1e-9, ("crosses", angle, rate)
    com = ROBOT.com_coefficients
    now = exact_stability(com, q[3], q[4])
    after = exact_stability(com, q[3] + dt * r1, q[4] + dt * r2)
    assert after >= min(FLOOR, now), ("stability", now, after)
    if getattr(controller, "base_motion", None) is not None:
        assert abs(v) <= BASE_SPEED and abs(w) <= YAW_RATE
        if previous is not None:
            assert abs(v - previous[0]) <= ACCELERATION * dt * (1 + 1e-9) + 1e-12
            assert abs(w - previous[1]) <= YAW_ACCELERATION * dt * (1 + 1e-9) + 1e-12
    hl, hw = 0.5 * ROBOT.base_length, 0.5 * ROBOT.base_width
    for circle in circles:
        d, rate_v, rate_w = clearance_and_rate(hl, hw, q[0], q[1], q[2], circle)
        if math.isfinite(d) and d < 0.05:  # within the margin: never closer
            assert rate_v * v + rate_w * w >= -1e-6, ("obstacle", d)


@settings(max_examples=500, deadline=None)
@given(
    options=configurations(),
    position=st.tuples(magnitude(-2.0, 14.0), magnitude(-2.0, 14.0))
    | st.tuples(magnitude(14.0, 300.0), magnitude(-2.0, 300.0)),
    heading=magnitude(-2.0, 13.0),
    th1=joint_angle(ROBOT.joint_limits[0]),
    th2=joint_angle(ROBOT.joint_limits[1]),
    target=st.tuples(magnitude(-2.0, 14.0), magnitude(-2.0, 14.0), magnitude(-2.0, 13.0))
    | st.tuples(magnitude(-2.0, 300.0), magnitude(-2.0, 300.0), magnitude(-2.0, 13.0)),
    relative_target=st.booleans(),
    velocity=st.tuples(magnitude(-3.0, 12.0), magnitude(-3.0, 12.0), magnitude(-3.0, 12.0)),
    previous=st.none() | st.tuples(st.floats(-BASE_SPEED, BASE_SPEED), st.floats(-2.0, 2.0)),
    dt=st.sampled_from([0.005, 0.02, 0.1, 1.0 / JOINT_GAIN]),
)
def test_every_limit_holds_for_extreme_finite_states(
    options, position, heading, th1, th2, target, relative_target, velocity, previous, dt
):
    q = np.array([*position, heading, th1, th2])
    circles = []
    if options.get("obstacles") == "near":  # one circle touching the footprint, one inside
        circles = [Circle(q[0] + 0.3, q[1], 0.1), Circle(q[0], q[1] - 0.1, 0.05)]
        if not all(math.isfinite(c.x) and math.isfinite(c.y) for c in circles):
            return
        options = {**options, "obstacles": circles}
    pose_d = np.array(target)
    if relative_target:  # a target near the robot: the tracking rows stay small
        pose_d = ROBOT.fk(q) + np.array(target) * 1e-300
    controller = make_controller("qp", ROBOT, stability_min=FLOOR, dt=dt, **options)
    controller.ctx.previous_command = previous
    u = controller.command(0.0, q, pose_d, np.array(velocity))
    _check_command(controller, q, u, dt, previous, circles)


@pytest.mark.parametrize(
    "q",
    [
        [1e12, -1e12, 0.3, -0.4, 0.9],  # found: th2dot 41.2 against the 7.79 rad/s limit
        [0.0, 0.0, 1e12, 50.0, -50.0],  # angles far outside [-pi, pi]
        [0.0, 0.0, 0.0, math.pi, -math.pi],  # both joints at a limit
        [0.0, 0.0, 0.0, 1.57, 0.0],  # stretched sideways: S = 1.0, far below 1.25
        [1.7e308, -1.7e308, 0.0, 0.3, 0.5],  # pose errors overflow to inf
    ],
)
@pytest.mark.parametrize("mode", ["weighted", "hierarchical"])
def test_named_extreme_states(q, mode):
    q = np.array(q)
    controller = make_controller("qp", ROBOT, stability_min=FLOOR, mode=mode, dt=0.02)
    for pose_d, velocity_d in (
        (np.zeros(3), np.array([0.1, 0.0, 0.0])),
        (np.array([-1e12, 1e12, 3.0]), np.array([1e9, -1e9, 1e9])),
    ):
        u = controller.command(0.0, q, pose_d, velocity_d)
        _check_command(controller, q, u, 0.02, None, [])


def test_huge_demands_still_give_a_qp_answer_not_a_fallback():
    """The bounded demand keeps the problem well scaled: a best effort, no safe stop."""
    controller = make_controller("qp", ROBOT, dt=0.02)
    q = np.array([1e12, -1e12, 0.3, -0.4, 0.9])
    u = controller.command(0.0, q, np.zeros(3), np.array([0.1, 0.0, 0.0]))
    assert not controller.last.fallback
    # Full speed towards the target, which lies along (-1, +1) from the base.
    direction = controller.ctx.jac_e[:2] @ u
    assert direction[0] < 0.0 < direction[1]
    assert np.linalg.norm(direction) > 0.5


def test_fallback_never_drives_a_joint_further_past_its_limit():
    """A contradictory user limit forces the fallback with th1 beyond its upper limit (the
    arm sideways, th1 = 3 pi / 2 + 0.2) and S = 1.05, far below the floor: there the
    stability gradient asks th1 to grow, further past its limit."""
    from ddwmmr.qp.limits import Limit, stability_terms_gradient

    class Impossible(Limit):
        def compute(self, ctx, G, lower, upper, lb, ub):
            lb[0], ub[0] = 1.0, -1.0

    th1, th2 = 1.5 * math.pi + 0.2, 0.2
    (s_lon, _, _), (s_lat, g1, g2) = stability_terms_gradient(ROBOT.com_coefficients, th1, th2)
    assert s_lat < 1.1 < FLOOR < s_lon and g1 > 0.0 and g2 > 0.0  # ascent: both rates up
    controller = make_controller("qp", ROBOT, limits=[Impossible()], dt=0.02)
    q = np.array([0.0, 0.0, 0.0, th1, th2])
    u = controller.command(0.0, q, ROBOT.fk(q), np.zeros(3))
    assert controller.last.fallback
    assert u[2] == 0.0  # th1 beyond its upper limit: held, not driven further out
    assert u[3] > 0.0  # th2 (within its limits) still raises S
    _check_command(controller, q, u, 0.02, None, [])
