"""A plug-in arbiter's decisions and a plug-in controller's waypoint options are checked:
anything wrong is one line naming the plug-in, recorded per scenario (arbiter) or refused
(waypoint options), never a KeyError or AttributeError from deep inside the protocol."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ddwmmr.arbiters import (
    MOVE_BASE,
    STATES,
    CheckedArbiter,
    CompetitiveDynamicsArbiter,
    Hysteresis,
    Selection,
    StateMachineArbiter,
)
from ddwmmr.arbiters.competitive import Blend
from ddwmmr.arbiters.state_machine import THESIS_STABILITY
from ddwmmr.controllers import StepInfo
from ddwmmr.errors import ParameterError, PluginError
from ddwmmr.registry import CONTROLLERS
from ddwmmr.scenarios import RunConfig, generate, run_scenario

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = generate(1, 0)[0]
ALLOWED = "allowed: move_base, move_arm, manipulability, stability, obstacle"


class Delegating:
    """A plug-in arbiter: the state machine's decisions, optionally spoilt by ``spoil``."""

    def __init__(self, spoil=None, stability=THESIS_STABILITY) -> None:
        self.inner = StateMachineArbiter(stability)
        self.spoil = spoil
        self.calls = 0

    @property
    def state(self) -> str:
        return self.inner.state

    def reset(self) -> None:
        self.inner.reset()

    def select(self, p, behaviours):
        self.calls += 1
        selection = self.inner.select(p, behaviours)
        return selection if self.spoil is None else self.spoil(selection, behaviours, p)


def _reason(arbiter, time_limit: float = 1.0) -> str:
    outcome = run_scenario(SCENARIO, RunConfig(arbiter=arbiter, time_limit=time_limit))
    return outcome.metrics["reason"]


def test_an_unknown_state_ends_the_scenario_in_one_line_naming_the_arbiter():
    """Without the check the protocol's tally raised KeyError: 'dance' and ended the batch."""
    reason = _reason(Delegating(lambda s, b, p: Selection("dance", s.behaviour, s.proposal)))
    assert reason == (
        "controller error: PluginError: arbiter: Delegating.select() returned state 'dance' "
        f"at t = 0 s; {ALLOWED} (ddwmmr.arbiters.STATES)"
    )


def test_no_selection_or_an_unknown_behaviour_is_named():
    none = _reason(Delegating(lambda s, b, p: None))
    assert none == (
        "controller error: PluginError: arbiter: Delegating.select() returned None at t = 0 s; "
        "it must return a Selection(state, behaviour, proposal) (ddwmmr.arbiters.Selection)"
    )
    late = Delegating(lambda s, b, p: s if p.t < 0.25 else Selection(s.state, "nope", s.proposal))
    assert _reason(late) == (
        "controller error: PluginError: arbiter: Delegating.select() returned behaviour 'nope' "
        "at t = 0.25 s; allowed: objective, manipulability, stability (the behaviours it was given)"
    )
    assert late.calls == 26  # steps 0 .. 25 of 0.01 s: the run stopped at the bad one


def test_what_an_arbiter_raises_is_named():
    def boom(selection, behaviours, p):
        raise KeyError("nope")

    assert _reason(Delegating(boom)) == (
        "controller error: PluginError: arbiter: Delegating.select() raised KeyError: 'nope' "
        "at t = 0 s"
    )


def test_an_arbiter_without_a_state_is_refused_in_one_line():
    class Stateless:
        def reset(self):
            pass

        def select(self, p, behaviours):
            return None

    with pytest.raises(PluginError) as error:
        _reason(Stateless())
    assert str(error.value) == (
        "arbiter: Stateless has no attribute state (the state it is in, one of "
        "ddwmmr.arbiters.STATES; ddwmmr.arbiters.Arbiter)"
    )


def test_a_valid_plug_in_arbiter_runs_as_the_built_in_one():
    """The check changes nothing: the same decisions give the same numbers."""
    config = {"time_limit": 20.0, "stability": (1.6, 1.8)}
    arbiter = Delegating(stability=Hysteresis(1.6, 1.8))  # an instance keeps its thresholds
    wrapped = run_scenario(SCENARIO, RunConfig(arbiter=arbiter, **config)).metrics
    built_in = run_scenario(SCENARIO, RunConfig(**config)).metrics
    assert wrapped["time_stability_s"] > 0.5  # the fix state was entered and counted
    for key in ("time_s", "min_stability", "time_stability_s", "transitions_stability"):
        assert wrapped[key] == pytest.approx(built_in[key], abs=1e-12), key


def test_a_blending_plug_in_is_checked_and_keeps_its_weigh():
    class Blender(CompetitiveDynamicsArbiter):
        """Competitive dynamics reporting a state of its own."""

        name = "blender94"

    Blender.__module__ = "outside_plugin"  # a class from outside the library
    assert not callable(getattr(CheckedArbiter(Delegating(), "d"), "weigh", None))
    inner = Blender()
    checked = CheckedArbiter(inner, "blender94")
    assert callable(checked.weigh) and checked.dynamics is inner.dynamics

    original = CompetitiveDynamicsArbiter.weigh

    def weigh(self, p, behaviours):
        blend = original(self, p, behaviours)
        return Blend("dancing", blend.behaviour, blend.shares, blend.proposals)

    Blender.weigh = weigh
    assert _reason(Blender()) == (
        "controller error: PluginError: arbiter: blender94.weigh() returned state 'dancing' at "
        f"t = 0 s; {ALLOWED} (ddwmmr.arbiters.STATES)"
    )


