"""The wheel-force limit for the qp on the thesis plant (qp/limits/wheel_forces.py)."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.model.symbolic import ThesisDynamics
from ddwmmr.plants.thesis import ThesisPlant, ThesisState
from ddwmmr.plants.thesis import VelocityServo as VelocityLoop
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import INF
from ddwmmr.qp.limits.wheel_forces import WheelForceLimit


def test_rows_are_the_velocity_loop_wheel_forces(rng):
    """G u + offset equals the (unclipped) wheel forces of the scenario velocity loop when
    the base moves at the previous command; the bounds are the force limit."""
    robot = Robot().with_payload(3.0)
    dynamics = ThesisDynamics.from_robot(robot)
    limit = WheelForceLimit(dynamics, fraction=1.0)
    loop = VelocityLoop(ThesisPlant(robot))
    ctx = StepContext(robot, 0.01)
    G, lower, upper = np.zeros((2, 4)), np.zeros(2), np.zeros(2)
    lb, ub = np.full(4, -INF), np.full(4, INF)
    for _ in range(50):
        q = rng.uniform(-3.0, 3.0, 5)
        v, w = rng.uniform(-0.3, 0.3), rng.uniform(-0.2, 0.2)
        v_d, w_d = v + rng.uniform(-0.05, 0.05), w + rng.uniform(-0.05, 0.05)
        ctx.update(0.0, q, np.zeros(3), np.zeros(3))
        ctx.previous_command = (v, w)
        limit.compute(ctx, G, lower, upper, lb, ub)
        forces = loop.forces(ThesisState(*q, v, w), v_d, w_d)  # small: no clipping
        u = np.array([v_d, w_d, 0.3, -0.2])
        rows = G @ u
        # bounds are -F_max - offset and F_max - offset, the force is row + offset
        np.testing.assert_allclose(rows - forces, (lower + upper) / 2.0, atol=1e-9)
        np.testing.assert_allclose((upper - lower) / 2.0, dynamics.force_limit)
    ctx.previous_command = None
    limit.compute(ctx, G, lower, upper, lb, ub)
    assert np.all(lower == -INF) and np.all(upper == INF)


def test_bad_bandwidth_is_a_parameter_error():
    from ddwmmr import ParameterError

    with pytest.raises(ParameterError, match="bandwidth must be > 0"):
        WheelForceLimit(ThesisDynamics.from_robot(Robot()), bandwidth=0.0)
