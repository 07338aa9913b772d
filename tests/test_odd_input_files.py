"""Input files with odd names, line ends or bytes, and odd output conditions: each is read
or refused in one line, and nothing a tool writes fails on them.

A trajectory file whose name holds a byte that is not UTF-8 (or a newline) loads with a
name every report can print and draw; a report quoting its path is still written; a
robot, trajectory or obstacle TOML saved with CR-only line ends loads as the CSV inputs
do; a CSV value spoilt by a no-break space is shown with it; a support polygon refused
for thousands of casters is refused in a message of bounded length; a write that fails
(a full disk) names the file.
"""

import errno
import os
import sys
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from ddwmmr.errors import ParameterError, load_toml
from ddwmmr.model.robot import Robot
from ddwmmr.outputs.atomic import write_atomic
from ddwmmr.qp.limits.obstacles import load_obstacles
from ddwmmr.trajectories import Ellipse, SampledTrajectory, load_trajectory, read_csv
from ddwmmr.trajectories.base import file_name
from one_line import one_line

CSV = "t,x,y\n0,1.0,0.0\n1,1.5,0.5\n2,2.0,0.0\n"
LINUX = sys.platform.startswith("linux")


def _bytes_path(folder: Path, name: bytes) -> Path:
    """``folder / name`` with ``name`` as raw file-system bytes (Linux keeps any)."""
    return Path(os.fsdecode(os.fsencode(folder) + b"/" + name))


@pytest.mark.skipif(not LINUX, reason="file names of any bytes are a Linux file system's")
def test_a_csv_named_with_a_latin1_byte_gets_a_printable_name(tmp_path):
    path = _bytes_path(tmp_path, b"caf\xe9.csv")
    path.write_text(CSV)
    trajectory = read_csv(path)
    assert trajectory.name == "caf\ufffd"
    trajectory.name.encode("utf-8")  # a lone surrogate here failed every figure's title
    figure, axes = plt.subplots()
    axes.set_title(f"pi on {trajectory.name}")
    figure.canvas.draw()  # raised TypeError inside matplotlib with the raw name
    plt.close(figure)


@pytest.mark.skipif(not LINUX, reason="file names of any bytes are a Linux file system's")
def test_a_toml_named_with_a_latin1_byte_gets_a_printable_name(tmp_path):
    path = _bytes_path(tmp_path, b"ov\xe9le.toml")
    path.write_text('shape = "ellipse"\n')
    assert load_trajectory(path).name == "ov\ufffdle"


def test_a_utf8_file_name_the_locale_read_as_ascii_keeps_its_letters():
    # Under LC_ALL=POSIX with PYTHONUTF8=0 Python reads the bytes of "é" as two surrogates.
    assert file_name(os.fsdecode("caf\xe9.csv".encode())) == "caf\xe9"
    assert file_name(Path("plain.csv")) == "plain"


@pytest.mark.skipif(os.name == "nt", reason="Windows file names hold no newline")
def test_a_newline_in_a_file_name_becomes_a_question_mark(tmp_path):
    path = tmp_path / "two\nlines.csv"
    path.write_text(CSV)
    assert read_csv(path).name == "two?lines"


@pytest.mark.parametrize("name", ["a\nb", "tab\there", "bell\x07", "lat\udce9"])
def test_a_name_with_control_characters_or_surrogates_is_refused(name):
    with pytest.raises(ParameterError) as info:
        Ellipse(name=name)
    text = one_line(info)
    assert text.startswith("name must be text on one line, without control characters")
    with pytest.raises(ParameterError, match=r"^trajectory samples: name must be text on one"):
        SampledTrajectory([0, 1, 2], [[0, 0], [1, 0], [2, 0]], name=name)


def test_a_toml_name_with_a_newline_is_refused_naming_the_file(tmp_path):
    path = tmp_path / "nl.toml"
    path.write_text('shape = "ellipse"\nname = "a\\nb"\n')
    with pytest.raises(ParameterError, match=r"^traj: .*nl\.toml: name must be text on one"):
        load_trajectory(path)


def test_names_with_accents_and_spaces_stay_as_given():
    assert Ellipse(name="ovale é 2").name == "ovale é 2"


def test_a_text_with_a_lone_surrogate_is_written_with_its_escape(tmp_path):
    target = tmp_path / "report.md"
    write_atomic(target, "path: /data/caf\udce9.csv\n")  # raised UnicodeEncodeError
    assert target.read_bytes() == b"path: /data/caf\\udce9.csv\n"


def test_plain_text_is_written_as_utf8_unchanged(tmp_path):
    target = tmp_path / "a.txt"
    write_atomic(target, "café ✓\n")
    assert target.read_bytes() == "café ✓\n".encode()


def test_a_failed_write_names_the_file_and_leaves_nothing(tmp_path):
    target = tmp_path / "timeseries.csv"

    def full_disk(handle):
        handle.write(b"t,x\n")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    with pytest.raises(OSError) as info:
        write_atomic(target, full_disk)
    assert info.value.errno == errno.ENOSPC
    assert info.value.filename == str(target)  # was None: "error: No space left on device"
    assert list(tmp_path.iterdir()) == []


def test_a_failed_write_keeps_its_own_file_name_and_kind(tmp_path):
    target = tmp_path / "x.csv"

    def refused(handle):
        raise PermissionError(errno.EACCES, "Permission denied", "/elsewhere")

    with pytest.raises(PermissionError) as info:
        write_atomic(target, refused)
    assert info.value.filename == "/elsewhere"


@pytest.mark.parametrize("ends", ["\r", "\r\n", "\n"])
def test_toml_inputs_take_any_line_ends(tmp_path, ends):
    robot = tmp_path / "robot.toml"
    robot.write_bytes(ends.join(["# mine", "L1 = 0.4", "L2 = 0.3", ""]).encode())
    assert Robot.from_toml(robot).L1 == 0.4
    trajectory = tmp_path / "t.toml"
    trajectory.write_bytes(ends.join(['shape = "ellipse"', "a = 0.7", ""]).encode())
    assert load_trajectory(trajectory).a == 0.7
    obstacles = tmp_path / "o.toml"
    lines = ["[[obstacle]]", "x = 5", "y = 4", "radius = 0.5", ""]
    obstacles.write_bytes(ends.join(lines).encode())
    (circle,) = load_obstacles(obstacles)
    assert (circle.x, circle.y, circle.radius) == (5.0, 4.0, 0.5)


def test_a_lone_cr_inside_a_string_still_ends_the_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_bytes(b'name = "a\rb"\n')
    with pytest.raises(ParameterError, match=r"^robot: .*bad\.toml is not valid TOML"):
        load_toml(path, "robot")


def test_a_no_break_space_in_a_csv_value_is_shown(tmp_path):
    path = tmp_path / "nbsp.csv"
    path.write_text("t,x,y\n0,1,0\n1,\u00a01.5,0\n2,2,0\n")
    with pytest.raises(ParameterError) as info:
        read_csv(path)
    assert one_line(info).endswith(r"data row 2, column x: '\xa01.5' is not a number")


def test_a_caster_list_refused_is_shown_cut(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text("caster_positions = [" + ", ".join(["[0.2, 0.1]"] * 5000) + "]\n")
    with pytest.raises(ParameterError) as info:
        Robot.from_toml(path)
    text = one_line(info)
    assert "caster_positions: the base centre must lie strictly inside" in text
    assert text.endswith("put casters on both sides of the wheel axle (x > 0 and x < 0)")
    assert len(text) < 500  # was the whole list: 60 000 characters here
