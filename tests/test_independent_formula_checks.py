"""Formulas checked against independent computations from the raw robot description.

Each reference below is built from the robot's raw masses and lengths (links as uniform
rods, the payload a point mass at the end effector, the base's own centre of mass at the
base centre) and from the support polygon as ``scipy.spatial.ConvexHull`` finds it over
the wheels' and casters' contact points; none reuses the library's collected constants
(``mass.YawInertia``, ``ComCoefficients``, ``SupportEdges``). Checked:

* the arm's own angular momentum about the base centre, ``ThesisDynamics.arm_momentum``;
* the QP's stability rows (``StabilityLimit``): each row's gradient against a finite
  difference of the edge's moment ratio ``d / (n . c)``, and its bound
  ``min(damper, achievable)``, through ``compute`` and through the compiled writer;
* ``max_payload`` against the closed form: one linear equation per support edge.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment
from scipy.spatial import ConvexHull

from ddwmmr import Robot
from ddwmmr.errors import MASS_RANGE_KG
from ddwmmr.model.stability import STABILITY_CAP, max_payload
from ddwmmr.model.symbolic import ThesisDynamics
from ddwmmr.qp.blocks import LimitBlock
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits import StabilityLimit
from ddwmmr.qp.limits.base import INF
from scaled_robots import TWENTIETH

Vec = np.ndarray

#: Support layouts other than the default rectangle: casters on the x axis (a diamond
#: with the wheels) and one front caster with two at the back (a pentagon).
DIAMOND = Robot(caster_positions=((0.225, 0.0), (-0.225, 0.0))).with_payload(2.5)
PENTAGON = Robot(caster_positions=((0.3, 0.0), (-0.3, 0.1), (-0.3, -0.1))).with_payload(3.0)
OTHER_ARM = Robot(L1=0.5, L2=0.2, link_masses=(2.0, 0.7), payload=0.4, base_inertia=0.8)


# -- independent references -----------------------------------------------------------
def _cross(p: Vec, v: Vec) -> float:
    """z component of ``p x v`` (planar)."""
    return float(p[0] * v[1] - p[1] * v[0])


def _perp(a: Vec) -> Vec:
    """``a`` turned by +90 degrees: the velocity of a point at ``a`` turning at 1 rad/s."""
    return np.array([-a[1], a[0]])


def _rod_momentum(mass: float, p0: Vec, p1: Vec, v0: Vec, v1: Vec) -> float:
    """Angular momentum about the origin (kg m^2/s) of a uniform rigid rod from ``p0`` to
    ``p1`` with end velocities ``v0``, ``v1``: ``p x v`` is quadratic along the rod, so
    Simpson's rule over its ends and midpoint is exact."""
    middle = _cross((p0 + p1) / 2, (v0 + v1) / 2)
    return mass * (_cross(p0, v0) + 4.0 * middle + _cross(p1, v1)) / 6.0


def _arm_points(robot: Robot, th1: float, th2: float) -> tuple[Vec, Vec]:
    """Elbow and end effector (m, base frame)."""
    elbow = robot.L1 * np.array([math.cos(th1), math.sin(th1)])
    tip = elbow + robot.L2 * np.array([math.cos(th1 + th2), math.sin(th1 + th2)])
    return elbow, tip


def arm_momentum_of_rods(robot: Robot, th1: float, th2: float, r1: float, r2: float) -> float:
    """The arm's angular momentum about the base centre (kg m^2/s), base at rest, joint
    rates ``r1``, ``r2`` (rad/s): link 1 and link 2 as rods, the payload at the tip."""
    m1, m2 = robot.link_masses
    elbow, tip = _arm_points(robot, th1, th2)
    v_elbow = r1 * _perp(elbow)
    v_tip = v_elbow + (r1 + r2) * _perp(tip - elbow)
    origin = np.zeros(2)
    return (
        _rod_momentum(m1, origin, elbow, origin, v_elbow)
        + _rod_momentum(m2, elbow, tip, v_elbow, v_tip)
        + robot.payload * _cross(tip, v_tip)
    )


