"""Input files and values: types, documented caps, FIFOs, encodings."""

from __future__ import annotations

import math
import os
import re

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot
from ddwmmr.errors import (
    MAX_STEPS,
    check_int_at_least,
    check_range,
    check_step_count,
    read_text_file,
    texts_apart,
)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('L1 = "0.3"', r"robot: .*: L1 must be a number in \[1e-06, 1000\] m \(got '0.3'\)"),
        ("L1 = true", r"L1 must be a number in \[1e-06, 1000\] m \(got True\)"),
        ("wheel_radius = 1e-320", r"wheel_radius must be in \[1e-06, 1000\] m"),
        ("L1 = 1e300", r"L1 must be in \[1e-06, 1000\] m"),
        ("base_mass = 1e9", r"base_mass must be in \(0, 100000\] kg"),
        ("link_masses = 1.0", "link_masses must be a pair of numbers"),
        ("joint_limits = [[-1, 1]]", r"joint_limits must be two \[min, max\] pairs"),
        ('home_pose = [0.1, "x"]', r"home_pose\[2\] must be a number \(got 'x'\)"),
        (
            "joint_limits = [-1, 1]",
            r"joint_limits must be two \[min, max\] pairs \(got \[-1, 1\]\)",
        ),
        ('joint_limits = "ab"', r"joint_limits must be two \[min, max\] pairs \(got 'ab'\)"),
        ('joint_limits = [[-1, 1], [-1, "a"]]', r"joint_limits\[2\]\[2\] must be a number"),
        (
            'caster_positions = "corners"',
            r"caster_positions must be a non-empty list of \(x, y\) pairs in m",
        ),
        ("base_mas = 10.0", r"unknown parameter 'base_mas' \(did you mean base_mass\?\)"),
        ("[[robot]]\nL1 = 0.4", r"\[robot\] must be one table .*\[\[robot\]\]"),
        ("robot = 3", r"\[robot\] must be one table"),
    ],
)
def test_robot_toml_types_and_ranges(tmp_path, text, message):
    path = tmp_path / "robot.toml"
    path.write_text(text + "\n")
    with pytest.raises(ParameterError, match=message):
        Robot.from_toml(path)


def test_valid_robot_toml_still_loads(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text("[robot]\nL1 = 0.4\nlink_masses = [1, 2]\njoint_limits = [[-3, 3], [-2, 2]]\n")
    robot = Robot.from_toml(path)
    assert robot.L1 == 0.4 and robot.link_masses == (1.0, 2.0)
    assert robot.joint_limits == ((-3.0, 3.0), (-2.0, 2.0))


def test_api_robot_shapes_are_named_whole():
    """A value of the wrong shape is refused as a whole, not one letter or number of it."""
    with pytest.raises(ParameterError, match=r"joint_limits must be two \(min, max\) pairs"):
        Robot(joint_limits=[-1, 1])
    with pytest.raises(ParameterError, match=r"joint_limits must be two \(min, max\) pairs"):
        Robot(joint_limits="ab")
    with pytest.raises(
        ParameterError, match=r"caster_positions must be a non-empty list of \(x, y\)"
    ):
        Robot(caster_positions="corners")


def test_api_robot_magnitudes():
    with pytest.raises(ParameterError, match="wheel_radius must be in"):
        Robot(wheel_radius=1e-320)
    with pytest.raises(ParameterError, match="payload must be in"):
        Robot().with_payload(1e300)
    assert Robot(L1=1e-3).L1 == 1e-3


def test_fifo_is_never_opened(tmp_path):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)  # opening it for reading would block forever
    with pytest.raises(ParameterError, match=r"is not a regular file \(a FIFO\)$"):
        read_text_file(fifo, "robot")
    with pytest.raises(ParameterError, match=r"is not a regular file \(a FIFO\)$"):
        Robot.from_toml(fifo)
    with pytest.raises(ParameterError, match=r"is not a regular file \(a folder\)$"):
        read_text_file(tmp_path, "robot")


