"""Method ``mpc``: registry, options, constraints along runs, fallback, determinism, solvers."""

from __future__ import annotations

import math

import casadi as ca
import control
import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, available_methods, make_controller, simulate
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.commands import WheelForces
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc import terminal
from ddwmmr.mpc.fallback import make_fallback
from ddwmmr.mpc.models import KinematicPrediction, ThesisPrediction
from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP, Weights, grid_intervals, shooting_grid
from ddwmmr.mpc.solvers import GaussNewtonSQP, NLPSolver, SolverFailure
from ddwmmr.plants.thesis import ThesisPlant, ThesisState

HEAVY = Robot().with_payload(3.0)


def run_thesis_plant(controller, target, steps, dt=0.01, state=None):
    """Closed loop of a force-level controller on the thesis plant (like the scenario loop).

    Returns the commands and the states after each step."""
    plant = ThesisPlant(controller.robot)
    state = state or ThesisState(0.0, 0.0, 0.0, *default_pose(controller.robot))
    controller.reset(None, np.array(state.q))
    commands, states = [], []
    for k in range(steps):
        command = controller.command(
            k * dt,
            np.array(state.q),
            np.array([*target, 0.0]),
            np.zeros(3),
            base_velocity=(state.v, state.w),
        )
        commands.append(command)
        plant.advance(
            state, command.left, command.right, (command.th1_target, command.th2_target), dt
        )
        states.append(state.copy())
    return commands, states


def test_registered_with_its_interfaces():
    assert "mpc" in available_methods()
    kinematic = make_controller("mpc", Robot())
    assert kinematic.interface == "velocity" and kinematic.zero_order_hold
    assert not kinematic.wants_base_velocity
    thesis = make_controller("mpc", HEAVY, model="thesis")
    assert thesis.interface == "force" and thesis.wants_base_velocity


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"model": "mujoco"}, "model must be one of kinematic, thesis"),
        ({"solver": "snopt"}, "solver must be one of rti, sqp, ipopt, sqpmethod, fatrop"),
        ({"qp_solver": "gurobi"}, "qp_solver must be one of"),
        ({"horizon": -1.0}, "horizon must be in [0.0001, 100] s"),
        ({"intervals": 1}, "intervals must be an integer in [2, 200]"),
        ({"intervals": 2.5}, "intervals must be an integer in [2, 200]"),
        ({"horizon": 0.5, "intervals": 20, "first_interval": 0.1}, "horizon must be >="),
        # the OCP's own bound: dt + 9 x 0.01 = 0.14 s > 0.1 s (10 x 0.01 = 0.1 s would fit)
        (
            {"horizon": 0.1, "intervals": 10, "first_interval": 0.01, "dt": 0.05},
            "horizon must be >= dt + (intervals - 1) x first_interval = 0.14 s (got 0.1)",
        ),
        ({"horizon": 0.05, "dt": 0.05}, "horizon must be > the control step dt = 0.05 s"),
        ({"stability_min": 12.0}, "stability_min must be in (0, 10)"),
        ({"manipulability_weight": -1.0}, "manipulability_weight must be in [0, 1e+06] (got -1)"),
        # capped as the qp's weights: at 1e300 the LQR terminal design failed every step
        ({"position_weight": 1e300}, "position_weight must be in [0, 1e+06] (got 1e+300)"),
        ({"orientation_weight": 1e300}, "orientation_weight must be in [0, 1e+06]"),
        ({"input_weight": 1e300}, "input_weight must be in [0, 1e+06] (got 1e+300)"),
        ({"huber": 1e300}, "huber must be in [1e-06, 1000] m (got 1e+300)"),
        ({"reach_speed": 0.0}, "reach_speed must be > 0"),
        ({"dt": 0.0}, "dt must be > 0"),
        ({"obstacles": [(1.0, 2.0)]}, "obstacles must be Circle(x, y, radius)"),
        ({"colour": "red"}, "unknown option 'colour'"),
    ],
)
def test_bad_options_are_one_line_errors(options, message):
    with pytest.raises(ParameterError) as error:
        make_controller("mpc", Robot(), **options)
    assert message in str(error.value)
    assert "\n" not in str(error.value)


