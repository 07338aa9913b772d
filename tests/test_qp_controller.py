"""The QP controller: interface, solver parity, modes, fallback, extension, safety property."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddwmmr import ParameterError, Robot, available_methods, make_controller
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.qp.controller import QPController
from ddwmmr.qp.limits import Circle, Limit, exact_stability, stability_terms_gradient
from ddwmmr.qp.naive import NaiveQPController
from ddwmmr.qp.tasks import Task
from one_line import one_line

ROBOT = Robot().with_payload(3.0)
Q = np.array([0.2, -0.1, 0.3, -0.4, 0.9])


def _demand(robot, q, velocity):
    """Desired pose = current end-effector pose, desired velocity given."""
    return robot.fk(q), np.asarray(velocity, float)


def test_registered_without_its_benchmark_twin():
    assert "qp" in available_methods() and "qp-naive" not in available_methods()
    controller = make_controller("qp", ROBOT, stability_min=1.3, manipulability_weight=0.5)
    assert isinstance(controller, QPController) and controller.stability_min == 1.3
    assert isinstance(NaiveQPController(ROBOT), NaiveQPController)
    with pytest.raises(ParameterError, match="unknown option"):
        make_controller("qp", ROBOT, stability=1.3)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"mode": "lexicographic"}, "mode must be one of weighted, hierarchical"),
        ({"solver": "nope"}, "solver must be one of"),
        ({"stability_min": 0.0}, r"stability_min must be in \(0, 10\) \(got 0\)"),
        ({"stability_min": 12.0}, "stability_min must be in"),
        ({"manipulability_weight": -1.0}, r"manipulability_weight must be in \[0, 1e\+06\]"),
        ({"max_speed": 0.0}, "max_speed must be > 0"),
        ({"tau": -0.5}, "tau must be > 0"),
        ({"tau": (0.5, 0.5)}, "tau must be one value or 3"),
        ({"obstacles": [(1.0, 2.0)]}, "obstacles must be Circle"),
        ({"obstacles": [(1.0, 2.0, -0.3)]}, "obstacle radius must be > 0"),
        ({"dt": 0.0}, r"dt must be in \[0.0001, 100\] s"),
        ({"tasks": [object()]}, "tasks must be"),
    ],
)
def test_bad_options_raise_one_line_parameter_errors(options, match):
    with pytest.raises(ParameterError, match=match) as info:
        QPController(ROBOT, **options)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("method", ["qp", "mpc"])
def test_obstacle_tables_are_refused_as_tables(method):
    # A TOML file's [[obstacle]] table given as a dict unpacked into its three keys:
    # "obstacle x must be a finite number (got 'x')".
    with pytest.raises(ParameterError) as info:
        make_controller(method, Robot(), obstacles=[{"x": 1, "y": 1, "radius": 0.2}])
    assert one_line(info) == (
        "obstacles are Circle(x, y, radius) or (x, y, radius) triples, not tables "
        "(got {'x': 1, 'y': 1, 'radius': 0.2}); a file of [[obstacle]] tables goes in "
        "by its path"
    )
    with pytest.raises(ParameterError) as info:
        make_controller(method, Robot(), obstacles=["xyr"])
    assert one_line(info) == (
        "obstacles must be Circle(x, y, radius) or (x, y, radius) triples (got 'xyr')"
    )
    made = make_controller(method, Robot(), obstacles=[(1, 1, 0.2)])
    assert list(made.obstacles) == [Circle(1.0, 1.0, 0.2)]


def test_tracks_a_feasible_demand_exactly_within_every_limit():
    controller = QPController(ROBOT, manipulability_weight=0.0)
    velocity = np.array([0.2, -0.1, 0.3])
    u = controller.command(0.0, Q, *_demand(ROBOT, Q, velocity))
    jac = controller.ctx.jac_e
    assert jac @ u == pytest.approx(velocity, abs=1e-4)
    assert not controller.last.fallback
    assert max(abs(w) for w in ROBOT.wheel_speeds_from_u(u[0], u[1])) <= ROBOT.wheel_speed_limit
    assert np.all(np.abs(u[2:]) <= ROBOT.joint_speed_limit)


@pytest.mark.parametrize("solver", ["quadprog", "osqp", "proxqp", "clarabel", "qpsolvers-daqp"])
@pytest.mark.parametrize("mode", ["weighted", "hierarchical"])
def test_every_backend_gives_the_direct_daqp_answer(solver, mode):
    q = np.array([0.0, 0.0, 0.0, 0.95, 0.5])  # near the stability floor: the limit is active
    pose_d, velocity_d = _demand(ROBOT, q, [-0.3, 0.4, 0.0])
    reference = QPController(ROBOT, mode=mode).command(0.0, q, pose_d, velocity_d)
    other = QPController(ROBOT, mode=mode, solver=solver)
    assert other.command(0.0, q, pose_d, velocity_d) == pytest.approx(reference, abs=2e-3)
    assert not other.last.fallback


def test_naive_twin_gives_the_same_command():
    pose_d, velocity_d = _demand(ROBOT, Q, [0.2, 0.1, -0.2])
    fast = QPController(ROBOT).command(0.0, Q, pose_d, velocity_d)
    naive = NaiveQPController(ROBOT).command(0.0, Q, pose_d, velocity_d)
    assert naive == pytest.approx(fast, abs=2e-3)


class _BrakeTask(Task):
    """A secondary task in conflict with tracking: v = 0 (the demand needs the base)."""

    name = "brake"

    def compute(self, ctx, jac, error):
        jac[:] = (1.0, 0.0, 0.0, 0.0)
        error[0] = 0.0


def test_hierarchical_mode_never_trades_tracking_for_a_secondary_task():
    """A demand the robot can meet only by driving; a heavy secondary task asks it not to.
    The weighted solution bends away from the demand, the lexicographic one not at all."""
    q = np.array([0.0, 0.0, 0.0, -0.3, 0.3])
    pose_d, velocity_d = _demand(ROBOT, q, [0.1, 0.05, 0.0])
    errors = {}
    for mode in ("weighted", "hierarchical"):
        controller = QPController(ROBOT, mode=mode, tasks=[_BrakeTask(1e4)])
        u = controller.command(0.0, q, pose_d, velocity_d)
        errors[mode] = float(np.linalg.norm(controller.ctx.jac_e @ u - velocity_d))
    assert errors["hierarchical"] < 1e-5
    assert errors["weighted"] > 1e-2


class _Impossible(Limit):
    """Contradictory box on v: nothing satisfies it."""

    def compute(self, ctx, G, lower, upper, lb, ub):
        lb[0], ub[0] = 1.0, -1.0


class _Unbounded(Limit):
    """Contradictory row (lower > upper) handed to the solver itself."""

    rows = 1

    def compute(self, ctx, G, lower, upper, lb, ub):
        G[0] = (1.0, 0.0, 0.0, 0.0)
        lower[0], upper[0] = 2.0, 1.0


@pytest.mark.parametrize("limit", [_Impossible(), _Unbounded()])
@pytest.mark.parametrize("solver", ["daqp", "osqp"])
def test_infeasible_problem_falls_back_to_a_safe_finite_command(limit, solver):
    q = np.array([0.0, 0.0, 0.0, 1.1, 0.3])  # S below the floor: fallback raises it
    controller = QPController(ROBOT, limits=[limit], solver=solver)
    u = controller.command(0.0, q, *_demand(ROBOT, q, [0.3, 0.0, 0.0]))
    assert controller.last.fallback and controller.fallbacks == 1
    assert np.all(np.isfinite(u)) and u[0] == 0.0 and u[1] == 0.0
    grad = stability_terms_gradient(ROBOT.com_coefficients, 1.1, 0.3)[1][1:]
    assert np.dot(grad, u[2:]) > 0.0  # the arm moves to raise S
    calm = np.array([0.0, 0.0, 0.0, -0.3, 0.6])
    assert controller.command(0.0, calm, *_demand(ROBOT, calm, [0.3, 0, 0])) == pytest.approx(0)


class _SpinTask(Task):
    """A user task: yaw at 0.5 rad/s."""

    name = "spin"

    def compute(self, ctx, jac, error):
        jac[:] = (0.0, 1.0, 0.0, 0.0)
        error[0] = 0.5


def test_a_user_task_is_one_small_class():
    pose_d, velocity_d = _demand(ROBOT, Q, [0.0, 0.0, 0.0])
    plain = QPController(ROBOT, manipulability_weight=0.0, posture_weight=0.0)
    spun = QPController(
        ROBOT, manipulability_weight=0.0, posture_weight=0.0, tasks=[_SpinTask(1.0)]
    )
    assert abs(plain.command(0.0, Q, pose_d, velocity_d)[1]) < 0.05
    u = spun.command(0.0, Q, pose_d, velocity_d)
    assert u[1] == pytest.approx(0.5, abs=0.01)
    assert spun.ctx.jac_e @ u == pytest.approx(np.zeros(3), abs=1e-4)  # tracking kept


def test_summarize_reports_violations_fallbacks_and_clearance():
    """A run of 3 steps, 4 samples: S ends below the floor after the first and the third
    step (samples 1 and 3; the start, below it too, is no step's); the fallback commanded
    the second step (sample 1); the last sample's, recorded but never applied, is no
    step's."""
    controller = QPController(ROBOT, obstacles=[Circle(1.0, 0.0, 0.2)])
    ts = {
        "stability": np.array([1.1, 1.2, 1.26, 1.1]),
        "fallback": np.array([0.0, 1.0, 0.0, 1.0]),
        "x": np.zeros(4),
        "y": np.zeros(4),
        "phi": np.zeros(4),
    }
    summary = controller.summarize(ts)
    assert summary["stability_min"] == 1.25
    assert summary["stability_violations"] == 2
    assert summary["qp_fallbacks"] == 1
    assert summary["min_obstacle_clearance_m"] == pytest.approx(1.0 - 0.225 - 0.2)
    assert QPController(ROBOT).summarize(ts)["min_obstacle_clearance_m"] is None


def test_far_waypoint_is_reached_with_bounded_commands():
    """Waypoint 3 m behind and to the side, no orientation, feedback clipped at 0.5 m/s."""
    controller = QPController(ROBOT, track_orientation=False, max_speed=0.5)
    plant = KinematicPlant(ROBOT, "euler")
    q = np.array([0.0, 0.0, 0.0, *ROBOT.home_pose])
    target = np.array([-2.5, 1.5, 0.0])
    controller.reset(None, q)
    peak, t = 0.0, 0.0
    while math.dist(ROBOT.fk(q)[:2], target[:2]) > 0.01 and t < 30.0:
        u = controller.command(t, q, target, np.zeros(3))
        peak = max(peak, abs(u[0]))
        q = plant.integrate(t, q, 0.02, None, first_command=u)[0]
        t += 0.02
    assert math.dist(ROBOT.fk(q)[:2], target[:2]) <= 0.01
    assert t < 20.0
    assert peak <= 0.8  # near the 0.5 m/s clip, far below the 1.46 m/s wheel limit
    assert controller.fallbacks == 0


@settings(max_examples=60, deadline=None)
@given(
    th1=st.floats(0.95, 2.19),
    side=st.sampled_from([-1.0, 1.0]),
    elbow=st.sampled_from([-1.0, 1.0]),
    excess=st.floats(0.0, 0.02),
    speed=st.floats(0.05, 1.0),
    dt=st.sampled_from([0.01, 0.02, 0.1]),
)
def test_one_step_keeps_exact_stability_above_the_floor(th1, side, elbow, excess, speed, dt):
    """Start just above S_min (S = S_min + excess), demand the end effector to move outward
    (away from the base) and integrate the command for dt with a zero-order hold."""
    com = ROBOT.com_coefficients
    floor = 1.25
    th1 *= side  # a sideways shoulder: only there can the arm reach the floor

    def margin(th2: float) -> float:
        return exact_stability(com, th1, th2) - (floor + excess)

    # Stretched (th2 = 0) is below the floor, folded (th2 = pi) far above: bisect.
    lo, hi = 0.0, elbow * math.pi
    assert margin(lo) < 0.0 < margin(hi)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if margin(mid) < 0.0 else (lo, mid)
    q = np.array([0.0, 0.0, 0.0, th1, hi])
    assert floor <= exact_stability(com, th1, hi) <= floor + excess + 1e-9
    pose = ROBOT.fk(q)
    outward = pose[:2] / np.linalg.norm(pose[:2])
    controller = QPController(ROBOT, stability_min=floor, dt=dt)
    u = controller.command(0.0, q, pose, np.array([*(speed * outward), 0.0]))
    assert np.all(np.isfinite(u)) and not controller.last.fallback
    q_next = q + dt * KinematicPlant.derivative(q, u)  # zero-order hold: joints exact
    assert exact_stability(com, q_next[3], q_next[4]) >= floor - 1e-9


def test_unknown_or_missing_solver_is_a_parameter_error():
    with pytest.raises(ParameterError, match="solver must be one of the installed QP solvers"):
        make_controller("qp", ROBOT, solver="nope")


@pytest.mark.parametrize("dt", [1e-300, 9.9e-5, 0.0, 100.1, 1e300])
def test_the_dt_option_is_a_control_step_in_range(dt):
    """``dt`` took anything from 1e-300 s to 1e300 s: a step no run has."""
    with pytest.raises(ParameterError, match=r"^dt must be in \[0\.0001, 100\] s \(got "):
        make_controller("qp", ROBOT, dt=dt)


def test_the_dt_range_is_the_mpcs_step_range():
    from ddwmmr.mpc.ocp import MAX_HORIZON, MIN_INTERVAL
    from ddwmmr.qp.controller import DT_RANGE_S

    assert DT_RANGE_S == (MIN_INTERVAL, MAX_HORIZON)
    for dt in DT_RANGE_S:
        make_controller("qp", ROBOT, dt=dt)
