"""The ``mpc``'s safe command when a solve fails: the ``qp`` controller's, for that step.

The ``qp`` is built on the first failure of a run (with the run's control step) from the
``mpc``'s own options (floor, obstacles, orientation tracking; in waypoint mode a speed
limit of one of the robot's length units per second, 1 m/s for the default robot; with the
force model its velocity envelope), ``fallback_options`` merged over them. With the force
model its velocity command is turned into wheel forces by the model's velocity loop and its
joint rates clipped to the model's joint speed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc.options import MPCOptions
from ddwmmr.resolution.kernels import length_unit

if TYPE_CHECKING:
    from ddwmmr.qp.controller import QPController


def make_fallback(
    robot: Robot,
    options: MPCOptions,
    trajectory: Any,
    dt: float,
    dynamics: sym.ThesisDynamics | None,
) -> Any:
    """The ``qp`` controller standing in for the ``mpc`` of ``options`` on a run of
    ``trajectory`` (None: waypoint mode) at control step ``dt`` (s), reset for the run."""
    from ddwmmr.controllers.base import make_controller

    qp_options: dict[str, Any] = {
        "stability_min": options.stability_min,
        "track_orientation": options.track_orientation and trajectory is not None,
        "obstacles": list(options.obstacles),
        "dt": dt,
    }
    if trajectory is None:
        # 1 m/s on the default robot, as fast in the robot's own length unit on another
        qp_options["max_speed"] = 1.0 * length_unit(robot.L1)
    if dynamics is not None:
        qp_options.update(dynamics.velocity_envelope())
    qp_options.update(options.fallback_options or {})
    # "qp" is the built-in QPController (the registry refuses a second class under a
    # built-in's name), whose reset takes warn_start; Controller's reset does not have it
    qp = cast("QPController", make_controller("qp", robot, **qp_options))
    qp.reset(trajectory, np.zeros(5), warn_start=False)  # a placeholder, not a start
    return qp


def fallback_input(
    qp: Any,
    robot: Robot,
    dynamics: sym.ThesisDynamics | None,
    t: float,
    q: np.ndarray,
    pose_d: np.ndarray,
    velocity_d: np.ndarray,
    x0: np.ndarray,
) -> tuple[tuple[float, float, float, float], tuple[float, float]]:
    """``((first, second, r1, r2), velocity)``: the ``qp``'s command at time t (s) as the
    ``mpc`` sends it (``u``, or wheel forces N and joint rates rad/s with the force model)
    and the base velocity (m/s, rad/s) the force model predicts from (the measured one in
    ``x0``; zero without the force model)."""
    if dynamics is not None:
        qp.ctx.previous_command = (float(x0[5]), float(x0[6]))
    u = np.asarray(qp.command(t, q, pose_d, velocity_d), dtype=float)
    if not np.all(np.isfinite(u)):  # pragma: no cover - the qp has its own safe command
        u = np.zeros(4)
    if dynamics is None:
        return (float(u[0]), float(u[1]), float(u[2]), float(u[3])), (0.0, 0.0)
    v, w = float(x0[5]), float(x0[6])
    f_left, f_right = dynamics.velocity_tracking_forces(v, w, u[0], u[1], float(q[4]))
    limit = min(dynamics.joint_speed, robot.joint_speed_limit)
    r1 = min(limit, max(-limit, float(u[2])))
    r2 = min(limit, max(-limit, float(u[3])))
    return (float(f_left), float(f_right), r1, r2), (v, w)
