"""The ``qp`` at other robot sizes (docs/qp.md, "Robot size").

The QP works in the robot's length unit (``length_unit(L1) = L1 / 0.35 m``): its ``v`` is
``v / unit``, its linear rows, targets and length constants are in the unit. A robot scaled
by a power of two (exact in binary floating point) then hands the solver the default
robot's problem to the last bit, and runs the default robot's steps with ``s`` times its
errors; at another scale the two runs differ by rounding only. Options given in m or m/s
stay in metres (the obstacle margin is scaled with the scene below), and a user's piece
keeps writing its rows for ``v`` in m/s.
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import replace

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, make_controller, simulate
from ddwmmr.commands import PlantTraits
from ddwmmr.qp import QPProblem
from ddwmmr.qp.limits import Limit
from ddwmmr.qp.limits.base import INF
from scaled_robots import TEN_TIMES, TWENTIETH, scaled_options, scaled_robot

ELLIPSE = Ellipse()
#: Start offset (m) on the default robot, along both end-effector axes.
OFFSET = -0.03
#: The shipped post on the default ellipse (trajectories/obstacles/ellipse_post.toml), m.
POST = (-0.2, 1.05, 0.3)
#: Options in m or m/s, scaled with the robot below (``obstacle_margin``: the default).
METRE_OPTIONS = ("obstacle_margin", "max_speed", "max_base_speed", "max_acceleration")
ARRAYS = ("H", "f", "C", "lower", "upper")


def run(robot: Robot, factor: float, dt: float | None = None, **options):
    """``qp`` on ``robot``, the ellipse and start offset scaled by ``factor``."""
    task = replace(ELLIPSE, a=factor * ELLIPSE.a, b=factor * ELLIPSE.b)
    step = {} if dt is None else {"dt": dt}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a small robot's lengths look like unit mistakes
        return simulate(
            robot,
            task,
            "qp",
            initial_offset=(factor * OFFSET, factor * OFFSET),
            **step,
            **scaled_options(options, factor, METRE_OPTIONS),
        )


def errors(result, factor: float = 1.0) -> np.ndarray:
    """Position errors divided by ``factor`` (m) and orientation errors (rad), per step."""
    series = result.timeseries
    return np.array(
        [
            np.asarray(series["position_error_m"]) / factor,
            np.asarray(series["orientation_error_rad"]),
        ]
    )


RUNS = {
    "default": (None, {}),
    "dt 2 s": (2.0, {}),
    "hierarchical": (None, {"mode": "hierarchical"}),
    "position, base envelope": (
        None,
        {
            "track_orientation": False,  # the heading task on
            "max_speed": 0.5,
            "max_base_speed": 0.3,
            "max_acceleration": 1.0,
            "speed_budget": (0.5, 2.0),
        },
    ),
}


@functools.cache
def reference_errors(name: str) -> np.ndarray:
    """``errors`` of the default robot's run ``RUNS[name]``, computed once per module: the
    run is deterministic and the tests compare against it at every scale (read only)."""
    dt, options = RUNS[name]
    reference = errors(run(Robot(), 1.0, dt, **options))
    reference.setflags(write=False)
    return reference


@pytest.mark.parametrize("name", list(RUNS))
@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_a_power_of_two_scale_gives_the_default_runs_errors_on_every_step(factor, name):
    """Exact, at dt = 2 s too, where the default run itself amplifies one ulp on the
    ellipse's axes to a 50 % different error within 17 steps."""
    dt, options = RUNS[name]
    reference = reference_errors(name)
    scaled = errors(run(scaled_robot(factor), factor, dt, **options), factor)
    assert reference.shape[1] in (21, 2001)
    assert reference[0].max() > 0.04  # the start offset, 0.03 sqrt(2) m
    np.testing.assert_allclose(scaled, reference, rtol=1e-12, atol=0.0)


#: Position tracking round the shipped post (``obstacle_margin`` in m, scaled by ``run``).
POST_OPTIONS = {"obstacles": [POST], "track_orientation": False, "obstacle_margin": 0.05}


@functools.cache
def post_reference():
    """The default robot's run round the post, computed once per module (read only)."""
    return run(Robot(), 1.0, **POST_OPTIONS)


@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_a_power_of_two_scale_with_the_scene_scaled_passes_the_post_alike(factor):
    """Position tracking round the shipped post, the post and ``obstacle_margin`` scaled:
    the obstacle limit, steering and detour work in the robot's unit too."""
    reference = post_reference()
    scaled = run(scaled_robot(factor), factor, **POST_OPTIONS)
    np.testing.assert_allclose(errors(scaled, factor), errors(reference), rtol=1e-12, atol=0.0)
    clearance = reference.summary["min_obstacle_clearance_m"]
    assert 0.0 < clearance < 0.6  # the post was within reach of the limit
    assert scaled.summary["min_obstacle_clearance_m"] == pytest.approx(factor * clearance)


@pytest.mark.parametrize(("robot", "factor"), [(TWENTIETH, 0.05), (TEN_TIMES, 10.0)])
def test_another_scale_differs_from_the_default_run_by_rounding_only(robot, factor):
    """Masses by s^3, torques by s^4 (the kinematic plant uses neither), at the default
    step; at dt = 2 s the default run amplifies rounding (see above), so it is not here."""
    reference = reference_errors("default")
    scaled = errors(run(robot, factor), factor)
    np.testing.assert_allclose(scaled[0], reference[0], rtol=1e-7)
    np.testing.assert_allclose(scaled[1], reference[1], rtol=0.0, atol=1e-9)


