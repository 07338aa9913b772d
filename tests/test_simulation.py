"""Closed- and open-loop tracking on the kinematic plant (docs/theory.md, slides' observations).

The measured behaviour documented in docs/theory.md ("Measured behaviour") is asserted here.
"""

import math

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Rectangle, Robot, load_trajectory, simulate
from ddwmmr.plants import KinematicPlant
from ddwmmr.resolution.reference import DEFAULT_INITIAL_OFFSET, start_configuration
from expected import REQUIRED_SUMMARY_KEYS

ON_TRACK = (0.0, 0.0)

# (method, options, trajectory, horizon in s, bound on the max position error in m)
BOUNDS = [
    ("ats", {"aux": "shoulder"}, "ellipse", 40.0, 1e-6),
    ("ats", {"aux": "sum"}, "ellipse", 40.0, 1e-6),
    ("ap", {"K3": 0.0}, "ellipse", 40.0, 1e-6),
    ("clrrmc-ts", {}, "ellipse", 40.0, 1e-6),
    ("clrrmc-cs", {}, "ellipse", 40.0, 1e-6),
    ("pi", {}, "ellipse", 9.5, 1e-6),  # then damped near cos(th1) = 0 (see docs)
    ("ap", {}, "ellipse", 4.0, 1e-6),  # K3 phi^2 drags th1 into the singularity
    ("ats", {}, "rectangle", 30.0, 1e-6),  # then th2 winds into its -pi limit
    ("clrrmc-cs", {}, "rectangle", 30.0, 1e-6),
    ("clrrmc-ts", {}, "rectangle", 40.0, 0.25),  # orientation jumps at corners saturate
    ("pi", {}, "rectangle", 13.5, 1e-6),
]


@pytest.mark.parametrize(("method", "options", "traj", "horizon", "bound"), BOUNDS)
def test_documented_tracking_bounds(method, options, traj, horizon, bound):
    result = simulate(
        Robot(), load_trajectory(traj), method, duration=horizon, initial_offset=ON_TRACK, **options
    )
    assert result.summary["max_position_error_m"] < bound
    assert result.summary["max_nonholonomic_residual_m_s"] < 1e-6


def test_pseudoinverse_reaches_the_shoulder_singularity_on_the_ellipse():
    # Documented failure mode: min-norm splits the yaw between base and shoulder.
    result = simulate(Robot(), Ellipse(), "pi", initial_offset=ON_TRACK)
    assert result.summary["singular_steps"] > 0
    assert np.min(np.abs(np.cos(result.timeseries["th1"]))) < 0.05
    assert result.summary["max_position_error_m"] > 0.5


@pytest.mark.parametrize("traj", [Ellipse(), Rectangle()])
def test_task_space_error_decays_as_exp_minus_t_over_tau(traj):
    # Error dynamics Xe_dot + K Xe = 0 (docs/theory.md): e(t) = e(0) exp(-t/tau) while nothing
    # saturates (measured to 2.4e-6 relative with RK4 at dt = 0.02 s).
    tau = 0.5
    ts = simulate(Robot(), traj, "clrrmc-ts", duration=3.0, tau=tau).timeseries
    error = ts["position_error_m"]
    assert error[0] == pytest.approx(math.hypot(0.03, 0.03), rel=1e-12)
    for t in (tau, 2 * tau, 5 * tau):
        k = int(np.searchsorted(ts["t"], t - 1e-9))
        assert ts["t"][k] == pytest.approx(t)
        assert error[k] / error[0] == pytest.approx(math.exp(-t / tau), rel=1e-5)


@pytest.mark.parametrize("traj", [Ellipse(), Rectangle()])
def test_configuration_space_error_decays_as_exp_minus_t_over_tau(traj):
    # qe_dot + K qe = 0 (docs/theory.md) for clrrmc-cs, in configuration space: q_d - q against
    # the controller's own reference q_d(t).
    tau = 0.5
    result = simulate(Robot(), traj, "clrrmc-cs", duration=3.0, tau=tau)
    ts, reference = result.timeseries, result.controller.reference
    q = np.column_stack([ts[k] for k in ("x", "y", "phi", "th1", "th2")])
    error = np.linalg.norm(q - np.array([reference(t)[0] for t in ts["t"]]), axis=1)
    for t in (tau, 2 * tau, 5 * tau):
        k = int(np.searchsorted(ts["t"], t - 1e-9))
        assert error[k] / error[0] == pytest.approx(math.exp(-t / tau), rel=1e-6)


