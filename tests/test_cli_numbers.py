"""Negative numbers in any float notation are values on every command line, not options."""

from __future__ import annotations

import json

import pytest

from ddwmmr.cli.common import NEGATIVE_NUMBER, ArgumentParser
from ddwmmr.cli.track import main as track_main


@pytest.mark.parametrize("text", ["-1", "-0.5", "-.5", "-3e-2", "-1E5", "-2.5e+3", "-inf", "-NaN"])
def test_negative_numbers_in_every_notation_are_values(text):
    parser = ArgumentParser(prog="t")
    parser.add_argument("--x", type=float)
    parser.add_argument("--pair", nargs=2, type=float)
    args = parser.parse_args(["--x", text, "--pair", text, text])
    assert str(args.x) == str(float(text)) and len(args.pair) == 2


@pytest.mark.parametrize("text", ["-x", "--x", "-e5", "-1e", "-"])
def test_option_like_words_are_not_numbers(text):
    assert NEGATIVE_NUMBER.match(text) is None


def test_track_takes_an_offset_in_scientific_notation(tmp_path):
    out = tmp_path / "out"
    argv = ["--method", "pi", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    argv += ["--no-progress", "--offset", "-3e-2", "-2e-2", "--out", str(out)]
    assert track_main(argv) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["initial_offset_m"] == pytest.approx((0.03**2 + 0.02**2) ** 0.5, rel=1e-9)


def test_a_negative_infinite_payload_gets_the_parameters_message(capsys):
    assert track_main(["--method", "pi", "--traj", "ellipse", "--payload", "-inf"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "payload must be a finite number" in err
