"""``--arbiter-option NAME=VALUE`` (``RunConfig.arbiter_options``): a plug-in arbiter's own
constructor options reach it from the scenarios tool, read as ``--option`` reads a
method's; anything no arbiter would read is one line; a batch without them is recorded
as before they existed."""

import pytest

from ddwmmr.arbiters import MOVE_BASE, make_arbiter
from ddwmmr.cli.scenarios import build_parser, config_from_arguments, config_record
from ddwmmr.errors import ParameterError
from ddwmmr.registry import ARBITERS
from ddwmmr.scenarios import RunConfig


class Patient:
    """An arbiter with options of its own: patience (s) and a mode."""

    def __init__(self, stability=None, manipulability=None, patience=1.0, eager=False):
        self.patience, self.eager, self.state = patience, eager, MOVE_BASE

    def reset(self):
        self.state = MOVE_BASE

    def select(self, p, behaviours):
        raise NotImplementedError


@pytest.fixture
def patient(registered):
    registered(ARBITERS, "patient", Patient)


def _config(*argv: str) -> RunConfig:
    return config_from_arguments(build_parser().parse_args(list(argv)))


def test_a_plug_in_arbiter_takes_its_options_from_the_command_line(patient):
    config = _config("--arbiter", "patient", "--arbiter-option", "patience=2.5",
                     "--arbiter-option", "eager=on")  # fmt: skip
    assert config.arbiter_options == (("patience", 2.5), ("eager", True))
    arbiter = make_arbiter(config)
    assert (arbiter.patience, arbiter.eager) == (2.5, True)
    assert config_record(config)["arbiter_options"] == (("patience", 2.5), ("eager", True))


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["--arbiter", "patient", "--arbiter-option", "patince=2"],
            "arbiter-option: the patient arbiter has no option 'patince' (did you mean "
            "patience?) (options: patience, eager)",
        ),
        (
            ["--arbiter", "patient", "--arbiter-option", "seed=2"],
            "arbiter-option: the patient arbiter has no option 'seed' (the run sets it) "
            "(options: patience, eager)",
        ),
        (
            ["--arbiter-option", "patience=2"],
            "arbiter-option: the state-machine arbiter has no option 'patience' (options: none)",
        ),
        (
            ["--arbiter", "patient", "--arbiter-option", "patience=soon"],
            "arbiter-option: patience must be a number (got 'soon')",
        ),
        (
            ["--controller", "qp", "--plant", "kinematic", "--arbiter-option", "patience=2"],
            "arbiter-option: only the thesis controller has an arbiter",
        ),
        (
            ["--study", "arbiters", "--arbiter-option", "patience=2"],
            "--arbiter-option: the arbiter study runs the built-in arbiters",
        ),
    ],
)
def test_an_arbiter_option_nothing_would_read_is_one_line(patient, argv, message):
    with pytest.raises(ParameterError) as error:
        _config(*argv)
    assert str(error.value) == message


def test_the_api_checks_them_alike_and_a_batch_without_them_records_none(patient):
    with pytest.raises(ParameterError, match=r"^arbiter_options: the patient arbiter has no "):
        RunConfig(arbiter="patient", arbiter_options=(("patince", 2.0),))
    with pytest.raises(ParameterError, match=r"^arbiter_options must be a tuple of \(name, "):
        RunConfig(arbiter="patient", arbiter_options={"patience": 2.0})
    assert RunConfig(arbiter="patient", arbiter_options=[("patience", 2.0)]).arbiter_options == (
        ("patience", 2.0),
    )
    assert "arbiter_options" not in config_record(_config())
    assert "arbiter_options" not in config_record(_config("--arbiter", "patient"))
