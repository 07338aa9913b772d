"""Prediction models of the MPC: what it integrates over the horizon and what it may command.

Two models, one interface (:class:`PredictionModel`):

* :class:`KinematicPrediction` (``model="kinematic"``): state ``q`` (5), inputs
  ``u = (v, w, th1dot, th2dot)``; the velocity command is applied as it is (the kinematic
  plant). Bounds: wheel speeds (rows), joint speeds (box).
* :class:`ThesisPrediction` (``model="thesis"``): state ``[q, v, w]`` (7), inputs the wheel
  forces and the joint rates ``(F_left, F_right, th1dot, th2dot)`` (N, N, rad/s, rad/s);
  the thesis plant's force-level dynamics (:class:`ddwmmr.model.symbolic.ThesisDynamics`).
  Bounds: the force limit per wheel, joint speeds (box), wheel speeds of the predicted
  base velocity (rows).

Joint-position limits are state bounds in both.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any

import numpy as np

from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym

INF = math.inf


class PredictionModel(ABC):
    """Interface: sizes, the symbolic right-hand side, bounds, rows, scaling.

    Attributes:
        name: ``"kinematic"`` or ``"thesis"``.
        nx, nu: state and input sizes.
        interface: command interface of the controller using it (``"velocity"``/``"force"``).
        u_lower, u_upper: input box (nu,); x_lower, x_upper: state box (nx,).
        u_scale: typical input magnitudes (nu,) used to normalise the input cost.
    """

    name = "model"
    nx = 0
    nu = 0
    interface = "velocity"

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        lo1, hi1 = robot.joint_limits[0]
        lo2, hi2 = robot.joint_limits[1]
        x_lower = np.full(self.nx, -INF)
        x_upper = np.full(self.nx, INF)
        x_lower[3:5], x_upper[3:5] = (lo1, lo2), (hi1, hi2)
        self.x_lower, self.x_upper = x_lower, x_upper
        self.wheel_limit = robot.wheel_speed_limit * (1.0 - 1e-6)

    @abstractmethod
    def rhs(self, x: Any, u: Any) -> Any:
        """State rate (symbolic)."""

    @abstractmethod
    def wheel_rows(self, x: Any, u: Any | None) -> Any | None:
        """Wheel speeds (rad/s) implied at a node, or None when they are not decided there."""

    def configuration(self, x: Any) -> Any:
        """The configuration part ``q`` of a state."""
        return x[:5]


class KinematicPrediction(PredictionModel):
    """``qdot = G(q) u``: the velocity command integrates into the configuration."""

    name = "kinematic"
    nx = sym.NQ
    nu = sym.NU
    interface = "velocity"

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        r, lw, limit = robot.wheel_radius, robot.track_width, robot.wheel_speed_limit
        v_max, w_max = r * limit, 2.0 * r * limit / lw
        rate = robot.joint_speed_limit * (1.0 - 1e-6)
        self.u_lower = np.array([-v_max, -w_max, -rate, -rate])
        self.u_upper = -self.u_lower
        self.u_scale = np.array([1.0, 1.0, robot.joint_speed_limit, robot.joint_speed_limit])

    def rhs(self, x: Any, u: Any) -> Any:
        return sym.kinematic_rhs(x, u)

    def wheel_rows(self, x: Any, u: Any | None) -> Any | None:
        """Wheel speeds of the command ``u`` (none at the last node)."""
        return None if u is None else sym.wheel_speeds(self.robot, u[0], u[1])


class ThesisPrediction(PredictionModel):
    """The thesis plant: wheel forces drive a damped base, the arm follows joint rates."""

    name = "thesis"
    nx = sym.NX_FORCE
    nu = sym.NU_FORCE
    interface = "force"

    def __init__(self, robot: Robot, dynamics: sym.ThesisDynamics) -> None:
        super().__init__(robot)
        self.dynamics = dynamics
        force = dynamics.force_limit
        rate = min(dynamics.joint_speed, robot.joint_speed_limit) * (1.0 - 1e-6)
        self.u_lower = np.array([-force, -force, -rate, -rate])
        self.u_upper = -self.u_lower
        self.u_scale = np.array([force, force, rate, rate])

    def rhs(self, x: Any, u: Any) -> Any:
        return self.dynamics.rhs(x, u)

    def wheel_rows(self, x: Any, u: Any | None) -> Any | None:
        """Wheel speeds of the predicted base velocity (the forces do not enter)."""
        return sym.wheel_speeds(self.robot, x[5], x[6])


def make_model(name: str, robot: Robot, dynamics: sym.ThesisDynamics | None) -> PredictionModel:
    """The prediction model called ``name`` (validated by the controller)."""
    if name == "thesis":
        assert dynamics is not None
        return ThesisPrediction(robot, dynamics)
    return KinematicPrediction(robot)
