"""The options a scenario batch records for its controller: every option with the value
its runs use, for every controller, the defaults read from the one place they are
defined (docs/cli.md, "scenarios")."""

from __future__ import annotations

import json

import pytest

from ddwmmr.controllers.base import method_options
from ddwmmr.errors import ParameterError
from ddwmmr.scenarios import RunConfig, generate
from ddwmmr.scenarios.protocol import controller_options_record


@pytest.fixture(scope="module")
def scenario():
    return generate(1, 0)[0]


def test_a_qp_batch_records_every_option_with_its_defaults_filled(scenario):
    config = RunConfig(controller="qp", qp_max_speed=0.8, controller_options=(("tau", 0.3),))
    record = controller_options_record(config, scenario)
    defaults = method_options("qp")
    assert set(record) == set(defaults) - {"obstacles"}  # each scenario's own
    # given: by the protocol (floor, speed, step, position only), the plant's envelope
    # and the user's own
    assert record["stability_min"] == pytest.approx(1.25, abs=1e-12)
    assert record["max_speed"] == pytest.approx(0.8, abs=1e-12)
    assert record["dt"] == pytest.approx(0.01, abs=1e-12)
    assert record["track_orientation"] is False
    assert record["tau"] == pytest.approx(0.3, abs=1e-12)
    assert record["max_base_speed"] == pytest.approx(1.0666666666666667, rel=1e-12)
    # the rest: the constructor's defaults
    assert record["tracking_weight"] == pytest.approx(defaults["tracking_weight"], abs=1e-12)
    assert record["solver"] == defaults["solver"] == "daqp"
    assert record["tasks"] == [] and record["limits"] == []
    json.dumps(record, allow_nan=False)  # plain JSON


def test_a_thesis_batch_records_its_options_and_names_its_arbiter(scenario):
    record = controller_options_record(RunConfig(controller="thesis"), scenario)
    assert record == {
        "arbiter": "ddwmmr.arbiters.state_machine.StateMachineArbiter",
        "gains": None,
        "adjust": pytest.approx(0.5, abs=1e-12),
    }
    competitive = RunConfig(controller="thesis", arbiter="competitive")
    assert controller_options_record(competitive, scenario)["arbiter"] == (
        "ddwmmr.arbiters.competitive.CompetitiveDynamicsArbiter"
    )


def test_an_mpc_batch_records_its_options_resolved_for_the_plant(scenario):
    """The mpc's options as resolved for the thesis plant (its force model, the grid of
    the reach objective), as the batch's summary.json recorded them already."""
    record = controller_options_record(RunConfig(controller="mpc"), scenario)
    assert record["model"] == "thesis"
    assert record["horizon"] == pytest.approx(5.0, abs=1e-12)
    assert record["intervals"] == 12
    assert record["position_weight"] == pytest.approx(50.0, abs=1e-12)
    assert record["dt"] == pytest.approx(0.01, abs=1e-12)
    assert "obstacles" not in record


def test_a_bad_option_is_refused_in_one_line(scenario):
    config = RunConfig(controller="qp", controller_options=(("tau", -1.0),))
    with pytest.raises(ParameterError) as caught:
        controller_options_record(config, scenario)
    assert "tau" in str(caught.value) and "\n" not in str(caught.value)
