"""ddwmmr: redundancy resolution and control of differential-drive mobile manipulators.

Quick use::

    from ddwmmr import Robot, Ellipse, simulate
    result = simulate(Robot(), Ellipse(), "clrrmc-ts")
    print(result.summary["rms_position_error_m"])
"""

from ddwmmr._version import __version__
from ddwmmr.controllers import available_methods, make_controller, register
from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.sim import SimulationResult, simulate
from ddwmmr.trajectories import (
    Ellipse,
    Rectangle,
    SampledTrajectory,
    available_trajectories,
    load_trajectory,
)

__all__ = [
    "Ellipse",
    "ParameterError",
    "Rectangle",
    "Robot",
    "SampledTrajectory",
    "SimulationResult",
    "__version__",
    "available_methods",
    "available_trajectories",
    "load_trajectory",
    "make_controller",
    "register",
    "simulate",
]
