"""The qp's stability rows and recovery on a support polygon's ridges.

Where two edges of the polygon meet, S (the least ``d_e / (n_e . c)``) has a ridge. A row
on each group's active edge alone let the other edge of the group fall through the floor
within a step, and a recovery up the active edge's gradient froze on the ridge. The limit
has a row per edge and the recovery raises every edge below the floor
(:mod:`ddwmmr.qp.limits.stability`, docs/qp.md "Limits").
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq

from ddwmmr import Robot, load_trajectory, make_controller, simulate
from ddwmmr.model.stability import STABILITY_CAP, STABILITY_FLOOR, stability_terms
from ddwmmr.qp import QPProblem
from ddwmmr.qp.limits import safe_arm_scale, stability_terms_gradient
from ddwmmr.qp.limits.stability import (
    StabilityLimit,
    ascent_direction,
    stability_rows,
)

DIAMOND = ((0.225, 0.0), (-0.225, 0.0))
TRICYCLE = ((0.225, 0.175), (0.225, -0.175), (-0.225, 0.0))
PENTAGON = ((0.3, 0.0), (0.1, 0.25), (-0.2, 0.15), (-0.2, -0.15), (0.1, -0.25))


def s_of(k, th1: float, th2: float) -> float:
    return stability_terms(k, th1, th2)[2]


def ridge_pose(k, margin: float) -> tuple[float, float]:
    """The diamond's ridge case: the centre of mass straight to the left (+y) at S = the
    damper's target + 0.002, then 1 mrad past the ridge (x < 0)."""
    target = STABILITY_FLOOR + margin

    def heading(th2: float) -> float:
        return math.atan2(k.B * math.sin(th2), k.A + k.B * math.cos(th2))

    th2 = brentq(lambda t: s_of(k, math.pi / 2 - heading(t), t) - (target + 0.002), 0.0, 2.5)
    return math.pi / 2 - heading(th2) + 0.001, th2


def closest_rates(wanted, rows, lower, bound: float) -> np.ndarray:
    """The joint rates nearest ``wanted`` (rad/s) with ``rows @ u >= lower`` and
    ``|u_i| <= bound``: the least-distance QP in the plane, solved exactly by its
    candidates (the point itself, its projection on one constraint, two constraints'
    intersection)."""
    wanted = np.asarray(wanted, dtype=float)
    lines = [(np.asarray(g, dtype=float), b) for g, b in zip(rows, lower) if b > -1e20]
    lines += [(np.array(e), -bound) for e in ((1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0))]
    candidates = [wanted]
    for g, b in lines:
        candidates.append(wanted + (b - g @ wanted) / (g @ g) * g)
    for i, (g, b) in enumerate(lines):
        for h, c in lines[i + 1 :]:
            matrix = np.array([g, h])
            if abs(np.linalg.det(matrix)) > 1e-12:
                candidates.append(np.linalg.solve(matrix, [b, c]))
    feasible = [u for u in candidates if all(g @ u >= b - 1e-12 for g, b in lines)]
    return min(feasible, key=lambda u: float(np.sum((u - wanted) ** 2)))


def test_the_rows_hold_the_floor_across_the_diamonds_ridge():
    """At the ridge the old lateral row (its active edge's) allowed (-2, 0) rad/s, after
    which S was 1.2438 < 1.25 and the look-ahead halved the rate. With a row per edge the
    QP's rates keep S above the floor at the next sample on their own."""
    robot = Robot(caster_positions=DIAMOND).with_payload(2.5)
    k, dt = robot.com_coefficients, 0.01
    limit = StabilityLimit(k, joint_speed=robot.joint_speed_limit)
    th1, th2 = ridge_pose(k, limit.margin)
    assert s_of(k, th1, th2) == pytest.approx(1.2610, abs=1e-4)
    assert limit.rows == 4
    terms = stability_rows(k, th1, th2)
    rows = [(g1, g2) for _, g1, g2 in terms]
    lower = [limit.lower_bound(*term) for term in terms]
    r1, r2 = closest_rates((-2.0, 0.0), rows, lower, robot.joint_speed_limit)
    after = s_of(k, th1 + dt * r1, th2 + dt * r2)
    assert after >= STABILITY_FLOOR
    assert safe_arm_scale(k, th1, th2, r1, r2, dt, STABILITY_FLOOR) == 1.0
    assert r1 < -0.5  # th1 still turns the way it was asked to (th2 makes up for it)
    # started above the damper's target (S_min + margin), S stays above it: the margin holds
    assert after >= STABILITY_FLOOR + limit.margin


def test_the_recovery_leaves_the_tricycles_ridge():
    """From S 1.076 the recovery (the qp's fallback) used to climb its active edge onto a
    ridge at S 1.153 and stop there (scale 0 forever). Raising every edge below the floor
    reaches the floor within 1 s and never lowers S. (The pose is the review's ``(pi +
    0.3, -0.6)`` with th1 inside the joint range.)"""
    robot = Robot(caster_positions=TRICYCLE).with_payload(4.0)
    k = robot.com_coefficients
    controller = make_controller("qp", robot, dt=0.02)
    ctx = controller.ctx
    q = [0.0, 0.0, 0.0, -math.pi + 0.3, -0.6]
    s = s_of(k, q[3], q[4])
    assert s == pytest.approx(1.076, abs=1e-3)
    for _ in range(50):  # 1 s
        ctx.update(0.0, np.array(q), np.zeros(3), np.zeros(3))
        _, _, r1, r2 = controller._fallback(ctx)
        q[3] += ctx.dt * r1
        q[4] += ctx.dt * r2
        after = s_of(k, q[3], q[4])
        assert after >= s - 1e-12
        s = after
        if s >= STABILITY_FLOOR:
            break
    assert s >= STABILITY_FLOOR


