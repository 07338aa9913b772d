"""An empty item of a list option (``--option tau=0.5,,0.5``) is refused naming the item."""

from __future__ import annotations

import math

import pytest

from ddwmmr import ParameterError, make_controller
from ddwmmr.cli.track import main as track
from ddwmmr.controllers.option_specs import parse_option


@pytest.mark.parametrize(
    ("text", "item"),
    [("0.5,,0.5", 2), (",0.5,0.5", 1), ("0.5,", 2), ("0.5 , ,0.5", 2), ("0.5 0.5,,0.5", 3)],
)
def test_an_empty_item_of_a_list_option_is_refused_by_its_number(text, item):
    """``tau=0.5,,0.5`` said "tau must be one value or 3 values in s (got 2)" and
    ``tau=0.5,`` ran with tau = 0.5 on every channel: the empty item is named now."""
    with pytest.raises(ParameterError) as info:
        parse_option("clrrmc-ts", f"tau={text}")
    assert str(info.value) == (
        f"tau: item {item} is empty (got {text!r}); separate the numbers by one comma or by spaces"
    )


def test_list_options_without_an_empty_item_still_parse():
    assert parse_option("clrrmc-ts", "tau=0.5, 0.5 inf") == ("tau", (0.5, 0.5, math.inf))
    assert parse_option("clrrmc-ts", "tau=0.3") == ("tau", 0.3)


def test_a_one_number_option_with_a_trailing_comma_is_refused_naming_its_range():
    """``damping=1,`` was taken as 1.0."""
    name, value = parse_option("ats", "damping=1,")
    with pytest.raises(ParameterError, match=r"^damping must be a finite number in \[1e-06, "):
        make_controller("ats", **{name: value})


def test_track_refuses_an_empty_tau_item_in_one_line(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["--method", "clrrmc-ts", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    status = track([*argv, "--no-progress", "--out", str(out), "--option", "tau=0.5,,0.5"])
    assert (status, out.exists()) == (2, False)
    assert capsys.readouterr().err == (
        "error: tau: item 2 is empty (got '0.5,,0.5'); separate the numbers by one comma or "
        "by spaces\n"
    )
