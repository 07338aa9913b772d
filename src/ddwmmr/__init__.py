"""ddwmmr: redundancy resolution and control of differential-drive mobile manipulators.

Quick use::

    from ddwmmr import Robot, Ellipse, simulate
    result = simulate(Robot(), Ellipse(), "clrrmc-ts")
    print(result.summary["rms_position_error_m"])

The public names are imported on first use (PEP 562): ``import ddwmmr`` imports neither
numpy nor CasADi, so a command-line tool (``python -m ddwmmr.<tool>``) gets its Ctrl-C
guard in place before its heavy imports start (:mod:`ddwmmr.cli.signals`).
"""

import os
import sys


def _starting_tool() -> bool:
    """Whether this process is one of the command-line tools starting: its own command
    line (``sys.orig_argv``) is ``python -m ddwmmr.<tool>`` (Python is locating that module;
    ``sys.argv[0]`` is ``"-m"`` meanwhile) or a console script ``ddwmmr-<tool>``.

    A worker process a tool spawns (multiprocessing's spawn, Dask's workers) is given the
    tool's ``sys.argv`` but has a command line of its own: it is no tool, and must not
    say the tool's line when the tool stops it."""
    argv = getattr(sys, "argv", None) or [""]
    if len(argv) >= len(sys.orig_argv):
        return False
    word = sys.orig_argv[-len(argv)]  # the script, or -m's module, just before the arguments
    if argv[0] == "-m":
        name = word[word.index("m") + 1 :] if word.startswith("-") else word  # -mddwmmr.gui
    elif word == argv[0]:
        name = os.path.splitext(os.path.basename(word))[0]  # .../ddwmmr-track(.exe)
    else:
        return False
    if not name.startswith(("ddwmmr.", "ddwmmr-")):
        return False
    from ddwmmr.__main__ import TOOLS

    return any(name in (module, script) for module, script, _ in TOOLS)


# Before every import Python has not made at start-up already (typing, this package's
# own): a tool's Ctrl-C from here on is one line, not a traceback.
if _starting_tool():
    from ddwmmr.cli.signals import guard_start

    guard_start()

import importlib  # noqa: E402
from typing import TYPE_CHECKING, Any  # noqa: E402

from ddwmmr._version import __version__  # noqa: E402

if TYPE_CHECKING:  # what the names are, for type checkers and IDEs; imported on use
    from ddwmmr.controllers import available_methods, make_controller, register
    from ddwmmr.errors import ParameterError
    from ddwmmr.model import Robot
    from ddwmmr.sim.result import SimulationResult
    from ddwmmr.sim.simulate import simulate  # the function: ddwmmr.sim.simulate is a module
    from ddwmmr.trajectories import (
        Ellipse,
        Rectangle,
        SampledTrajectory,
        ScaledTrajectory,
        available_trajectories,
        load_trajectory,
    )

#: Each public name with the module it is imported from (the same as under TYPE_CHECKING).
_EXPORTS = {
    "available_methods": "ddwmmr.controllers",
    "make_controller": "ddwmmr.controllers",
    "register": "ddwmmr.controllers",
    "ParameterError": "ddwmmr.errors",
    "Robot": "ddwmmr.model",
    "SimulationResult": "ddwmmr.sim.result",
    "simulate": "ddwmmr.sim.simulate",
    "Ellipse": "ddwmmr.trajectories",
    "Rectangle": "ddwmmr.trajectories",
    "SampledTrajectory": "ddwmmr.trajectories",
    "ScaledTrajectory": "ddwmmr.trajectories",
    "available_trajectories": "ddwmmr.trajectories",
    "load_trajectory": "ddwmmr.trajectories",
}

__all__ = [
    "Ellipse",
    "ParameterError",
    "Rectangle",
    "Robot",
    "SampledTrajectory",
    "ScaledTrajectory",
    "SimulationResult",
    "__version__",
    "available_methods",
    "available_trajectories",
    "load_trajectory",
    "make_controller",
    "register",
    "simulate",
]


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use (then kept here)."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
