"""Support layouts other than the footprint's corners: a diamond (a caster ahead of and one
behind the axle, the wheels at the sides).

The edge-load model covers any polygon: on the diamond its loads are the closed form's and
MuJoCo's contact forces. So does the stability margin S, measured on the support polygon
(tests/test_polygon_stability.py): the MuJoCo plant builds every such layout without a
warning.
"""

import math
import warnings

import numpy as np
import pytest

from ddwmmr.model import Robot
from ddwmmr.model.stability import GRAVITY_M_S2, centre_of_mass, stability_terms
from ddwmmr.model.support_loads import EdgeLoadModel
from ddwmmr.plants.mujoco import MujocoPlant

#: Half-diagonals of the diamond (m): the casters at (+-A, 0), the wheels at (0, +-B).
A, B = 0.225, 0.175
DIAMOND = Robot(caster_positions=((A, 0.0), (-A, 0.0)), payload=2.5)
#: An arm pose the QP reached on the sideways reach with this robot when S was measured on
#: the footprint (1.78 there): S = 1.07 on the diamond, whose right-front edge keeps 3 % of
#: the weight.
POSE = (-0.839, 0.948)


def test_the_diamonds_edge_loads_are_the_closed_form():
    """Each edge of a rhombus has both supports off it at the full depth ``2 A B / hypot(A,
    B)``, so its load is the load on them: ``W d_e(c) / D`` with the centre of mass c."""
    model = EdgeLoadModel.from_robot(DIAMOND)
    depth = 2.0 * A * B / math.hypot(A, B)
    assert model.polygon.depths == pytest.approx([depth] * 4, abs=1e-12)
    x, y = centre_of_mass(DIAMOND.com_coefficients, *POSE)
    weight = DIAMOND.total_mass * GRAVITY_M_S2
    # signed distance from each edge line |x|/A + |y|/B = 1, in the quadrant it bounds
    expected = {
        (sx, sy): weight * (1.0 - sx * x / A - sy * y / B) * A * B / math.hypot(A, B) / depth
        for sx in (1, -1)
        for sy in (1, -1)
    }
    loads = model.static_loads(*POSE)
    for vertex, normal, load in zip(model.polygon.vertices, model.polygon.normals, loads):
        quadrant = (-int(np.sign(normal[0])), -int(np.sign(normal[1])))
        assert load == pytest.approx(expected[quadrant], abs=1e-9), vertex
    assert min(loads) == pytest.approx(4.78, abs=0.01)  # of 142.2 N


def test_mujoco_carries_the_diamonds_edge_loads_as_the_model_says():
    """At rest in the pose, the floor's normal forces on the supports off each edge sum to
    the model's edge load within 1 N (0.45 N measured; the tyres' lean moves the centre of
    mass by about a millimetre), with S on the diamond 1.07."""
    plant = MujocoPlant(DIAMOND)
    plant.reset(np.array([0.0, 0.0, 0.0, *POSE]), 0.02)
    forces, _ = plant.support_forces()
    model = EdgeLoadModel.from_robot(DIAMOND)
    points = [s.point for s in plant.supports]
    measured = model.polygon.off_edge(points) @ forces
    assert measured == pytest.approx(model.static_loads(*POSE), abs=1.0)
    assert stability_terms(DIAMOND.com_coefficients, *POSE)[2] == pytest.approx(1.072, abs=1e-3)
    assert min(measured) < 0.05 * DIAMOND.total_mass * GRAVITY_M_S2


@pytest.mark.parametrize(
    "casters",
    [
        None,  # the footprint's corners: the polygon is the footprint
        ((0.3, 0.2), (0.3, -0.2), (-0.3, 0.2), (-0.3, -0.2)),  # outriggers
        ((A, 0.0), (-A, 0.0)),  # the diamond
        ((A, B), (A, -B), (-A, 0.0)),  # a tricycle
        ((A, B), (A, -B), (-0.75 * A, B), (-0.75 * A, -B)),  # a short back
    ],
)
def test_every_layout_builds_silently(casters):
    """S is measured on the support polygon itself: nothing to warn about."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        MujocoPlant(Robot(caster_positions=casters))
