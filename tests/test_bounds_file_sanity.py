"""``scenarios --bounds``: a bounds file with a byte-order mark is read, and one whose
lower bounds the run beats is named in a warning (a lower bound holds for every run)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ddwmmr.bounds.batch import read_bounds, read_bounds_file
from ddwmmr.cli.scenarios import main as cli
from ddwmmr.errors import ParameterError

HEADER = "scenario,lower_bound_s,best_known_s,replay_ok"


def _bounds(folder: Path, rows: list[str], bom: bool = False) -> Path:
    """bounds.csv and its summary.json (seed 0, the default payload) in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    text = "\n".join([HEADER, *rows]) + "\n"
    (folder / "bounds.csv").write_bytes(("\ufeff" if bom else "").encode() + text.encode())
    summary = json.dumps({"seed": 0, "payload": 3.0})
    (folder / "summary.json").write_bytes(("\ufeff" if bom else "").encode() + summary.encode())
    return folder / "bounds.csv"


def test_a_bounds_file_with_a_utf8_byte_order_mark_is_read(tmp_path):
    """A spreadsheet's "CSV UTF-8" starts with a BOM: it was refused as lacking the
    column scenario (the first column's name read as "\\ufeffscenario")."""
    path = _bounds(tmp_path, ["1,10,12,True", "2,nan,nan,False"], bom=True)
    plain = _bounds(tmp_path / "plain", ["1,10,12,True", "2,nan,nan,False"])
    assert read_bounds(path).keys() == {1, 2}
    assert read_bounds(path)[1] == (10.0, 12.0)
    assert read_bounds_file(path, 0, 3.0)[1] == read_bounds_file(plain, 0, 3.0)[1]


def test_a_lower_bound_above_an_achieved_time_is_warned_about(tmp_path, capsys):
    """Scenario 1 reaches its last waypoint in about 30 s: a file giving it a lower bound
    of 40 s printed "mean ratio to the lower bound 0.757" without comment."""
    path = _bounds(tmp_path / "b", ["1,40,45,True", "2,1,2,True"])
    out = tmp_path / "r"
    assert (
        cli(["--n", "2", "--jobs", "1", "--no-progress", "--out", str(out), "--bounds", str(path)])
        == 0
    )
    err = capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    (warning,) = [line for line in err.splitlines() if line.startswith("warning: ")]
    assert warning.startswith(
        f"warning: {path} gives lower bounds above the times achieved in scenario 1 ("
    )
    assert "s < 40 s); a lower bound holds for every run of its scenario" in warning
    assert summary["bracket"]["scenarios_below_lower_bound"] == [1]


def test_no_warning_when_the_run_is_slower_than_its_lower_bounds(tmp_path, capsys):
    path = _bounds(tmp_path / "b", ["1,10,12,True"])
    out = tmp_path / "r"
    assert cli(["--n", "1", "--no-progress", "--out", str(out), "--bounds", str(path)]) == 0
    assert "gives lower bounds above" not in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["bracket"]["scenarios_below_lower_bound"] == []


def test_a_fifo_or_a_device_as_bounds_file_is_refused_in_one_line(tmp_path):
    """A FIFO named as the bounds file (or as the summary.json beside it) blocked the run
    until killed; a UTF-16 file gave the codec's own error. Each is one line now."""
    import os

    import pytest

    from ddwmmr.errors import ParameterError

    fifo = tmp_path / "fifo" / "bounds.csv"
    fifo.parent.mkdir()
    os.mkfifo(fifo)
    with pytest.raises(
        ParameterError, match=r"^bounds: .*bounds\.csv is not a regular file \(a FIFO\)$"
    ):
        read_bounds_file(fifo, 0, 3.0)
    path = _bounds(tmp_path / "record", ["1,10,12,True"])
    (path.parent / "summary.json").unlink()
    os.mkfifo(path.parent / "summary.json")
    with pytest.raises(ParameterError, match=r"summary\.json is not a regular file \(a FIFO\)"):
        read_bounds_file(path, 0, 3.0)
    wide = tmp_path / "wide" / "bounds.csv"
    wide.parent.mkdir()
    wide.write_text(HEADER + "\n1,10,12,True\n", encoding="utf-16")
    with pytest.raises(ParameterError, match=r"is not UTF-8 text \(byte 0xff at offset 0\)"):
        read_bounds(wide)


def test_a_column_read_twice_or_a_row_longer_than_the_header_is_refused(tmp_path):
    """The csv module read the last of two scenario columns (scenario 2 for a row of 1,
    then "covers none of the run's scenario 1") and put the fields beyond the header
    under a key None, ignored."""
    twice = tmp_path / "twice.csv"
    twice.write_text("scenario,scenario,lower_bound_s,best_known_s,replay_ok\n1,2,10,12,True\n")
    with pytest.raises(ParameterError) as error:
        read_bounds(twice)
    assert str(error.value) == (
        f"bounds: {twice} has the column scenario more than once (a bounds.csv of python -m "
        "ddwmmr.bounds has each once)"
    )
    longer = tmp_path / "longer.csv"
    longer.write_text(f"{HEADER}\n1,10,12,True,7\n")
    with pytest.raises(ParameterError) as error:
        read_bounds(longer)
    assert str(error.value) == (
        f"bounds: {longer} line 2 has more fields than the header has columns"
    )