OPTIONS = {
    "default": {},
    "scene": {
        "obstacles": [POST, (0.9, -0.2, 0.2)],
        "track_orientation": False,
        "obstacle_margin": 0.05,
    },
    "base motion": {
        "max_base_speed": 0.6,
        "max_yaw_rate": 1.2,
        "max_acceleration": 1.0,
        "speed_budget": (0.9, 1.5),
    },
}
#: A configuration, a desired pose and velocity (default robot's sizes, m and m/s).
STATE = ([0.1, 0.7, 0.4, 0.3, 1.2], [0.35, 1.3, 1.0], [0.2, -0.1, 0.3])


def built(factor: float, options: dict, compiled: bool = True) -> tuple:
    """The controller for the robot scaled by ``factor`` and its problem built at
    ``STATE`` scaled by ``factor`` (after a first step, for the slew limits)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        controller = make_controller(
            "qp", scaled_robot(factor), **scaled_options(options, factor, METRE_OPTIONS)
        )
    q, pose, velocity = (np.array(values) for values in STATE)
    for values in (q, pose, velocity):
        values[:2] *= factor
    controller.reset(None, q)
    controller.command(0.0, q, pose, velocity)
    problem = controller.problem
    if not compiled:
        problem = QPProblem(
            controller.tasks, controller.limits, compiled=False, unit=controller.unit
        )
    controller.ctx.update(0.02, q, pose, velocity)
    problem.build(controller.ctx)
    return controller, problem


@pytest.mark.parametrize("name", list(OPTIONS))
@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_the_solver_gets_the_default_robots_problem_bit_for_bit(name, factor):
    _, reference = built(1.0, OPTIONS[name])
    for compiled in (True, False):
        _, problem = built(factor, OPTIONS[name], compiled)
        for array in ARRAYS:
            assert np.array_equal(getattr(problem, array), getattr(reference, array)), array


class _MetreCap(Limit):
    """A user's limit in m/s: a row ``v <= top`` and the box ``v >= bottom``."""

    rows = 1

    def __init__(self, top: float, bottom: float) -> None:
        self.top, self.bottom = top, bottom

    def compute(self, ctx, G, lower, upper, lb, ub) -> None:
        G[0] = (1.0, 0.0, 0.0, 0.0)
        lower[0], upper[0] = -INF, self.top
        lb[0] = max(lb[0], self.bottom)


@pytest.mark.parametrize("factor", [8.0, 0.05])
def test_a_users_limit_keeps_its_rows_in_metres(factor):
    """The user's row caps ``v`` at ``top`` m/s, its box at ``bottom`` m/s, on a robot
    of another size too: the problem converts its ``v`` column (and the box) to the robot's
    unit (a limit read in the unit would cap at ``top`` times the unit)."""
    robot = scaled_robot(factor)
    top, bottom = 0.05 * factor, -0.02 * factor
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        free = make_controller("qp", robot)
        capped = make_controller("qp", robot, limits=[_MetreCap(top, bottom)])
    q = np.array([0.0, 0.0, 0.0, 0.3, 1.2])
    ahead = np.array([factor, 0.0, 0.0])  # a target one robot unit ahead
    for controller in (free, capped):
        controller.reset(None, q)
    assert free.command(0.0, q, ahead, np.zeros(3))[0] > 0.1 * factor
    assert capped.command(0.0, q, ahead, np.zeros(3))[0] == pytest.approx(top, rel=1e-6)
    capped.reset(None, q)
    behind = np.array([-factor, 0.0, 0.0])
    assert capped.command(0.0, q, behind, np.zeros(3))[0] == pytest.approx(bottom, rel=1e-6)


def test_a_problem_in_metres_gives_the_same_command():
    """A problem built in metres (unit 1.0, as the benchmark's generic problem) around the
    robot's pieces converts their ``v`` columns back: the same command as in the unit."""
    robot = scaled_robot(8.0)
    q = np.array([0.8, 5.6, 0.4, 0.3, 1.2])
    pose, velocity = np.array([2.8, 10.4, 1.0]), np.array([1.6, -0.8, 0.3])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        unit, metres = (make_controller("qp", robot) for _ in range(2))
    metres.problem = QPProblem(metres.tasks, metres.limits, compiled=False)
    commands = []
    for controller in (unit, metres):
        controller.reset(None, q)
        commands.append(controller.command(0.0, q, pose, velocity))
    np.testing.assert_allclose(commands[1], commands[0], rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("compiled", [True, False])
def test_the_edge_load_rows_take_v_in_the_unit(compiled):
    """Loads in N stay in N; only the ``v`` entry of each edge row is per ``v / unit``
    (the loads themselves do not scale with the robot: gravity does not)."""
    q, pose, velocity = np.array([0.8, 5.6, 0.4, 0.3, 1.2]), np.zeros(3), np.zeros(3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        controller = make_controller("qp", scaled_robot(8.0))
    controller.adopt_plant(PlantTraits(("velocity",), True, 0.02))
    controller.reset(None, q)
    limit = controller.edge_loads
    limit.observe(0.4, 0.3)
    problem = QPProblem(controller.tasks, controller.limits, compiled=compiled, unit=8.0)
    controller.ctx.update(0.0, q, pose, velocity)
    problem.build(controller.ctx)
    newtons = np.array(limit.rows_and_floors(controller.ctx)[0])  # per m/s, rad/s
    written = problem.C[problem.m - limit.rows :, :4]
    assert np.abs(newtons[:, 0]).min() > 0.0
    np.testing.assert_array_equal(written[:, 0], 8.0 * newtons[:, 0])
    np.testing.assert_array_equal(written[:, 1:], newtons[:, 1:])
