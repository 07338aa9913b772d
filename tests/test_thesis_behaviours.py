"""Each high-level behaviour and the low-level controllers of the thesis controller."""

from __future__ import annotations

import math

import pytest

from ddwmmr.behaviours import (
    BRAKE,
    DRIVE,
    TURN,
    BaseMover,
    Manipulability,
    Objective,
    ObstacleAvoidance,
    Stability,
    default_pose,
    sense,
)
from ddwmmr.model import Robot
from ddwmmr.plants.thesis import ThesisPlant, ThesisState
from ddwmmr.thesis_controller import ThesisController

ROBOT = Robot().with_payload(3.0)


def percept(q, target=(5.0, 0.0), v=0.0, w=0.0, hold=None):
    return sense(ROBOT, 0.0, q, v, w, target, hold)


def ee_world(p, arm):
    """End effector (world) if the arm were at joint targets ``arm`` with the base of p."""
    x, y, _ = ROBOT.fk([p.x, p.y, p.phi, arm[0], arm[1]])
    return x, y


# -- objective -----------------------------------------------------------------------------
def test_default_pose_has_best_manipulability_and_ee_ahead():
    th1, th2 = default_pose(ROBOT)
    assert abs(math.sin(th2)) == pytest.approx(1.0)
    xe, ye, _ = ROBOT.fk([0, 0, 0, th1, th2])
    assert (xe, ye) == pytest.approx((math.hypot(0.35, 0.30), 0.0), abs=1e-12)


def test_objective_drives_base_when_target_beyond_80_percent_of_reach():
    p = percept((0.0, 0.0, 0.3, 0.0, 1.0), target=(0.53, 0.0))  # 0.8 * 0.65 = 0.52
    out = Objective(ROBOT).propose(p)
    assert (out.mode, out.label, out.bx, out.by) == (DRIVE, "base", 0.53, 0.0)
    assert out.arm == default_pose(ROBOT)


def test_objective_reaches_with_arm_when_in_range():
    p = percept((1.0, 2.0, 0.7, 0.0, 1.0), target=(1.2, 2.4))
    out = Objective(ROBOT).propose(p)
    assert (out.mode, out.label) == (BRAKE, "arm")
    assert ee_world(p, out.arm) == pytest.approx((1.2, 2.4), abs=1e-12)
    assert out.arm[1] > 0  # keeps the elbow branch of th2 = 1.0


def test_objective_backs_off_when_target_inside_inner_radius():
    p = percept((0.0, 0.0, 0.0, 0.0, 1.0), target=(0.02, 0.0))
    out = Objective(ROBOT).propose(p)
    assert (out.mode, out.label) == (DRIVE, "base")
    assert out.bx < 0.0  # away from the target, behind the base
    assert math.hypot(out.bx - 0.02, out.by) == pytest.approx(0.5 * (0.05 + 0.52))


# -- manipulability -----------------------------------------------------------------------
def test_manipulability_outstretched_ahead_drives_forward_and_keeps_reaching():
    p = percept((0.0, 0.0, 0.0, 0.0, 0.3), target=(0.6, 0.1))
    out = Manipulability(ROBOT, adjust=0.5).propose(p)
    assert out.mode == DRIVE
    assert (out.bx, out.by) == pytest.approx((0.5, 0.0))
    assert ee_world(p, out.arm) == pytest.approx((0.6, 0.1), abs=1e-12)  # soft threshold


def test_manipulability_folded_moves_away():
    p = percept((0.0, 0.0, 0.0, -1.02, 2.5), target=(0.1, 0.0))
    out = Manipulability(ROBOT, adjust=0.5).propose(p)
    ex, ey = p.to_base(p.xe, p.ye)
    assert abs(math.atan2(ey, ex)) <= math.pi / 4  # end effector in the front quadrant
    assert (out.bx, out.by) == pytest.approx((-0.5, 0.0))


def test_manipulability_side_quadrant_targets_89_degrees():
    p = percept((0.0, 0.0, 0.5, 1.4, 0.4), target=(0.0, 1.0))  # EE to the left
    out = Manipulability(ROBOT, adjust=0.5).propose(p)
    bearing = math.atan2(out.by, out.bx) - 0.5
    assert bearing == pytest.approx(math.radians(89.0))


# -- stability ----------------------------------------------------------------------------
def test_stability_lateral_risk_turns_to_face_held_end_effector():
    q = (0.0, 0.0, 0.2, 1.45, 0.05)  # arm stretched to the left
    p = percept(q)
    assert p.s_lat < p.s_lon
    out = Stability(ROBOT).propose(p)
    assert out.mode == TURN
    facing = math.atan2(p.ye, p.xe)
    assert out.heading == pytest.approx(facing)
    assert ee_world(p, out.arm) == pytest.approx((p.xe, p.ye), abs=1e-12)


def test_stability_lateral_risk_behind_left_turns_the_short_way_to_reverse():
    q = (0.0, 0.0, 0.0, 2.0, 0.05)  # arm stretched back-left: face it with the rear
    p = percept(q)
    assert p.s_lat < p.s_lon
    out = Stability(ROBOT).propose(p)
    facing = math.atan2(p.ye, p.xe)
    assert out.heading == pytest.approx(facing - math.pi)
    assert abs(out.heading) < math.pi / 2