def test_tracking_run_respects_every_bound_and_beats_the_qp_on_the_ellipse():
    robot = Robot()
    trajectory = Ellipse(T=20.0, N=1000)
    result = simulate(robot, trajectory, "mpc", integrator="euler", duration=6.0)
    ts, summary = result.timeseries, result.summary
    assert summary["mpc_fallbacks"] == 0 and summary["stability_violations"] == 0
    assert summary["saturated_steps"] == 0  # the commands already respect the limits
    wheels = np.maximum(np.abs(ts["wheel_left_rad_s"]), np.abs(ts["wheel_right_rad_s"]))
    assert np.max(wheels) <= robot.wheel_speed_limit
    assert np.max(np.abs(ts["th1dot"])) <= robot.joint_speed_limit
    assert np.max(np.abs(ts["th2dot"])) <= robot.joint_speed_limit
    # converges from the 3 cm initial offset: the last 3 s within 1 mm
    late = ts["t"] >= 3.0
    assert np.max(ts["position_error_m"][late]) < 1e-3
    qp = simulate(robot, trajectory, "qp", integrator="euler", duration=6.0).summary
    assert summary["rms_position_error_m"] < qp["rms_position_error_m"]


def test_stability_floor_holds_at_every_step_when_it_binds():
    """A target 0.6 m to the side: reaching it with the arm first (the fastest way) would
    take S towards 1.0. The floor (1.25, kept with the 0.01 margin) binds and holds at every
    step; forces and joint rates stay in bounds."""
    controller = make_controller("mpc", HEAVY, model="thesis", track_orientation=False, dt=0.01)
    commands, states = run_thesis_plant(controller, (0.3, 0.6), steps=300)
    s = np.array([HEAVY.stability(state.q)[2] for state in states])
    assert np.min(s) >= 1.25
    assert np.min(s) < 1.27  # the floor is active (the fastest reach stretches the arm)
    forces = np.array([[c.left, c.right] for c in commands])
    assert np.max(np.abs(forces)) <= 10.0 + 1e-9
    steps = np.diff(np.array([[st.th1, st.th2] for st in states]), axis=0)
    assert np.max(np.abs(steps)) <= 2.0 * 0.01 + 1e-9
    xe, ye, _ = HEAVY.fk(np.array(states[-1].q))
    assert math.hypot(xe - 0.3, ye - 0.6) < 0.01  # and it got there
    assert controller.fallbacks == 0


def test_the_input_change_cost_starts_from_the_applied_command(monkeypatch):
    """When the exact one-step stability check scales the joint rates down, the next
    plan's input-change cost is measured from the rates applied, not the planned ones."""
    from ddwmmr.mpc import controller as mpc_controller

    robot = Robot()
    controller = make_controller("mpc", robot, dt=0.02)
    trajectory = Ellipse()
    q0 = robot.base_for_end_effector(trajectory.pose(0.0), *robot.home_pose)
    controller.reset(trajectory, q0)
    planned = {}

    def halve(k, th1, th2, r1, r2, dt, floor):
        planned["rates"] = (r1, r2)
        return 0.5

    monkeypatch.setattr(mpc_controller, "safe_arm_scale", halve)
    u = controller.command(0.0, q0, trajectory.pose(0.0), trajectory.velocity(0.0))
    assert abs(planned["rates"][0]) > 1e-3  # the plan moves the arm
    np.testing.assert_allclose(u[2:], 0.5 * np.array(planned["rates"]), rtol=1e-12)
    np.testing.assert_array_equal(controller._u_prev, u)


def test_runs_are_deterministic():
    def run():  # at the loop's step: the problem of the other closed-loop tests here
        controller = make_controller("mpc", HEAVY, model="thesis", track_orientation=False, dt=0.01)
        commands, _ = run_thesis_plant(controller, (1.5, -1.0), steps=120)
        return np.array([[c.left, c.right, c.th1_target, c.th2_target] for c in commands])

    first, second = run(), run()
    np.testing.assert_array_equal(first, second)


