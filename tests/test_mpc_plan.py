"""``plan``: an offline minimum-time trajectory of the task as the mpc's cold start (the
file format of ``python -m ddwmmr.bounds``, its loading, the leg it hands each new target,
and that the plan's structure is what the controller settles in)."""

from __future__ import annotations

import math
import pickle
import zipfile
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, make_controller
from ddwmmr.cli.scenarios import main as scenarios_main
from ddwmmr.commands import traits_of
from ddwmmr.controllers.base import WaypointRun
from ddwmmr.mpc.cache import shared_ocp
from ddwmmr.mpc.controller import MPCController
from ddwmmr.mpc.min_time import PLAN_FOLDER, PLAN_NAME, Guess, MinimumTimeProblem, plan_path
from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP
from ddwmmr.plants import ThesisPlant
from ddwmmr.scenarios import RunConfig, Scenario, generate, run_scenario
from one_line import one_line

ROBOT = Robot().with_payload(3.0)
#: the default pose at rest: the end effector about 0.5 m ahead of the base
START = np.array([0.0, 0.0, 0.0, 0.3, 1.2])
BEHIND = (-1.2, 0.0)


def straight_plan(speed: float, turn: float, duration: float = 3.0, n: int = 30) -> dict:
    """A plan of one leg: the base at ``speed`` (m/s) along x turning at ``turn`` (rad/s),
    the arm still, the wheel forces that drive it that way (N, left and right)."""
    times = np.linspace(0.0, duration, n + 1)
    states = np.zeros((n + 1, 7))
    states[:, 0] = speed * times
    states[:, 2] = turn * times
    states[:, 3:5] = START[3:5]
    states[:, 5], states[:, 6] = speed, turn
    push, twist = 10.0 * np.sign(speed), 10.0 * np.sign(turn)
    inputs = np.tile([push - twist, push + twist, 0.0, 0.0], (n, 1))
    return {"times": times, "states": states, "inputs": inputs, "legs": np.array([duration])}


def write_plan(path: Path, arrays: dict) -> Path:
    np.savez(path, **arrays)
    return path


#: two waypoints behind the start, on the straight plans' line
ROUTE = [(-0.9, 0.0), (-1.7, 0.0)]


def two_leg_controller(folder: Path, turn: float = 0.0, **options) -> MPCController:
    """The mpc (force model, ``lookahead``, the scenarios' 0.01 s step) on :data:`ROUTE`
    with a plan of two legs, 1 s and 3 s, of the base reversing at 0.4 m/s while turning
    at ``turn`` (rad/s). Its problems are those of the scenario runs below with the same
    ``plan_weight``: built once per process, they serve both."""
    arrays = straight_plan(-0.4, turn, duration=4.0, n=40)
    arrays["legs"] = np.array([1.0, 3.0])
    path = str(write_plan(folder / "plan.npz", arrays))
    controller = MPCController(
        ROBOT, model="thesis", lookahead=True, route=ROUTE, plan=path, dt=0.01, **options
    )
    controller.adopt_plant(traits_of(ThesisPlant(ROBOT)))
    return controller


def test_a_stored_plan_loads_with_its_arrival_times_and_samples_its_legs(tmp_path):
    arrays = straight_plan(-0.4, 0.0, duration=2.0, n=20)
    arrays["legs"] = np.array([0.5, 1.5])
    plan = Guess.load(write_plan(tmp_path / "plan.npz", arrays))
    assert plan.arrivals == pytest.approx([0.5, 2.0])
    assert plan.legs == pytest.approx([0.5, 1.5])
    # leg 1 starts at the arrival at the first waypoint (0.5 s): x = -0.4 t
    states, inputs = plan.leg_samples(1, np.array([0.0, 0.25, 10.0]))
    assert states[:, 0] == pytest.approx([-0.2, -0.3, -0.8])  # held beyond the end
    assert inputs[:, 0] == pytest.approx([-10.0] * 3)


