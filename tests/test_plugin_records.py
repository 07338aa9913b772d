"""A run of a plug-in records the plug-in's module (``run.plugins``, and ``DDWMMR_PLUGINS``
in the command that repeats it), so that a rerun without it says how to load it, not only
"unknown method"; an unknown name anywhere says how plug-ins are loaded. A run of the
built-ins records what it recorded before (no ``plugins`` key)."""

from __future__ import annotations

import importlib
import json
import sys
import types
from pathlib import Path

import pytest

from ddwmmr import make_controller
from ddwmmr.cli.compare import build_parser as compare_parser
from ddwmmr.cli.compare import config_from_arguments as compare_config
from ddwmmr.cli.scenarios import build_parser as scenarios_parser
from ddwmmr.cli.scenarios import config_from_arguments as scenarios_config
from ddwmmr.cli.track import main as track
from ddwmmr.errors import ParameterError
from ddwmmr.provenance import command_record
from ddwmmr.registry import (
    ARBITERS,
    CONTROLLERS,
    INTERACTIVE,
    PLANTS,
    SCRIPT_ADVICE,
    register_controller,
    used_plugins,
)

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


class _ScriptPlugin:
    """A controller a script registers in its own ``__main__``."""

    def __init__(self, robot, gain=2.0):
        self.inner = make_controller("pi", robot)
        self.last = self.inner.last

    def reset(self, trajectory, q0):
        self.inner.reset(trajectory, q0)

    def command(self, t, q, pose_d, velocity_d):
        u = self.inner.command(t, q, pose_d, velocity_d)
        self.last = self.inner.last
        return u


def _register_in_main(monkeypatch, script: str | None) -> None:
    """``script-p`` registered by ``__main__``, a script at ``script`` (None: no file, as
    ``python -c`` or a notebook), for this test."""
    main = types.ModuleType("__main__")
    if script is not None:
        main.__file__ = script
    monkeypatch.setitem(sys.modules, "__main__", main)
    cls = type("ScriptP", (_ScriptPlugin,), {"__module__": "__main__"})
    register_controller("script-p", tasks=("tracking",))(cls)


@pytest.fixture
def script_plugin(monkeypatch):
    yield lambda script: _register_in_main(monkeypatch, script)
    CONTROLLERS.unregister("script-p")


def test_a_script_s_own_plug_in_records_the_script_and_no_loadable_module(
    plugins, script_plugin, tmp_path, capsys
):
    script = str(tmp_path / "study.py")
    script_plugin(script)
    record = _run(tmp_path, "--method", "script-p", "--plant", "ideal")
    assert record["plugins"] == {"method": {"script-p": script}, "plant": {"ideal": "ideal_plant"}}
    # DDWMMR_PLUGINS names what it can load; the note says what else the command needs
    assert record["command"].startswith("DDWMMR_PLUGINS=ideal_plant python -m ddwmmr.track ")
    assert record["command_note"] == (
        f"needs method 'script-p' of the script {script}, which DDWMMR_PLUGINS cannot load: "
        f"{SCRIPT_ADVICE}"
    )
    assert list(record).index("command_note") == list(record).index("command") + 1
    summary = tmp_path / "out" / "summary.json"
    CONTROLLERS.unregister("script-p")  # a new process, DDWMMR_PLUGINS set as recorded
    capsys.readouterr()
    assert track(["--rerun", str(summary), "--out", str(tmp_path / "again")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"error: rerun: {summary}: method: 'script-p' is the plug-in of the script {script}, "
        f"which DDWMMR_PLUGINS cannot load: {SCRIPT_ADVICE}"
    ]
    script_plugin(script)  # the script again, rerunning its record: the run repeats
    again = tmp_path / "again"
    assert track(["--rerun", str(summary), "--out", str(again), "--no-progress"]) == 0
    assert json.loads((again / "summary.json").read_text())["run"]["plugins"] == record["plugins"]


def test_a_plug_in_of_a_main_without_a_file_is_recorded_as_interactive(script_plugin):
    script_plugin(None)
    plugins = used_plugins(method=["script-p"])
    assert plugins == {"method": {"script-p": INTERACTIVE}}
    record = command_record("python -m ddwmmr.track", ["--method", "script-p"], plugins)
    assert record["command"] == "python -m ddwmmr.track --method script-p"
    assert record["command_note"].startswith(
        "needs method 'script-p' of a script without a file (python -c, an interactive "
        "session or a notebook), which DDWMMR_PLUGINS cannot load: "
    )
    argv = ["--methods", "script-p,pi", "--only", "ellipse", "--study", "none"]
    config = compare_config(compare_parser().parse_args(argv), argv)
    assert config.command.startswith("python -m ddwmmr.compare --methods script-p,pi ")
    assert config.command_note == record["command_note"]


def test_the_simulator_and_bench_refuse_an_unknown_name_with_the_plug_in_hint(capsys):
    from ddwmmr.cli.bench import main as bench
    from ddwmmr.gui.settings import Settings, check_settings

    for settings, start in [
        (Settings(methods=("p-only", None)), "method: unknown method 'p-only' (tracking: pi, "),
        (Settings(methods=("pi", "p-only")), "method: unknown method 'p-only' (tracking: pi, "),
        (Settings(plant="ideal"), "plant must be one of kinematic, "),
    ]:
        with pytest.raises(ParameterError) as error:
            check_settings(settings)
        assert str(error.value).startswith(start) and str(error.value).endswith(f"; {HINT}")
    with pytest.raises(ParameterError, match=r"unknown method 'qpp' .*\(did you mean qp\?\)$"):
        check_settings(Settings(methods=("qpp", None)))
    with pytest.raises(ParameterError, match="the thesis controller does not track"):
        check_settings(Settings(methods=("thesis", None)))  # registered, not tracking
    assert bench(["--method", "p-only"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: method: unknown method 'p-only' (choose from ")
    assert err.endswith(f"; {HINT}\n") and err.count("\n") == 1


def test_a_close_name_is_suggested_only_among_the_names_the_check_takes():
    """The closest name an unknown one's error suggests is one the refusing check would
    take: a close name it refuses too (a controller the scenarios do not run, the
    kinematic plant compare always runs, a controller that does not track) is not
    offered, the plug-in hint is."""
    from ddwmmr.cli.compare import parse_plants
    from ddwmmr.scenarios.protocol import RunConfig
    from ddwmmr.sim.simulate import check_tracks

    for refused in [
        lambda: RunConfig(controller="clrrmc-t"),  # clrrmc-ts is no scenario controller
        lambda: parse_plants(["kinematc"]),  # --plant adds others than kinematic
        lambda: check_tracks("thesiss"),  # the thesis controller does not track
    ]:
        with pytest.raises(ParameterError) as error:
            refused()
        assert "did you mean" not in str(error.value)
        assert str(error.value).endswith(f"; {HINT}")
    with pytest.raises(ParameterError, match=r"\(did you mean qp\?\)$"):
        RunConfig(controller="qpp")
    with pytest.raises(ParameterError, match=r"\(did you mean mujoco\?\)$"):
        parse_plants(["mujoc"])
