"""Tip-over read from the contact forces: support loads, centre of pressure, margins.

All geometry is in the *base frame* (origin at the axle midpoint, x along the heading, y to
the left; only the base's yaw is removed, so a tilted base is measured in its heading
frame on the floor). Forces are floor normal forces in N.

Definitions (docs/physics.md, "Tip-over from the contact forces"):

* **support polygon**: convex hull of the nominal support points (wheels and casters).
  With the default casters it is the footprint ``base_length x base_width``
  (docs/theory.md, "Tip-over stability").
* **centre of pressure** ``c``: the force-weighted mean of the contact points. At rest it
  is the projection of the centre of mass (the floor carries the weight); when the robot
  accelerates it moves with the inertial forces (the zero-moment point).
* **physics stability** ``S_phys``: for each polygon edge e with distance ``d_e(o)`` from
  the base centre o and ``d_e(c)`` from the centre of pressure, ``d_e(o) / (d_e(o) -
  d_e(c))`` is the factor by which the centre of pressure's offset from o (towards e) could
  grow before it reaches e; ``S_phys`` is the smallest over the edges, capped at
  :data:`~ddwmmr.model.stability.STABILITY_CAP`. For the rectangular footprint this is
  ``min((length/2)/|x_c|, (width/2)/|y_c|)``, the formula of S with the centre of pressure
  in place of the centre of mass: at rest ``S_phys = S``; ``S_phys = 1`` when all the load
  sits on one edge, i.e. the base pivots about it. 0 when nothing touches the floor.
* **edge load** of edge e: the total force on the supports *off* e. The base can only
  pivot about e when it is 0, so ``min_edge_load_n`` (the smallest over the edges) is the
  load that still holds the robot down on its weakest side. A single support can carry no
  load while the robot stands firmly (six supports on a plane are statically
  indeterminate: e.g. with the arm forward the base rests on wheels and front casters and
  the rear casters go light), so "a support lost its load" is read per edge.
"""

from __future__ import annotations

import numpy as np

from ddwmmr.model.stability import STABILITY_CAP
from ddwmmr.plants.mujoco.model import convex_hull

#: A support point lies on a polygon edge when closer to its line than this (m).
ON_EDGE_TOLERANCE = 1e-9


class SupportGeometry:
    """The support polygon and which supports lie on each of its edges.

    Args:
        points: nominal base-frame support points (n, 2) in m.
    """

    def __init__(self, points) -> None:
        self.points = np.asarray(points, dtype=float).reshape(-1, 2)
        self.hull = convex_hull(self.points)
        start, end = self.hull, np.roll(self.hull, -1, axis=0)
        edge = end - start
        length = np.hypot(edge[:, 0], edge[:, 1])
        #: inward unit normals (k, 2) and offsets: d_e(p) = normal . p - offset >= 0 inside
        self.normals = np.column_stack([-edge[:, 1], edge[:, 0]]) / length[:, None]
        self.offsets = np.sum(self.normals * start, axis=1)
        self.centre_distance = -self.offsets  # d_e at the base centre (0, 0)
        distances = self.distances(self.points)  # (n, k)
        #: off_edge[e, i]: support i is not on edge e (its load keeps e from pivoting)
        self.off_edge = (np.abs(distances) > ON_EDGE_TOLERANCE).T
        self._off_edge_lists = [np.flatnonzero(row).tolist() for row in self.off_edge]

    def distances(self, points) -> np.ndarray:
        """Signed distances (n, k) of points (n, 2) from each edge line (inside > 0), m."""
        return np.asarray(points, dtype=float) @ self.normals.T - self.offsets

    def edge_loads(self, forces: np.ndarray) -> np.ndarray:
        """Load (N) on the supports off each edge, for support forces (n,) in N."""
        return self.off_edge @ forces

    def min_edge_load(self, forces: list[float]) -> float:
        """The smallest of :meth:`edge_loads` (N), on plain lists: a handful of supports,
        read after every control step."""
        return min(sum(forces[i] for i in off) for off in self._off_edge_lists)

    def stability(self, centre_of_pressure) -> float:
        """``S_phys`` of a centre of pressure (base frame, m); see the module docstring."""
        d_cop = self.distances(np.asarray(centre_of_pressure, dtype=float)[None, :])[0]
        d_o = self.centre_distance
        room = d_o - d_cop  # how far the centre of pressure has moved towards each edge
        ratios = np.where(room * STABILITY_CAP > d_o, d_o / np.maximum(room, 1e-300), np.inf)
        return float(min(STABILITY_CAP, np.min(ratios)))


def footprint_excess(geometry: SupportGeometry, half_length: float, half_width: float) -> float:
    """The largest stability margin S at which the centre of mass reaches an edge of the
    support polygon: S measures the footprint ``2 half_length x 2 half_width`` (m, centred
    on the base centre), the base tips about the polygon's edges.

    It is the largest ratio of S to ``S_phys`` over all directions, reached towards a
    corner of the footprint: 1 when the polygon contains the footprint (S never overstates
    it; the default casters), above 1 when a corner lies outside (2 for a diamond through
    the footprint's edge midpoints).
    """
    corners = [(sx * half_length, sy * half_width) for sx in (1.0, -1.0) for sy in (1.0, -1.0)]
    return max(1.0, max(1.0 / geometry.stability(corner) for corner in corners))


def centre_of_pressure(points: np.ndarray, forces: np.ndarray) -> np.ndarray | None:
    """Force-weighted mean (2,) of contact points (n, 2); None if the total force is ~0."""
    total = float(np.sum(forces))
    if total <= 1e-9:
        return None
    return forces @ points / total