@pytest.mark.parametrize("method", ["pi", "ats", "ap"])
def test_open_loop_methods_keep_the_initial_offset(method):
    # Open loop on track of the desired velocity: the offset hypot(0.03, 0.03) m stays,
    # up to the RK4 truncation error (2e-12 m for pi and ats, 1.4e-10 m for ap).
    result = simulate(Robot(), Ellipse(), method, duration=3.0)
    error = result.timeseries["position_error_m"]
    assert error[0] == pytest.approx(math.hypot(0.03, 0.03), rel=1e-12)
    np.testing.assert_allclose(error, error[0], rtol=0, atol=1e-9)


def test_larger_tau_is_more_sluggish():
    errors = []
    for tau in (0.25, 0.5, 1.0, 2.0):
        ts = simulate(Robot(), Ellipse(), "clrrmc-ts", duration=2.0, tau=tau).timeseries
        errors.append(ts["position_error_m"][-1])
    assert errors == sorted(errors)
    assert errors[-1] > 10 * errors[0]


def drift(integrator, dt, key="end_position_error_m"):
    """Open-loop drift of ats on the ellipse, started on the path."""
    return simulate(
        Robot(), Ellipse(), "ats", integrator=integrator, dt=dt, initial_offset=ON_TRACK
    ).summary[key]


def test_euler_drifts_more_than_rk4():
    euler, rk4 = drift("euler", 0.1), drift("rk4", 0.1)
    assert euler > 1e-3
    assert euler > 1e4 * rk4  # measured 1.2e-3 m against 6.7e-9 m


def test_drift_shrinks_with_the_order_of_the_integrator():
    # Halving the step divides the global error by 2^p: p = 1 for forward Euler (measured
    # ratios 1.996, 1.998), p = 4 for RK4 (16.7, 16.3; the O(dt) terms fade as dt shrinks).
    euler = [drift("euler", dt) for dt in (0.1, 0.05, 0.025)]
    assert euler[0] / euler[1] == pytest.approx(2.0, abs=0.01)
    assert euler[1] / euler[2] == pytest.approx(2.0, abs=0.005)
    rk4 = [drift("rk4", dt, "max_position_error_m") for dt in (0.2, 0.1, 0.05)]
    assert rk4[0] / rk4[1] == pytest.approx(16.0, rel=0.06)
    assert rk4[1] / rk4[2] == pytest.approx(16.0, rel=0.03)


class WrappedHeading:
    """A trajectory whose desired heading is given wrapped to [-pi, pi)."""

    def __init__(self, trajectory):
        self.trajectory = trajectory
        self.duration, self.samples = trajectory.duration, trajectory.samples

    def pose(self, t):
        x, y, heading = self.trajectory.pose(t)
        return np.array([x, y, (heading + math.pi) % (2 * math.pi) - math.pi])

    def velocity(self, t):
        return self.trajectory.velocity(t)


@pytest.mark.parametrize("method", ["clrrmc-ts", "qp"])
def test_wrapped_and_unwrapped_headings_give_the_same_run(method):
    # The ellipse's tangent heading runs from pi/2 to 5 pi/2; wrapped, it jumps by -2 pi at
    # t = 30 s. An orientation error of 2 pi is no error: the runs must agree.
    unwrapped = simulate(Robot(), Ellipse(), method).timeseries
    wrapped = simulate(Robot(), WrappedHeading(Ellipse()), method).timeseries
    assert np.ptp(wrapped["phiE_d"]) < 2 * math.pi <= np.ptp(unwrapped["phiE_d"])
    for column in ("xE", "yE", "v", "w", "th1dot", "th2dot", "orientation_error_rad"):
        np.testing.assert_allclose(wrapped[column], unwrapped[column], rtol=0, atol=1e-8)
    assert np.sum(wrapped["saturated"]) == np.sum(unwrapped["saturated"]) == 0


HEADINGS = [2 * math.pi * k / 16 for k in range(16)]