def test_a_solutions_stored_arrays_load_back_as_its_trajectory(tmp_path):
    """What the bounds tool stores of a best-known solution is what a plan reads."""
    problem = MinimumTimeProblem(
        ROBOT, [(1.5, 0.5), (1.5, 1.5)], [*START, 0.0, 0.0], intervals_per_leg=4
    )
    solution = problem.solve(problem.straight_line_guess())
    plan = Guess.load(write_plan(tmp_path / "plan.npz", solution.plan_arrays()))
    assert np.array_equal(plan.states, solution.states)
    assert np.array_equal(plan.inputs, solution.inputs)
    assert plan.legs == pytest.approx(solution.legs)
    assert plan.arrivals[-1] == pytest.approx(solution.total)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"legs": None}, r"must be a \.npz with times, states, inputs, legs \(legs is not"),
        ({"states": np.zeros((5, 7))}, r"states \(M\+1, 7\)"),
        ({"legs": np.array([3.0, 0.0])}, r"legs \(> 0 s\)"),
        ({"times": np.linspace(3.0, 0.0, 31)}, "times .* increasing"),
        ({"inputs": np.full((30, 4), np.nan)}, "all finite"),
        # a shifted plan and legs of another length than the times loaded, to be followed
        # against arrivals the trajectory does not have
        ({"times": np.linspace(5.0, 8.0, 31)}, "times .* increasing from 0"),
        ({"legs": np.array([1.5])}, r"legs \(> 0 s\) summing to the last time"),
        ({"legs": np.array([2.0, 2.0])}, r"legs \(> 0 s\) summing to the last time"),
    ],
)
def test_a_bad_plan_file_is_a_one_line_error(tmp_path, change, match):
    arrays = {**straight_plan(0.5, 0.0), **change}
    arrays = {k: v for k, v in arrays.items() if v is not None}
    path = write_plan(tmp_path / "plan.npz", arrays)
    with pytest.raises(ParameterError, match=match) as error:
        Guess.load(path)
    assert "\n" not in str(error.value)


def test_a_missing_or_unreadable_plan_is_a_one_line_error(tmp_path):
    with pytest.raises(ParameterError, match=r"plan .*nowhere\.npz: no such file"):
        Guess.load(tmp_path / "nowhere.npz")
    (tmp_path / "text.npz").write_text("not an archive")
    with pytest.raises(ParameterError, match=r"plan .*text.npz must be a \.npz"):
        Guess.load(tmp_path / "text.npz")


