"""Plug-ins that misbehave fail in one line, whichever order and whichever part fails:
a built-in's name taken, a module that cannot be imported, a plug-in plant that raises or
blows up, a force controller declared by the decorator alone, a malformed ``law``."""

from __future__ import annotations

import importlib.util
import math
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, simulate
from ddwmmr.commands import FORCE, WheelForces
from ddwmmr.controllers import StepInfo
from ddwmmr.errors import PluginError
from ddwmmr.registry import CONTROLLERS, PLANTS, _import_plugin, _read_builtins
from ddwmmr.scenarios import RunConfig, generate, run_scenario

ROOT = Path(__file__).resolve().parents[1]


# -- registration and import ----------------------------------------------------------------
def test_a_plug_in_taking_a_built_in_name_before_the_first_listing_is_refused(monkeypatch):
    """The plug-in registered "ats" before the registry read the built-ins from source: it
    must not silently stand in for the built-in."""
    entries = {n: e for n, e in CONTROLLERS._entries.items() if n != "ats"}
    monkeypatch.setattr(CONTROLLERS, "_entries", entries)

    class MyAts:
        """My own ats."""

    CONTROLLERS.register("ats")(MyAts)
    with pytest.raises(ParameterError) as error:
        _read_builtins()
    assert str(error.value) == (
        f"method: 'ats' is registered twice ({__name__}.{MyAts.__qualname__} and "
        "ddwmmr.controllers.resolved_rate.AugmentedTaskSpaceController)"
    )


@pytest.mark.parametrize(
    ("source", "reason"),
    [
        ("def f(:\n    pass\n", "SyntaxError: invalid syntax (broken_plugin.py, line 1)"),
        ("raise RuntimeError('plugin config\\nmissing')\n", "RuntimeError: plugin config missing"),
        ("raise KeyError\n", "KeyError"),
    ],
)
def test_a_plug_in_module_that_fails_to_import_is_one_line(tmp_path, monkeypatch, source, reason):
    (tmp_path / "broken_plugin.py").write_text(source)
    monkeypatch.syspath_prepend(str(tmp_path))
    sys.modules.pop("broken_plugin", None)
    with pytest.raises(ParameterError) as error:
        _import_plugin("broken_plugin")
    assert str(error.value) == (
        f"DDWMMR_PLUGINS: cannot import plug-in module 'broken_plugin' ({reason})"
    )