@pytest.mark.parametrize("beta", HEADINGS)
@pytest.mark.parametrize("orientation", ["tangent", "constant"])
def test_the_default_offset_is_reachable_whichever_way_the_start_faces(beta, orientation):
    # Start headings all round (the ellipse rotated by beta, or a constant orientation
    # beta): the offset is in the end effector's frame, so the arm motion is the same.
    robot = Robot()
    phi = beta if orientation == "constant" else 0.0  # the tangent one has no phi
    trajectory = Ellipse(beta=beta, orientation=orientation, phi=phi)
    ts = simulate(robot, trajectory, "ats", duration=0.1).timeseries
    x_d, y_d, heading = trajectory.pose(0.0)
    dx, dy = DEFAULT_INITIAL_OFFSET
    expected = [
        x_d + math.cos(heading) * dx - math.sin(heading) * dy,
        y_d + math.sin(heading) * dx + math.cos(heading) * dy,
    ]
    np.testing.assert_allclose([ts["xE"][0], ts["yE"][0]], expected, atol=1e-12)
    assert ts["position_error_m"][0] == pytest.approx(math.hypot(dx, dy), rel=1e-12)


def test_the_default_offset_is_the_old_world_offset_on_the_default_ellipse():
    ts = simulate(Robot(), Ellipse(), "ats", duration=0.1).timeseries
    start = Ellipse().pose(0.0)
    np.testing.assert_allclose(
        [ts["xE"][0] - start[0], ts["yE"][0] - start[1]], [0.03, -0.03], atol=1e-12
    )


def test_start_configuration_puts_the_end_effector_on_the_trajectory(robot):
    for traj in (Ellipse(), Rectangle(), load_trajectory("figure8")):
        q = start_configuration(robot, traj)
        np.testing.assert_allclose(robot.fk(q), traj.pose(0.0), atol=1e-12)
        np.testing.assert_allclose(q[3:], robot.home_pose)


def test_kinematic_plant_never_moves_the_base_sideways(robot, rng):
    plant = KinematicPlant(robot)
    q = np.array([0.0, 0.0, 0.4, 0.1, 0.5])
    for _ in range(50):
        u = rng.uniform(-0.5, 0.5, 4)
        q_next, _, _ = plant.integrate(0.0, q, 0.01, lambda t, x, u=u: u)
        # Constant (v, w) moves the base along an arc: the chord is at heading phi + w dt / 2.
        chord = q_next[:2] - q[:2]
        mid_heading = q[2] + 0.5 * (q_next[2] - q[2])
        assert -chord[0] * math.sin(mid_heading) + chord[1] * math.cos(mid_heading) == (
            pytest.approx(0.0, abs=1e-9)
        )
        q = q_next


def test_plant_saturates_wheels_and_joints(robot):
    plant = KinematicPlant(robot)
    q = np.zeros(5)
    u, saturated = plant.saturate(q, np.array([5.0, 1.0, 3.0, -0.5]))
    left, right = robot.wheel_speeds_from_u(u[0], u[1])
    assert saturated
    assert max(abs(left), abs(right)) == pytest.approx(robot.wheel_speed_limit)
    assert u[0] / u[1] == pytest.approx(5.0)  # curvature kept
    assert u[2] == pytest.approx(robot.joint_speed_limit) and u[3] == -0.5
    # At the joint position limit a joint cannot be driven further out.
    at_limit = np.array([0, 0, 0, robot.joint_limits[0][1], 0.0])
    u, _ = plant.saturate(at_limit, np.array([0.0, 0.0, 1.0, 0.0]))
    assert u[2] == 0.0


def test_summary_keys_and_shapes():
    result = simulate(Robot(), Ellipse(), "clrrmc-ts", duration=1.0)
    assert set(result.summary) >= REQUIRED_SUMMARY_KEYS
    assert result.summary["steps"] == 50
    assert all(len(v) == 51 for v in result.timeseries.values())
    assert result.summary["median_step_us"] > 0