def _damaged_plans(folder: Path) -> dict[str, Path]:
    """Files that are no readable plan archive, by what is wrong with them."""
    whole = write_plan(folder / "whole.npz", straight_plan(0.5, 0.0)).read_bytes()
    files = {
        "empty": b"",
        "truncated": whole[: len(whole) // 2],
        # a byte of the times' data flipped: the member's checksum fails
        "bad checksum": whole[:200] + bytes([whole[200] ^ 0xFF]) + whole[201:],
        "pickled": pickle.dumps({"times": [0.0, 1.0]}),
    }
    paths = {}
    for name, content in files.items():
        paths[name] = folder / f"{name.replace(' ', '-')}.npz"
        paths[name].write_bytes(content)
    paths["not an array"] = folder / "text-member.npz"
    with zipfile.ZipFile(paths["not an array"], "w") as archive:
        for key in ("times", "states", "inputs", "legs"):
            archive.writestr(f"{key}.npy", "not an array")
    paths["object array"] = write_plan(
        folder / "objects.npz", {**straight_plan(0.5, 0.0), "legs": np.array([None], dtype=object)}
    )
    paths["compressed, damaged"] = folder / "deflated.npz"
    np.savez_compressed(paths["compressed, damaged"], **straight_plan(0.5, 0.0))
    deflated = bytearray(paths["compressed, damaged"].read_bytes())
    deflated[80:120] = b"x" * 40
    paths["compressed, damaged"].write_bytes(bytes(deflated))
    paths["one .npy array"] = folder / "single.npy"
    np.save(paths["one .npy array"], np.zeros(3))
    return paths


def test_a_damaged_plan_file_is_the_one_line_error_of_any_unreadable_plan(tmp_path):
    """Empty and truncated files raised EOFError and zipfile.BadZipFile (a traceback in
    the tools); every damaged file is the plan's own one-line error, through the API and
    the controller it configures."""
    for name, path in _damaged_plans(tmp_path).items():
        with pytest.raises(ParameterError) as error:
            Guess.load(path)
        message = one_line(error)
        assert message.startswith(
            f"plan {path} must be a .npz with times, states, inputs, legs ("
        ), name
        with pytest.raises(ParameterError) as error:
            make_controller("mpc", ROBOT, model="thesis", route=[(1.0, 0.0)], plan=str(path))
        assert one_line(error) == message, name


@pytest.mark.parametrize("damage", ["empty", "truncated"])
def test_a_damaged_plan_stops_the_scenario_tool_with_one_line(tmp_path, capsys, damage):
    path = _damaged_plans(tmp_path)[damage]
    out = tmp_path / "run"
    args = ["--controller", "mpc", "--n", "1", "--option", f"plan={path}"]
    assert scenarios_main([*args, "--no-progress", "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.err.startswith(f"error: plan {path} must be a .npz with times, states, ")
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err
    assert not out.exists()


def test_plan_option_errors_name_the_option(tmp_path):
    path = str(write_plan(tmp_path / "plan.npz", straight_plan(0.5, 0.0)))
    with pytest.raises(ParameterError, match="plan must be a file path"):
        MPCController(ROBOT, plan=3)
    with pytest.raises(ParameterError, match=r"plan .* has 1 legs: route must list as many"):
        MPCController(ROBOT, model="thesis", plan=path, route=[(1.0, 0.0), (2.0, 0.0)])
    with pytest.raises(ParameterError, match="plan needs the force model"):
        MPCController(ROBOT, model="kinematic", plan=path, route=[(1.0, 0.0)])


def test_the_cold_start_is_the_plans_leg_on_the_ocps_nodes(tmp_path):
    controller = two_leg_controller(tmp_path)
    problem = controller._problem("reach2")
    ocp = problem.ocp
    x0 = np.array([*START, 0.0, 0.0])
    w, horizon = problem.planned_start(x0, controller._plan, 0)
    xs, us = ocp.trajectories(w)
    assert horizon == pytest.approx(1.0)
    assert xs[:, ocp.nxm] == pytest.approx(1.0)  # T1: the first leg's duration
    assert xs[:, ocp.nxm + 1] == pytest.approx(3.0)  # T2: the next leg's
    times = ocp.node_times(1.0, 3.0)
    assert xs[1:, 0] == pytest.approx(-0.4 * times[1:])  # the plan's x at the node times
    assert xs[0, : ocp.nxm] == pytest.approx(x0)  # node 0 is the measured state
    assert us[:, :2] == pytest.approx(np.full((ocp.N, 2), -10.0))
    assert np.all(us[:, ocp.num :] == 0.0)  # no slack
    # the last leg: the longest second leg after the plan's end
    _, _ = problem.planned_start(x0, controller._plan, 1)
    w_last, _ = problem.planned_start(x0, controller._plan, 1)
    assert ocp.second_leg_of(w_last) == pytest.approx(ocp.config.second_leg_horizon)


def first_plan(tmp_path: Path, arrays: dict | None) -> tuple[float, float]:
    """The first step's plan toward a waypoint behind the robot, from ``arrays`` as the
    plan or from the standing guess: its duration T (s) and the heading it ends in (rad).
    On the thesis plant at the scenarios' step, as the scenario runs below (whose
    one-target problems it shares)."""
    options = {"model": "thesis", "route": [BEHIND], "track_orientation": False, "dt": 0.01}
    if arrays is not None:
        options["plan"] = str(write_plan(tmp_path / "plan.npz", arrays))
    controller = MPCController(ROBOT, **options)
    controller.adopt_plant(traits_of(ThesisPlant(ROBOT)))
    controller.command(0.0, START, np.array([*BEHIND, 0.0]), np.zeros(3), base_velocity=(0, 0))
    ocp = controller._problem("reach").ocp
    w = np.asarray(controller._warm).ravel()
    xs, _ = ocp.trajectories(w)
    return ocp.horizon_of(w), float(xs[-1][2])


def test_the_plans_structure_is_the_one_the_controller_settles_in(tmp_path):
    """A waypoint behind the robot: from the standing guess the first plan (5 cold
    iterations) still needs the longest horizon; from a plan turning either way it
    settles in a plan half as long that turns the way the plan does."""
    standing, _ = first_plan(tmp_path, None)
    left, heading_left = first_plan(tmp_path, straight_plan(0.05, 1.0))
    right, heading_right = first_plan(tmp_path, straight_plan(0.05, -1.0))
    assert standing == pytest.approx(5.0, abs=0.01)  # the longest horizon
    assert max(left, right) < 0.7 * standing
    assert heading_left > 0.1 and heading_right < -0.1


def test_the_protocol_hands_each_scenario_its_plan_from_a_bounds_folder(tmp_path):
    scenario = generate(2, seed=0)[1]
    (tmp_path / PLAN_FOLDER).mkdir()
    stored = write_plan(tmp_path / PLAN_FOLDER / PLAN_NAME.format(2), straight_plan(0.5, 0.0))
    assert plan_path(tmp_path, 2) == stored
    assert plan_path(tmp_path / PLAN_FOLDER, 2) == stored  # the cache folder itself
    config = RunConfig(controller="mpc", controller_options=(("plan", str(tmp_path)),))
    run = WaypointRun(scenario, config, traits_of(ThesisPlant(ROBOT)), ROBOT)
    options = MPCController.waypoint_options(run)
    assert options["plan"] == str(stored)
    assert options["route"] == [tuple(w) for w in scenario.waypoints]


def test_the_arrival_term_is_the_weighted_state_error_at_the_first_legs_end(tmp_path):
    controller = two_leg_controller(tmp_path, turn=0.3, plan_weight=3.0)
    problem = controller._problem("reach2")
    ocp = problem.ocp
    assert ocp.config.arrival_weight == 3.0
    # the plan's state where its first leg ends (t = 1 s), none at the last waypoint
    arrival = problem.planned_arrival(controller._plan, 0)
    assert arrival[0] == pytest.approx(-0.4) and arrival[2] == pytest.approx(0.3)
    assert problem.planned_arrival(controller._plan, 1) is None
    x0 = np.array([*START, 0.0, 0.0])
    w, _ = problem.planned_start(x0, controller._plan, 0)
    xs, _ = ocp.trajectories(w)
    cost = ca.Function("cost", [ocp.w, ocp.p], [0.5 * ca.sumsqr(ocp.residual)])
    u_prev = np.zeros(ocp.num)
    refs = np.tile([*ROUTE[0], 0.0], (ocp.N, 1))
    target = arrival + np.array([0.1, -0.2, 0.5, 0.2, -0.1, 0.3, -0.4])
    p_on = ocp.parameters(refs, u_prev, horizon_prev=2.5, arrival=target)
    p_off = ocp.parameters(refs, u_prev, horizon_prev=2.5)
    assert p_on[-1] == p_off[-1] == 2.5  # the previous horizon stays last
    block = slice(ocp._arrival_start, ocp._arrival_start + ocp.nxm)
    assert np.array_equal(p_on[block], target) and p_on[block.stop] == 1.0
    assert np.all(p_off[block] == 0.0) and p_off[block.stop] == 0.0
    on, off = float(cost(w, p_on)), float(cost(w, p_off))
    # by hand: the heading's chord, then joints and velocities (position left out)
    end = xs[ocp.split]
    error = np.concatenate(
        [
            [np.cos(end[2]) - np.cos(target[2]), np.sin(end[2]) - np.sin(target[2])],
            end[3:7] - target[3:7],
        ]
    )
    assert on - off == pytest.approx(0.5 * 3.0 * error @ error, rel=1e-9)
    # without the weight the OCP has neither the term nor its parameters
    plain = two_leg_ocp(two_leg_controller(tmp_path, turn=0.3, plan_weight=0.0))
    unplanned = MPCController(ROBOT, model="thesis", lookahead=True, route=ROUTE)
    assert plain.np == two_leg_ocp(unplanned).np
    assert plain.arrival_size == 0


def two_leg_ocp(controller: MPCController) -> ShootingOCP:
    """The OCP of ``controller``'s two-leg plans (its ``reach2`` problem's), without the
    solvers its problem would build on it."""
    config = controller._config("reach2")
    return shared_ocp(controller._unit_robot, controller._choice, controller._unit_model, config)


def test_plan_weight_must_be_nonnegative():
    with pytest.raises(ParameterError, match=r"plan_weight must be in \[0, 1e\+06\] \(got -1\)"):
        MPCController(ROBOT, plan_weight=-1.0)
    with pytest.raises(ParameterError, match=r"arrival_weight must be in \[0, 1e\+06\] \(got -1\)"):
        OCPConfig(reach=True, arrival_weight=-1.0)


def test_every_step_of_a_leg_sends_the_plans_arrival_and_the_last_leg_none(tmp_path):
    controller = two_leg_controller(tmp_path, turn=0.3)
    rest = np.zeros(3)
    for t in (0.0, 0.01, 0.02):  # a cold step, then warm ones
        controller.command(t, START, np.array([*ROUTE[0], 0.0]), rest, base_velocity=(0, 0))
        problem = controller._problem("reach2")
        ocp, p = problem.ocp, problem.last_parameters
        block = slice(ocp._arrival_start, ocp._arrival_start + ocp.nxm)
        assert p[block] == pytest.approx(problem.planned_arrival(controller._plan, 0))
        assert p[block.stop] == 1.0
    controller.command(0.03, START, np.array([*ROUTE[1], 0.0]), rest, base_velocity=(0, 0))
    last = controller._problem("reach")
    flag = last.ocp._arrival_start + last.ocp.nxm
    assert last.ocp.arrival_size and last.last_parameters[flag] == 0.0


def test_the_controller_arrives_as_the_plan_does(tmp_path):
    """Two waypoints on the thesis plant, a minimum-time plan of both as ``plan``: with the
    arrival term the mpc reaches the first waypoint heading the way the plan does, and
    sooner; with the plan as its cold starts alone it arrives about 50 degrees off."""
    waypoints = ((2.0, 0.5), (0.0, 1.5))
    problem = MinimumTimeProblem(ROBOT, waypoints, [*START, 0.0, 0.0], intervals_per_leg=10)
    solution = problem.solve(problem.straight_line_guess())
    path = write_plan(tmp_path / "plan.npz", solution.plan_arrays())
    plan = Guess.load(path)
    heading = float(plan.sample(plan.arrivals[:1])[0][0, 2])
    arrivals = {}
    for weight in (0.0, 2.0):
        options = (("lookahead", True), ("plan", str(path)), ("plan_weight", weight))
        outcome = run_scenario(
            Scenario(0, waypoints),
            RunConfig(controller="mpc", plant="thesis", record=True, controller_options=options),
        )
        assert outcome.metrics["success"]
        t, phi, distance = (np.array(outcome.trace[k]) for k in ("t", "phi", "distance"))
        reached = np.flatnonzero((distance[:-1] <= 0.0102) & (distance[1:] > 0.02))[0]
        arrivals[weight] = (t[reached], phi[reached], outcome.metrics["time_s"])

    def off(angle: float) -> float:  # heading difference on the circle (rad)
        return abs(math.remainder(angle - heading, 2.0 * math.pi))

    assert off(arrivals[2.0][1]) < 0.2
    assert off(arrivals[0.0][1]) > 0.5
    assert arrivals[2.0][0] < arrivals[0.0][0] and arrivals[2.0][2] < arrivals[0.0][2]
