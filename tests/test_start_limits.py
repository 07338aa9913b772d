"""The start pose's limits said before a run: the heaviest payload a start pose holds (one
bisection for every robot and pose), a start below the qp's/mpc's stability floor, and the
benchmark tools' refusal of --robot."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory, make_controller
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.cli.bench import main as bench
from ddwmmr.cli.scenarios import main as scenarios
from ddwmmr.cli.track import main as track
from ddwmmr.model.stability import MASS_RANGE_KG, max_payload
from ddwmmr.scenarios.protocol import max_start_payload
from ddwmmr.sim.simulate import tipping_message


def _s(robot: Robot, q) -> float:
    return robot.stability(np.asarray(q, dtype=float))[2]


# -- the heaviest payload a start pose holds -------------------------------------------


@pytest.mark.parametrize(
    ("robot", "pose"),
    [
        (Robot(), None),  # the scenarios' pose: 9.338 kg
        (Robot(), (0.0, 0.0)),  # arm straight ahead
        (Robot(L1=0.4, base_length=0.6), (0.3, 1.2)),
    ],
)
def test_max_payload_is_the_last_gram_that_stands(robot, pose):
    th1, th2 = default_pose(robot) if pose is None else pose
    q = (0.0, 0.0, 0.0, th1, th2)
    limit = max_payload(robot, th1, th2)
    assert 0.0 < limit < MASS_RANGE_KG[1]
    assert limit == math.floor(limit * 1e3) / 1e3  # whole grams
    assert _s(robot.with_payload(limit), q) > 1.0
    assert _s(robot.with_payload(limit + 1e-3), q) <= 1.0


def test_max_payload_at_its_ends():
    # the scenarios' number, now from the shared bisection
    assert max_start_payload() == pytest.approx(9.338, abs=1e-9)
    # a folded arm of equal links puts the end effector on the base centre: all stand
    assert max_payload(Robot(L1=0.3, L2=0.3), 0.0, math.pi) == MASS_RANGE_KG[1]
    # an arm that tips the robot unloaded holds no payload
    heavy_arm = Robot(L1=0.6, L2=0.6, link_masses=(4.0, 4.0))
    assert _s(heavy_arm, [0.0] * 5) <= 1.0
    assert max_payload(heavy_arm, 0.0, 0.0) == 0.0


def test_the_payload_refusal_names_what_the_pose_holds():
    message = tipping_message(Robot(payload=30.0), [0.0] * 5, start="--offset")
    assert message == (
        "payload: a 30 kg payload tips the robot over in this run's start pose "
        "(S = 0.468 <= 1), which holds at most 4.764 kg; lighten the payload or change "
        "--offset"
    )
    assert _s(Robot(payload=4.764), [0.0] * 5) > 1.0
    assert _s(Robot(payload=4.765), [0.0] * 5) <= 1.0


def test_track_names_the_heaviest_payload_of_its_start_pose(tmp_path, capsys):
    """6 kg tips the default robot at track's start (S = 0.959); 5.535 kg stands there."""
    argv = ["--method", "pi", "--traj", "ellipse", "--duration", "0.05", "--no-plots"]
    out = tmp_path / "out"
    assert track([*argv, "--payload", "6", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (
        "error: payload: a 6 kg payload tips the robot over in this run's start pose "
        "(S = 0.959 <= 1), which holds at most 5.535 kg; lighten the payload or change "
        "the default --offset\n"
    )
    assert not out.exists()
    ok = [*argv, "--no-progress", "--payload", "5.535", "--out", str(out)]
    assert track(ok) == 0
    assert track([*argv, "--payload", "5.536", "--out", str(tmp_path / "b")]) == 2


# -- a start below the stability floor -------------------------------------------------

#: The scenarios' start with 7 kg: S = 1.148, below the default floor 1.25.
HEAVY = Robot().with_payload(7.0)
START = np.array([0.0, 0.0, 0.0, *default_pose(HEAVY)])
BELOW = (
    "stability_min: the start pose has S = 1.148, below the {method}'s stability floor "
    "stability_min = 1.25, which the run starts by breaking; lower the floor "
    "(stability_min=1.14) or start where S >= 1.25"
)


@pytest.mark.parametrize("method", ["qp", "mpc"])
def test_a_start_below_the_floor_is_warned_at_reset(method):
    controller = make_controller(method, HEAVY)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        controller.reset(None, START)
    assert [str(w.message) for w in caught] == [BELOW.format(method=method)]
    assert caught[0].category is UserWarning


@pytest.mark.parametrize("method", ["qp", "mpc"])
def test_no_floor_warning_at_or_above_the_floor_or_for_a_tipped_start(method):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        make_controller(method, HEAVY, stability_min=1.14).reset(None, START)
        make_controller(method, Robot().with_payload(3.0)).reset(None, START)
        # S = 0.959 <= 1: the tipping message speaks for it, not this one
        tipped = Robot().with_payload(10.0)
        assert _s(tipped, START) <= 1.0
        make_controller(method, tipped).reset(None, START)


# -- the benchmark tools run the thesis robot ------------------------------------------


@pytest.mark.parametrize("argv", [["--robot", "x.toml"], ["--robot=x.toml"], ["--robot"]])
def test_scenarios_and_bench_refuse_robot_in_one_line(argv, capsys):
    with pytest.raises(SystemExit) as stopped:
        scenarios(argv)
    assert stopped.value.code == 2
    assert capsys.readouterr().err == (
        "python -m ddwmmr.scenarios: error: --robot: the scenario benchmark runs the thesis "
        'robot only (docs/thesis.md, "What is simulated"); use --payload\n'
    )
    with pytest.raises(SystemExit) as stopped:
        bench(argv)
    assert stopped.value.code == 2
    assert capsys.readouterr().err == (
        "python -m ddwmmr.bench: error: --robot: the benchmark times the thesis robot only, "
        'as the scenario benchmark runs it (docs/thesis.md, "What is simulated")\n'
    )


def test_the_mpc_fallback_built_mid_run_does_not_warn_of_a_start(monkeypatch):
    """The fallback qp is reset at a placeholder pose (zeros: S = 1.099 with 4 kg), not the
    run's start (S = 1.366 here, above the floor): no start warning from it."""
    from ddwmmr.mpc.problem import Problem
    from ddwmmr.mpc.solvers import SolverFailure

    robot = Robot().with_payload(4.0)
    assert 1.0 < _s(robot, [0.0] * 5) < 1.25
    start = np.array([0.0, 0.0, 0.0, *default_pose(robot)])

    def fail(*args, **kwargs):
        raise SolverFailure("forced")

    monkeypatch.setattr(Problem, "solve", fail)
    controller = make_controller("mpc", robot)
    pose = np.asarray(robot.fk(start), dtype=float)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        controller.reset(load_trajectory("ellipse"), start)
        controller.command(0.0, start, pose, np.zeros(3))
    assert controller.fallbacks == 1