def test_custom_trajectory_object_is_accepted():
    class Line:
        duration = 4.0

        def pose(self, t):
            return np.array([0.1 * t, 0.5, 0.0])

        def velocity(self, t):
            return np.array([0.1, 0.0, 0.0])

    result = simulate(Robot(), Line(), "clrrmc-ts", dt=0.01, initial_offset=ON_TRACK)
    assert result.summary["max_position_error_m"] < 1e-6
    assert result.summary["trajectory"] == "line"


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"dt": 0.0}, "dt must be > 0"),
        ({"dt": -0.1}, "dt must be > 0"),
        ({"dt": float("nan")}, "dt must be a finite number"),
        ({"duration": -1.0}, "duration must be > 0"),
        ({"integrator": "rk45"}, "integrator must be one of"),
        ({"initial_offset": (2.0, 0.0)}, "cannot be reached with the arm"),
    ],
)
def test_simulate_rejects_bad_input(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        simulate(Robot(), Ellipse(), "ats", **kwargs)


def test_plant_holds_a_given_command_without_a_policy(robot):
    """Zero-order hold: Euler is exact for the first step; RK4 integrates the held input
    along the arc of constant (v, w): x = v/w sin(w t), y = v/w (1 - cos(w t))."""
    u = np.array([0.2, 0.1, 0.3, -0.2])
    q_next, _, _ = KinematicPlant(robot, "euler").integrate(0.0, np.zeros(5), 0.1, None, u)
    np.testing.assert_allclose(q_next, [0.02, 0.0, 0.01, 0.03, -0.02], rtol=0, atol=1e-15)
    dt = 0.1
    q_rk4, _, _ = KinematicPlant(robot, "rk4").integrate(0.0, np.zeros(5), dt, None, u)
    v, w = u[0], u[1]
    arc = [v / w * math.sin(w * dt), v / w * (1 - math.cos(w * dt)), w * dt, 0.3 * dt, -0.2 * dt]
    np.testing.assert_allclose(q_rk4, arc, rtol=0, atol=1e-10)
    with pytest.raises(ValueError, match="a policy or a first_command is needed"):
        KinematicPlant(robot, "rk4").integrate(0.0, np.zeros(5), 0.1, None, None)


def test_step_counts_are_of_the_runs_steps_not_its_samples():
    """A 10-step run records 11 samples; the last sample's command is never applied and the
    start is no step's result, so no count exceeds the 10 steps (it was 11 of 10: the
    verdict said "saturated 11 of 10 steps", track "steps with S < S_min 11")."""
    fast = simulate(Robot(), Ellipse(T=0.5, N=10), "clrrmc-ts")  # far beyond every rate limit
    assert fast.summary["steps"] == 10 and len(fast.timeseries["t"]) == 11
    assert np.all(fast.timeseries["saturated"] == 1.0)  # every sample clipped, the last too
    assert fast.summary["saturated_steps"] == 10
    assert "saturated 10 of 10 steps" in fast.summary["verdict"]
    # the start pose's S is 2.18: a floor of 3 is broken before and after every step
    for method in ("qp", "mpc"):
        high = simulate(Robot(), Ellipse(), method, duration=0.2, stability_min=3.0).summary
        assert high["steps"] == 10 and high["min_stability"] < 3.0
        assert high["stability_violations"] == 10, method


def test_the_counts_of_commands_leave_out_the_last_sample_and_of_states_the_first():
    from ddwmmr.controllers.base import commanded_steps, step_results

    flags = [0.0, 1.0, 0.0, 1.0]  # 3 steps: the command at sample 3 is never applied
    np.testing.assert_array_equal(commanded_steps(flags), [0.0, 1.0, 0.0])
    np.testing.assert_array_equal(step_results(flags), [1.0, 0.0, 1.0])
    assert len(commanded_steps([0.0])) == len(step_results([0.0])) == 0  # 0 steps


def test_a_controller_built_for_another_robot_is_named_in_a_warning():
    """A qp built for the light robot keeps its floor with the wrong payload's model: on
    the 3 kg robot the run's S falls below it. simulate says so before it runs."""
    import warnings

    from ddwmmr import make_controller

    light, heavy = Robot(), Robot().with_payload(3.0)
    trajectory = load_trajectory("sideways_reach")
    with pytest.warns(UserWarning, match=r"another robot .*\(payload 1\.25 vs 3\.0\)"):
        result = simulate(heavy, trajectory, make_controller("qp", light, stability_min=1.25))
    assert result.summary["min_stability"] < 1.2  # the model mismatch shows
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the same robot: no warning
        matched = simulate(heavy, trajectory, make_controller("qp", heavy, stability_min=1.25))
    assert matched.summary["min_stability"] >= 1.25 - 1e-6


def test_a_result_prints_as_one_line_naming_the_run():
    """``print(result)`` is what a user types first: one line, no time-series arrays."""
    result = simulate(Robot(), load_trajectory("ellipse"), "ats", duration=2.0)
    text = repr(result)
    assert "\n" not in text and len(text) < 300
    rms = result.summary["rms_position_error_m"]
    assert text == (
        f"SimulationResult(method='ats', trajectory='ellipse', plant='kinematic', steps=100, "
        f"rms_position_error_m={rms!r}, verdict='tracked', "
        f"timeseries=<{len(result.timeseries)} columns>)"
    )
    assert 0.04 < rms < 0.045
    assert str(result) == text
