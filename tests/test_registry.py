"""The plug-in registries: built-ins found from source, one-file plug-ins of each kind run
through every path (docs/api.md, "Extending"), and found by every tool's --help."""

from __future__ import annotations

import importlib
import inspect
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, available_methods, make_controller, simulate
from ddwmmr.arbiters import available_arbiters, make_arbiter
from ddwmmr.controllers import available_controllers, method_description
from ddwmmr.plants import available_plants, make_plant
from ddwmmr.registry import ARBITERS, BUILTIN_MODULES, CONTROLLERS, PLANTS, _read_source
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.scenarios.protocol import plants_for, scenario_controllers

ROOT = Path(__file__).resolve().parents[1]
PLUGINS = Path(__file__).with_name("plugins")
#: The one-file plug-ins of docs/api.md, "Extending": module -> (registry, name).
PLUGIN_FILES = {
    "p_only": (CONTROLLERS, "p-only"),
    "ideal_plant": (PLANTS, "ideal"),
    "objective_only": (ARBITERS, "objective-only"),
}


@pytest.fixture
def plugins(monkeypatch):
    """Import the plug-ins of tests/plugins/ for this test only (unregistered after)."""
    monkeypatch.syspath_prepend(str(PLUGINS))
    modules = {name: importlib.import_module(name) for name in PLUGIN_FILES}
    yield modules
    for name, (registry, entry) in PLUGIN_FILES.items():
        registry.unregister(entry)
        sys.modules.pop(name, None)


