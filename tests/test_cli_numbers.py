"""Negative numbers in any float notation are values on every command line, not options."""

from __future__ import annotations

import json

import pytest

from ddwmmr.cli.common import NEGATIVE_NUMBER, ArgumentParser
from ddwmmr.cli.track import main as track_main
from in_process import call_main


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


# -- number texts a float cannot hold, and huge texts in messages ---------------------------

#: A tool's ``main`` and the arguments that make it refuse nothing but the option tried.
TOOLS = {
    "track": ("ddwmmr.cli.track", ["--method", "ats", "--traj", "ellipse", "--no-plots"]),
    "compare": ("ddwmmr.cli.compare", ["--methods", "ats", "--traj", "ellipse"]),
    "scenarios": ("ddwmmr.cli.scenarios", ["--n", "1"]),
    "bench": ("ddwmmr.cli.bench", ["--method", "ats"]),
    "bounds": ("ddwmmr.cli.bounds", ["--scenarios", "1", "--lower-only"]),
    "gui": ("ddwmmr.cli.gui", ["--snapshot", "snapshot.png"]),
}
#: A numeric option of each tool (its value first, then what else it needs), and the range
#: its refusal states.
NUMBER_OPTIONS = [
    ("track", ["--dt", "{}"], "> 0 s"),
    ("track", ["--duration", "{}"], "> 0 s"),
    ("track", ["--payload", "{}"], "in [0, 100000] kg"),
    ("track", ["--offset", "{}", "0"], "in [-reach, reach] m"),
    ("track", ["--traj-scale", "{}"], "in [1e-06, 1e+06] or robot"),
    ("compare", ["--duration", "{}"], "> 0 s"),
    ("scenarios", ["--dt", "{}"], "in (0, 0.1] s"),
    ("scenarios", ["--time-limit", "{}"], "> 0 s"),
    ("scenarios", ["--stability", "{}", "1.3"], "in (0, 10]"),
    ("bench", ["--duration", "{}"], "in [0.02, 20000] s"),
    ("bounds", ["--payload", "{}"], "in [0, 100000] kg"),
    ("gui", ["--dt", "{}"], "> 0 s"),
    ("gui", ["--a", "{}"], "in [1e-06, 1000] m"),
]


def _refusal(tool, argv, capsys, monkeypatch, tmp_path, base=None):
    """The one line of stderr with which ``tool`` refuses ``argv`` after ``base`` (default:
    its :data:`TOOLS` arguments), status 2."""
    import importlib

    module, default = TOOLS[tool]
    base = default if base is None else base
    monkeypatch.chdir(tmp_path)
    status, _, err = call_main(importlib.import_module(module).main, [*base, *argv], capsys)
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err, err[:500]
    return err.strip()


@pytest.mark.parametrize(
    ("text", "why"),
    [
        ("1e-400", "too small for a float, which reads it as 0"),
        ("-1e-400", "too small for a float, which reads it as 0"),
        ("1e999", "beyond the largest float, 1.798e+308"),
        ("-1E999", "beyond the largest float, 1.798e+308"),
    ],
)
@pytest.mark.parametrize(("tool", "option", "allowed"), NUMBER_OPTIONS)
def test_a_number_a_float_cannot_hold_is_refused_as_typed(
    tool, option, allowed, text, why, capsys, monkeypatch, tmp_path
):
    """``--dt 1e-400`` was refused as "dt must be > 0 (got 0)", ``--dt 1e999`` as "(got
    inf)": the text reads as 0 or inf, which the user never typed; some options took 1e-400
    as a valid 0 (``--payload``, ``--offset``)."""
    argv = [word.replace("{}", text) for word in option]
    err = _refusal(tool, argv, capsys, monkeypatch, tmp_path)
    assert f"argument {option[0]}: must be a number {allowed}" in err
    assert err.endswith(f"(got {text!r}, {why})")


@pytest.mark.parametrize("text", ["0", "-0", "0e-999", "0.000", "5e-324", "1e308", "inf", "nan"])
def test_zeros_infinities_and_subnormals_read_as_typed(text):
    from ddwmmr.errors import plain_float

    assert str(plain_float(text)) == str(float(text))


