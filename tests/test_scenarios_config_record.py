"""A scenarios batch records only the settings its controller reads: the thesis
controller's thresholds and arbiter are left out of a qp or mpc batch's ``config`` (and of
its run record), the qp options out of a thesis batch's; what is recorded still builds
the batch's ``RunConfig``."""

from __future__ import annotations

import json

import pytest

from ddwmmr.cli.scenarios import config_record
from ddwmmr.cli.scenarios import main as cli
from ddwmmr.scenarios import RunConfig

FAST = ["--n", "1", "--time-limit", "0.3", "--jobs", "1", "--no-progress"]
THESIS_ONLY = {"stability", "manipulability", "arbiter", "arbiter_seed"}


@pytest.mark.parametrize(
    ("controller", "left_out"),
    [
        ("qp", THESIS_ONLY),
        ("mpc", THESIS_ONLY | {"qp_max_speed"}),
        ("thesis", {"qp_stability_min", "qp_max_speed"}),
    ],
)
def test_the_record_leaves_out_what_the_controller_does_not_read(controller, left_out):
    config = RunConfig(controller=controller, payload=2.5, dt=0.02)
    record = config_record(config)
    # arbiter_options: recorded only when given (a batch without them as before them)
    assert set(record) == {f for f in config.__dataclass_fields__} - left_out - {"arbiter_options"}
    assert record["payload"] == 2.5 and record["dt"] == 0.02
    assert RunConfig(**record) == config  # the left-out fields held their defaults


def test_a_qp_batch_records_no_thresholds(tmp_path):
    out = tmp_path / "qp"
    assert cli([*FAST, "--controller", "qp", "--qp-stability-min", "1.4", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for config in (summary["config"], summary["run"]["config"]):
        assert not THESIS_ONLY & set(config)
        assert config["qp_stability_min"] == 1.4 and config["controller"] == "qp"
        assert config["time_limit"] == 0.3


def test_a_thesis_batch_keeps_its_thresholds(tmp_path):
    out = tmp_path / "thesis"
    assert cli([*FAST, "--stability", "1.3", "1.7", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for config in (summary["config"], summary["run"]["config"]):
        assert config["stability"] == [1.3, 1.7] and config["manipulability"] == [0.75, 0.9]
        assert "qp_stability_min" not in config


def test_the_payload_help_says_whose_payload_the_thesis_value_is():
    """--payload's help names the 1.25 kg as the payload of the thesis's experiments (the
    Robot default), not a setting of the thesis controller."""
    from ddwmmr.cli.scenarios import build_parser
    from ddwmmr.model import Robot

    parser = build_parser()
    (action,) = [a for a in parser._actions if "--payload" in a.option_strings]
    assert action.default == 3.0 and Robot().payload == 1.25
    assert "thesis: 1.25" not in action.help
    assert "the thesis's own experiments carried 1.25 kg, the Robot default" in action.help
