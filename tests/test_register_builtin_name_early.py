"""A plug-in registered under a built-in's name before anything asked the registry (a
user's own ``pi``, first thing in a script): ``register`` took it, and the first query
after (``simulate``, ``available_methods``) raised "registered twice", as did every
query after that: the registry stayed unusable for the process. ``register`` now
refuses it, and the registry goes on working."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import ddwmmr

SCRIPT = """
from ddwmmr import available_methods, register
from ddwmmr.errors import ParameterError

class Mine:
    def __init__(self, robot, **options):
        self.robot = robot
    def reset(self, trajectory, q0):
        pass
    def command(self, t, q, pose_d, velocity_d):
        return [0.0, 0.0, 0.0, 0.0]

try:
    register("pi")(Mine)
    print("registered")
except ParameterError as error:
    print("refused:", error)
register("mine")(type("Other", (Mine,), {}))
print(available_methods())
"""


def test_a_builtins_name_is_refused_by_register_before_any_query():
    source = str(Path(ddwmmr.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": source, "DDWMMR_PLUGINS": ""}
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=120
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == (
        "refused: method: 'pi' is registered twice "
        "(ddwmmr.controllers.resolved_rate.PseudoinverseController and __main__.Mine)"
    )
    assert lines[1] == "['pi', 'ats', 'ap', 'clrrmc-ts', 'clrrmc-cs', 'qp', 'mpc', 'mine']"


def test_the_builtins_are_read_once_when_a_plugin_comes_before_the_first_query():
    """register read the built-ins' sources (for the refusal above), and the first query
    read them all again."""
    script = """
from ddwmmr import available_methods, register, registry

reads = []
real_read_source = registry._read_source
registry._read_source = lambda module: reads.append(module) or real_read_source(module)
register("mine")(type("Mine", (), {}))
methods = available_methods()
assert "pi" in methods and "mine" in methods, methods
print(len(reads), len(set(reads)), len(registry.BUILTIN_MODULES))
"""
    source = str(Path(ddwmmr.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": source, "DDWMMR_PLUGINS": ""}
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=120
    )
    assert done.returncode == 0, done.stderr
    reads, distinct, modules = map(int, done.stdout.split())
    assert reads == distinct == modules
