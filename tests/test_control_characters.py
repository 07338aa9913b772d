"""A control character (a line break, a tab) in a name the user gives: a message quoting
it stays one line (ParameterError escapes it), and an output folder named with one is
refused, since the tools' last line, ``wrote <path>``, would be split."""

from __future__ import annotations

import pickle

import pytest

from ddwmmr.cli.bench import main as bench
from ddwmmr.cli.track import main as track
from ddwmmr.errors import ParameterError, escaped_controls
from ddwmmr.model import Robot
from ddwmmr.outputs import check_output_path


def test_a_parameter_error_is_one_line_by_construction():
    error = ParameterError("robot: cannot read a\nb\t.toml\x1b[2J (No such file)")
    assert str(error) == "robot: cannot read a\\nb\\t.toml\\x1b[2J (No such file)"
    assert str(pickle.loads(pickle.dumps(error))) == str(error)  # workers send it back
    assert escaped_controls("café \udcff ok") == "café \udcff ok"  # undecodable bytes kept


@pytest.mark.parametrize("separator", ["\u2028", "\u2029"])
def test_the_unicode_line_separators_are_escaped_too(separator, tmp_path):
    """str.splitlines cuts at U+2028 and U+2029 as at a newline: a message quoting a file
    named with one printed as two lines."""
    error = ParameterError(f"robot: cannot read a{separator}b.toml")
    assert len(str(error).splitlines()) == 1 and str(error).endswith("b.toml")
    with pytest.raises(ParameterError):
        check_output_path(tmp_path / f"run{separator}1")


def test_a_robot_file_named_with_a_line_break_is_named_on_one_line(tmp_path):
    """Robot.from_toml's message quoted the name as it is: two lines."""
    path = tmp_path / "bad\nrobot.toml"
    path.write_text('L1 = "x"\n')
    with pytest.raises(ParameterError) as info:
        Robot.from_toml(path)
    assert "\n" not in str(info.value) and "bad\\nrobot.toml: L1 must be a number" in str(
        info.value
    )
    with pytest.raises(ParameterError, match=r"cannot read .*no\\nsuch\.toml") as info:
        Robot.from_toml(tmp_path / "no\nsuch.toml")


@pytest.mark.parametrize("name", ["a\nb", "a\rb", "a\tb", "a\x1bb", "a\x85b"])
def test_an_output_name_with_a_control_character_is_refused(tmp_path, name):
    with pytest.raises(ParameterError) as info:
        check_output_path(tmp_path / name)
    assert str(info.value).startswith("out: the folder name holds a control character")
    check_output_path(tmp_path / "caf\udce9")  # an undecodable byte is no control character


def test_track_and_bench_refuse_an_out_with_a_line_break(tmp_path, capsys, monkeypatch):
    """track wrote the folder 'a\\nb' and printed its last line 'wrote a\\nb/' on two
    lines; a script reading the folder from that line got 'b/'."""
    monkeypatch.chdir(tmp_path)
    argv = ["--method", "ats", "--traj", "ellipse", "--duration", "0.1", "--no-plots"]
    assert track([*argv, "--out", "a\nb"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: out: the folder name holds a control character")
    assert err.count("\n") == 1
    assert bench(["--out", "r\n.json", "--repeats", "1", "--calls", "1"]) == 2
    assert "out: the file name holds a control character" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
