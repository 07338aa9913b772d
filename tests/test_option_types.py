"""Options of the wrong type (None where a number is due, a list where a name is, an
integer beyond a float) are one-line ParameterErrors naming the option, refused when the
controller is made, not TypeErrors or OverflowErrors from deep inside a solve."""

from __future__ import annotations

import pytest

from ddwmmr import simulate
from ddwmmr.controllers.base import make_controller
from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.model.support_loads import check_min_edge_load
from ddwmmr.mpc.controller import MPCController
from ddwmmr.mpc.options import MPCOptions
from ddwmmr.trajectories import Ellipse

ROBOT = Robot()


def refusal(call) -> str:
    """The one-line message of the ParameterError ``call()`` raises."""
    with pytest.raises(ParameterError) as error:
        call()
    message = str(error.value)
    assert "\n" not in message
    return message


@pytest.mark.parametrize(
    "name, allowed",
    [
        ("proximal", ">= 0"),
        ("stability_margin", ">= 0"),
        ("plan_weight", "in [0, 1e+06]"),
    ],
)
def test_none_is_refused_for_an_mpc_option_with_a_number_default(name, allowed):
    """None is not "chosen for the plant" for these (their defaults are numbers): the
    qp's wording, naming the option and its range."""
    options = {name: None, "obstacles": [(5.0, 5.0, 0.3)]}
    message = refusal(lambda: make_controller("mpc", ROBOT, **options))
    assert message == f"{name} must be a finite number {allowed} (got None)"


def test_a_none_proximal_is_refused_before_the_run_starts():
    message = refusal(lambda: simulate(ROBOT, Ellipse(), "mpc", proximal=None, duration=0.1))
    assert message == "proximal must be a finite number >= 0 (got None)"


def test_the_mpc_controller_names_an_unknown_option_and_nothing_else_as_one():
    """A TypeError while the options are checked is not reported as an unknown keyword."""
    assert refusal(lambda: MPCController(ROBOT, horizn=2.0)).startswith(
        "method mpc: unknown option 'horizn' (accepted: arm_time_constant, brake_slack, "
    )
    assert (
        refusal(lambda: MPCController(ROBOT, stability_margin="0.01"))
        == "stability_margin must be a finite number >= 0 (got '0.01')"
    )


@pytest.mark.parametrize("method", ["ats", "clrrmc-ts", "clrrmc-cs"])
@pytest.mark.parametrize("aux", [["sum"], {}, None])
def test_an_aux_that_is_no_name_is_refused(method, aux):
    message = refusal(lambda: make_controller(method, ROBOT, aux=aux))
    assert message.startswith("aux must be one of sum, shoulder (got ")


@pytest.mark.parametrize("method", ["qp", "mpc"])
def test_a_min_edge_load_beyond_a_float_is_refused_compactly(method):
    message = refusal(lambda: make_controller(method, ROBOT, min_edge_load=10**400))
    assert message == (
        "min_edge_load must be a share of the weight in [0, 0.5) (got an integer of about 1e400)"
    )


def test_min_edge_load_keeps_its_range_and_its_values():
    assert check_min_edge_load(0.25) == pytest.approx(0.25, abs=0.0)
    assert check_min_edge_load(0) == pytest.approx(0.0, abs=0.0)
    for bad in (0.5, -0.1, True, "0.1", float("nan")):
        assert "min_edge_load must be a share" in refusal(lambda bad=bad: check_min_edge_load(bad))


@pytest.mark.parametrize("bad", ["x", True, [("max_speed", 1.0)], {1: 2.0}])
def test_fallback_options_must_be_a_dict_by_name(bad):
    message = refusal(lambda: MPCOptions(fallback_options=bad))
    assert message.startswith("fallback_options must be a dict of qp options by name (got ")


def test_fallback_options_are_kept_as_given():
    assert MPCOptions(fallback_options={"max_speed": 0.5}).fallback_options == {"max_speed": 0.5}
    assert MPCOptions(fallback_options=None).fallback_options == {}
