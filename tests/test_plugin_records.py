"""A run of a plug-in records the plug-in's module (``run.plugins``, and ``DDWMMR_PLUGINS``
in the command that repeats it), so that a rerun without it says how to load it, not only
"unknown method"; an unknown name anywhere says how plug-ins are loaded. A run of the
built-ins records what it recorded before (no ``plugins`` key)."""

from __future__ import annotations

import importlib
import json
import sys
from pathlib import Path

import pytest

from ddwmmr import make_controller
from ddwmmr.cli.compare import build_parser as compare_parser
from ddwmmr.cli.compare import config_from_arguments as compare_config
from ddwmmr.cli.scenarios import build_parser as scenarios_parser
from ddwmmr.cli.scenarios import config_from_arguments as scenarios_config
from ddwmmr.cli.track import main as track
from ddwmmr.errors import ParameterError
from ddwmmr.registry import ARBITERS, CONTROLLERS, PLANTS

PLUGINS = Path(__file__).with_name("plugins")
FILES = {"p_only": (CONTROLLERS, "p-only"), "ideal_plant": (PLANTS, "ideal")}
FILES["objective_only"] = (ARBITERS, "objective-only")
HINT = (
    "a plug-in's name is known once its module is imported: DDWMMR_PLUGINS=MODULE "
    '(docs/api.md, "Extending")'
)


def _unload() -> None:
    for module, (registry, name) in FILES.items():
        registry.unregister(name)
        sys.modules.pop(module, None)


@pytest.fixture
def plugins(monkeypatch):
    """tests/plugins/ imported for this test (unregistered after, or by ``unload``)."""
    monkeypatch.syspath_prepend(str(PLUGINS))
    for module in FILES:
        importlib.import_module(module)
    yield _unload
    _unload()


def _run(tmp_path: Path, *argv: str) -> dict:
    out = tmp_path / "out"
    base = ["--traj", "ellipse", "--duration", "0.2", "--no-plots", "--no-progress"]
    assert track([*argv, *base, "--out", str(out)]) == 0
    return json.loads((out / "summary.json").read_text())["run"]


def test_a_plug_in_run_records_its_modules_and_a_rerun_without_them_says_how(
    plugins, tmp_path, capsys
):
    record = _run(tmp_path, "--method", "p-only", "--plant", "ideal")
    assert record["plugins"] == {"method": {"p-only": "p_only"}, "plant": {"ideal": "ideal_plant"}}
    assert record["command"].startswith(
        "DDWMMR_PLUGINS=p_only,ideal_plant python -m ddwmmr.track --method p-only --plant ideal "
    )
    plugins()  # as a new process without DDWMMR_PLUGINS
    summary = tmp_path / "out" / "summary.json"
    capsys.readouterr()
    assert track(["--rerun", str(summary), "--out", str(tmp_path / "again")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"error: rerun: {summary}: method: 'p-only' is the plug-in of module 'p_only', which "
        "is not loaded: run with DDWMMR_PLUGINS=p_only,ideal_plant (importable from sys.path, "
        'e.g. with PYTHONPATH; docs/api.md, "Extending")'
    ]


def test_a_run_of_the_built_ins_records_no_plug_ins(plugins, tmp_path):
    record = _run(tmp_path, "--method", "pi")
    assert "plugins" not in record
    assert record["command"].startswith("python -m ddwmmr.track --method pi ")


def test_compare_and_scenarios_record_the_plug_ins_they_run(plugins):
    argv = ["--methods", "p-only,pi", "--only", "ellipse", "--study", "none"]
    config = compare_config(compare_parser().parse_args(argv), argv)
    assert config.command.startswith("DDWMMR_PLUGINS=p_only python -m ddwmmr.compare ")
    from ddwmmr.cli.compare import compared_plugins
    from ddwmmr.cli.scenarios import batch_plugins

    assert compared_plugins(config) == {"method": {"p-only": "p_only"}}
    argv = ["--controller", "p-only", "--plant", "ideal"]
    assert batch_plugins(scenarios_config(scenarios_parser().parse_args(argv))) == {
        "method": {"p-only": "p_only"},
        "plant": {"ideal": "ideal_plant"},
    }
    config = scenarios_config(scenarios_parser().parse_args(["--arbiter", "objective-only"]))
    assert batch_plugins(config) == {"arbiter": {"objective-only": "objective_only"}}


def test_an_unknown_name_says_how_plug_ins_are_loaded_unless_one_is_close(tmp_path, capsys):
    with pytest.raises(ParameterError) as error:
        make_controller("p-only")
    assert str(error.value).endswith(f"; {HINT}")
    with pytest.raises(ParameterError) as error:
        make_controller("qpp")
    assert str(error.value).endswith("(did you mean qp?)")
    for argv, ending in [
        (["--method", "p-only"], f"; {HINT}"),
        (["--method", "qp", "--plant", "ideal"], f"; {HINT}"),
        (["--method", "qpp"], " (did you mean qp?)"),
    ]:
        with pytest.raises(SystemExit) as stop:  # argparse's refusal of a choice
            track([*argv, "--traj", "ellipse", "--out", str(tmp_path / "x")])
        err = capsys.readouterr().err
        assert stop.value.code == 2
        assert err.endswith(ending + "\n") and err.count("\n") == 1, err
    with pytest.raises(SystemExit):  # a registered controller the scenarios do not run
        scenarios_parser().parse_args(["--controller", "pi"])
    err = capsys.readouterr().err
    assert "invalid choice: 'pi'" in err and "plug-in" not in err and "did you" not in err
    with pytest.raises(ParameterError) as error:
        compare_config(compare_parser().parse_args(["--methods", "p-only"]), [])
    assert str(error.value).endswith(f"; {HINT}")