def first_moment(robot: Robot, th1: float, th2: float) -> tuple[Vec, float]:
    """The links' first mass moment about the base centre (kg m, base frame: each link's
    mass at its midpoint, the base's at the origin) and the mass without the payload (kg)."""
    m1, m2 = robot.link_masses
    elbow, tip = _arm_points(robot, th1, th2)
    moment = m1 * elbow / 2 + m2 * (elbow + tip) / 2
    return moment, robot.base_mass + m1 + m2


def com_of_masses(robot: Robot, th1: float, th2: float) -> Vec:
    """Whole robot's centre of mass (m, base frame) from the raw masses."""
    moment, unloaded = first_moment(robot, th1, th2)
    tip = _arm_points(robot, th1, th2)[1]
    return (moment + robot.payload * tip) / (unloaded + robot.payload)


def hull_edges(robot: Robot) -> list[tuple[Vec, float]]:
    """The support polygon's edges ``(n, d)``: outward unit normal and the distance of the
    edge's line from the base centre (m), from the convex hull of the wheels' contact
    points ``(0, +-track_width/2)`` and the casters'."""
    half = robot.track_width / 2
    points = np.array([(0.0, half), (0.0, -half), *robot.casters])
    return [(eq[:2].copy(), float(-eq[2])) for eq in ConvexHull(points).equations]


def moment_ratio(robot: Robot, edge: tuple[Vec, float], th1: float, th2: float) -> float:
    """The edge's ratio of counter to tipping moment ``d / (n . c)``, capped at
    ``STABILITY_CAP`` where the centre of mass does not face the edge that closely."""
    n, d = edge
    reach = float(n @ com_of_masses(robot, th1, th2))
    return d / reach if reach * STABILITY_CAP > d else STABILITY_CAP


def ratio_and_gradient(
    robot: Robot, edges: list[tuple[Vec, float]], th1: float, th2: float, h: float = 1e-6
) -> tuple[float, float, float]:
    """The least ratio over ``edges`` and its central finite-difference gradient (1/rad)."""

    def least(a: float, b: float) -> float:
        return min(moment_ratio(robot, e, a, b) for e in edges)

    g1 = (least(th1 + h, th2) - least(th1 - h, th2)) / (2 * h)
    g2 = (least(th1, th2 + h) - least(th1, th2 - h)) / (2 * h)
    return least(th1, th2), g1, g2


# -- arm momentum ---------------------------------------------------------------------
MOMENTUM_ROBOTS = [Robot(), Robot().with_payload(3.0), OTHER_ARM]


def _momentum_errors(model: ThesisDynamics, robot: Robot, seed: int) -> list[float]:
    """``|H_model - H_rods|`` relative to the arm's largest momentum scale, over random
    poses and joint rates."""
    rng = np.random.default_rng(seed)
    m1, m2 = robot.link_masses
    reach = robot.L1 + robot.L2
    errors = []
    for th1, th2, r1, r2 in rng.uniform(-3.0, 3.0, (200, 4)):
        scale = (m1 + m2 + robot.payload) * reach**2 * (abs(r1) + abs(r2))
        got = float(model.arm_momentum(th2, (r1, r2)))
        errors.append(abs(got - arm_momentum_of_rods(robot, th1, th2, r1, r2)) / scale)
    return errors


@pytest.mark.parametrize("robot", MOMENTUM_ROBOTS, ids=["default", "3kg", "other_arm"])
def test_arm_momentum_matches_rods(robot: Robot) -> None:
    """H = a th1dot + b (th1dot + th2dot) equals the rods' and payload's momentum about
    the base centre at any shoulder angle, to 1e-10 of the arm's momentum scale."""
    model = ThesisDynamics.from_robot(robot)
    assert max(_momentum_errors(model, robot, seed=158)) < 1e-10


@pytest.mark.parametrize("field", ["shoulder_fixed", "elbow_fixed", "inertia_cos"])
def test_arm_momentum_check_rejects_a_wrong_lever(field: str) -> None:
    """The comparison above has the power to see a lever 0.1 % off."""
    robot = Robot().with_payload(3.0)
    model = ThesisDynamics.from_robot(robot)
    wrong = dataclasses.replace(model, **{field: getattr(model, field) * 1.001})
    assert max(_momentum_errors(wrong, robot, seed=158)) > 1e-5


