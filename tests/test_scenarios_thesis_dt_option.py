"""The scenarios' ``--option dt=...`` for the thesis controller, which has no dt option."""

from __future__ import annotations

import pytest

from ddwmmr import ParameterError
from ddwmmr.cli.scenarios import build_parser as scenarios_parser
from ddwmmr.cli.scenarios import config_from_arguments
from ddwmmr.cli.scenarios import main as scenarios


def test_the_thesis_controller_s_dt_option_is_refused_as_an_option_it_does_not_take(
    tmp_path, capsys
):
    """It was refused in the qp's and mpc's words ("the controller's planning step"), but
    the thesis controller has no dt option."""
    message = "option: thesis has no option 'dt' (options: adjust)"
    with pytest.raises(ParameterError) as info:
        config_from_arguments(scenarios_parser().parse_args(["--option", "dt=0.05"]))
    assert str(info.value) == message
    out = tmp_path / "out"
    assert scenarios(["--option", "dt=0.05", "--out", str(out)]) == 2
    assert (capsys.readouterr().err, out.exists()) == (f"error: {message}\n", False)


@pytest.mark.parametrize("controller", ["qp", "mpc"])
def test_an_unknown_option_lists_only_the_options_the_scenarios_let_one_set(controller):
    """The list of a qp's or mpc's options named dt, obstacles, stability_min and
    max_speed, which the scenarios set themselves and refuse as --option; it now lists
    only what --option may set, while a misspelling still points to the closest name of
    all (whose own message then says what sets it)."""
    args = scenarios_parser().parse_args(["--controller", controller, "--option", "foo=1"])
    with pytest.raises(ParameterError) as info:
        config_from_arguments(args)
    listed = str(info.value).split("(options: ")[1].rstrip(")").split(", ")
    assert listed and not {"dt", "obstacles", "stability_min", "max_speed", "route"} & set(listed)
    args = scenarios_parser().parse_args(["--controller", controller, "--option", "stabilty_min=1"])
    with pytest.raises(ParameterError, match=r"did you mean stability_min\?"):
        config_from_arguments(args)