def test_solver_failure_falls_back_to_the_qp_command_and_is_counted(monkeypatch):
    controller = make_controller("mpc", HEAVY, model="thesis", track_orientation=False, dt=0.01)
    run_thesis_plant(controller, (2.0, 1.0), steps=5)  # builds the problem
    problem = next(iter(controller._problems.values()))

    def fail(*args, **kwargs):
        raise SolverFailure("forced")

    monkeypatch.setattr(problem.solver, "solve", fail)
    monkeypatch.setattr(problem.cold, "solve", fail)
    state = ThesisState(0.2, 0.1, 0.3, *default_pose(HEAVY), 0.4, 0.1)
    command = controller.command(
        0.0, np.array(state.q), np.array([2.0, 1.0, 0.0]), np.zeros(3), base_velocity=(0.4, 0.1)
    )
    assert isinstance(command, WheelForces)
    assert controller.last.fallback and controller.fallbacks == 1
    values = [command.left, command.right, command.th1_target, command.th2_target]
    assert all(math.isfinite(v) for v in values)
    # the qp's velocity command (a fresh twin, slewing from the measured velocity), through
    # the model-based velocity loop of the plant
    qp = make_fallback(HEAVY, controller.options, None, controller.dt, controller.dynamics)
    qp.ctx.previous_command = (0.4, 0.1)
    u = qp.command(0.0, np.array(state.q), np.array([2.0, 1.0, 0.0]), np.zeros(3))
    expected = controller.dynamics.velocity_tracking_forces(0.4, 0.1, u[0], u[1], state.th2)
    assert (command.left, command.right) == pytest.approx(expected, abs=1e-9)
    assert abs(command.left) <= 10.0 and abs(command.right) <= 10.0
    # 3 samples, 2 steps: the last sample's command (a fallback too) is never applied
    summary = controller.summarize({"stability": np.array([1.5, 1.6, 1.2]), "fallback": np.ones(3)})
    assert summary["mpc_fallbacks"] == 2 and summary["stability_violations"] == 1


def test_kinematic_fallback_returns_the_qp_velocity_command(monkeypatch):
    robot = Robot()
    controller = make_controller("mpc", robot, dt=0.02)
    trajectory = Ellipse()
    q0 = robot.base_for_end_effector(trajectory.pose(0.0), *robot.home_pose)
    controller.reset(trajectory, q0)
    controller.command(0.0, q0, trajectory.pose(0.0), trajectory.velocity(0.0))
    problem = next(iter(controller._problems.values()))
    monkeypatch.setattr(
        problem.solver, "solve", lambda *a, **k: (_ for _ in ()).throw(SolverFailure("forced"))
    )
    u = controller.command(0.02, q0, trajectory.pose(0.02), trajectory.velocity(0.02))
    reference = make_controller("qp", robot, dt=0.02)
    reference.reset(trajectory, q0)
    expected = reference.command(0.02, q0, trajectory.pose(0.02), trajectory.velocity(0.02))
    np.testing.assert_allclose(u, expected, atol=1e-9)
    assert controller.last.fallback


def test_grid_sums_to_the_horizon_and_grows_geometrically():
    lengths = grid_intervals(10, 0.05, 2.0)
    assert lengths.sum() == pytest.approx(2.0)
    ratios = lengths[1:] / lengths[:-1]
    np.testing.assert_allclose(ratios, ratios[0], rtol=1e-9)
    assert lengths[0] == pytest.approx(0.05, rel=1e-6) and ratios[0] > 1.0
    np.testing.assert_allclose(grid_intervals(4, 0.25, 1.0), 0.25)
    config = OCPConfig(intervals=5, control_interval=0.01, first_interval=0.25, horizon=1.01)
    np.testing.assert_allclose(config.interval_lengths(), [0.01, 0.25, 0.25, 0.25, 0.25])


