"""Mass properties (ddwmmr.model.mass): the whole robot's mass, its yaw inertia and the
arm's own levers, against point masses summed independently; the stability floor's check."""

import math

import pytest

from ddwmmr import ParameterError, Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.mass import YawInertia
from ddwmmr.model.stability import (
    STABILITY_CAP,
    STABILITY_FLOOR,
    check_stability_floor,
    com_coefficients,
    inertial_terms,
)
from ddwmmr.plants.thesis import ThesisPlant

#: A robot with no round numbers, so that no term hides behind another.
ODD = Robot(
    L1=0.41,
    L2=0.27,
    base_mass=12.3,
    base_inertia=0.61,
    link_masses=(1.7, 0.9),
    payload=2.2,
    wheel_mass=0.8,
)


def _points(robot: Robot, th1: float, th2: float, n: int = 4000):
    """``(mass, x, y)`` of the arm as point masses: n along each link, the payload at the
    end effector (base frame, shoulder at the origin)."""
    m1, m2 = robot.link_masses
    elbow = (robot.L1 * math.cos(th1), robot.L1 * math.sin(th1))
    points = []
    for length, mass, start, angle in (
        (robot.L1, m1, (0.0, 0.0), th1),
        (robot.L2, m2, elbow, th1 + th2),
    ):
        for i in range(n):
            s = (i + 0.5) / n * length
            points.append(
                (mass / n, start[0] + s * math.cos(angle), start[1] + s * math.sin(angle))
            )
    c12, s12 = math.cos(th1 + th2), math.sin(th1 + th2)
    points.append((robot.payload, elbow[0] + robot.L2 * c12, elbow[1] + robot.L2 * s12))
    return points


@pytest.mark.parametrize("robot", [Robot(), Robot().with_payload(3.0), ODD])
def test_total_mass_is_every_body(robot):
    m1, m2 = robot.link_masses
    assert robot.total_mass == pytest.approx(robot.base_mass + m1 + m2 + robot.payload)
    assert robot.base_body_mass + 2 * robot.wheel_mass == pytest.approx(robot.base_mass)
    arm = sum(m for m, _, _ in _points(robot, 0.3, 0.2))
    assert robot.total_mass == pytest.approx(robot.base_mass + arm, rel=1e-12)


@pytest.mark.parametrize("th1, th2", [(0.0, 0.0), (0.4, -1.1), (-2.0, 2.9)])
def test_yaw_inertia_against_point_masses(th1, th2):
    """Both forms of I(th2) (per body and collected) vs the arm as point masses."""
    inertia = ODD.yaw_inertia
    total = ODD.base_inertia + sum(m * (x * x + y * y) for m, x, y in _points(ODD, th1, th2))
    assert inertia.at(th2) == pytest.approx(total, rel=1e-6)
    assert inertia.fixed + inertia.cos * math.cos(th2) == pytest.approx(total, rel=1e-6)


def test_arm_levers_against_point_masses():
    """The shoulder lever is the arm's inertia about the shoulder with the elbow straight
    less the parts the elbow term and the pose-dependent term carry; the elbow lever is
    link 2 and the payload about the elbow."""
    m2 = ODD.link_masses[1]
    inertia = ODD.yaw_inertia
    elbow_x = ODD.L1
    about_elbow = sum(
        m * ((x - elbow_x) ** 2 + y * y) for m, x, y in _points(ODD, 0.0, 0.0) if x >= elbow_x
    )
    assert inertia.elbow == pytest.approx(about_elbow, rel=1e-6)
    link1 = sum(m * x * x for m, x, _ in _points(ODD, 0.0, 0.0) if x < elbow_x)
    assert inertia.shoulder == pytest.approx(link1 + (m2 + ODD.payload) * ODD.L1**2, rel=1e-6)


def test_every_user_reads_the_one_home():
    """The thesis plant, the symbolic model and the stability margin take their mass and
    inertia from Robot (the same numbers, to the bit)."""
    plant = ThesisPlant(ODD)
    dynamics = sym.ThesisDynamics.from_robot(ODD)
    inertia = YawInertia.of(ODD)
    assert plant.mass == dynamics.mass == ODD.total_mass
    assert (dynamics.inertia_fixed, dynamics.inertia_cos) == (inertia.fixed, inertia.cos)
    assert (dynamics.shoulder_fixed, dynamics.elbow_fixed) == (inertia.shoulder, inertia.elbow)
    for th2 in (0.0, 1.3, -2.2):
        assert plant.inertia(0.7, th2) == inertia.at(th2)
        assert dynamics.inertia(th2) == pytest.approx(inertia.at(th2), rel=1e-14)
    assert inertial_terms(ODD).weight == pytest.approx(ODD.total_mass * 9.81)
    m1, m2 = ODD.link_masses
    k = com_coefficients(ODD.L1, ODD.L2, m1, m2, ODD.payload, ODD.base_mass, 0.4, 0.3)
    expected = (0.5 * m2 + ODD.payload) * ODD.L2 / ODD.total_mass
    lever = k.B
    assert lever == pytest.approx(expected)


def test_stability_floor_default_and_range():
    assert 1.0 < STABILITY_FLOOR < STABILITY_CAP
    assert check_stability_floor(1.4) == 1.4
    assert check_stability_floor(9.99) == 9.99
    with pytest.raises(ParameterError, match=r"stability_min must be in \(0, 10\) \(got 0\)"):
        check_stability_floor(0.0)
    with pytest.raises(ParameterError, match=r"floor must be in \(0, 10\) \(got 10\)"):
        check_stability_floor(STABILITY_CAP, "floor")