@pytest.mark.parametrize(
    "text", ["1e-400", "-1e-400", "1e999", "1.8e308", "9" * 5000, "1_0", "0x10"]
)
def test_plain_float_refuses_what_no_float_holds(text):
    from ddwmmr.errors import plain_float

    with pytest.raises(ValueError):
        plain_float(text)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--option", "dt=1e-400"], "dt must be a finite number in [0.0001, 100] s (got '1e-400')"),
        (["--option", "dt=1e300"], "dt must be in [0.0001, 100] s (got 1e+300)"),
        (["--option", "dt=1e-300"], "dt must be in [0.0001, 100] s (got 1e-300)"),
        (
            ["--tau", "1e999"],
            "argument --tau: must be a number > 0 s (at least 0.0001 s), or inf to disable a "
            "channel (got '1e999', beyond the largest float, 1.798e+308)",
        ),
        (
            ["--option", "tau=0.5,1e999,0.5"],
            "tau must be > 0 s (at least 0.0001 s), or inf to disable a channel (got "
            "'0.5,1e999,0.5')",
        ),
        (
            ["--plant", "thesis", "--plant-option", "c1=1e-400"],
            "c1 must be a finite number in [1e-20, 1e+13] N s/m (got '1e-400')",
        ),
    ],
)
def test_method_and_plant_options_refuse_numbers_a_float_cannot_hold(
    argv, message, capsys, monkeypatch, tmp_path
):
    """``--option dt=1e-400`` was read as 0 ("dt must be > 0 (got 0)"); the qp's ``dt``
    took anything from 1e-300 s to 1e300 s; ``--tau 1e999`` read as inf switched the
    tracking off."""
    base = ["--method", "qp", "--traj", "ellipse", "--no-plots"]
    err = _refusal("track", argv, capsys, monkeypatch, tmp_path, base)
    assert err.endswith(f"error: {message}")


HUGE = "9" * 5000


@pytest.mark.parametrize(
    ("tool", "argv", "expected"),
    [
        ("scenarios", ["--seed", HUGE], "must be an integer >= 0 (got '999"),
        ("bounds", ["--seed", HUGE], "must be an integer >= 0 (got '999"),
        ("bench", ["--repeats", HUGE], "must be an integer in [1, 1000] (got '999"),
        ("bench", ["--calls", "1" + "0" * 4000], "must be an integer in [1, 10000] (got '100"),
        ("track", ["--stability-min", HUGE], "must be a number in (0, 10) (got '999"),
        ("gui", ["--T", HUGE], "must be a number in [1e-06, 1e+09] s (got '999"),
        ("track", [HUGE], "unrecognized arguments: 999"),
        ("track", ["--method", HUGE], "invalid choice: '999"),
        (
            "track",
            ["--plant", "thesis", "--plant-option", "x" * 5000 + "=1"],
            "has no option 'xxx",
        ),
    ],
)
def test_huge_texts_are_shortened_in_the_message(
    tool, argv, expected, capsys, monkeypatch, tmp_path
):
    """A 5000-digit ``--seed`` was echoed whole: a 5000-character error line."""
    err = _refusal(tool, argv, capsys, monkeypatch, tmp_path)
    assert expected in err and len(err) < 600, err[:700]  # at most 200 of HUGE
    if argv == ["--seed", HUGE]:  # an integer >= 0, refused for its length: said so
        assert err.endswith("..., 5000 digits, more than the 4300 Python reads)")


def test_message_words_are_cut_in_the_middle():
    from ddwmmr.errors import MAX_WORD, ParameterError, clipped_words

    path = "/" + "d" * 300 + "/robot.toml"
    cut = clipped_words(f"robot: {path} is not valid TOML")
    assert cut.startswith("robot: /ddd") and cut.endswith("d/robot.toml is not valid TOML")
    assert len(cut.split()[1]) == MAX_WORD and "..." in cut
    assert str(ParameterError(f"x must be > 0 (got {'7' * 5000})")).endswith("777)")
    assert len(str(ParameterError("y" * 5000))) == MAX_WORD
    short = "a " + "b" * MAX_WORD
    assert clipped_words(short) is short