def test_two_intervals_are_the_control_step_and_the_rest_of_the_horizon():
    """intervals = 2, the documented minimum: dt, then one interval to the horizon (the
    OCP used to ask its geometric grid for intervals - 1 = 1 and refuse it)."""
    np.testing.assert_allclose(shooting_grid(2, 0.02, 0.05, 1.0), [0.02, 0.98])
    np.testing.assert_allclose(shooting_grid(3, 0.01, 0.25, 0.51), [0.01, 0.25, 0.25])
    with pytest.raises(ParameterError, match=r"intervals must be an integer in \[2, 200\]"):
        shooting_grid(1, 0.02, 0.05, 1.0)
    config = OCPConfig(intervals=2, control_interval=0.02, first_interval=0.05, horizon=1.0)
    np.testing.assert_allclose(config.interval_lengths(), [0.02, 0.98])
    result = simulate(Robot(), Ellipse(), "mpc", duration=0.4, intervals=2)
    assert result.summary["steps"] == 20 and result.summary["mpc_fallbacks"] == 0
    recorded = result.summary["mpc_options"]
    assert recorded["intervals"] == 2 and recorded["first_interval"] == pytest.approx(0.98)
    assert result.summary["max_position_error_m"] < 0.05  # 3 cm start offset, not lost


@pytest.mark.parametrize(
    ("options", "accepted"),
    [
        ({"intervals": 2}, True),
        ({"intervals": 200, "horizon": 2.0}, True),
        ({"intervals": 10, "horizon": 0.5, "first_interval": 0.05}, True),  # 0.47 s needed
        ({"intervals": 10, "horizon": 0.46, "first_interval": 0.05}, False),
        ({"intervals": 10, "horizon": 0.95, "first_interval": 0.1}, True),  # 0.92 s needed
        ({"horizon": 0.03}, True),  # default first interval: 9 equal ones of 1.1 ms
        ({"horizon": 0.02}, False),  # not beyond the control step
    ],
)
def test_the_options_accept_exactly_the_grids_the_ocp_builds(options, accepted):
    """The options' grid check is the OCP's: what MPCOptions accepts at dt = 0.02 s builds
    (tracking), what it refuses would have failed in the OCP."""
    if not accepted:
        with pytest.raises(ParameterError, match="horizon must be"):
            make_controller("mpc", Robot(), dt=0.02, **options)
        return
    controller = make_controller("mpc", Robot(), dt=0.02, **options)
    config = controller._config("tracking")
    lengths = config.interval_lengths()
    assert len(lengths) == controller.options.grid("tracking")[0]
    assert lengths[0] == 0.02 and lengths.sum() == pytest.approx(config.horizon)


@pytest.mark.parametrize("model_name", ["kinematic", "thesis"])
def test_lqr_terminal_design_leaves_out_errors_of_zero_weight(model_name):
    """position_weight=0 or orientation_weight=0 (documented >= 0): the errors nothing
    depends on and nothing charges are left out of the design, exactly. orientation 0 gives
    the design without orientation tracking (padded with zeros); position 0 a cost-to-go
    on the orientation error alone; both 0 no terminal cost. Each P still solves the full
    Riccati equation (the least solution; a stabilising one does not exist there)."""
    robot = HEAVY
    if model_name == "thesis":
        model = ThesisPrediction(robot, sym.ThesisDynamics.from_robot(robot))
    else:
        model = KinematicPrediction(robot)
    pose = default_pose(robot)

    def design(position, orientation, track_orientation=True):
        config = OCPConfig(
            intervals=10,
            control_interval=0.02,
            first_interval=0.05,
            horizon=1.0,
            track_orientation=track_orientation,
            weights=Weights(position=position, orientation=orientation),
        )
        found = terminal.design(robot, model, config, pose)
        A, B, Q, R, P = found.A, found.B, found.Q, found.R, found.P
        gain = np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)
        riccati = A.T @ P @ A - P - A.T @ P @ B @ gain + Q
        assert np.max(np.abs(riccati)) < 1e-8 * max(1.0, np.max(np.abs(P)))
        np.testing.assert_allclose(found.K, gain, atol=1e-9)  # u = -K z with that P
        np.testing.assert_allclose(found.factor @ found.factor.T, P, atol=1e-9)
        return found

    without = design(100.0, 10.0, track_orientation=False)  # z = [ex, ey(, v, w)]
    no_orientation = design(100.0, 0.0)  # z = [ex, ey, eo(, v, w)]
    keep = [0, 1, *range(3, no_orientation.P.shape[0])]
    np.testing.assert_allclose(no_orientation.P[np.ix_(keep, keep)], without.P, rtol=1e-9)
    assert not np.any(no_orientation.P[2]) and not np.any(no_orientation.K[:, 2])
    assert without.P[0, 0] > 10.0  # a real cost-to-go on the position (about 20)
    no_position = design(0.0, 10.0)
    assert not np.any(no_position.P[:2]) and not np.any(no_position.P[:, :2])
    assert no_position.P[2, 2] > 1.0  # on the orientation error alone (about 2)
    # the unweighted position errors are neither fed back nor moved: poles at 1
    assert np.sum(np.isclose(np.abs(no_position.poles), 1.0)) == 2
    assert np.all(np.abs(no_position.poles) <= 1.0 + 1e-12)
    nothing = design(0.0, 0.0)
    assert not np.any(nothing.P) and not np.any(nothing.K)


