"""The compiled (fast) path builds exactly the generic path's problem, and user pieces plug in.

Every built-in task and limit fills its rows twice: through ``compute`` on numpy views (the
generic interface a user's piece implements) and through the writer its ``compile``
returns. The two must give the same arrays to the last bit: the solver then returns the
same command, and the recorded runs (tests/test_golden.py) stay unchanged.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddwmmr import Robot, make_controller
from ddwmmr.qp import QPProblem
from ddwmmr.qp.blocks import CONSTANT
from ddwmmr.qp.limits import Circle, JointLimit, Limit, full_step_is_safe, safe_arm_scale
from ddwmmr.qp.tasks import EndEffectorTask, PostureTask, Task

ROBOT = Robot().with_payload(3.0)
OBSTACLES = [Circle(0.8, 0.3, 0.25), Circle(-0.4, -0.9, 0.4)]

CONFIGS = {
    "default": {},
    "position only": {"track_orientation": False, "max_speed": 1.0},
    "obstacles": {"obstacles": OBSTACLES},
    "base motion": {
        "max_base_speed": 0.6,
        "max_yaw_rate": 1.2,
        "max_acceleration": 1.0,
        "max_yaw_acceleration": 3.0,
        "speed_budget": (0.9, 1.5),
        "dt": 0.02,
    },
    "no singularity limit": {"singularity_margin": None, "manipulability_weight": 0.0},
    "full posture": {"tasks": [PostureTask(0.3, K1=1.0, K2=0.25, K3=0.66)]},
}

ARRAYS = ("H", "f", "C", "lower", "upper", "sense")

state = st.tuples(
    st.floats(-5.0, 5.0),
    st.floats(-5.0, 5.0),
    st.floats(-20.0, 20.0),
    st.floats(-4.0, 4.0),
    st.floats(-4.0, 4.0),
)
pose = st.tuples(st.floats(-5.0, 5.0), st.floats(-5.0, 5.0), st.floats(-10.0, 10.0))
rate = st.tuples(st.floats(-2.0, 2.0), st.floats(-2.0, 2.0), st.floats(-2.0, 2.0))


def _problems(options: dict) -> tuple:
    controller = make_controller("qp", ROBOT, **options)
    generic = QPProblem(controller.tasks, controller.limits, compiled=False)
    return controller, generic


@settings(max_examples=60, deadline=None)
@given(
    name=st.sampled_from(sorted(CONFIGS)),
    q=state,
    pose_d=pose,
    velocity_d=rate,
    previous=st.none() | st.tuples(st.floats(-1.0, 1.0), st.floats(-2.0, 2.0)),
)
def test_compiled_writers_fill_the_generic_arrays_bit_for_bit(
    name, q, pose_d, velocity_d, previous
):
    controller, generic = _problems(CONFIGS[name])
    ctx = controller.ctx
    ctx.update(0.0, np.array(q), np.array(pose_d), np.array(velocity_d))
    ctx.previous_command = previous
    controller.problem.build(ctx)
    generic.build(ctx)
    for array in ARRAYS:
        fast, slow = getattr(controller.problem, array), getattr(generic, array)
        assert fast.tobytes() == slow.tobytes(), array
    assert controller.problem.box_consistent() == generic.box_consistent()


def test_every_built_in_piece_is_compiled():
    controller, _ = _problems(
        {**CONFIGS["obstacles"], **CONFIGS["base motion"], "track_orientation": False}
    )
    problem = controller.problem
    assert problem._all_compiled
    names = {type(p).__name__ for p in problem.tasks + problem.limits}
    assert {
        "HeadingTask",
        "ObstacleSteeringTask",
        "BaseMotionLimit",
        "SpeedBudgetLimit",
        "ObstacleLimit",
    } <= names


class _Spin(Task):
    """A user task (generic interface only): yaw at 0.5 rad/s."""

    name = "spin"

    def compute(self, ctx, jac, error):
        jac[:] = (0.0, 1.0, 0.0, 0.0)
        error[0] = 0.5


class _SlowArm(Limit):
    """A user limit with one row and a box bound."""

    rows = 1

    def compute(self, ctx, G, lower, upper, lb, ub):
        G[0] = (0.0, 0.0, 1.0, 1.0)
        lower[0], upper[0] = -1.5, 1.5
        lb[0], ub[0] = max(lb[0], -0.3), min(ub[0], 0.3)


class _SlowerTracking(EndEffectorTask):
    """A subclass overriding ``compute``: must not be bypassed by the parent's writer."""

    def compute(self, ctx, jac, error):
        super().compute(ctx, jac, error)
        error[:] *= 0.5


