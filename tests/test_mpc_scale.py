"""The ``mpc`` at other robot sizes (docs/mpc.md, "Robot size").

With the kinematic model the OCP works in the robot's length unit (``length_unit(L1) =
L1 / 0.35 m``): its robot is the robot with every length divided by the unit, its
positions, references and ``v`` are in the unit. A robot scaled by a power of two (exact in
binary floating point) then hands the solver the default robot's problem to the last bit
and runs the default robot's steps with ``s`` times its errors; at another scale the two
runs differ by rounding only. Options given in m or m/s stay in metres (scaled with the
scene below).
"""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, make_controller
from ddwmmr.cli.track import main as track_main
from ddwmmr.mpc.fallback import make_fallback
from ddwmmr.mpc.min_time import Guess
from scaled_robots import (
    TEN_TIMES,
    TWENTIETH,
    mpc_on_scaled_ellipse,
    scaled_options,
    scaled_robot,
)

#: A short run (s): the offset's transient and a stretch of the ellipse.
DURATION = 3.0
#: Options in m or m/s, scaled with the robot below.
METRE_OPTIONS = ("obstacle_margin", "reach_speed", "huber")


def errors(robot: Robot, factor: float, **options) -> np.ndarray:
    """Position errors divided by ``factor`` (m) and orientation errors (rad), per step, of
    the ``mpc`` on ``robot`` tracking the ellipse and start offset scaled by ``factor``."""
    options = scaled_options(options, factor, METRE_OPTIONS)
    series = mpc_on_scaled_ellipse(robot, factor, DURATION, **options).timeseries
    return np.array(
        [
            np.asarray(series["position_error_m"]) / factor,
            np.asarray(series["orientation_error_rad"]),
        ]
    )


@functools.cache
def reference_errors(name: str) -> np.ndarray:
    """:func:`errors` of the default robot (factor 1) with the options ``RUNS[name]``, run
    once per worker (every test compares its scaled runs with it); read-only."""
    reference = errors(Robot(), 1.0, **RUNS[name])
    reference.flags.writeable = False
    return reference


RUNS = {
    "default": {},
    "position only, huber": {"track_orientation": False, "huber": 0.02},
    "post": {
        "obstacles": [(-0.2, 1.05, 0.3)],
        "track_orientation": False,
        "obstacle_margin": 0.05,
    },
}


@pytest.mark.parametrize("name", list(RUNS))
@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_a_power_of_two_scale_gives_the_default_runs_errors_on_every_step(factor, name):
    reference = reference_errors(name)
    scaled = errors(scaled_robot(factor), factor, **RUNS[name])
    assert reference.shape[1] == 151
    assert reference[0].max() > 0.04  # the start offset, 0.03 sqrt(2) m
    np.testing.assert_array_equal(scaled, reference)


@pytest.mark.parametrize(("robot", "factor"), [(TWENTIETH, 0.05), (TEN_TIMES, 10.0)])
def test_another_scale_differs_from_the_default_run_by_rounding_only(robot, factor):
    """Masses by s^3 (the centre of mass does not move), lengths by s."""
    reference = reference_errors("default")
    scaled = errors(robot, factor)
    np.testing.assert_allclose(scaled[0], reference[0], rtol=1e-6)
    np.testing.assert_allclose(scaled[1], reference[1], rtol=0.0, atol=1e-9)


class _Recorder:
    """Wraps a solver: every call's inputs ``(w0, p, lbw, ubw, lbg, ubg)`` and solution."""

    def __init__(self, solver) -> None:
        self.solver, self.calls = solver, []
        self.last_iterations = 0

    def solve(self, *inputs):
        w = self.solver.solve(*inputs)
        self.last_iterations = self.solver.last_iterations
        self.calls.append([np.array(value, dtype=float) for value in (*inputs, w)])
        return w


#: A configuration (default robot's sizes, m and rad) and a waypoint 0.6 m away.
START, WAYPOINT = [0.1, 0.7, 0.4, 0.3, 1.2], [0.5, 1.3, 0.0]


def solver_calls(factor: float, options: dict, steps: int = 4) -> tuple[list, list]:
    """The solver inputs and solutions of ``steps`` waypoint steps of the mpc on the robot
    scaled by ``factor`` (the kinematic model's state integrated by Euler steps), and the
    commands sent."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        controller = make_controller(
            "mpc", scaled_robot(factor), **scaled_options(options, factor, METRE_OPTIONS)
        )
    q, target = np.array(START), np.array(WAYPOINT)
    q[:2] *= factor
    target[:2] *= factor
    controller.reset(None, q)
    problem = controller._problem("reach")
    problem.cold = problem.solver = recorder = _Recorder(problem.solver)
    commands = []
    for step in range(steps):
        u = np.asarray(controller.command(0.02 * step, q, target, np.zeros(3)))
        commands.append(u)
        q = q + 0.02 * np.array([u[0] * np.cos(q[2]), u[0] * np.sin(q[2]), *u[1:]])
    return recorder.calls, commands


WAYPOINT_OPTIONS = {
    # the default Huber scale (0.01 of the robot's unit); reach_speed the default (m/s)
    "default": {"reach_speed": 0.05},
    "scene": {"obstacles": [(0.3, 1.8, 0.1)], "obstacle_margin": 0.05, "reach_speed": 0.2},
}


@pytest.mark.parametrize("name", list(WAYPOINT_OPTIONS))
@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_the_solver_gets_the_default_robots_problem_bit_for_bit(factor, name):
    """The parameter vector (references, previous command, terminal factor, horizon), the
    bounds (the measured state pinned), the warm start and the solution: the default
    robot's; the command's ``v`` is ``factor`` times the default's, the rates the same."""
    reference, default_commands = solver_calls(1.0, WAYPOINT_OPTIONS[name])
    calls, commands = solver_calls(factor, WAYPOINT_OPTIONS[name])
    assert len(calls) == len(reference) == 4
    for call, expected in zip(calls, reference):
        for value, wanted in zip(call, expected):
            np.testing.assert_array_equal(value, wanted)
    for u, wanted in zip(commands, default_commands):
        assert abs(wanted[0]) > 0.01  # the base moves
        np.testing.assert_array_equal(u, wanted * [factor, 1.0, 1.0, 1.0])