def tool_help(module: str) -> str:
    """``python -m <module> --help`` with the plug-ins named in DDWMMR_PLUGINS."""
    env = {
        **os.environ,
        "DDWMMR_PLUGINS": ",".join(PLUGIN_FILES),
        "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(PLUGINS)]),
        "MPLBACKEND": "Agg",
    }
    result = subprocess.run(
        [sys.executable, "-m", module, "--help"],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    return " ".join(result.stdout.split())  # argparse wraps lines anywhere


# -- the built-ins --------------------------------------------------------------------------
def test_built_ins_in_listing_order():
    assert available_methods() == ["pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs", "qp", "mpc"]
    assert scenario_controllers() == ["thesis", "qp", "mpc"]
    assert available_plants() == ["kinematic", "thesis", "mujoco"]
    assert available_plants("force") == ["thesis", "mujoco"]
    assert available_arbiters() == ["state-machine", "competitive"]
    assert plants_for("thesis") == ["thesis", "mujoco"]
    assert plants_for("qp") == plants_for("mpc") == ["kinematic", "thesis", "mujoco"]
    assert "thesis" in available_controllers() and "thesis" not in available_methods()


@pytest.mark.parametrize("module", BUILTIN_MODULES)
def test_what_the_source_says_is_what_the_import_registers(module):
    """Names, descriptions and traits read from a module's source without importing it
    are those its decorators register when it is imported."""
    found = _read_source(module)
    assert found, f"{module} registers nothing"
    imported = importlib.import_module(module)
    for _, decorator, name, traits, qualname, doc in found:
        registry = {"register_controller": CONTROLLERS, "register_plant": PLANTS}.get(
            decorator, ARBITERS
        )
        cls = registry.load(name)
        assert cls is getattr(imported, qualname) and cls.name == name
        assert registry.describe(name) == inspect.cleandoc(cls.__doc__).splitlines()[0]
        assert registry.describe(name) == doc.splitlines()[0]
        assert registry.traits(name) == {**registry.defaults, **traits}
        if registry is PLANTS:
            assert cls.interfaces == traits["interfaces"]


def test_listing_imports_neither_mujoco_nor_casadi():
    code = (
        "import sys; import ddwmmr; "
        "from ddwmmr.plants import available_plants; "
        "from ddwmmr.scenarios.protocol import plants_for, scenario_controllers; "
        "from ddwmmr.arbiters import available_arbiters; "
        "names = available_plants(), ddwmmr.available_methods(), available_arbiters(), "
        "[plants_for(c) for c in scenario_controllers()]; "
        "print('mujoco' in sys.modules, 'casadi' in sys.modules)"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120
    )
    assert out.stdout.split() == ["False", "False"], out.stderr


def test_unknown_names_are_one_line_naming_the_known_ones():
    cases = [
        (lambda: make_controller("nope"), "method: unknown method 'nope' (known: thesis, pi,"),
        (lambda: make_plant("nope", Robot()), "plant must be one of kinematic, thesis, mujoco"),
        (
            lambda: make_arbiter(RunConfig(arbiter="nope")),
            "arbiter must be one of state-machine, competitive (got 'nope')",
        ),
        (lambda: RunConfig(controller="pi"), "controller must be one of thesis, qp, mpc"),
        (
            lambda: RunConfig(plant="kinematic"),
            "plant: the thesis controller outputs wheel forces and needs a plant that takes "
            "them (thesis or mujoco)",
        ),
        (lambda: simulate(Robot(), Ellipse(), "thesis"), "does not track trajectories"),
        # a tracking run names the methods it can take, not the thesis controller
        (
            lambda: simulate(Robot(), Ellipse(), "nope"),
            "method: unknown method 'nope' (tracking: pi, ats, ap, clrrmc-ts, clrrmc-cs, qp, mpc)",
        ),
    ]
    for call, message in cases:
        with pytest.raises(ParameterError) as error:
            call()
        assert message in str(error.value) and "\n" not in str(error.value)


def test_a_name_registered_twice_is_refused():
    class Other:
        """Another class."""

    with pytest.raises(ParameterError, match="'ats' is registered twice"):
        CONTROLLERS.register("ats")(Other)
    with pytest.raises(ParameterError, match="unknown keyword 'speed'"):
        CONTROLLERS.register("fast", speed=3)


# -- one file each ----------------------------------------------------------------------------
def test_the_documented_plug_ins_are_these_files():
    """docs/api.md, "Extending", shows tests/plugins/ as they are."""
    api = (ROOT / "docs" / "api.md").read_text()
    for module in PLUGIN_FILES:
        assert (PLUGINS / f"{module}.py").read_text() in api, module


def test_a_controller_in_one_file(plugins):
    assert "p-only" in available_methods() and "p-only" in scenario_controllers()
    assert method_description("p-only").startswith("Task-space P control without")
    ellipse, gain = Ellipse(), 4.0
    result = simulate(Robot(), ellipse, "p-only", gain=gain, duration=10.0)
    assert result.summary["method"] == "p-only"
    # Without feed-forward the error obeys e_dot = Xd_dot - K e: once the start offset has
    # decayed (time constant 1/K = 0.25 s) the end effector lags by |Xd_dot| / K.
    ts = result.timeseries
    settled = ts["t"] >= 3.0
    speed = np.array([np.hypot(*ellipse.velocity(t)[:2]) for t in ts["t"][settled]])
    assert ts["position_error_m"][settled] == pytest.approx(speed / gain, rel=0.02)


def test_a_plant_in_one_file(plugins):
    """The ideal plant integrates as the kinematic plant's Euler integrator does while no
    limit is hit (ats on the ellipse never reaches one)."""
    assert "ideal" in available_plants() and plants_for("qp")[-1] == "ideal"
    robot, ellipse = Robot(), Ellipse()
    ideal = simulate(robot, ellipse, "ats", plant="ideal", duration=10.0)
    euler = simulate(robot, ellipse, "ats", integrator="euler", duration=10.0)
    assert ideal.summary["plant"] == "ideal" and not np.any(euler.timeseries["saturated"])
    for column in ("x", "y", "phi", "th1", "th2"):
        assert ideal.timeseries[column] == pytest.approx(euler.timeseries[column], abs=1e-12)


def test_an_arbiter_in_one_file(plugins):
    """With a stability threshold the reach crosses (enter below S = 1.6; scenario 1 with 3
    kg dips to 1.46), the state machine goes into its stability state and holds S near the
    threshold; the objective-only arbiter never leaves the task."""
    arbiter = make_arbiter(RunConfig(arbiter="objective-only"))
    assert type(arbiter).__name__ == "ObjectiveOnly" and arbiter.name == "objective-only"
    scenario, strict = generate(1, 0)[0], {"stability": (1.6, 1.8), "time_limit": 20.0}
    alone = run_scenario(scenario, RunConfig(arbiter="objective-only", **strict)).metrics
    machine = run_scenario(scenario, RunConfig(**strict)).metrics
    assert machine["time_stability_s"] > 0.0 and machine["min_stability"] > 1.55
    assert alone["time_stability_s"] == alone["transitions_stability"] == 0
    assert alone["min_stability"] < 1.5


def test_the_plug_ins_together_in_the_scenario_protocol(plugins):
    outcome = run_scenario(
        generate(1, 0)[0], RunConfig(controller="p-only", plant="ideal", time_limit=2.0)
    )
    assert outcome.metrics["sim_steps"] == 200 and outcome.metrics["reason"] == "timeout"
    assert outcome.metrics["min_stability"] > 1.0
    with pytest.raises(ParameterError, match="only the thesis controller has an arbiter"):
        RunConfig(controller="p-only", plant="ideal", arbiter="competitive")
    with pytest.raises(ParameterError, match="outputs wheel forces and needs a plant that"):
        RunConfig(plant="ideal")  # the thesis controller: no force interface there


@pytest.mark.parametrize(
    ("tool", "shown"),
    [
        ("ddwmmr.track", ["{pi,ats,ap,clrrmc-ts,clrrmc-cs,qp,mpc,p-only}", "ideal:"]),
        ("ddwmmr.scenarios", ["{thesis,qp,mpc,p-only}", "p-only: Task-space P", "ideal"]),
        ("ddwmmr.scenarios", ["{state-machine,competitive,objective-only}"]),
        ("ddwmmr.bench", ["p-only"]),
        ("ddwmmr.gui", ["{pi,ats,ap,clrrmc-ts,clrrmc-cs,qp,mpc,p-only}", "ideal"]),
    ],
)
def test_every_tool_lists_the_plug_ins(tool, shown):
    text = tool_help(tool)
    for words in shown:
        assert words in text, (tool, words)


def test_a_plug_in_that_cannot_be_imported_is_one_line():
    env = {**os.environ, "DDWMMR_PLUGINS": "no_such_plugin", "PYTHONPATH": str(ROOT / "src")}
    result = subprocess.run(
        [sys.executable, "-m", "ddwmmr.track", "--help"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.splitlines() == [
        "error: DDWMMR_PLUGINS: cannot import plug-in module 'no_such_plugin' "
        "(No module named 'no_such_plugin')"
    ]


def test_an_arbiter_plug_in_without_the_thresholds_is_refused_in_one_line(registered):
    from types import SimpleNamespace

    from ddwmmr.arbiters.factory import make_arbiter

    class NoThresholds:
        def __init__(self):
            pass

        def reset(self):
            pass

        def select(self, p, behaviours):
            return None

    class Anything(NoThresholds):
        def __init__(self, **options):
            self.options = options

    registered(ARBITERS, "no-thresholds", NoThresholds)
    registered(ARBITERS, "anything", Anything)
    config = SimpleNamespace(stability=(1.5, 2.0), manipulability=(0.3, 0.5), arbiter_seed=0)
    with pytest.raises(ParameterError) as error:
        make_arbiter(SimpleNamespace(**vars(config), arbiter="no-thresholds"))
    assert str(error.value) == (
        "arbiter: no-thresholds: its constructor must take the keyword arguments stability "
        "and manipulability (ddwmmr.arbiters.Hysteresis thresholds; lacks stability)"
    )
    made = make_arbiter(SimpleNamespace(**vars(config), arbiter="anything"))
    assert set(made.options) == {"stability", "manipulability"}  # **options take them