@pytest.mark.parametrize("option", ["position_weight", "orientation_weight"])
def test_tracking_runs_with_a_zero_weight(option):
    """The terminal design used to raise LinAlgError (control.dlqr) here. Without an
    orientation cost the position is still tracked; without a position cost it is not
    (nothing asks for it), but the run completes without a fallback."""
    result = simulate(Robot(), Ellipse(), "mpc", duration=0.4, **{option: 0.0})
    summary = result.summary
    assert summary["steps"] == 20 and summary["mpc_fallbacks"] == 0
    assert summary["mpc_options"][option] == 0.0
    if option == "orientation_weight":
        assert summary["end_position_error_m"] < summary["initial_offset_m"]
    else:
        assert summary["end_position_error_m"] > summary["initial_offset_m"]


@pytest.mark.parametrize("reach", [False, True])
def test_gauss_newton_sqp_on_hpipm_converges_to_a_kkt_point_of_the_ocp(reach):
    """Iterated to a zero step, the structured QP path (Gauss-Newton SQP on HPIPM) stops at a
    KKT point of the NLP: stationarity with the last QP's multipliers, every constraint
    met. IPOPT (exact Hessian) started there finds no better point than 0.2 % (the problem
    is non-convex: both are local solutions)."""
    robot = HEAVY
    model = ThesisPrediction(robot, sym.ThesisDynamics.from_robot(robot))
    config = OCPConfig(
        intervals=8,
        control_interval=0.01,
        first_interval=0.1,
        horizon=1.5,
        reach=reach,
        track_orientation=False,
        huber=0.01 if reach else None,
        weights=Weights(position=50.0, manipulability=0.5, input=0.01, terminal=0.0),
    )
    ocp = ShootingOCP(robot, model, config)
    x0 = np.array([0.0, 0.0, 0.2, *default_pose(robot), 0.3, -0.1])
    node = np.concatenate([x0, [config.horizon]])[: ocp.nx]
    guess = ocp.pack(np.tile(node, (ocp.N + 1, 1)), np.zeros((ocp.N, ocp.nu)))
    p = ocp.parameters(np.tile([0.9, 0.4, 0.0], (ocp.N, 1)), np.zeros(4))
    lbw, ubw = ocp.bounds(x0)
    sqp = GaussNewtonSQP(ocp, "hpipm", iterations=100, tolerance=1e-10)
    w = sqp.solve(guess, p, lbw, ubw, ocp.lbg, ocp.ubg)
    assert sqp.last_iterations < 100
    objective = 0.5 * ca.sumsqr(ocp.residual) + ca.dot(ocp.linear_cost, ocp.w)
    lam_g, lam_x = (np.array(m).ravel() for m in sqp.last_multipliers)
    pieces = ca.Function(
        "kkt", [ocp.w, ocp.p], [ca.gradient(objective, ocp.w), ca.jacobian(ocp.g, ocp.w), ocp.g]
    )
    gradient, jacobian, g = (np.array(v) for v in pieces(w, p))
    stationarity = gradient.ravel() + jacobian.T @ lam_g + lam_x
    assert np.max(np.abs(stationarity)) < 1e-6 * max(1.0, np.max(np.abs(gradient)))
    assert np.all(g.ravel() >= ocp.lbg - 1e-8) and np.all(g.ravel() <= ocp.ubg + 1e-8)
    assert np.all(w >= lbw - 1e-9) and np.all(w <= ubw + 1e-9)
    cost = ca.Function("f", [ocp.w, ocp.p], [objective])
    w_ipopt = NLPSolver(ocp, "ipopt").solve(w, p, lbw, ubw, ocp.lbg, ocp.ubg)
    assert float(cost(w_ipopt, p)) >= 0.998 * float(cost(w, p))