def test_the_default_robot_plans_in_metres_with_its_own_model():
    controller = make_controller("mpc", Robot())
    controller.reset(None, START)
    problem = controller._problem("reach")
    assert controller.unit == 1.0
    assert problem.robot is controller.robot and problem.model is controller.model


def test_a_scaled_robots_summary_records_the_huber_scale_in_metres():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        controller = make_controller("mpc", scaled_robot(8.0))
    assert controller.resolved.record("reach", 0.02, controller.unit)["huber"] == 0.08
    assert controller.resolved.record("tracking", 0.02, controller.unit)["huber"] is None


def _kinematic_plan(factor: float) -> Guess:
    """A plan of two 1 s legs for the kinematic model (states ``x, y, theta, q1, q2``,
    inputs ``v, omega, r1, r2``) from :data:`START`, its positions and ``v`` scaled by
    ``factor`` (m, m/s)."""
    times = np.linspace(0.0, 2.0, 21)
    states = np.tile(np.array(START, dtype=float), (21, 1))
    states[:, 0] += 0.2 * times
    states[:, 1] += 0.3 * times
    states[:, 2] += 0.1 * times
    inputs = np.tile([0.36, 0.1, 0.0, 0.0], (20, 1))
    states[:, :2] *= factor
    inputs[:, 0] *= factor
    return Guess(times, states, inputs, np.array([1.0, 2.0]))


def plan_solver_calls(factor: float) -> list:
    """The solver inputs and solutions of the first waypoint step of the mpc on the robot
    scaled by ``factor``, on a two-waypoint route with a plan scaled alike (the plan's cold
    start and its arrival term)."""
    route = [(factor * x, factor * y) for x, y in ((0.5, 1.3), (0.7, 1.9))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        controller = make_controller("mpc", scaled_robot(factor), route=route)
    # the plan option takes the force model's plans only; the OCP's conversion is what is
    # tested here, so the plan is handed over as loading would
    controller._plan = _kinematic_plan(factor)
    q = np.array(START)
    q[:2] *= factor
    controller.reset(None, q)
    problem = controller._problem("reach")
    assert problem.ocp.arrival_size > 0
    problem.cold = problem.solver = recorder = _Recorder(problem.solver)
    controller.command(0.0, q, np.array([*route[0], 0.0]), np.zeros(3))
    return recorder.calls


@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_a_plan_scaled_with_the_robot_gives_the_solver_the_default_robots_problem(factor):
    """The plan's cold start and arrival state (in the parameter vector) in the robot's
    unit: the default robot's to the bit."""
    reference = plan_solver_calls(1.0)
    calls = plan_solver_calls(factor)
    assert len(calls) == len(reference) == 1
    for value, wanted in zip(calls[0], reference[0]):
        np.testing.assert_array_equal(value, wanted)


@pytest.mark.parametrize("factor", [1.0, 8.0])
def test_the_waypoint_fallbacks_speed_limit_is_one_length_unit_per_second(factor):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = scaled_robot(factor)
        controller = make_controller("mpc", robot)
    qp = make_fallback(robot, controller.options, None, 0.02, None)
    assert qp.tracking.max_speed == factor  # 1 m/s on the default robot


def test_proportions_too_far_apart_for_the_mpcs_unit_name_the_robots_own_lengths(tmp_path, capsys):
    """L1 0.1 mm and L2 0.3 m are both valid; in the unit L1 / 0.35 L2 is 1050 units."""
    robot = Robot(L1=0.0001, L2=0.3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ParameterError) as error:
            make_controller("mpc", robot)
        make_controller("mpc", robot, model="thesis")  # plans in metres
    message = str(error.value)
    assert message.startswith("mpc: the kinematic model measures lengths in the robot's ")
    assert "L2 = 0.3 m is 1050 length units of 0.000285714 m" in message
    assert "(got 1050)" not in message and "\n" not in message
    path = tmp_path / "robot.toml"
    path.write_text("L1 = 0.0001\nL2 = 0.3\n")
    out = tmp_path / "run"
    argv = ["--robot", str(path), "--method", "mpc", "--traj", "ellipse", "--no-progress"]
    argv += ["--out", str(out)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert track_main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: mpc: the kinematic model measures lengths in the robot's ")
    assert err.count("\n") == 1 and "Traceback" not in err