# -- QP stability rows ----------------------------------------------------------------
STABILITY_MIN, GAIN, MARGIN, JOINT_SPEED = 1.3, 4.0, 0.02, 1.5


def expected_rows(robot: Robot, th1: float, th2: float) -> list[tuple[float, float, float]]:
    """``(g1, g2, lower)`` of the rows the limit should have: one per support edge, or on
    the rectangle one per group (front/back edges, ``|n_x| >= |n_y|``; side edges), each
    the least ratio of its edges. The bound is ``min(damper, achievable)``; a capped term
    has no gradient and no bound."""
    edges = hull_edges(robot)
    if robot.com_coefficients.edges is None:  # the rectangle: two rows, lon then lat
        groups = [
            [e for e in edges if abs(e[0][0]) >= abs(e[0][1])],
            [e for e in edges if abs(e[0][0]) < abs(e[0][1])],
        ]
    else:
        groups = [[e] for e in edges]
    rows = []
    for group in groups:
        s_e, g1, g2 = ratio_and_gradient(robot, group, th1, th2)
        if s_e >= STABILITY_CAP:
            rows.append((0.0, 0.0, -INF))
            continue
        damper = -GAIN * (s_e - STABILITY_MIN - MARGIN)
        achievable = 0.5 * JOINT_SPEED * (abs(g1) + abs(g2))
        rows.append((g1, g2, min(damper, achievable)))
    return rows


def near_a_kink(robot: Robot, th1: float, th2: float) -> bool:
    """Whether a finite difference at this pose could straddle the cap of some edge."""
    c = com_of_masses(robot, th1, th2)
    return any(abs(float(n @ c) * STABILITY_CAP - d) < 1e-3 * d for n, d in hull_edges(robot))


def rows_by_compute(limit: StabilityLimit, robot: Robot, q: Vec) -> np.ndarray:
    """``(g1, g2, lower)`` of each row written by ``StabilityLimit.compute``."""
    ctx = StepContext(robot, 0.01)
    ctx.update(0.0, q, np.zeros(3), np.zeros(3))
    n = limit.rows
    G, lower, upper = np.zeros((n, 4)), np.zeros(n), np.zeros(n)
    limit.compute(ctx, G, lower, upper, np.full(4, -INF), np.full(4, INF))
    assert np.all(G[:, :2] == 0.0) and np.all(upper == INF)
    return np.column_stack([G[:, 2], G[:, 3], lower])