@pytest.mark.parametrize("model_name", ["kinematic", "thesis"])
def test_lqr_terminal_cost_solves_the_riccati_equation(model_name):
    robot = HEAVY
    if model_name == "thesis":
        model = ThesisPrediction(robot, sym.ThesisDynamics.from_robot(robot))
    else:
        model = KinematicPrediction(robot)
    config = OCPConfig(intervals=10, control_interval=0.02, first_interval=0.05, horizon=1.0)
    design = terminal.design(robot, model, config, default_pose(robot))
    A, B, Q, R, P = design.A, design.B, design.Q, design.R, design.P
    riccati = A.T @ P @ A - P - A.T @ P @ B @ np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A) + Q
    assert np.max(np.abs(riccati)) < 1e-8 * max(1.0, np.max(np.abs(P)))
    assert np.all(np.abs(design.poles) < 1.0)
    np.testing.assert_allclose(design.factor @ design.factor.T, P, atol=1e-9)
    K, _, _ = control.dlqr(A, B, Q, R)
    np.testing.assert_allclose(design.K, K, rtol=1e-9, atol=1e-12)


def test_a_broken_qp_raises_solver_failure_not_nan():
    robot = HEAVY
    model = ThesisPrediction(robot, sym.ThesisDynamics.from_robot(robot))
    config = OCPConfig(intervals=4, control_interval=0.01, first_interval=0.1, horizon=0.5)
    ocp = ShootingOCP(robot, model, config)
    x0 = np.array([0.0, 0.0, 0.0, *default_pose(robot), 0.0, 0.0])
    guess = ocp.pack(np.tile(x0, (ocp.N + 1, 1)), np.zeros((ocp.N, ocp.nu)))
    p = ocp.parameters(np.full((ocp.N, 3), np.nan), np.zeros(4))
    lbw, ubw = ocp.bounds(x0)
    with pytest.raises(SolverFailure):
        GaussNewtonSQP(ocp, "hpipm").solve(guess, p, lbw, ubw, ocp.lbg, ocp.ubg)


