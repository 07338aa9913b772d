"""Tip-over read from the contact forces: support loads, centre of pressure, margins.

All geometry is in the *base frame* (origin at the axle midpoint, x along the heading, y to
the left; only the base's yaw is removed, so a tilted base is measured in its heading
frame on the floor). Forces are floor normal forces in N.

Definitions (docs/physics.md, "Tip-over from the contact forces"):

* **support polygon**: convex hull of the nominal support points (wheels and casters),
  :class:`~ddwmmr.model.support_loads.SupportPolygon`. With the default casters it is the
  footprint ``base_length x base_width`` (docs/theory.md, "Tip-over stability").
* **centre of pressure** ``c``: the force-weighted mean of the contact points. At rest it
  is the projection of the centre of mass (the floor carries the weight); when the robot
  accelerates it moves with the inertial forces (the zero-moment point).
* **physics stability** ``S_phys``: the stability margin S of the model
  (:func:`ddwmmr.model.stability.support_margins`) with the centre of pressure in place of
  the centre of mass: for each polygon edge e with outward normal ``n_e`` and distance
  ``d_e`` from the base centre, ``d_e / (n_e . c)`` is the factor by which the centre of
  pressure's offset from the base centre could grow before it reaches e; ``S_phys`` is the
  smallest over the edges, capped at :data:`~ddwmmr.model.stability.STABILITY_CAP`. At
  rest ``S_phys = S``; ``S_phys = 1`` when all the load sits on one edge, i.e. the base
  pivots about it. 0 when nothing touches the floor.
* **edge load** of edge e: the total force on the supports *off* e. The base can only
  pivot about e when it is 0, so ``min_edge_load_n`` (the smallest over the edges) is the
  load that still holds the robot down on its weakest side. A single support can carry no
  load while the robot stands firmly (six supports on a plane are statically
  indeterminate: e.g. with the arm forward the base rests on wheels and front casters and
  the rear casters go light), so "a support lost its load" is read per edge.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ddwmmr.model.stability import SupportEdges, support_margins
from ddwmmr.model.support_loads import SupportPolygon

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt


class SupportGeometry:
    """The support polygon and which supports lie on each of its edges.

    Args:
        points: nominal base-frame support points (n, 2) in m, spanning a polygon that
            holds the base centre strictly inside (the robots the plant builds).

    Attributes:
        points: the support points (n, 2); polygon: their
            :class:`~ddwmmr.model.support_loads.SupportPolygon`; edges: its
            :class:`~ddwmmr.model.stability.SupportEdges`, on which S is measured;
            off_edge: (k, n) booleans, support i is not on edge e (its load keeps e from
            pivoting).
    """

    def __init__(self, points: npt.ArrayLike) -> None:
        self.points = np.asarray(points, dtype=float).reshape(-1, 2)
        self.polygon = SupportPolygon.from_points(self.points)
        polygon = self.polygon
        self.edges = SupportEdges.from_lines(polygon.normals, polygon.offsets, polygon.vertices)
        self.off_edge = polygon.off_edge(self.points)
        self._off_edge_lists = [np.flatnonzero(row).tolist() for row in self.off_edge]

    def distances(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Signed distances (n, k) of points (n, 2) from each edge line (inside > 0), m."""
        return self.polygon.distances(points)

    def edge_loads(self, forces: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """Load (N) on the supports off each edge, for support forces (n,) in N."""
        return self.off_edge @ forces

    def min_edge_load(self, forces: list[float]) -> float:
        """The smallest of :meth:`edge_loads` (N), on plain lists: a handful of supports,
        read after every control step."""
        return min(sum(forces[i] for i in off) for off in self._off_edge_lists)

    def stability(self, centre_of_pressure: Sequence[float] | npt.NDArray[np.float64]) -> float:
        """``S_phys`` of a centre of pressure (base frame, m); see the module docstring."""
        return support_margins(
            self.edges, float(centre_of_pressure[0]), float(centre_of_pressure[1])
        )[2]


def centre_of_pressure(
    points: npt.NDArray[np.float64], forces: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64] | None:
    """Force-weighted mean (2,) of contact points (n, 2); None if the total force is ~0."""
    total = float(np.sum(forces))
    if total <= 1e-9:
        return None
    return forces @ points / total