def test_non_utf8_names_the_byte_and_offset(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_bytes(b"L1 = 0.4\n# caf\xe9\n")
    with pytest.raises(ParameterError, match=r"not UTF-8 text \(byte 0xe9 at offset 14\)"):
        Robot.from_toml(path)


def test_oversized_file_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr("ddwmmr.errors.MAX_INPUT_BYTES", 10)
    path = tmp_path / "big.toml"
    path.write_text("L1 = 0.40000000\n")
    with pytest.raises(ParameterError, match=r"too large \(16 bytes, at most 10\)"):
        read_text_file(path, "robot")


@pytest.mark.parametrize(
    ("duration", "dt", "steps"),
    [(40.0, 0.02, 2000), (1.0, 0.3, 3), (0.2, 0.2, 1), (20000.0, 0.02, MAX_STEPS)],
)
def test_step_count(duration, dt, steps):
    assert check_step_count(duration, dt) == steps


@pytest.mark.parametrize(
    ("duration", "dt", "message"),
    [
        (-5.0, 0.02, r"^duration must be > 0 \(got -5\)"),
        (math.nan, 0.02, "^duration must be a finite number"),
        (math.inf, 0.02, "^duration must be a finite number"),
        (40.0, 0.0, r"^dt must be > 0 \(got 0\)"),
        (40.0, -1.0, "^dt must be > 0"),
        (1.0, 2.0, r"^dt must be <= duration \(1 s\)"),
        (1e9, 0.02, f"^duration / dt must be <= {MAX_STEPS} steps per run"),
        (40.0, 1e-300, "^duration / dt must be <="),
        ("40", 0.02, r"^duration must be a finite number > 0 \(got '40'\)"),
    ],
)
def test_step_count_names_the_parameter(duration, dt, message):
    with pytest.raises(ParameterError, match=message):
        check_step_count(duration, dt)


def test_int_checks_refuse_huge_floats_and_text():
    assert check_int_at_least("n", 10**30, 1) == 10**30
    with pytest.raises(ParameterError, match=r"n must be an integer in \[1, 5\]"):
        check_int_at_least("n", 1e30, 1, 5)
    for bad in ("3", True, math.inf, 2.5):
        with pytest.raises(ParameterError, match="n must be an integer"):
            check_int_at_least("n", bad, 1)


@pytest.mark.parametrize(
    "value",
    ["[" * 5000 + "]" * 5000, "{a = " * 500 + "1" + "}" * 500, "[" * 40 + "]" * 40],
    ids=["arrays 5000 deep", "inline tables 500 deep", "arrays 40 deep"],
)
def test_deeply_nested_toml_is_a_parameter_error_naming_the_file(tmp_path, value):
    from ddwmmr.trajectories import load_trajectory

    robot, trajectory = tmp_path / "robot.toml", tmp_path / "traj.toml"
    robot.write_text(f"L1 = {value}\n")
    trajectory.write_text(f'shape = "ellipse"\na = {value}\n')
    with pytest.raises(ParameterError, match=f"robot: {robot} nests arrays or tables more"):
        Robot.from_toml(robot)
    with pytest.raises(ParameterError, match=f"traj: {trajectory} nests arrays or tables more"):
        load_trajectory(trajectory)


def test_nesting_depth_counts_lists_and_tables_without_recursion():
    from ddwmmr.errors import nesting_depth

    deep: list = []
    for _ in range(100_000):  # far beyond the recursion limit
        deep = [deep]
    assert nesting_depth(deep) == 100_001
    assert nesting_depth({"obstacle": [{"x": 1.0, "y": [0.0]}]}) == 4
    assert nesting_depth(3.0) == 0


def test_a_byte_order_mark_is_not_part_of_the_text(tmp_path):
    # a CSV saved with a BOM said "lacks column(s) t" (the first name was "\ufefft")
    from ddwmmr.trajectories import load_trajectory

    rows = "t,x,y\n0,2,0\n1,2.1,0.1\n2,2.2,0.25\n"
    (tmp_path / "plain.csv").write_text(rows)
    (tmp_path / "marked.csv").write_bytes(b"\xef\xbb\xbf" + rows.encode())
    plain = load_trajectory(str(tmp_path / "plain.csv"))
    marked = load_trajectory(str(tmp_path / "marked.csv"))
    assert marked.times.tolist() == plain.times.tolist()
    assert marked.points.tolist() == plain.points.tolist()
    (tmp_path / "robot.toml").write_bytes(b"\xef\xbb\xbfL1 = 0.4\n")
    assert Robot.from_toml(tmp_path / "robot.toml").L1 == 0.4
    assert read_text_file(tmp_path / "robot.toml", "robot") == "L1 = 0.4\n"


@pytest.mark.parametrize("path", [3, None, b"robot.toml", 2.5])
def test_an_input_file_that_is_not_a_path_is_one_line_naming_the_option(path):
    """Robot.from_toml(3) raised Python's TypeError from pathlib; every reader of an input
    file now refuses what is not a str or os.PathLike with its option's name."""
    from ddwmmr.qp.limits.obstacles import load_obstacles
    from ddwmmr.trajectories.files import read_toml
    from ddwmmr.trajectories.sampled import read_csv

    for read, label in (
        (Robot.from_toml, "robot"),
        (read_toml, "traj"),
        (read_csv, "traj"),
        (load_obstacles, "obstacles"),
    ):
        with pytest.raises(ParameterError) as info:
            read(path)
        assert str(info.value) == (
            f"{label}: a file path (str or os.PathLike) is needed (got {path!r})"
        )


def test_int_check_shows_an_integral_float_as_the_integer_it_is():
    """A command line reads ``--N 1`` as 1.0: the refusal says "got 1"; a huge float keeps
    its own spelling, a fraction is shown as given."""
    cases = ((1.0, "1"), (np.float64(7.0), "7"), (2e15, "2000000000000000"), (1e16, "1e+16"))
    for value, got in (*cases, (1e300, "1e+300"), (0.5, "0.5")):
        with pytest.raises(ParameterError, match=rf"in \[2, 5\] \(got {re.escape(got)}\)$"):
            check_int_at_least("n", value, 2, 5)


def test_a_refusal_never_shows_the_value_as_its_bound():
    """``:g`` spells 0.1000000001 as 0.1: where a value differs from a bound that reads
    the same, the refusal spells both in full."""
    with pytest.raises(ParameterError, match=r"in \[0, 0\.1\] s \(got 0\.1000000001\)$"):
        check_range("dt", 0.1000000001, 0.0, 0.1, "s")
    reach = 0.35 + 0.30  # 0.6499999999999999: the arm's reach as the robot computes it
    expected = r"in \[-0\.6499999999999999, 0\.6499999999999999\] m \(got 0\.65\)$"
    with pytest.raises(ParameterError, match=expected):
        check_range("offset", 0.65, -reach, reach, "m")
    # the usual case keeps :g
    with pytest.raises(ParameterError, match=r"in \[0, 0\.1\] s \(got 0\.2\)$"):
        check_range("dt", 0.2, 0.0, 0.1, "s")
    assert texts_apart(0.1, 0.1) == ("0.1", ["0.1"])  # equal: nothing to tell apart


def test_a_start_outside_the_joint_limits_is_refused():
    from ddwmmr import simulate
    from ddwmmr.sim.simulate import check_start
    from ddwmmr.trajectories import Ellipse

    robot = Robot(joint_limits=((-1.0, 1.0), (-1.0, 1.5)))
    assert robot.joints_outside((0, 0, 0, 1.0, -1.0)) is None  # the limits are inclusive
    assert robot.joints_outside((0, 0, 0, 0.0, 1.6)) == (
        "joint th2 = 1.6 rad is outside joint_limits[2] = [-1, 1.5] rad"
    )
    with pytest.raises(ParameterError, match=r"^q0: joint th1 = 2\.5 rad is outside "):
        simulate(robot, Ellipse(), "clrrmc-ts", q0=(2, 0, 1.57, 2.5, 1.0))
    # the start the offset builds: the home pose moved by the offset leaves the limits
    narrow = Robot(joint_limits=((-0.31, -0.29), (0.59, 0.61)))
    with pytest.raises(ParameterError, match=r"^the start pose \(initial_offset applied\): "):
        simulate(narrow, Ellipse(), "ats", duration=0.1)
    simulate(narrow, Ellipse(), "ats", duration=0.1, initial_offset=(0.0, 0.0))  # inside
    with pytest.raises(ParameterError, match=r"change the robot's joint_limits or --offset$"):
        check_start(robot, (0, 0, 0, 0.0, 1.6), start="--offset")


def test_a_reachable_offset_is_started_within_the_joint_limits():
    """Newton lands th1 whole turns away for a 0.25 m offset (-24.2 rad): the start turns
    it back into the limits, the same arm pose, and the run goes ahead."""
    from ddwmmr import simulate
    from ddwmmr.resolution.reference import initial_configuration, offset_configuration
    from ddwmmr.trajectories import Ellipse

    robot, trajectory = Robot(), Ellipse()
    start = initial_configuration(robot, trajectory, (-0.22, 0.11))
    assert robot.joints_outside(start) is None
    assert all(-math.pi <= angle <= math.pi for angle in start[3:])
    home = initial_configuration(robot, trajectory, (0.0, 0.0))
    moved = robot.fk(start)[:2] - robot.fk(home)[:2]
    assert math.hypot(*moved) == pytest.approx(math.hypot(-0.22, 0.11), abs=1e-9)
    q = np.array(home)
    assert offset_configuration(robot, q, (0.0, 0.0)).tolist() == home.tolist()  # to the bit
    ts = simulate(robot, trajectory, "clrrmc-ts", duration=0.2, initial_offset=(-0.22, 0.11))
    assert ts.timeseries["th1"][0] == pytest.approx(start[3])


def test_a_step_count_rounded_onto_the_cap_is_spelt_apart_from_it():
    """10001 s / 0.01 s read '= 1e+06' against the cap 1000000 in every tool."""
    with pytest.raises(ParameterError, match=re.escape("0.01 s = 1.0001e+06); use a larger")):
        check_step_count(10001.0, 0.01)
    with pytest.raises(ParameterError, match=re.escape("0.0001 s = 1.2e+06); use a larger")):
        check_step_count(120.0, 1e-4)  # clearly above: three digits as before
