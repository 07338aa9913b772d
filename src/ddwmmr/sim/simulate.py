"""The simulation loop: connects a controller to a plant along a desired trajectory."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ddwmmr.controllers.base import Controller, make_controller
from ddwmmr.errors import ParameterError, check_finite, check_positive
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import wrap_angle
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.resolution.reference import (
    DEFAULT_INITIAL_OFFSET,
    offset_configuration,
    start_configuration,
)
from ddwmmr.sim.result import SimulationResult
from ddwmmr.trajectories.base import trajectory_name

#: Column names of the recorded time series, in order.
COLUMNS = (
    "t",
    "x",
    "y",
    "phi",
    "th1",
    "th2",
    "v",
    "w",
    "th1dot",
    "th2dot",
    "xE",
    "yE",
    "phiE",
    "xE_d",
    "yE_d",
    "phiE_d",
    "position_error_m",
    "orientation_error_rad",
    "wheel_left_rad_s",
    "wheel_right_rad_s",
    "manipulability",
    "stability_lon",
    "stability_lat",
    "stability",
    "nonholonomic_residual_m_s",
    "singular",
    "saturated",
    "fallback",
    "step_us",
)


def simulate(
    robot: Robot | None,
    trajectory: Any,
    method: str | Controller,
    *,
    dt: float | None = None,
    duration: float | None = None,
    integrator: str = "rk4",
    initial_offset: tuple[float, float] = DEFAULT_INITIAL_OFFSET,
    q0: np.ndarray | None = None,
    progress: Callable[[int, int], None] | None = None,
    **controller_options: Any,
) -> SimulationResult:
    """Simulate ``method`` tracking ``trajectory`` on the kinematic plant.

    Args:
        robot: the robot (default ``Robot()``).
        trajectory: any object with ``duration``, ``pose(t)`` and ``velocity(t)``.
        method: a registered method name (see ``available_methods()``) or a controller.
        dt: control/integration step (s); default ``duration / samples`` of the trajectory
            (its resolution N), or duration / 1000.
        duration: simulated time (s); default one trajectory period.
        integrator: ``"rk4"`` (default) or ``"euler"``.
        initial_offset: end-effector offset (dx, dy) in m, applied with the arm joints to
            the start configuration, so closed-loop convergence shows. ``(0, 0)`` starts on
            the trajectory.
        q0: explicit start configuration (overrides the construction above).
        progress: optional callback ``progress(step, steps)``.
        **controller_options: passed to :func:`make_controller` when ``method`` is a name.

    Returns:
        A :class:`SimulationResult` with ``.timeseries`` and ``.summary``.
    """
    robot = robot if robot is not None else Robot()
    if isinstance(method, str):
        controller = make_controller(method, robot, **controller_options)
    elif controller_options:
        raise ParameterError("controller options are only accepted with a method name")
    else:
        controller = method
    duration = check_positive("duration", trajectory.duration if duration is None else duration)
    if dt is None:
        dt = trajectory.duration / getattr(trajectory, "samples", 1000)
    dt = check_positive("dt", dt)
    if dt > duration:
        raise ParameterError(f"dt must be <= duration ({duration:g} s) (got {dt:g})")
    steps = max(1, round(duration / dt))
    plant = KinematicPlant(robot, integrator)
    if q0 is None:
        offset = tuple(check_finite("initial_offset", v) for v in initial_offset)
        if len(offset) != 2:
            raise ParameterError(f"initial_offset must be two numbers dx, dy in m (got {offset})")
        q = offset_configuration(robot, start_configuration(robot, trajectory), offset)
    else:
        q = np.array(q0, dtype=float)
        if q.shape != (5,) or not np.all(np.isfinite(q)):
            raise ParameterError("q0 must be 5 finite numbers [x, y, phi, th1, th2]")
    controller.reset(trajectory, q.copy())

    rows = np.zeros((steps + 1, len(COLUMNS)))
    call_ns: list[int] = []  # duration of every controller call

    def policy(t: float, q_now: np.ndarray) -> np.ndarray:
        pose_d = trajectory.pose(t)
        velocity_d = trajectory.velocity(t)
        start = time.perf_counter_ns()
        u = controller.command(t, q_now, pose_d, velocity_d)
        call_ns.append(time.perf_counter_ns() - start)
        return u

    for k in range(steps + 1):
        t = k * dt
        first_call = len(call_ns)
        if k < steps:
            # The step's first controller call (at q, t) is the one recorded: rk4 calls the
            # controller again at its stages, and those leave controller.last behind.
            u, saturated = plant.saturate(q, policy(t, q))
            info = controller.last
            q_next = plant.step(t, q, dt, policy, first_command=u)[0]
        else:
            u, saturated = plant.saturate(q, policy(t, q))
            info = controller.last
        rows[k] = _record(robot, trajectory, t, q, u, info, saturated, call_ns[first_call])
        if k < steps:
            q = q_next
            if progress is not None:
                progress(k + 1, steps)
    timeseries = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    summary = summarize(timeseries, robot)
    summary.update(
        method=getattr(controller, "name", type(controller).__name__),
        trajectory=trajectory_name(trajectory),
        integrator=integrator,
        dt=dt,
        duration=steps * dt,
        steps=steps,
        initial_offset_m=float(timeseries["position_error_m"][0]),
    )
    if hasattr(controller, "summarize"):
        summary.update(controller.summarize(timeseries))
    return SimulationResult(timeseries, summary, robot, trajectory, controller)


def _record(robot, trajectory, t, q, u, info, saturated, step_ns) -> np.ndarray:
    pose = robot.fk(q)
    pose_d = trajectory.pose(t)
    wheels = robot.wheel_speeds_from_u(u[0], u[1])
    s_lon, s_lat, s = robot.stability(q)
    return np.concatenate(
        [
            [t],
            q,
            u,
            pose,
            pose_d,
            [
                math.hypot(pose_d[0] - pose[0], pose_d[1] - pose[1]),
                wrap_angle(pose_d[2] - pose[2]),
                wheels[0],
                wheels[1],
                robot.manipulability(q),
                s_lon,
                s_lat,
                s,
                info.nonholonomic_residual,
                float(info.singular),
                float(saturated),
                float(info.fallback),
                step_ns / 1000.0,
            ],
        ]
    )


def summarize(ts: dict[str, np.ndarray], robot: Robot) -> dict[str, Any]:
    """Scalar metrics of a recorded run (errors in m and rad, speeds in rad/s and m/s)."""
    position = ts["position_error_m"]
    orientation = ts["orientation_error_rad"]
    q = np.column_stack([ts[k] for k in ("x", "y", "phi", "th1", "th2")])
    return {
        "rms_position_error_m": float(np.sqrt(np.mean(position**2))),
        "max_position_error_m": float(np.max(position)),
        "final_position_error_m": float(position[-1]),
        "rms_orientation_error_rad": float(np.sqrt(np.mean(orientation**2))),
        "max_orientation_error_rad": float(np.max(np.abs(orientation))),
        "max_nonholonomic_residual_m_s": float(np.max(np.abs(ts["nonholonomic_residual_m_s"]))),
        "max_wheel_speed_rad_s": float(
            np.max(np.maximum(np.abs(ts["wheel_left_rad_s"]), np.abs(ts["wheel_right_rad_s"])))
        ),
        "min_manipulability": float(np.min(ts["manipulability"])),
        "mean_manipulability": float(np.mean(ts["manipulability"])),
        "min_stability": float(np.min(ts["stability"])),
        "singular_steps": int(np.sum(ts["singular"])),
        "saturated_steps": int(np.sum(ts["saturated"])),
        "fallback_steps": int(np.sum(ts["fallback"])),
        "max_condition_number": max_condition_number(robot, q),
        "median_step_us": float(np.median(ts["step_us"])),
    }


def max_condition_number(robot: Robot, q: np.ndarray) -> float:
    """Largest 2-norm condition number of the 4x5 Jacobian J(q) over the configurations."""
    phi, th1, th2 = q[:, 2], q[:, 3], q[:, 4]
    a1, a12 = phi + th1, phi + th1 + th2
    n = len(q)
    jac = np.zeros((n, 4, 5))
    dx = -robot.L1 * np.sin(a1) - robot.L2 * np.sin(a12)
    dy = robot.L1 * np.cos(a1) + robot.L2 * np.cos(a12)
    jac[:, 0, 0] = jac[:, 1, 1] = 1.0
    jac[:, 0, 2] = jac[:, 0, 3] = dx
    jac[:, 0, 4] = -robot.L2 * np.sin(a12)
    jac[:, 1, 2] = jac[:, 1, 3] = dy
    jac[:, 1, 4] = robot.L2 * np.cos(a12)
    jac[:, 2, 2:] = 1.0
    jac[:, 3, 0] = -np.sin(phi)
    jac[:, 3, 1] = np.cos(phi)
    sv = np.linalg.svd(jac, compute_uv=False)
    with np.errstate(divide="ignore"):
        return float(np.max(sv[:, 0] / sv[:, -1]))