def test_the_allowed_states_are_the_documented_ones():
    text = " ".join((ROOT / "docs" / "thesis.md").read_text(encoding="utf-8").split())
    assert ", ".join(f"`{s}`" for s in STATES) in text
    assert STATES[0] == MOVE_BASE and len(STATES) == 5


class _Still:
    """Commands nothing (a plug-in doing the waypoint task)."""

    def __init__(self, robot, gain: float = 1.0) -> None:
        self.robot, self.gain, self.last = robot, gain, StepInfo()

    def reset(self, trajectory, q0) -> None:
        pass

    def command(self, t, q, pose_d, velocity_d):
        return np.zeros(4)


def _register(registered, name: str, options) -> None:
    attributes = {} if options is None else {"waypoint_options": classmethod(options)}
    cls = type(name.replace("-", "_"), (_Still,), {"__doc__": "Still.", **attributes})
    cls.__module__ = "outside_plugin"
    registered(CONTROLLERS, name, cls, tasks=("tracking", "waypoints"))


def _run(name: str) -> None:
    run_scenario(SCENARIO, RunConfig(controller=name, plant="kinematic", time_limit=0.1))


def test_waypoint_options_missing_or_raising_is_one_line_naming_the_controller(registered):
    """Without the check: AttributeError (no waypoint_options) and the raw ValueError."""
    _register(registered, "plug-none", None)
    with pytest.raises(PluginError) as missing:
        _run("plug-none")
    assert str(missing.value) == (
        "controller plug-none: declares the waypoints task but has no waypoint_options(run) "
        "classmethod (ddwmmr.controllers.base.WaypointRun -> dict of options)"
    )

    def raising(cls, run):
        raise ValueError("no options\nfor you")

    _register(registered, "plug-raise", raising)
    with pytest.raises(PluginError) as raised:
        _run("plug-raise")
    assert str(raised.value) == (
        "controller plug-raise: waypoint_options(run) raised ValueError: no options for you"
    )
    assert isinstance(raised.value.__cause__, ValueError)

    _register(registered, "plug-list", lambda cls, run: [("gain", 2.0)])
    with pytest.raises(PluginError, match=r"plug-list: waypoint_options\(run\) must return a dict"):
        _run("plug-list")


def test_waypoint_options_bad_input_passes_and_good_options_are_used(registered):
    def bad_input(cls, run):
        raise ParameterError("gain must be > 0 (got -1)")

    _register(registered, "plug-bad", bad_input)
    with pytest.raises(ParameterError, match=r"^gain must be > 0 \(got -1\)$"):
        _run("plug-bad")
    _register(registered, "plug-ok", lambda cls, run: {"gain": 2.5})
    outcome = run_scenario(
        SCENARIO, RunConfig(controller="plug-ok", plant="kinematic", time_limit=0.1)
    )
    assert outcome.metrics["sim_steps"] == 10 and outcome.metrics["reason"] == "timeout"


def test_the_scenarios_tool_refuses_a_controller_without_waypoint_options(tmp_path):
    (tmp_path / "no_waypoint_options.py").write_text(
        "import numpy as np\n"
        "from ddwmmr.controllers import StepInfo, register_controller\n\n\n"
        '@register_controller("nowo94", tasks=("tracking", "waypoints"))\n'
        "class NoWaypointOptions:\n"
        '    """Says waypoints but has no waypoint_options."""\n\n'
        "    def __init__(self, robot):\n"
        "        self.robot, self.last = robot, StepInfo()\n\n"
        "    def reset(self, trajectory, q0):\n"
        "        pass\n\n"
        "    def command(self, t, q, pose_d, velocity_d):\n"
        "        return np.zeros(4)\n"
    )
    env = {
        **os.environ,
        "DDWMMR_PLUGINS": "no_waypoint_options",
        "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(tmp_path)]),
        "MPLBACKEND": "Agg",
    }
    command = [sys.executable, "-m", "ddwmmr.scenarios", "--controller", "nowo94"]
    command += ["--plant", "kinematic", "--n", "1", "--jobs", "1", "--time-limit", "0.1"]
    command += ["--out", str(tmp_path / "out")]
    result = subprocess.run(
        command, capture_output=True, text=True, env=env, timeout=300, check=False
    )
    assert result.returncode == 1, result.stderr
    assert result.stderr.splitlines() == [
        "error: controller nowo94: declares the waypoints task but has no waypoint_options(run) "
        "classmethod (ddwmmr.controllers.base.WaypointRun -> dict of options)"
    ]


def test_an_arbiter_that_is_no_arbiter_is_refused_by_name(monkeypatch):
    from ddwmmr import Robot
    from ddwmmr.errors import PluginError
    from ddwmmr.plants import make_plant
    from ddwmmr.scenarios import RunConfig, generate, protocol

    # a name where an Arbiter object belongs
    monkeypatch.setattr(protocol, "waypoint_options", lambda c, run: {"arbiter": "mine"})
    robot = Robot().with_payload(3.0)
    with pytest.raises(PluginError, match="arbiter 'mine', which has no select"):
        protocol.make_scenario_controller(
            robot, generate(1, 0)[0], RunConfig(), make_plant("thesis", robot)
        )
