"""The simulation loop and its results."""

from ddwmmr.sim.result import SimulationResult, write_atomic
from ddwmmr.sim.simulate import COLUMNS, simulate, summarize

__all__ = ["COLUMNS", "SimulationResult", "simulate", "summarize", "write_atomic"]