@pytest.mark.parametrize(
    ("th1", "th2", "before"), [(-math.pi + 0.3, -0.6, 28), (math.pi - 0.4, 0.7, 24)]
)
def test_a_qp_run_from_below_the_floor_leaves_the_tricycles_ridges(th1, th2, before):
    """The whole controller (rows, look-ahead and recovery) on the ellipse, starting 0.5 m
    behind it with S 1.076 and 1.025: S rises every sample and reaches the floor at
    sample 15 and 11 (with a row and a recovery on the active edges only: 28 and 24,
    creeping along a ridge), and stays above it."""
    robot = Robot(caster_positions=TRICYCLE).with_payload(4.0)
    trajectory = load_trajectory("ellipse")
    x, y, phi = trajectory.pose(0.0)
    start = np.array([x - 0.5, y, phi, th1, th2])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # the start is below the floor
        result = simulate(robot, trajectory, "qp", duration=1.0, dt=0.02, q0=start)
    s = np.asarray(result.timeseries["stability"])
    first = int(np.argmax(s >= STABILITY_FLOOR))
    assert 0 < first <= 16 < before
    assert np.all(np.diff(s[: first + 1]) > 0.0)
    assert np.all(s[first:] >= STABILITY_FLOOR)


@pytest.mark.parametrize("casters", [DIAMOND, TRICYCLE, PENTAGON], ids=["d", "t", "p"])
def test_every_rows_gradient_matches_finite_differences(casters):
    """Each row's term is its edge's ``d / (n . c)`` (uncapped where it faces c) and its
    gradient that term's central difference; S is the least term."""
    robot = Robot(caster_positions=casters).with_payload(3.0)
    k = robot.com_coefficients
    edges = (*k.edges.lon, *k.edges.lat)
    rng = np.random.default_rng(3)
    h, checked = 1e-6, 0

    def term(edge, th1, th2):
        x = k.A * math.cos(th1) + k.B * math.cos(th1 + th2)
        y = k.A * math.sin(th1) + k.B * math.sin(th1 + th2)
        return edge[2] / (edge[0] * x + edge[1] * y)

    for th1, th2 in rng.uniform(-math.pi, math.pi, (150, 2)):
        terms = stability_rows(k, th1, th2)
        assert len(terms) == len(edges)
        assert min(t[0] for t in terms) == pytest.approx(s_of(k, th1, th2), abs=1e-12)
        for edge, (s_e, g1, g2) in zip(edges, terms):
            if s_e >= STABILITY_CAP:
                assert (g1, g2) == (0.0, 0.0)
                continue
            checked += 1
            d1 = (term(edge, th1 + h, th2) - term(edge, th1 - h, th2)) / (2 * h)
            d2 = (term(edge, th1, th2 + h) - term(edge, th1, th2 - h)) / (2 * h)
            assert s_e == pytest.approx(term(edge, th1, th2), rel=1e-14)
            assert (g1, g2) == pytest.approx((d1, d2), rel=1e-6, abs=1e-6)
    assert checked > 200


def test_the_diamonds_compiled_rows_are_the_generic_ones():
    robot = Robot(caster_positions=DIAMOND).with_payload(2.5)
    controller = make_controller("qp", robot)
    generic = QPProblem(controller.tasks, controller.limits, compiled=False)
    ctx = controller.ctx
    for th1, th2 in ((1.1752, 1.0413), (math.pi + 0.3, -0.6), (0.2, 0.1)):
        ctx.update(0.0, np.array([0.1, 0.2, 0.3, th1, th2]), np.ones(3), np.zeros(3))
        controller.problem.build(ctx)
        generic.build(ctx)
        for name in ("C", "lower", "upper"):
            fast, slow = getattr(controller.problem, name), getattr(generic, name)
            assert fast.tobytes() == slow.tobytes(), name


def test_the_rectangle_keeps_its_two_rows_and_recovery():
    """The default robot: the rows are the two terms, float for float, and the recovery's
    direction the summed unit gradients of the terms below the target."""
    k = Robot().with_payload(3.0).com_coefficients
    assert StabilityLimit(k).rows == 2
    rng = np.random.default_rng(5)
    for th1, th2 in rng.uniform(-math.pi, math.pi, (200, 2)):
        terms = stability_terms_gradient(k, th1, th2)
        assert stability_rows(k, th1, th2) == terms
        r1 = r2 = 0.0
        for s_i, g1, g2 in terms:
            norm = math.hypot(g1, g2)
            if s_i < 1.26 and norm > 0.0:
                r1 += g1 / norm
                r2 += g2 / norm
        assert ascent_direction(terms, 1.26) == (r1, r2)


def test_the_ascent_raises_three_edges_where_the_summed_directions_would_not():
    """Three terms below the target whose unit gradients (at 0, 130 and 130 degrees) sum
    to a direction lowering the first: the least-norm direction raising each at unit rate
    is used instead; none when the gradients surround the origin."""
    c, s = math.cos(math.radians(130.0)), math.sin(math.radians(130.0))
    terms = ((1.0, 1.0, 0.0), (1.1, c, s), (1.2, c, s), (1.3, 0.0, -5.0))
    d1, d2 = ascent_direction(terms, 1.26)
    assert (d1, d2) == pytest.approx((1.0, (1.0 - c) / s), rel=1e-12)
    assert 1.0 + 2.0 * c < 0.0  # the summed unit gradients would lower the first term
    terms = ((1.0, 1.0, 0.0), (1.0, -0.6, 0.8), (1.0, -0.6, -0.8))
    assert ascent_direction(terms, 1.26) == (0.0, 0.0)
    assert ascent_direction(terms, 1.0) == (0.0, 0.0)  # none below the target
