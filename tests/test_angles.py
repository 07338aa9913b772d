"""Whole turns of an angle are the same pose: a start given turns apart, or a trajectory
whose heading carries many turns, runs as the reduced one does."""

import math

import numpy as np
import pytest

from ddwmmr import Robot, simulate
from ddwmmr.model.kinematics import principal_angle, whole_turns
from ddwmmr.resolution.reference import (
    DEFAULT_INITIAL_OFFSET,
    initial_configuration,
    start_configuration,
)
from ddwmmr.trajectories import Ellipse
from ddwmmr.trajectories.sampled import SampledTrajectory

TURN = 2.0 * math.pi


def test_principal_angle_is_the_identity_in_range():
    inside = np.concatenate(
        [np.linspace(-math.pi, math.pi, 10001)[1:], [math.pi, np.nextafter(-math.pi, 0.0)]]
    )
    inside = np.concatenate([inside, np.random.default_rng(0).uniform(-1e-3, 1e-3, 1000)])
    for angle in inside.tolist():
        assert principal_angle(angle) is angle or principal_angle(angle) == angle
        assert math.copysign(1.0, principal_angle(angle)) == math.copysign(1.0, angle)
        assert whole_turns(angle) == 0.0


@pytest.mark.parametrize("angle", [-math.pi, 3 * math.pi, -3 * math.pi, 7.0, -100.5, 1e6, -1e6])
def test_principal_angle_reduces_to_the_same_direction(angle):
    reduced = principal_angle(angle)
    assert -math.pi < reduced <= math.pi
    # independent check: the same direction (libm's sin/cos reduce large arguments exactly)
    assert math.cos(reduced) == pytest.approx(math.cos(angle), abs=1e-9)
    assert math.sin(reduced) == pytest.approx(math.sin(angle), abs=1e-9)
    assert whole_turns(angle) / TURN == pytest.approx(round(whole_turns(angle) / TURN))


ROBOT = Robot(joint_limits=((-100.0, 100.0), (-100.0, 100.0)))
TURNS = {
    "phi": [0.0, 0.0, TURN, 0.0, 0.0],
    "phi-2": [0.0, 0.0, -2 * TURN, 0.0, 0.0],
    "th1": [0.0, 0.0, 0.0, TURN, 0.0],
    "th2": [0.0, 0.0, 0.0, 0.0, -TURN],
    "all": [0.0, 0.0, TURN, -TURN, TURN],
}


def _rms(method, q0, trajectory=None, duration=3.0):
    result = simulate(ROBOT, trajectory or Ellipse(), method, q0=q0, duration=duration)
    return result.summary["rms_position_error_m"], result


@pytest.mark.parametrize("method", ["pi", "ats", "ap", "clrrmc-cs", "clrrmc-ts", "qp", "mpc"])
def test_turns_in_the_start_do_not_change_the_run(method):
    # before: clrrmc-cs 0.61 m and ap 0.81 m RMS with phi + 2 pi, against 0.012 / 0.042 m
    q0 = initial_configuration(ROBOT, Ellipse(), DEFAULT_INITIAL_OFFSET)
    reference, _ = _rms(method, q0)
    assert reference < 0.05
    for name, turns in TURNS.items():
        rms, _ = _rms(method, q0 + np.array(turns))
        assert rms == pytest.approx(reference, rel=1e-6, abs=1e-9), name


def test_a_start_in_range_keeps_its_configuration_bit_for_bit():
    trajectory = Ellipse()
    pose = trajectory.pose(0.0)
    expected = ROBOT.base_for_end_effector(pose, *ROBOT.home_pose)
    assert start_configuration(ROBOT, trajectory).tolist() == expected.tolist()


def _circle(heading_turns: float) -> SampledTrajectory:
    t = np.linspace(0.0, 20.0, 81)
    heading = t / 5.0 + math.pi / 2.0
    phi = heading + heading_turns
    return SampledTrajectory(t, np.column_stack([np.cos(t / 5.0), np.sin(t / 5.0), phi]))


@pytest.mark.parametrize("beta", [1e3, 1e5, 1e6 - 10.0, -1e6 + 10.0])
def test_large_ellipse_rotation_starts(beta):
    # before: beta = 1e5 was "initial_offset ... cannot be reached with the arm alone"
    trajectory = Ellipse(beta=beta)
    q0 = initial_configuration(Robot(), trajectory, DEFAULT_INITIAL_OFFSET)
    start = start_configuration(Robot(), trajectory)
    assert -math.pi < Robot().fk(start)[2] <= math.pi
    assert Robot().fk(start)[2] == pytest.approx(principal_angle(trajectory.pose(0.0)[2]))
    assert math.hypot(*(np.array(Robot().fk(q0)[:2]) - trajectory.pose(0.0)[:2])) == (
        pytest.approx(math.hypot(*DEFAULT_INITIAL_OFFSET), abs=1e-9)
    )


@pytest.mark.parametrize("method", ["clrrmc-ts", "clrrmc-cs", "ap", "qp"])
def test_heading_near_the_documented_limit_runs_as_the_reduced_one(method):
    turns = TURN * round((1e6 - 10.0) / TURN)
    big = simulate(Robot(), _circle(turns), method, duration=5.0).summary
    small = simulate(Robot(), _circle(0.0), method, duration=5.0).summary
    assert big["rms_position_error_m"] == pytest.approx(small["rms_position_error_m"], rel=1e-6)
    assert big["rms_orientation_error_rad"] == pytest.approx(
        small["rms_orientation_error_rad"], rel=1e-5, abs=1e-9
    )


def test_track_accepts_a_large_rotation_in_a_trajectory_file(tmp_path, monkeypatch, capsys):
    from ddwmmr.cli.track import main as track_main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "turned.toml").write_text('[trajectory]\nshape = "ellipse"\nbeta = 100000.0\n')
    args = ["--traj", "turned.toml", "--method", "clrrmc-ts", "--duration", "0.2"]
    assert track_main([*args, "--no-plots", "--no-progress", "--out", "out"]) == 0, (
        capsys.readouterr().err
    )


def test_gui_accepts_a_large_rotation(tmp_path, monkeypatch, capsys):
    from ddwmmr.cli.gui import main as gui_main

    monkeypatch.chdir(tmp_path)
    args = ["--snapshot", "s.png", "--duration", "0.2", "--dpi", "10", "--beta", "1e5"]
    assert gui_main([*args, "--method", "clrrmc-ts"]) == 0, capsys.readouterr().err
