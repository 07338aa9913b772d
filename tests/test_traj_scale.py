"""Trajectories scaled in space (``ScaledTrajectory``, ``--traj-scale``; docs/api.md,
"Scaled trajectories"): a robot scaled by a power of two s on the trajectory scaled by s
runs the default robot's run with s times its position errors, to the last bit; the
command lines take the factor (or ``robot``), record it and rerun it."""

from __future__ import annotations

import functools
import json
import warnings
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np
import pytest

from ddwmmr import Ellipse, Rectangle, Robot, ScaledTrajectory, load_trajectory, simulate
from ddwmmr.cli import compare as compare_cli
from ddwmmr.cli import track as track_cli
from ddwmmr.errors import ParameterError
from ddwmmr.trajectories.base import sampler
from in_process import call_main
from scaled_robots import scaled_robot

LENGTH_KEYS = ("rms_position_error_m", "max_position_error_m", "final_position_error_m")
ANGLE_KEYS = ("rms_orientation_error_rad",)


def _run(robot: Robot, trajectory, method: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a small robot's lengths look like unit mistakes
        return simulate(robot, trajectory, method)


#: The default robot's runs the scaled ones are compared with: a trajectory and a method.
CASES = {
    "ellipse-clrrmc-ts": (Ellipse(), "clrrmc-ts"),
    "rectangle-qp": (Rectangle(), "qp"),
    "figure8-ats": (load_trajectory("figure8"), "ats"),
}


@functools.cache
def default_summary(case: str) -> Mapping[str, Any]:
    """The summary of the default robot's run ``CASES[case]``, computed once per module:
    the run is deterministic and every scale is compared with it (read only)."""
    trajectory, method = CASES[case]
    return MappingProxyType(_run(Robot(), trajectory, method).summary)


@pytest.mark.parametrize("factor", [8.0, 0.0625])
@pytest.mark.parametrize("case", list(CASES))
def test_a_scaled_robot_on_the_scaled_trajectory_scales_the_errors_exactly(case, factor):
    trajectory, method = CASES[case]
    default = default_summary(case)
    scaled = _run(scaled_robot(factor), ScaledTrajectory(trajectory, factor), method).summary
    for key in LENGTH_KEYS:
        assert scaled[key] == factor * default[key], key
        assert scaled[key] > 0.0
    for key in ANGLE_KEYS:
        assert scaled[key] == default[key], key
    assert scaled["steps"] == default["steps"]


def test_pose_velocity_and_sample_scale_positions_only():
    base = Rectangle(x0=0.3, y0=-0.2, beta=0.4)
    scaled = ScaledTrajectory(base, 3.0)
    times = np.array([0.0, 7.3, 21.1, 40.0])
    poses, rates = scaled.sample(times)
    for row, t in enumerate(times.tolist()):
        want_pose = base.pose(t) * [3.0, 3.0, 1.0]
        want_rate = base.velocity(t) * [3.0, 3.0, 1.0]
        np.testing.assert_array_equal(scaled.pose(t), want_pose)
        np.testing.assert_array_equal(scaled.velocity(t), want_rate)
        np.testing.assert_array_equal(poses[row], want_pose)
        np.testing.assert_array_equal(rates[row], want_rate)
    assert sampler(scaled) is not None
    assert scaled.duration == base.duration and scaled.samples == base.samples
    assert scaled.corner_windows(40.0) == base.corner_windows(40.0)
    assert scaled.T == 40.0 and scaled.name == "rectangle x3"
    assert not hasattr(scaled, "a")  # a length of the base is not the scaled one's


def test_a_base_without_sample_is_sampled_point_by_point():
    class Line:
        duration = 2.0

        def pose(self, t):
            return [t, 1.0, 0.5]

        def velocity(self, t):
            return [1.0, 0.0, 0.0]

    poses, rates = ScaledTrajectory(Line(), 2.0).sample([0.5, 1.5])
    np.testing.assert_array_equal(poses, [[1.0, 2.0, 0.5], [3.0, 2.0, 0.5]])
    np.testing.assert_array_equal(rates, [[2.0, 0.0, 0.0], [2.0, 0.0, 0.0]])


@pytest.mark.parametrize("scale", [0.0, -1.0, 2e6, float("nan"), "2", None, True])
def test_a_bad_scale_is_one_line_naming_it(scale):
    with pytest.raises(ParameterError, match=r"^scale must be .*1e-06, 1e\+06") as error:
        ScaledTrajectory(Ellipse(), scale)
    assert "\n" not in str(error.value)


def test_a_non_trajectory_is_refused():
    with pytest.raises(ParameterError, match="trajectory must"):
        ScaledTrajectory("ellipse", 2.0)


def _summary(folder) -> dict:
    return json.loads((folder / "summary.json").read_text())


def test_track_records_the_scale_and_reruns_it(tmp_path, capsys):
    out, again = tmp_path / "ten", tmp_path / "again"
    robot = tmp_path / "big.toml"
    robot.write_text(
        "L1 = 2.8\nL2 = 2.4\nwheel_radius = 0.78\ntrack_width = 2.8\nbase_length = 3.6\n"
        "base_width = 2.8\nbase_height = 1.6\narm_height = 2.8\n"
    )
    common = ["--no-plots", "--no-progress", "--duration", "4"]
    argv = ["--method", "ats", "--traj", "ellipse", "--robot", str(robot), "--traj-scale"]
    assert track_cli.main([*argv, "robot", "--out", str(out), *common]) == 0
    summary = _summary(out)
    record = summary["run"]["trajectory"]
    assert summary["trajectory"] == "ellipse x8"
    assert record["type"] == "scaled" and record["scale"] == 8.0
    assert record["trajectory"]["type"] == "ellipse"
    assert record["trajectory"]["parameters"]["a"] == 2.0
    assert track_cli.main(["--rerun", str(out / "summary.json"), "--out", str(again)]) == 0
    rerun = _summary(again)
    for key in LENGTH_KEYS:
        assert rerun[key] == summary[key]
    assert rerun["run"]["trajectory"] == record
    default = tmp_path / "default"
    assert (
        track_cli.main(["--method", "ats", "--traj", "ellipse", "--out", str(default), *common])
        == 0
    )
    for key in LENGTH_KEYS:
        assert summary[key] == 8.0 * _summary(default)[key]
    capsys.readouterr()


def _without_provenance(summary: dict) -> dict:
    summary.pop("median_step_us")
    for key in ("command", "argv", "cwd", "time", "started", "git"):
        summary["run"].pop(key, None)
    return summary


def test_track_scale_one_is_the_run_without_it(tmp_path, capsys):
    common = ["--method", "ats", "--traj", "ellipse", "--no-plots", "--no-progress"]
    assert track_cli.main([*common, "--out", str(tmp_path / "a")]) == 0
    assert track_cli.main([*common, "--traj-scale", "1", "--out", str(tmp_path / "b")]) == 0
    plain, one = (_without_provenance(_summary(tmp_path / n)) for n in "ab")
    assert one == plain
    assert "scale" not in json.dumps(one["run"]["trajectory"])
    capsys.readouterr()


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("0", "error: traj-scale must be in [1e-06, 1e+06] (got 0)"),
        ("2e6", "error: traj-scale must be in [1e-06, 1e+06] (got 2e+06)"),
        ("-3", "error: traj-scale must be in [1e-06, 1e+06] (got -3)"),
        ("abc", "argument --traj-scale: must be a number in [1e-06, 1e+06] or robot (got 'abc')"),
        ("nan", "argument --traj-scale: must be a number in [1e-06, 1e+06] or robot (got 'nan')"),
    ],
)
@pytest.mark.parametrize("tool", [track_cli, compare_cli])
def test_a_bad_traj_scale_is_one_line_and_status_2(tool, value, message, tmp_path, capsys):
    argv = ["--traj-scale", value, "--out", str(tmp_path / "out")]
    argv += ["--method", "ats", "--traj", "ellipse"] if tool is track_cli else ["--methods", "ats"]
    status, _, err = call_main(tool.main, argv, capsys)
    assert status == 2
    assert err.count("\n") == 1 and message in err and "Traceback" not in err


