"""The default start offset is the robot's own (docs/api.md, ``simulate``; docs/cli.md).

``default_offset(robot)`` is (-0.03, -0.03) times the robot's length unit ``L1 / 0.35 m``:
the old fixed value for the default robot, s times it for a robot scaled by s, which then
runs the default robot's steps with s times its errors (exactly for a power of two). The
twentieth robot (arm reach 32.5 mm) starts from it in ``track`` and ``compare``; an offset
the arm cannot reach is refused naming the parameter as the tool calls it and the largest
offset along its direction that fits.
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, simulate
from ddwmmr.cli.compare import main as compare
from ddwmmr.cli.track import main as track
from ddwmmr.resolution.reference import (
    DEFAULT_INITIAL_OFFSET,
    default_offset,
    offset_configuration,
)
from scaled_robots import TWENTIETH, scaled_robot

#: The default robot's start error (m): its default offset's length, 42.4 mm.
DEFAULT_START_M = math.hypot(*DEFAULT_INITIAL_OFFSET)
#: What the twentieth robot's arm reaches along (-1, -1) in the end effector's frame from
#: its home pose, rounded down to two digits (m): found by bisection, 0.02168 m.
TWENTIETH_FIT = (-0.021, -0.021)


def robot_file(folder: Path, robot: Robot) -> Path:
    """A robot TOML holding every field of ``robot`` that differs from ``Robot()``."""
    default = Robot()
    lines = []
    for f in fields(Robot):
        value = getattr(robot, f.name)
        if f.name.startswith("_") or value == getattr(default, f.name):
            continue
        text = (
            f"[{', '.join(repr(float(v)) for v in value)}]" if isinstance(value, tuple) else value
        )
        lines.append(f"{f.name} = {text}")
    path = folder / "robot.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def quiet_run(robot: Robot, trajectory, method: str, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a small robot's lengths look like unit mistakes
        return simulate(robot, trajectory, method, **options)


def test_the_default_robots_default_offset_is_the_old_value_to_the_bit():
    offset = default_offset(Robot())
    assert offset == DEFAULT_INITIAL_OFFSET == (-0.03, -0.03)
    assert all(type(v) is float for v in offset)


@pytest.mark.parametrize("factor", [0.5, 8.0])
@pytest.mark.parametrize("method", ["clrrmc-ts", "qp"])
def test_a_scaled_robot_runs_the_default_steps_from_its_default_offset(method, factor):
    ellipse = Ellipse()
    task = replace(ellipse, a=factor * ellipse.a, b=factor * ellipse.b)
    reference = quiet_run(Robot(), ellipse, method, duration=4.0)
    scaled = quiet_run(scaled_robot(factor), task, method, duration=4.0)
    assert default_offset(scaled_robot(factor)) == (-0.03 * factor, -0.03 * factor)
    assert reference.summary["initial_offset_m"] == pytest.approx(DEFAULT_START_M, rel=1e-12)
    assert scaled.summary["initial_offset_m"] == factor * reference.summary["initial_offset_m"]
    errors = np.asarray(reference.timeseries["position_error_m"])
    assert errors.max() > 0.01  # a run that converges from its offset, not a flat zero
    np.testing.assert_array_equal(
        np.asarray(scaled.timeseries["position_error_m"]), factor * errors
    )
    np.testing.assert_array_equal(
        np.asarray(scaled.timeseries["orientation_error_rad"]),
        np.asarray(reference.timeseries["orientation_error_rad"]),
    )


def test_the_twentieth_robot_tracks_from_its_default_offset(tmp_path, capsys):
    path = robot_file(tmp_path, TWENTIETH)
    out = tmp_path / "run"
    argv = ["--robot", str(path), "--traj", "ellipse", "--method", "qp", "--duration", "1"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = track([*argv, "--no-plots", "--no-progress", "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    start = summary.get("summary", summary)
    assert start["initial_offset_m"] == pytest.approx(0.05 * DEFAULT_START_M, rel=1e-9)


def test_compare_runs_the_twentieth_robot_from_its_default_offset(tmp_path, capsys):
    path = robot_file(tmp_path, TWENTIETH)
    out = tmp_path / "report"
    argv = ["--robot", str(path), "--methods", "pi", "qp", "--study", "none"]
    argv += ["--only", "ellipse"]  # the offset is the robot's, the same on every trajectory
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = compare(
            [*argv, "--duration", "0.5", "--jobs", "1", "--no-progress", "--out", str(out)]
        )
    assert code == 0, capsys.readouterr().err
    report = (out / "report.md").read_text()
    assert "initial end-effector offset: (-0.0015 m, -0.0015 m)" in report
    assert "i.e. 2.1 mm: the robot's default" in report


def test_an_unreachable_offset_names_the_cli_option_and_a_value_that_fits(tmp_path, capsys):
    path = robot_file(tmp_path, TWENTIETH)
    argv = [
        "--robot",
        str(path),
        "--traj",
        "ellipse",
        "--method",
        "qp",
        "--offset",
        "-0.03",
        "-0.03",
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = track([*argv, "--no-plots", "--no-progress", "--out", str(tmp_path / "run")])
    assert code == 2
    err = capsys.readouterr().err
    assert err == (
        "error: --offset (-0.03, -0.03) m (end-effector frame) cannot be reached with the arm "
        "alone; along that direction it reaches (-0.021, -0.021) m\n"
    )


def test_an_unreachable_offset_names_initial_offset_in_the_api_and_the_fit_runs():
    with pytest.raises(ParameterError) as caught:
        quiet_run(TWENTIETH, Ellipse(), "qp", duration=0.1, initial_offset=(-0.03, -0.03))
    message = str(caught.value)
    assert message.startswith("initial_offset (-0.03, -0.03) m (end-effector frame)")
    assert message.endswith("it reaches (-0.021, -0.021) m") and "\n" not in message
    fitted = quiet_run(TWENTIETH, Ellipse(), "qp", duration=0.1, initial_offset=TWENTIETH_FIT)
    assert fitted.summary["initial_offset_m"] == pytest.approx(math.hypot(*TWENTIETH_FIT), rel=1e-9)
    # the next step up along the same direction is out of reach: the fit is the largest
    with pytest.raises(ParameterError, match="cannot be reached"):
        quiet_run(TWENTIETH, Ellipse(), "qp", duration=0.1, initial_offset=(-0.022, -0.022))


def test_track_help_states_the_default_in_the_robots_length_unit(capsys):
    with pytest.raises(SystemExit):
        track(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    default = "(default -0.03 -0.03 times the robot's length unit L1/0.35 m: -0.03 -0.03 for"
    assert f"{default} the default robot)" in text


def test_every_offset_keeps_the_start_poses_elbow_branch():
    """Newton converged on the other elbow for some reachable offsets (-0.64, -0.39 m put
    th2 at -0.87 rad between two rows at +0.79 and +1.07): a placement keeps the start's
    branch, also for a start elbow angle given past a full turn."""
    robot = Robot()
    start = np.array([0.0, 0.0, 0.0, *robot.home_pose])
    for dy in np.linspace(-0.45, -0.3, 16):
        q = offset_configuration(robot, start, (-0.64, float(dy)))
        assert math.sin(q[4]) > 0.0, dy
    wrapped = Robot(
        home_pose=(-0.3, 0.6 - 2.0 * math.pi), joint_limits=((-math.pi, math.pi), (-7.0, 7.0))
    )
    turned = offset_configuration(
        wrapped, np.array([0.0, 0.0, 0.0, *wrapped.home_pose]), (-0.65, -0.41)
    )
    assert math.sin(turned[4]) > 0.0
    assert np.allclose(
        wrapped.fk(turned), robot.fk(offset_configuration(robot, start, (-0.65, -0.41)))
    )


def refusal(offset) -> str:
    with pytest.raises(ParameterError) as caught:
        quiet_run(Robot(), Ellipse(), "clrrmc-ts", duration=0.1, initial_offset=offset)
    message = str(caught.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize(
    ("offset", "fit"),
    [
        ((1e300, 0.0), "(0.03, 0)"),
        ((1e17, 0.0), "(0.03, 0)"),
        ((-1e300, 1e300), "(-0.8, 0.8)"),
        ((1.7e308, -1.7e308), "(0.022, -0.022)"),
    ],
)
def test_an_absurd_offset_gets_the_fit_of_one_just_out_of_reach(offset, fit):
    # the reach search bisected [0, 1] times the offset: at 1e300 m forty halvings never
    # came near the arm and the message said it reaches (0, 0) m; at 1.7e308 m the target
    # overflowed and the refusal named q, the configuration, instead of the offset
    message = refusal(offset)
    assert message.startswith(f"initial_offset ({offset[0]:g}, {offset[1]:g}) m")
    assert message.endswith(f"it reaches {fit} m")
    near = tuple(5.0 * math.copysign(1.0, v) if v else 0.0 for v in offset)
    assert refusal(near).endswith(f"it reaches {fit} m")
