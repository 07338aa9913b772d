"""Method ``qp``: QP task priorities (SPEC §7).

Each control step solves one small quadratic programme over ``u = (v, w, th1dot,
th2dot)`` plus tracking slack: tip-over stability ``S >= stability_min`` and the robot's
limits are hard constraints, end-effector tracking is a heavily weighted slack task and
manipulability a soft reward (see :mod:`ddwmmr.qp` and docs/qp.md)::

    make_controller("qp", Robot().with_payload(3.0), stability_min=1.25,
                    obstacles=load_obstacles("trajectories/obstacles/ellipse_post.toml"))

``summarize`` adds to the run summary: ``stability_min`` (the floor), ``stability_violations``
(recorded steps with S < floor), ``qp_fallbacks`` (recorded steps that used the safe
command), ``min_obstacle_clearance_m`` (base footprint vs circles; None without obstacles),
``qp_mode`` and ``qp_solver``.

Its benchmark twin, :class:`ddwmmr.qp.naive.NaiveQPController`, is deliberately not a
registered method: it is a baseline for ``python -m ddwmmr.bench``, not a method to compare.
"""

from __future__ import annotations

from ddwmmr.controllers.base import register
from ddwmmr.qp.controller import QPControllerCore


@register("qp")
class QPController(QPControllerCore):
    """QP task priorities: hard stability/limits, tracking with slack, soft manipulability."""


__all__ = ["QPController"]