def _tool(module: str, plugins: str, path: Path, *args: str) -> subprocess.CompletedProcess:
    env = {
        **os.environ,
        "DDWMMR_PLUGINS": plugins,
        "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(path)]),
        "MPLBACKEND": "Agg",
    }
    return subprocess.run(
        [sys.executable, "-m", module, *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=False,
        cwd=path,
    )


def test_the_tools_report_a_raising_plug_in_module_in_one_line_with_status_2(tmp_path):
    (tmp_path / "raising_plugin.py").write_text("raise RuntimeError('plugin config missing')\n")
    result = _tool("ddwmmr.track", "raising_plugin", tmp_path, "--help")
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.splitlines() == [
        "error: DDWMMR_PLUGINS: cannot import plug-in module 'raising_plugin' "
        "(RuntimeError: plugin config missing)"
    ]


# -- a plug-in plant ----------------------------------------------------------------------------
def _ideal_plant() -> type:
    """``IdealPlant`` of tests/plugins/ideal_plant.py, the one-file plant plug-in of
    docs/api.md ("Extending"), loaded under a name of its own and its "ideal" registration
    undone (a test of test_registry.py imports the module and registers it itself)."""
    spec = importlib.util.spec_from_file_location(
        "ideal_plant_for_test_plugins", ROOT / "tests" / "plugins" / "ideal_plant.py"
    )
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    finally:
        PLANTS.unregister("ideal")
    return module.IdealPlant


class EulerPlant(_ideal_plant()):
    """The ideal plug-in plant (kinematic Euler steps); ``misuse`` makes step ``fail_at``
    raise or leave a NaN."""

    name = "plug-euler"
    interfaces = ("velocity",)

    def __init__(self, robot, misuse="raise", fail_at=10):
        super().__init__(robot)
        self.misuse, self.fail_at, self.k = misuse, fail_at, 0

    def reset(self, q0, dt):
        super().reset(q0, dt)
        self.k = 0

    def step(self, t, command, dt, policy=None):
        self.k += 1
        if self.k == self.fail_at and self.misuse == "raise":
            raise OverflowError("math range\nerror")
        super().step(t, command, dt, policy)
        if self.k == self.fail_at and self.misuse == "nan":
            self.q[0] = math.nan


def test_a_raising_plug_in_plant_stops_a_tracking_run_with_a_plugin_error():
    robot = Robot()
    with pytest.raises(PluginError) as error:
        simulate(robot, Ellipse(), "ats", plant=EulerPlant(robot), duration=1.0)
    assert str(error.value) == (
        "plant: plug-euler.step() raised OverflowError: 'math range error' at step 9, "
        "t = 0.18 s"  # the default step of the kinematic plant's run: 0.02 s
    )
    assert isinstance(error.value.__cause__, OverflowError)


@pytest.fixture
def euler_plant_registered():
    """EulerPlant registered as "plug-euler" (failing as the test's RunConfig options say)."""
    PLANTS.register("plug-euler", interfaces=("velocity",))(EulerPlant)
    yield
    PLANTS.unregister("plug-euler")


@pytest.mark.parametrize(
    ("misuse", "reason"),
    [
        (
            "raise",
            "PluginError: plant: plug-euler.step() raised OverflowError: 'math range error' at "
            "step 9, t = 0.09 s",
        ),
        ("nan", "ParameterError: plant: plug-euler.observe() must return an Observation(q, v"),
    ],
)
def test_a_failing_plug_in_plant_fails_its_scenario_only(
    euler_plant_registered, monkeypatch, misuse, reason
):
    monkeypatch.setattr(EulerPlant.__init__, "__defaults__", (misuse, 10))
    config = RunConfig(controller="qp", plant="plug-euler", time_limit=2.0)
    outcome = run_scenario(generate(1, 0)[0], config)
    assert reason in outcome.metrics["reason"]
    assert not outcome.metrics["success"]
    # stopped after the sample of the step that failed (step 9 at dt = 0.01 s)
    assert outcome.metrics["sim_steps"] == 10
    assert math.isclose(outcome.metrics["time_s"], 0.10, abs_tol=1e-9)


# -- the force interface, declared by the decorator ----------------------------------------------
class PushBase:
    """Pushes both wheels with 1 N and holds the arm where it is."""

    def __init__(self, robot):
        self.robot, self.last = robot, StepInfo()

    def reset(self, trajectory, q0):
        self.th = (float(q0[3]), float(q0[4]))

    def command(self, t, q, pose_d, velocity_d):
        return WheelForces(1.0, 1.0, *self.th)


@pytest.fixture
def force_controllers():
    """PushBase registered by the trait alone, by the class attribute alone (legacy), and a
    velocity controller claiming the force interface."""
    trait = CONTROLLERS.register("plug-push", interfaces=("force",))(type("Trait", (PushBase,), {}))
    legacy = CONTROLLERS.register("plug-legacy")(type("Legacy", (PushBase,), {"interface": FORCE}))

    class Claims(PushBase):
        def command(self, t, q, pose_d, velocity_d):
            return np.zeros(4)

    CONTROLLERS.register("plug-claims", interfaces=("force",))(Claims)
    yield trait, legacy
    for name in ("plug-push", "plug-legacy", "plug-claims"):
        CONTROLLERS.unregister(name)


def test_a_force_controller_declared_by_the_decorator_alone_runs(force_controllers):
    robot = Robot()
    run = simulate(robot, Ellipse(), "plug-push", plant="thesis", duration=0.5)
    assert run.summary["command_interface"] == FORCE
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        legacy = simulate(robot, Ellipse(), "plug-legacy", plant="thesis", duration=0.5)
    # the class attribute still works (the same run), with a deprecation warning
    assert [w.category for w in caught] == [FutureWarning]
    assert "declares interfaces=('velocity',)" in str(caught[0].message)
    np.testing.assert_array_equal(run.timeseries["x"], legacy.timeseries["x"])
    # 2 N pushing the base forward from rest: it moves forward
    assert run.timeseries["v_measured"][-1] > 0.01
    assert run.timeseries["x"][-1] - run.timeseries["x"][0] > 1e-3


def test_a_controller_declaring_force_but_returning_velocities_is_refused(force_controllers):
    with pytest.raises(ParameterError) as error:
        simulate(Robot(), Ellipse(), "plug-claims", plant="thesis", duration=0.5)
    assert str(error.value) == (
        "method: plug-claims.command() must return a WheelForces(left, right, th1_target, "
        "th2_target) of 4 finite numbers (N, N, rad, rad) (got array([0., 0., 0., 0.]) at "
        "step 0, t = 0 s)"
    )


# -- the law() fast path --------------------------------------------------------------------
@pytest.mark.parametrize(
    ("returned", "shown"),
    [
        (lambda u: tuple(u), "(0.0, 0.0, 0.0, 0.0)"),
        (lambda u: ((1.0, 0.0), None), "((1.0, 0.0), None)"),
        (lambda u: None, "None"),
    ],
)
def test_a_malformed_law_return_is_one_line(returned, shown):
    class Lawful:
        """Stands still, through a law() that returns the wrong shape."""

        name = "lawful"

        def __init__(self):
            self.last = StepInfo()

        def reset(self, trajectory, q0):
            pass

        def command(self, t, q, pose_d, velocity_d):
            return np.zeros(4)

        def law(self, t, q, pose_d, velocity_d):
            return returned([0.0] * 4)

    with pytest.raises(ParameterError) as error:
        simulate(Robot(), Ellipse(), Lawful(), plant="kinematic", integrator="rk4", duration=0.1)
    assert str(error.value).startswith(
        f"method: lawful.law() must return (u, ...) with u 4 numbers (v, w, th1dot, th2dot) "
        f"(got {shown} at step 0, t = "
    )


def test_a_controller_speaking_two_interfaces_chooses_afresh_for_each_plant():
    """A controller object used on a velocity plant and then on a force plant speaks each
    plant's interface: the first choice is not stored on it."""
    from types import SimpleNamespace

    from ddwmmr.sim.loop import check_interface

    both = SimpleNamespace(interfaces=("velocity", "force"))
    velocity_plant = SimpleNamespace(name="v", interfaces=("velocity",))
    force_plant = SimpleNamespace(name="f", interfaces=("force",))
    assert check_interface(both, velocity_plant) == "velocity"
    assert check_interface(both, force_plant) == "force"
    assert not hasattr(both, "interface")
