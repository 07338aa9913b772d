"""End-effector tracking: feed-forward desired velocity plus pose-error feedback."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ddwmmr.errors import check_positive
from ddwmmr.gains import gains_from_tau
from ddwmmr.model.kinematics import wrap_angle
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.tasks.base import Task


def feedback_gains(tau: float | Sequence[float]) -> tuple[float, float, float]:
    """Gains ``K = 1/tau`` (1/s) for xE, yE, phiE from one time constant or three (s)."""
    kx, ky, kphi = gains_from_tau(tau, 3)
    return kx, ky, kphi


class EndEffectorTask(Task):
    """``d(xE, yE, phiE)/dt = Xd_dot + K (Xd - X)`` with heavily weighted slack.

    The feedback part of the position rows is clipped to ``max_speed`` (m/s) when given, so
    a far-away waypoint does not produce a huge demand; the feed-forward part is kept. With
    ``track_orientation=False`` the orientation row is dropped (its slack is pinned to 0).
    With a ``detour`` set, feedback that would lead through an obstacle is turned towards a
    tangent point instead.
    """

    rows = 3
    slack = True
    name = "tracking"

    def __init__(
        self,
        weight: float = 1e3,
        tau: float | Sequence[float] = 0.5,
        track_orientation: bool = True,
        max_speed: float | None = None,
    ) -> None:
        super().__init__(weight)
        self.kx, self.ky, self.kphi = feedback_gains(tau)
        self.track_orientation = bool(track_orientation)
        self.max_speed = None if max_speed is None else check_positive("max_speed", max_speed)
        #: Optional :class:`~ddwmmr.qp.tasks.avoidance.Detour`: bends the position
        #: feedback round obstacles (same magnitude, towards the detour's aim point).
        self.detour = None

    def compute(self, ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
        """Rows: the end-effector Jacobian; target: feed-forward + clipped feedback."""
        xe, ye, phie = ctx.pose_e
        xd, yd, phid = ctx.pose_d
        vx, vy, vphi = ctx.velocity_d
        fx, fy = self.kx * (xd - xe), self.ky * (yd - ye)
        if self.detour is not None:
            ax, ay = self.detour.aim(ctx.x, ctx.y, xd, yd)
            if (ax, ay) != (xd, yd):  # blocked: same speed, towards the aim point
                ux, uy = ax - xe, ay - ye
                scale = math.hypot(fx, fy) / max(math.hypot(ux, uy), 1e-9)
                fx, fy = ux * scale, uy * scale
        if self.max_speed is not None:
            norm = math.hypot(fx, fy)
            if norm > self.max_speed:
                fx, fy = fx * self.max_speed / norm, fy * self.max_speed / norm
        jac[:] = ctx.jac_e
        error[0], error[1] = vx + fx, vy + fy
        if self.track_orientation:
            # Wrapped: a pose 2 pi away is the same orientation.
            error[2] = vphi + self.kphi * wrap_angle(phid - phie)
        else:
            jac[2] = 0.0
            error[2] = 0.0
