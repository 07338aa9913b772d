"""The obstacle row beside the middle of a footprint side, where no input changes the
clearance to first order (its rates are rounding noise): no approach, no demanded escape,
and every backend gives the same command."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.controller import QPController
from ddwmmr.qp.limits import Circle
from ddwmmr.qp.limits.obstacles import ObstacleLimit, clearance_and_rate
from ddwmmr.qp.solve import MODES

ROBOT = Robot()
#: The ellipse's start pose; CIRCLE is level with the base centre, 20 mm from the
#: footprint's left side (within the 50 mm margin): rates (-0.0, -1.3e-8 m).
Q0 = np.array([1.8023751343117378, -0.5888674652183874, 1.2707963267948967, -0.4378558, 0.7639293])
CIRCLE = Circle(1.5205509, -0.501689, 0.1)


def _context(q: np.ndarray) -> StepContext:
    ctx = StepContext(ROBOT, 0.02)
    ctx.x, ctx.y, ctx.phi = (float(v) for v in q[:3])
    return ctx


def test_the_pose_is_degenerate_within_the_margin():
    d, a_v, a_w = clearance_and_rate(0.225, 0.175, *Q0[:3], CIRCLE)
    assert d == pytest.approx(0.02, abs=1e-6)
    assert abs(a_v) < 1e-12 and 0.0 < abs(a_w) < 1e-7


def test_a_degenerate_row_asks_no_escape():
    """The row was (-0, -1.3e-8 m) >= 1.1e-8 m/s: a quarter of the top yaw rate for 1e-8
    m/s of clearance. Now the same half-plane with a unit gradient and bound 0."""
    a_v, a_w, lower = ObstacleLimit(ROBOT, [CIRCLE]).row(_context(Q0), CIRCLE)
    assert np.hypot(a_v, a_w) == pytest.approx(1.0)
    assert a_w == pytest.approx(-1.0)
    assert lower == 0.0


def test_a_well_conditioned_row_keeps_its_damper():
    """Driving at the circle: the rates and the damper bound as they always were."""
    circle = Circle(Q0[0] + 0.35 * np.cos(Q0[2]), Q0[1] + 0.35 * np.sin(Q0[2]), 0.1)
    limit = ObstacleLimit(ROBOT, [circle])
    d, a_v, a_w = clearance_and_rate(0.225, 0.175, *Q0[:3], circle)
    reach = abs(a_v) * limit.v_max + abs(a_w) * limit.w_max
    assert limit.row(_context(Q0), circle) == (a_v, a_w, min(-2.0 * (d - 0.05), 0.25 * reach))


@pytest.mark.parametrize("mode", MODES)
def test_every_backend_gives_the_same_command_beside_a_side(mode):
    """DAQP, the default, reported no solution here; the others spun the base or not."""
    trajectory = load_trajectory("ellipse")
    pose, velocity = (a[0] for a in trajectory.sample(np.array([0.0])))
    commands = {}
    for solver in ("daqp", "quadprog", "osqp", "proxqp", "clarabel", "qpsolvers-daqp"):
        controller = QPController(ROBOT, mode=mode, solver=solver, obstacles=[CIRCLE])
        commands[solver] = controller.command(0.0, Q0, pose, velocity)
        assert not controller.last.fallback, solver
    for solver, command in commands.items():
        assert command == pytest.approx(commands["daqp"], abs=2e-3), solver
    assert abs(commands["daqp"][0]) > 0.2  # it drives (the base used to stand still)


def test_daqp_tracks_beside_the_obstacle_without_fallbacks():
    """It fell back on every step (the base never moved); now no step does."""
    run = simulate(ROBOT, load_trajectory("ellipse"), "qp", duration=0.4, obstacles=[CIRCLE])
    assert run.summary["qp_fallbacks"] == 0
    assert run.summary["min_obstacle_clearance_m"] > 0.018