def test_docs_page_snippet_runs():
    """The python block of docs/mpc.md runs; the rectangle meets its tracking target
    (<= 0.5 x clrrmc-ts's 47 mm) without a fallback and the thesis model returns forces."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "mpc.md").read_text()
    blocks = [part.split("```", 1)[0] for part in text.split("```python\n")[1:]]
    assert blocks
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "docs/mpc.md", "exec"), namespace)
    assert namespace["result"].summary["rms_position_error_m"] < 0.0235
    assert namespace["result"].summary["mpc_fallbacks"] == 0
    forces = namespace["forces"]
    assert isinstance(forces, WheelForces) and abs(forces.left) <= 10.0


def test_warm_start_shift_interpolates_like_numpy(rng):
    from ddwmmr.mpc.problem import interpolate_rows

    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.5, 12))])
    rows = rng.normal(size=(13, 8))
    at = np.sort(rng.uniform(-0.2, times[-1] + 0.3, 13))
    expected = np.column_stack([np.interp(at, times, rows[:, i]) for i in range(8)])
    np.testing.assert_allclose(interpolate_rows(times, rows, at), expected, atol=1e-14)


def test_a_stalled_waypoint_approach_restarts_cold():
    """If the end effector does not move for 0.5 s short of the target (here: a plant that
    ignores the commands), the controller drops its plan and starts cold."""
    controller = make_controller("mpc", HEAVY, model="thesis", track_orientation=False, dt=0.01)
    q = np.array([0.0, 0.0, 0.0, *default_pose(HEAVY)])
    controller.reset(None, q)
    for k in range(120):
        controller.command(
            k * 0.01, q, np.array([1.0, 0.5, 0.0]), np.zeros(3), base_velocity=(0.0, 0.0)
        )
    assert controller.restarts == 2  # at 0.51 s and 1.02 s
    assert controller.summarize({"stability": np.array([1.5])})["mpc_restarts"] == 2


@pytest.mark.parametrize("rule", ["on", "off"])
def test_plans_that_need_slack_for_half_a_second_restart_cold(monkeypatch, rule):
    """A plant that holds the arm stretched below the stability floor (S 1.15 against
    1.25) while the base creeps on (the end effector moves, so the stall rule stays
    quiet): every plan needs slack, and after 0.5 s of that the controller drops its plan
    and starts cold, once per 0.5 s; with the slack rule off it never does."""
    from ddwmmr.mpc import stall

    if rule == "off":
        monkeypatch.setattr(stall, "STALL_SLACK", math.inf)
    controller = make_controller("mpc", HEAVY, model="thesis", track_orientation=False, dt=0.01)
    q = np.array([0.0, 0.0, 0.0, -1.2, 0.3])
    assert HEAVY.stability(q)[2] == pytest.approx(1.146, abs=1e-3)
    controller.reset(None, q)
    for k in range(120):
        q[0] = 0.002 * k  # 2 mm per step
        controller.command(
            k * 0.01, q, np.array([5.0, 3.0, 0.0]), np.zeros(3), base_velocity=(0.2, 0.0)
        )
        assert controller.last.extra["mpc_slack"] > 1e-3  # this plan needed slack
    assert controller.restarts == (2 if rule == "on" else 0)  # at 0.51 s and 1.02 s


def test_minimum_time_of_one_waypoint_is_feasible_and_equals_the_physical_bound():
    from scipy.optimize import brentq

    from ddwmmr.mpc.min_time import MinimumTimeProblem, solve_minimum_time, verify

    robot = HEAVY
    start = [0.0, 0.0, 0.0, *default_pose(robot), 0.0, 0.0]
    target = (3.0, 0.0)
    problem = MinimumTimeProblem(robot, [target], start, intervals_per_leg=12)
    result = solve_minimum_time(problem)
    check = verify(problem, result)
    assert result.success
    assert check["max_miss_m"] < 0.011
    assert check["min_stability"] > 1.245
    assert check["max_force_n"] <= 10.0 + 1e-6 and check["max_joint_rate"] <= 2.0 + 1e-6
    # From rest with the full 20 N the base covers at most v_top (t - tau (1 - exp(-t/tau))),
    # tau = m/c1; the end effector is at most L1 + L2 ahead of the base. Straight ahead this
    # bound is attainable (full force, arm stretched forwards: S_lon stays above 1.25), and
    # the OCP finds it.
    d = sym.ThesisDynamics.from_robot(robot)
    tau, top = d.mass / d.c1, d.top_speed
    needed = target[0] - robot.reach - 0.01
    bound = brentq(lambda t: top * (t - tau * (1 - math.exp(-t / tau))) - needed, 0.0, 60.0)
    assert result.total == pytest.approx(bound, abs=1e-3)


def test_obstacle_on_the_straight_line_is_passed_with_its_clearance():
    """A 0.3 m post on the way to the target: the base's enclosing circle (r = 0.285 m, the
    scenario protocol's collision test) keeps the 0.05 m margin, and the target is reached."""
    post = (1.5, 0.05, 0.3)
    controller = make_controller(
        "mpc", HEAVY, model="thesis", track_orientation=False, dt=0.01, obstacles=[post]
    )
    _, states = run_thesis_plant(controller, (3.2, 0.0), steps=700)
    bubble = math.hypot(0.5 * HEAVY.base_length, 0.5 * HEAVY.base_width)
    clearance = min(math.hypot(s.x - post[0], s.y - post[1]) - post[2] - bubble for s in states)
    assert clearance > 0.045
    ends = [HEAVY.fk(np.array(s.q))[:2] for s in states]
    assert min(math.hypot(x - 3.2, y) for x, y in ends) <= 0.01
    assert controller.fallbacks == 0
    summary = controller.summarize(
        {
            "stability": np.array([HEAVY.stability(s.q)[2] for s in states]),
            "x": np.array([s.x for s in states]),
            "y": np.array([s.y for s in states]),
            "phi": np.array([s.phi for s in states]),
        }
    )
    assert summary["min_obstacle_clearance_m"] > 0.045  # the footprint is inside the circle