def test_stability_longitudinal_risk_drives_toward_end_effector():
    p_front = percept((1.0, 1.0, math.pi / 2, 0.05, 0.05), hold=None)
    out = Stability(ROBOT, adjust=0.5).propose(p_front)
    assert p_front.s_lon < p_front.s_lat
    assert (out.mode, out.bx, out.by) == (DRIVE, pytest.approx(1.0), pytest.approx(1.5))
    p_back = percept((0.0, 0.0, 0.0, math.pi - 0.05, 0.05))
    out = Stability(ROBOT, adjust=0.5).propose(p_back)
    assert (out.bx, out.by) == pytest.approx((-0.5, 0.0))


def test_stability_holds_the_latched_point_not_the_current_one():
    p = percept((0.1, 0.0, 0.0, 0.05, 0.05), hold=(0.7, 0.05))
    out = Stability(ROBOT).propose(p)
    assert ee_world(p, out.arm) == pytest.approx((0.7, 0.05), abs=1e-12)


# -- obstacle avoidance --------------------------------------------------------------------
def test_obstacle_in_the_way_gives_tangent_waypoint_on_target_side():
    avoid = ObstacleAvoidance(ROBOT, [(1.0, 0.0, 0.3)])
    out = avoid.propose(percept((0.0, 0.0, 0.0, 0.0, 1.0), target=(3.0, 0.5)))
    # bubble 0.285 + clearance 0.2 + r 0.3 = 0.785 < 1.0: out of range at rest
    assert out is None
    out = avoid.propose(percept((0.0, 0.0, 0.0, 0.0, 1.0), target=(3.0, 0.5), v=1.0))
    assert out is not None and out.mode == DRIVE
    # along = 1.0 - 0.3 - 0.2 = 0.5, lateral +2.5 * 0.3 (target on the left)
    assert (out.bx, out.by) == pytest.approx((0.5, 0.75))
    right = avoid.propose(percept((0.0, 0.0, 0.0, 0.0, 1.0), target=(3.0, -0.5), v=1.0))
    assert (right.bx, right.by) == pytest.approx((0.5, -0.75))


def test_obstacle_not_in_the_way_beyond_60_degrees():
    avoid = ObstacleAvoidance(ROBOT, [(0.6, 0.0, 0.3)])
    assert avoid.propose(percept((0.0, 0.0, 0.0, 0.0, 1.0), target=(0.0, 3.0))) is None
    assert avoid.propose(percept((0.0, 0.0, 0.0, 0.0, 1.0), target=(3.0, 1.5))) is not None


# -- low level ----------------------------------------------------------------------------
def test_mixer_eqs_4_8_4_9_and_rotation_priority():
    mover = BaseMover()
    assert mover.mix(6.0, 2.0) == pytest.approx((2.0, 4.0))
    left, right = mover.mix(40.0, 10.0)  # translation saturated, rotation kept
    assert right - left == pytest.approx(10.0)
    assert max(abs(left), abs(right)) == pytest.approx(10.0)


def test_drive_pd_gains_units():
    mover = BaseMover()
    p = percept((0.0, 0.0, 0.0, 0.0, 1.0), v=0.2, w=0.1)
    f_t, f_r = mover.drive_forces(p, 1.0, math.tan(math.radians(10.0)))
    assert f_t == pytest.approx(8.0 * 1.0 - 1.5 * 0.2)  # P 8 N/m, D 150 x 0.01 s
    assert f_r == pytest.approx(0.6 * 10.0 - 0.01 * math.degrees(0.1))  # per degree
    f_t, f_r = mover.drive_forces(p, -1.0, 0.0)  # behind: reverse, no turning
    assert f_t == pytest.approx(-8.0 - 0.3)
    assert f_r == pytest.approx(-0.01 * math.degrees(0.1))


def test_translation_step_response_meets_thesis_design_criterion():
    """Thesis 4.4.1: rise time about 3 s for small errors and no overshoot."""
    plant = ThesisPlant(ROBOT)
    mover = BaseMover()
    state = ThesisState(0.0, 0.0, 0.0, *default_pose(ROBOT))
    xs = []
    for _ in range(1500):
        p = sense(ROBOT, 0.0, state.q, state.v, state.w, None)
        f_t, f_r = mover.drive_forces(p, 0.1, 0.0)
        plant.advance(state, *mover.mix(f_t, f_r), default_pose(ROBOT), 0.01)
        xs.append(state.x)
    t10 = next(i for i, x in enumerate(xs) if x >= 0.01) * 0.01
    t90 = next(i for i, x in enumerate(xs) if x >= 0.09) * 0.01
    assert 2.0 < t90 - t10 < 4.5
    assert max(xs) < 0.1 * 1.03
    # second-order check: zeta = (c1 + D) / (2 sqrt(P m)), a 0.75-damped system
    zeta = (15.0 + 1.5) / (2.0 * math.sqrt(8.0 * plant.mass))
    assert 0.7 < zeta < 0.8


def test_controller_reaches_a_waypoint_on_the_plant():
    plant = ThesisPlant(ROBOT)
    controller = ThesisController(ROBOT)
    controller.reset((2.0, 1.0))
    state = ThesisState(0.0, 0.0, 0.0, *controller.default_pose)
    seen = set()
    for k in range(2000):
        forces = controller.act(k * 0.01, state.q, state.v, state.w)
        seen.add(controller.state)
        plant.advance(state, forces[0], forces[1], forces[2:], 0.01)
    xe, ye, _ = ROBOT.fk(list(state.q))
    assert math.hypot(xe - 2.0, ye - 1.0) < 1e-3
    assert seen == {"move_base", "move_arm"}