def test_rerun_refuses_traj_scale(tmp_path, capsys):
    out = tmp_path / "run"
    argv = ["--method", "ats", "--traj", "ellipse", "--no-plots", "--no-progress"]
    assert track_cli.main([*argv, "--duration", "1", "--out", str(out)]) == 0
    capsys.readouterr()
    status = track_cli.main(["--rerun", str(out / "summary.json"), "--traj-scale", "2"])
    err = capsys.readouterr().err
    assert status == 2
    assert (
        err == "error: rerun: --traj-scale cannot be combined with --rerun (the record fixes it)\n"
    )


def test_a_bad_recorded_scale_is_refused_naming_the_file(tmp_path, capsys):
    out = tmp_path / "run"
    argv = ["--method", "ats", "--traj", "ellipse", "--traj-scale", "2", "--duration", "1"]
    assert track_cli.main([*argv, "--no-plots", "--no-progress", "--out", str(out)]) == 0
    path = out / "summary.json"
    summary = json.loads(path.read_text())
    summary["run"]["trajectory"]["scale"] = -2.0
    path.write_text(json.dumps(summary))
    capsys.readouterr()
    assert track_cli.main(["--rerun", str(path), "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert err == f"error: rerun: {path}: trajectory.scale must be in [1e-06, 1e+06] (got -2)\n"


def test_compare_scales_every_trajectory_and_records_it(tmp_path):
    args = compare_cli.build_parser().parse_args(
        ["--traj-scale", "robot", "--robot", str(_robot_file(tmp_path)), "--traj", "figure8"]
    )
    sources: dict = {}
    config = compare_cli.config_from_arguments(args, [], sources)
    assert list(config.trajectories) == ["ellipse", "rectangle", "figure8"]  # keys: the studies'
    assert [config.shown(n) for n in config.trajectories] == [
        "ellipse x0.25",
        "rectangle x0.25",
        "figure8 x0.25",
    ]
    for trajectory in config.trajectories.values():
        assert isinstance(trajectory, ScaledTrajectory) and trajectory.scale == 0.25
    record = compare_cli.run_record(config, sources, [], 1)["trajectories"]
    assert record["figure8"]["type"] == "scaled" and record["figure8"]["scale"] == 0.25
    assert record["figure8"]["trajectory"]["type"] == "samples"


def test_compare_without_traj_scale_keeps_the_trajectories(tmp_path):
    args = compare_cli.build_parser().parse_args(["--traj-scale", "robot"])
    config = compare_cli.config_from_arguments(args, [], {})
    assert config.trajectories == {"ellipse": Ellipse(), "rectangle": Rectangle()}


def _robot_file(folder):
    path = folder / "quarter.toml"
    path.write_text(
        "L1 = 0.0875\nL2 = 0.075\nwheel_radius = 0.024375\ntrack_width = 0.0875\n"
        "base_length = 0.1125\nbase_width = 0.0875\nbase_height = 0.05\narm_height = 0.0875\n"
    )
    return path


def test_obstacles_are_not_scaled_and_a_note_says_so(tmp_path, capsys):
    argv = ["--method", "qp", "--traj", "ellipse", "--obstacles", "ellipse_post"]
    argv += ["--duration", "0.1", "--no-plots", "--no-progress"]
    assert track_cli.main([*argv, "--traj-scale", "2", "--out", str(tmp_path / "a")]) == 0
    assert "note: --traj-scale scales the trajectory only" in capsys.readouterr().err
    assert _summary(tmp_path / "a")["run"]["options"]["obstacles"] == [[-0.2, 1.05, 0.3]]
    assert track_cli.main([*argv, "--out", str(tmp_path / "b")]) == 0
    assert "--traj-scale" not in capsys.readouterr().err


class _OneNumberPose:
    """A user's trajectory whose pose is one number: refused, not broadcast to three."""

    duration = 1.0
    name = "one"

    def pose(self, t):
        return [0.3]

    def velocity(self, t):
        return [0.0]


def test_a_scaled_broken_trajectory_is_refused_as_the_unscaled_one():
    messages = []
    for trajectory in (_OneNumberPose(), ScaledTrajectory(_OneNumberPose(), 2.0)):
        with pytest.raises(ParameterError) as refused:
            simulate(Robot(), trajectory, "ats", dt=0.05, duration=0.2)
        messages.append(str(refused.value))
    assert messages[0] == messages[1]
    assert messages[0].startswith("trajectory pose(t) must return 3 finite numbers")
    assert "(got [0.3] at t = 0 s)" in messages[0]


def test_a_nested_scaled_record_keeps_every_factor():
    from ddwmmr import provenance

    nested = ScaledTrajectory(ScaledTrajectory(load_trajectory("ellipse"), 2.0), 3.0)
    back, _, _ = provenance.read_trajectory_record(provenance.trajectory_record(nested, None))
    assert back.name == nested.name == "ellipse x2 x3"
    assert back.pose(1.0).tolist() == nested.pose(1.0).tolist()
    assert back.pose(1.0)[0] == 6.0 * load_trajectory("ellipse").pose(1.0)[0]
