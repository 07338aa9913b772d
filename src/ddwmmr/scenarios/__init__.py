"""Scenario benchmark of the thesis (ch. 5): generator, protocol, executors, reports."""

from ddwmmr.scenarios.generator import Scenario, generate, place_obstacles
from ddwmmr.scenarios.protocol import METRICS, Outcome, RunConfig, run_scenario

__all__ = [
    "METRICS",
    "Outcome",
    "RunConfig",
    "Scenario",
    "generate",
    "place_obstacles",
    "run_scenario",
]
