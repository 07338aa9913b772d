"""Seeded scenario generator (thesis 5.1; docs/thesis.md, "What is simulated").

A scenario is 5 waypoints drawn uniformly in the 8 m x 8 m square centred on the origin,
reached in order by the end effector, the base starting at the origin heading +x. The
draws come from ``numpy.random.default_rng(seed)`` in one block of shape (n, 5, 2), so
scenario i is the same whatever n (a prefix of the same stream) and whatever machine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ddwmmr.errors import (
    LENGTH_RANGE_M,
    MAX_OBSTACLES,
    MAX_SCENARIOS,
    check_int_at_least,
    check_nonnegative,
    check_range,
)

#: Workspace half-width (m): waypoints lie in [-4, 4] x [-4, 4].
HALF_SIZE = 4.0
WAYPOINTS_PER_SCENARIO = 5
#: Obstacle radius of the thesis's obstacle study (m).
OBSTACLE_RADIUS = 0.3


@dataclass(frozen=True)
class Scenario:
    """One task: waypoints (m, world) in order, optional circular obstacles (x, y, r) in m.

    ``index`` is 0-based; reports number scenarios from 1 as the thesis does.
    """

    index: int
    waypoints: tuple[tuple[float, float], ...]
    obstacles: tuple[tuple[float, float, float], ...] = field(default=())

    def path_length(self, start: tuple[float, float] = (0.0, 0.0)) -> float:
        """Straight-line length start -> waypoint 1 -> ... -> waypoint 5 (m)."""
        total, (px, py) = 0.0, start
        for wx, wy in self.waypoints:
            total += math.hypot(wx - px, wy - py)
            px, py = wx, wy
        return total


def generate(n: int, seed: int = 0) -> list[Scenario]:
    """``n`` scenarios of 5 waypoints uniform in the 8 m x 8 m square (seeded).

    ``n``: an integer in [1, :data:`ddwmmr.errors.MAX_SCENARIOS`] (the scenarios tool's
    cap); ``seed``: an integer >= 0. Anything else raises a one-line
    :class:`~ddwmmr.errors.ParameterError`.
    """
    n = check_int_at_least("n", n, 1, MAX_SCENARIOS)
    seed = check_int_at_least("seed", seed, 0)
    rng = np.random.default_rng(seed)
    points = rng.uniform(-HALF_SIZE, HALF_SIZE, size=(n, WAYPOINTS_PER_SCENARIO, 2))
    return [
        Scenario(i, tuple((float(x), float(y)) for x, y in points[i].tolist())) for i in range(n)
    ]


def place_obstacles(
    scenario: Scenario,
    count: int = 2,
    radius: float = OBSTACLE_RADIUS,
    keep_out: float = 1.0,
    separation: float = 2.0,
) -> Scenario:
    """The scenario with ``count`` obstacles placed on its legs (thesis 5.5, Fig 5.27).

    The thesis placed two obstacles by hand "in the expected path"; here they go on the
    longest legs (start -> waypoints), at the midpoint or else 40/60/30/70/20/80 % along the
    leg, skipping points within ``keep_out`` m of the start or a waypoint (so every
    waypoint stays reachable without touching an obstacle) or within ``separation`` m of an
    earlier obstacle (so the base, 0.57 m across, can pass between two). At most one
    obstacle per leg, so fewer than ``count`` where the legs run out.

    ``count``: an integer in [0, :data:`ddwmmr.errors.MAX_OBSTACLES`] (the cap of a run's
    obstacles; 0: none); ``radius``: in :data:`ddwmmr.errors.LENGTH_RANGE_M` (m);
    ``keep_out`` and ``separation``: finite, >= 0 (m). Anything else raises a one-line
    :class:`~ddwmmr.errors.ParameterError` naming the parameter.
    """
    count = check_int_at_least("count", count, 0, MAX_OBSTACLES)
    radius = check_range("radius", radius, *LENGTH_RANGE_M, "m")
    keep_out = check_nonnegative("keep_out", keep_out)
    separation = check_nonnegative("separation", separation)
    points = [(0.0, 0.0), *scenario.waypoints]
    legs = sorted(
        range(len(points) - 1),
        key=lambda i: -math.dist(points[i], points[i + 1]),
    )
    obstacles: list[tuple[float, float, float]] = []
    for i in legs:
        if len(obstacles) == count:
            break
        (ax, ay), (bx, by) = points[i], points[i + 1]
        for f in (0.5, 0.4, 0.6, 0.3, 0.7, 0.2, 0.8):
            spot = (ax + f * (bx - ax), ay + f * (by - ay))
            near = any(math.dist(p, spot) < keep_out for p in points) or any(
                math.dist(o[:2], spot) < separation for o in obstacles
            )
            if not near:
                obstacles.append((spot[0], spot[1], radius))
                break
    return Scenario(scenario.index, scenario.waypoints, tuple(obstacles))