def rows_by_writer(limit: StabilityLimit, robot: Robot, q: Vec) -> np.ndarray:
    """``(g1, g2, lower)`` of each row written by the compiled writer the QP uses."""
    n = limit.rows
    matrix, lower, upper = np.full(4 * n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    block = LimitBlock(
        matrix=memoryview(matrix),
        rows=tuple(4 * r for r in range(n)),
        lower=memoryview(lower),
        upper=memoryview(upper),
        bounds=tuple(range(n)),
        box=[-INF] * 4 + [INF] * 4,
    )
    write = limit.compile(block)
    assert write is not None
    ctx = StepContext(robot, 0.01)
    ctx.update(0.0, q, np.zeros(3), np.zeros(3))
    write(ctx)
    G = matrix.reshape(n, 4)
    assert np.all(G[:, :2] == 0.0) and np.all(upper == INF)
    return np.column_stack([G[:, 2], G[:, 3], lower])


def matched_errors(got: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """Row-by-row errors after pairing each expected row with one library row (the
    library lists the edges in its own order): the pairing of least total error."""
    # a capped row's -INF bound as a finite sentinel, so that capped rows pair up
    got, expected = (np.where(np.isinf(a), -1e6, a) for a in (got, expected))
    cost = np.abs(expected[:, None, :] - got[None, :, :]) / (1.0 + np.abs(expected[:, None, :]))
    cost = cost.max(axis=2)
    rows, cols = linear_sum_assignment(cost)
    return cost[rows, cols]


LAYOUTS = {"default_3kg": Robot().with_payload(3.0), "diamond": DIAMOND, "pentagon": PENTAGON}


@pytest.mark.parametrize("writer", [rows_by_compute, rows_by_writer], ids=["compute", "writer"])
@pytest.mark.parametrize("name", list(LAYOUTS))
def test_stability_rows_match_hull_edges(name: str, writer) -> None:
    """Every row's gradient is the finite difference of its edge's ratio ``d / (n . c)``
    (convex hull edges, centre of mass from the raw masses) and its bound is ``min(-gain
    (S_e - S_min - margin), joint_speed (|g1| + |g2|) / 2)``, to 1e-6 relative."""
    robot = LAYOUTS[name]
    expected_count = 2 if name == "default_3kg" else len(hull_edges(robot))
    limit = StabilityLimit(robot.com_coefficients, STABILITY_MIN, GAIN, MARGIN, JOINT_SPEED)
    assert limit.rows == expected_count
    rng = np.random.default_rng(1580)
    checked = live = 0
    for th1, th2 in rng.uniform(-3.1, 3.1, (150, 2)):
        if near_a_kink(robot, th1, th2):
            continue
        q = np.array([0.3, -0.2, 0.7, th1, th2])
        expected = np.array(expected_rows(robot, th1, th2))
        assert matched_errors(writer(limit, robot, q), expected).max() < 1e-6
        checked += 1
        live += int(np.sum(expected[:, 2] > -INF))
    assert checked > 100 and live > checked  # most poses have live (uncapped) rows


# -- max_payload ----------------------------------------------------------------------
def payload_limit_closed_form(robot: Robot, th1: float, th2: float) -> float:
    """The payload (kg) that puts the centre of mass on the first support edge at this
    pose: with ``F`` the links' first moment, ``M0`` the unloaded mass and ``e`` the end
    effector, ``n . (F + p e) = d (M0 + p)`` per edge, the least root over the edges the
    end effector lies beyond (``n . e > d``); 0 when the robot tips unloaded, the top of
    the mass range when no edge limits it."""
    moment, unloaded = first_moment(robot, th1, th2)
    tip = _arm_points(robot, th1, th2)[1]
    limit = MASS_RANGE_KG[1]
    for n, d in hull_edges(robot):
        if n @ moment >= d * unloaded:
            return 0.0
        if n @ tip > d:
            limit = min(limit, (d * unloaded - n @ moment) / (n @ tip - d))
    return float(limit)


def rounding_step(limit: float) -> float:
    """The documented resolution of ``max_payload`` (kg): the gram from 1 kg, four
    significant digits below."""
    return min(1e-3, 10.0 ** (math.floor(math.log10(limit)) - 3))


POSES = [(math.pi / 2, 0.0), (0.0, 0.0), (-2.4, 0.3), (0.7, -1.1), (3.0, 0.2)]
PAYLOAD_ROBOTS = {"default": Robot(), "pentagon": PENTAGON, "twentieth": TWENTIETH}


@pytest.mark.parametrize("pose", POSES, ids=[f"{a:.2f},{b:.2f}" for a, b in POSES])
@pytest.mark.parametrize("name", list(PAYLOAD_ROBOTS))
def test_max_payload_matches_closed_form(name: str, pose: tuple[float, float]) -> None:
    """``max_payload`` is the closed-form limit rounded down by at most one step of its
    resolution (strictly below the limit: the limit itself has S = 1, which tips)."""
    robot = PAYLOAD_ROBOTS[name]
    exact = payload_limit_closed_form(robot, *pose)
    assert 0.0 < exact < MASS_RANGE_KG[1]
    got = max_payload(robot, *pose)
    step = rounding_step(exact)
    assert exact - step * (1 + 1e-6) <= got < exact


def test_max_payload_sideways_and_folded_closed_forms() -> None:
    """The default arm stretched sideways carries exactly ``(d M0 - F_y) / (y_e - d)`` =
    1.425 / 0.475 = 3 kg (reported 2.999: 3 kg has S = 1); folded back over the base no
    edge limits it (the top of the mass range)."""
    robot = Robot()
    assert payload_limit_closed_form(robot, math.pi / 2, 0.0) == pytest.approx(3.0, abs=1e-12)
    assert max_payload(robot, math.pi / 2, 0.0) == 2.999
    assert payload_limit_closed_form(robot, 0.0, math.pi) == MASS_RANGE_KG[1]
    assert max_payload(robot, 0.0, math.pi) == MASS_RANGE_KG[1]
