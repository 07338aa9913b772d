"""The simulation loop, the tracking task and their results."""

from ddwmmr.outputs import write_atomic
from ddwmmr.plants import available_plants
from ddwmmr.sim.loop import LoopEnd, Task, run_loop
from ddwmmr.sim.result import SimulationResult
from ddwmmr.sim.simulate import COLUMNS, simulate, summarize

__all__ = [
    "COLUMNS",
    "LoopEnd",
    "SimulationResult",
    "Task",
    "available_plants",
    "run_loop",
    "simulate",
    "summarize",
    "write_atomic",
]