def test_user_pieces_use_the_generic_path_next_to_compiled_ones():
    spin, slow = _Spin(1.0), _SlowArm()
    options = {"manipulability_weight": 0.0, "posture_weight": 0.0}
    controller = make_controller("qp", ROBOT, tasks=[spin], limits=[slow], **options)
    problem = controller.problem
    assert [entry[0] for entry in problem._generic_cost] == [spin]
    assert [entry[0] for entry in problem._generic_limits] == [slow]
    assert len(problem._writers) >= 4  # the built-in pieces stay compiled
    reference = make_controller("qp", ROBOT, tasks=[spin], limits=[slow], **options)
    reference.problem = QPProblem(reference.tasks, reference.limits, compiled=False)
    q = np.array([0.2, -0.1, 0.3, -0.4, 0.9])
    pose_d, velocity_d = ROBOT.fk(q), np.array([0.8, 0.0, 0.0])
    u = controller.command(0.0, q, pose_d, velocity_d)
    assert u.tobytes() == reference.command(0.0, q, pose_d, velocity_d).tobytes()
    assert u[1] == pytest.approx(0.5, abs=0.01)  # the user task acts
    assert abs(u[0]) <= 0.3 + 1e-9  # the user box binds (the demand wants 0.8 m/s)
    assert abs(u[0]) >= 0.3 - 1e-6
    assert u[2] + u[3] <= 1.5 + 1e-9


def test_a_subclass_overriding_compute_is_not_bypassed():
    task = _SlowerTracking(1e4)
    assert task.compile(None) is None  # no fast path: compute() is called
    problem = QPProblem([task], [])
    ctx = make_controller("qp", ROBOT).ctx
    q = np.array([0.0, 0.0, 0.0, 0.3, 0.8])
    ctx.update(0.0, q, ROBOT.fk(q) + np.array([0.1, 0.0, 0.0]), np.zeros(3))
    problem.build(ctx)
    assert problem.cu[0] == pytest.approx(0.5 * 0.1 / 0.5)  # half of K (Xd - X)


def test_constant_pieces_are_written_once():
    controller, _ = _problems({})
    problem = controller.problem
    writers = {w.__qualname__.split(".")[0] for w in problem._writers}
    assert "RegularizationTask" not in writers and "WheelSpeedLimit" not in writers
    assert CONSTANT not in problem._writers


@settings(max_examples=300, deadline=None)
@given(
    th1=st.floats(-7.0, 7.0),
    th2=st.floats(-7.0, 7.0),
    rate1=st.floats(-2.0, 2.0),
    rate2=st.floats(-2.0, 2.0),
    dt=st.sampled_from([0.005, 0.02, 0.1, 0.5]),
    floor=st.floats(1.05, 2.0),
)
def test_skipping_the_exact_look_ahead_never_changes_the_scale(th1, th2, rate1, rate2, dt, floor):
    """When the bound proves the full step safe, the exact check would have said 1."""
    com = ROBOT.com_coefficients
    trig = (math.sin(th1), math.cos(th1), math.sin(th1 + th2), math.cos(th1 + th2))
    exact = safe_arm_scale(com, th1, th2, rate1, rate2, dt, floor)
    if full_step_is_safe(com, trig, th1, th2, rate1, rate2, dt, floor):
        assert exact == 1.0


def test_the_bound_skips_the_look_ahead_in_ordinary_tracking():
    """Far from the floor (S around 1.4 at the home pose) the exact check is skipped."""
    com = ROBOT.com_coefficients
    th1, th2 = ROBOT.home_pose
    trig = (math.sin(th1), math.cos(th1), math.sin(th1 + th2), math.cos(th1 + th2))
    assert full_step_is_safe(com, trig, th1, th2, 1.0, -1.0, 0.02, 1.25)
    assert not full_step_is_safe(com, trig, th1, th2, 1.0, -1.0, 0.02, 1.6)  # floor above S


def test_joint_writer_matches_joint_bounds_at_and_beyond_the_limits():
    limit = JointLimit(ROBOT)
    for angle in (-10.0, -math.pi - 0.01, -math.pi, -3.13, 0.0, 3.13, math.pi, 4.0, 1e6):
        low, up = limit.joint_bounds(angle, 1)
        assert low <= up
        if angle >= math.pi:
            assert up < 0.0  # beyond the upper limit: must move back
        if angle <= -math.pi:
            assert low > 0.0