@pytest.mark.parametrize("qp_solver", ["hpipm", "osqp"])
def test_controllers_on_the_same_problem_share_it_and_run_as_if_fresh(qp_solver):
    """The OCP and its compiled QP are built once per (robot, model, grid, options) and
    shared; a run on the shared problem, after another problem's run, repeats a run on a
    freshly built one to the last bit."""
    from ddwmmr.mpc import cache as core
    from ddwmmr.mpc import solvers

    trajectory = Ellipse(T=20.0, N=1000)

    def run(**options):
        result = simulate(Robot(), trajectory, "mpc", duration=0.4, qp_solver=qp_solver, **options)
        return np.column_stack([result.timeseries[c] for c in ("xE", "yE", "v", "w", "th1dot")])

    core._OCPS.clear()
    fresh = run()
    (ocp,) = core._OCPS.values()
    compiled = solvers._COMPILED[ocp]
    run(stability_min=1.4)  # a different problem (in between): built apart
    assert sorted(o.config.stability_min for o in core._OCPS.values()) == [1.25, 1.4]
    shared = run()
    assert len(core._OCPS) == 2 and ocp in core._OCPS.values()
    assert solvers._COMPILED[ocp] is compiled  # no new QP functions either
    np.testing.assert_array_equal(shared, fresh)


def test_the_shared_problem_is_not_shared_across_threads():
    """A solver reads its QP's statistics after each call: two threads on one compiled QP
    could read each other's. Each thread builds its own."""
    import threading

    from ddwmmr.mpc import cache as core

    trajectory = Ellipse(T=20.0, N=1000)
    core._OCPS.clear()
    simulate(Robot(), trajectory, "mpc", duration=0.1)
    worker = threading.Thread(target=lambda: simulate(Robot(), trajectory, "mpc", duration=0.1))
    worker.start()
    worker.join()
    first, second = core._OCPS.values()
    assert first is not second and first.config == second.config


def test_a_plant_that_states_its_facts_in_lists_still_runs():
    """The shared problem is keyed by the plant's facts: a plant that gives its damping as
    a list (unhashable) gets them as a tuple of floats (ddwmmr.commands.traits_of)."""

    class ListedPlant(ThesisPlant):
        @property
        def damping(self):
            return list(super().damping)

    robot = Robot()
    result = simulate(
        robot, Ellipse(T=20.0, N=1000), "mpc", duration=0.1, plant=ListedPlant(robot),
        model="thesis",
    )  # fmt: skip
    assert result.summary["mpc_model"] == "thesis" and result.summary["mpc_fallbacks"] == 0


def test_fatrop_solves_the_ocp_as_ipopt_does():
    """FATROP takes the shooting gaps only as ``x_{k+1} - F(x_k, u_k)``, as the OCP writes
    them (with ``F - x_{k+1}`` every solve raised inside FATROP): it solves a reach problem
    of the thesis model to ipopt's first input (both at the force limit and the joint speed
    limit)."""
    from ddwmmr.mpc.models import ThesisPrediction
    from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP
    from ddwmmr.mpc.solvers import NLPSolver

    assert ca.has_nlpsol("fatrop"), "the CasADi that pyproject.toml installs has FATROP"
    robot = Robot().with_payload(3.0)
    model = ThesisPrediction(robot, sym.ThesisDynamics.from_robot(robot))
    ocp = ShootingOCP(robot, model, OCPConfig(intervals=10, horizon=1.0))
    x0 = np.array([0.0, 0.0, 0.0, -0.7, 1.5, 0.0, 0.0])
    target = robot.fk(x0[:5]) + np.array([0.3, 0.1, 0.0])
    guess = ocp.pack(np.tile(x0, (ocp.N + 1, 1)), np.zeros((ocp.N, ocp.nu)))
    p = ocp.parameters(np.tile(target, (ocp.N, 1)), np.zeros(4))
    lbw, ubw = ocp.bounds(x0)
    first = {}
    for name in ("ipopt", "fatrop"):
        solver = NLPSolver(ocp, name)
        first[name] = ocp.first_input(solver.solve(guess, p, lbw, ubw, ocp.lbg, ocp.ubg))
    np.testing.assert_allclose(first["fatrop"], first["ipopt"], atol=0.01)
    np.testing.assert_allclose(first["fatrop"], [10.0, 10.0, 2.0, -2.0], atol=1e-3)
