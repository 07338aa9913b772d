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
