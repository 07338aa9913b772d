"""``scenarios --bounds``: a bounds file whose numbers Python cannot convert (a scenario of
5000 digits, a floor on S beyond a float) is refused in one line with status 2, as its
other malformed rows are, before any scenario runs."""

from __future__ import annotations

from pathlib import Path

import pytest

from ddwmmr.bounds.batch import bounds_floor
from ddwmmr.cli.scenarios import main as cli
from ddwmmr.errors import ParameterError

HEADER = "scenario,lower_bound_s,best_known_s,replay_ok"


def _bounds(folder: Path, row: str, floor: str | None = None) -> Path:
    """bounds.csv with ``row`` and its summary.json (seed 0, the default payload, and
    ``settings.stability_min`` spelt ``floor`` in the JSON text when given)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "bounds.csv").write_text(f"{HEADER}\n{row}\n")
    settings = "" if floor is None else f', "settings": {{"stability_min": {floor}}}'
    (folder / "summary.json").write_text(f'{{"seed": 0, "payload": 3.0{settings}}}')
    return folder / "bounds.csv"


def test_a_scenario_of_5000_digits_is_one_line_with_status_2(tmp_path, capsys):
    path = _bounds(tmp_path / "b", "9" * 5000 + ",10,12,True")
    out = tmp_path / "s"
    assert cli(["--n", "1", "--no-progress", "--out", str(out), "--bounds", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith(
        f"error: bounds: {path} line 2, column scenario: must be a whole number in 1-100000 "
        "(got '9999"
    )
    assert not out.exists()


def test_a_floor_beyond_a_float_is_one_line_with_status_2_from_the_tool(tmp_path, capsys):
    """It was int's OverflowError, a traceback and status 1 (in-process, an exception
    ``main`` lets out fails the test)."""
    path = _bounds(tmp_path / "b", "1,10,12,True", floor="1" + "0" * 400)
    argv = ["--n", "1", "--no-progress", "--out", str(tmp_path / "s"), "--bounds", str(path)]
    status = cli(argv)
    captured = capsys.readouterr()
    assert (status, captured.out) == (2, "")
    assert captured.err == (
        f"error: bounds: {path.parent / 'summary.json'}: settings.stability_min must be a "
        "finite number in (0, 10) (got an integer of about 1e400)\n"
    )
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize(
    ("floor", "got"), [("NaN", "nan"), ("Infinity", "inf"), ("10.0", "10"), ("-1", "-1")]
)
def test_a_floor_that_is_no_floor_on_s_is_refused(tmp_path, floor, got):
    path = _bounds(tmp_path, "1,10,12,True", floor=floor)
    with pytest.raises(ParameterError) as error:
        bounds_floor(path)
    assert str(error.value) == (
        f"bounds: {tmp_path / 'summary.json'}: settings.stability_min must be "
        f"{'a finite number ' if got in ('nan', 'inf') else ''}in (0, 10) (got {got})"
    )


@pytest.mark.parametrize(
    ("floor", "expected"), [("1.3", 1.3), ("2", 2.0), ('"1.3"', None), ("true", None)]
)
def test_a_recorded_floor_is_read_and_a_non_number_says_none(tmp_path, floor, expected):
    path = _bounds(tmp_path, "1,10,12,True", floor=floor)
    assert bounds_floor(path) == expected
    assert bounds_floor(_bounds(tmp_path / "none", "1,10,12,True")) is None
