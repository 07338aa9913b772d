"""RunConfig's controller_options and run_scenario's own arguments are refused in one line
naming the parameter and what is allowed (docs/api.md: each scenario limit is "refused
with one line")."""

from __future__ import annotations

import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.scenarios import RunConfig, generate, run_scenario

PAIRS = 'a tuple of (name, value) pairs with distinct names, e.g. (("horizon", 3.0),)'


@pytest.mark.parametrize(
    ("options", "got"),
    [
        ("x", "'x'"),  # was: ValueError: dictionary update sequence element #0 has length 1
        ({"horizon": 3.0}, "{'horizon': 3.0}"),
        (None, "None"),
        ((("horizon", 3.0), "lookahead"), "'lookahead'"),
        ((("horizon",),), "('horizon',)"),
        (((3, 1.0),), "(3, 1.0)"),
    ],
)
def test_controller_options_that_are_no_pairs_are_one_line(options, got):
    with pytest.raises(ParameterError) as error:
        RunConfig(controller_options=options)
    assert str(error.value) == f"controller_options must be {PAIRS} (got {got})"


def test_a_controller_option_given_twice_is_refused_not_last_wins():
    twice = (("stability_min", 1.3), ("stability_min", 1.4))
    with pytest.raises(ParameterError) as error:
        RunConfig(controller="mpc", controller_options=twice)
    assert str(error.value) == (
        f"controller_options: 'stability_min' is given twice; each name once ({PAIRS})"
    )


def test_pairs_as_a_tuple_or_a_list_reach_the_controller():
    from ddwmmr.model import Robot
    from ddwmmr.plants import make_plant
    from ddwmmr.scenarios.protocol import make_scenario_controller

    robot = Robot().with_payload(3.0)
    scenario = generate(1, 0)[0]
    for options in ((("adjust", 0.3),), [["adjust", 0.3]]):
        config = RunConfig(controller_options=options)
        controller = make_scenario_controller(robot, scenario, config, make_plant("thesis", robot))
        assert controller.behaviours["stability"].adjust == pytest.approx(0.3, abs=1e-12)


def test_run_scenario_refuses_what_is_no_scenario_or_no_config():
    scenario = generate(1, 0)[0]
    with pytest.raises(ParameterError) as error:
        run_scenario(None, RunConfig())
    assert str(error.value) == (
        "scenario must be a Scenario (ddwmmr.scenarios.generate) (got None)"
    )
    with pytest.raises(ParameterError) as error:
        run_scenario(scenario, None)
    assert str(error.value) == "config must be a RunConfig (ddwmmr.scenarios.RunConfig) (got None)"
    with pytest.raises(ParameterError) as error:
        run_scenario(scenario, {"dt": 0.01})
    assert str(error.value) == (
        "config must be a RunConfig (ddwmmr.scenarios.RunConfig) (got {'dt': 0.01})"
    )


def test_options_given_as_lists_are_kept_as_tuples():
    """A list of lists is stored as a tuple of pairs, so the frozen configuration stays
    hashable (a list inside would make hash() raise)."""
    config = RunConfig(controller_options=[["adjust", 0.3]])
    assert config.controller_options == (("adjust", 0.3),)
    assert hash(config) == hash(RunConfig(controller_options=(("adjust", 0.3),)))
