"""End-effector tracking: feed-forward desired velocity plus pose-error feedback."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from ddwmmr.errors import check_positive
from ddwmmr.gains import gains_from_tau
from ddwmmr.model.kinematics import wrap_angle
from ddwmmr.qp.blocks import TaskBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.tasks.avoidance import Detour
from ddwmmr.qp.tasks.base import Task, bounded, bounded_pair


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
    tangent point instead. ``demand_limit = (m/s, rad/s)`` bounds the whole target (norm of
    the position part, and the orientation part): the controller sets it far above what the
    robot can do (10x), so it only acts on absurd demands (a pose error of 1e12 m), whose
    magnitude would otherwise swamp the solver's tolerances.

    ``unit`` (m, :attr:`Task.unit`): the position rows are written divided by it, in units
    per second with ``v`` in units per second, so their slack, and ``weight``, are per
    unit per second: a robot scaled by s, given its unit, weighs its errors as the
    default robot does. :meth:`targets` stays in m/s.
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
        demand_limit: tuple[float, float] | None = None,
        unit: float = 1.0,
    ) -> None:
        super().__init__(weight)
        self.unit: float = check_positive("unit", unit)
        self.kx, self.ky, self.kphi = feedback_gains(tau)
        self.track_orientation = bool(track_orientation)
        self.max_speed = None if max_speed is None else check_positive("max_speed", max_speed)
        self.demand_limit = (
            None
            if demand_limit is None
            else tuple(check_positive("demand_limit", v) for v in demand_limit)
        )
        #: Optional :class:`~ddwmmr.qp.tasks.avoidance.Detour`: bends the position
        #: feedback round obstacles (same magnitude, towards the detour's aim point).
        self.detour: Detour | None = None

    def targets(self, ctx: StepContext) -> tuple[float, float, float]:
        """Target rates ``(xE_dot, yE_dot, phiE_dot)``: feed-forward + clipped feedback
        (m/s, m/s, rad/s); the last is 0 without orientation tracking."""
        xe, ye, phie = ctx.pose_e
        xd, yd, phid = ctx.pose_d
        vx, vy, vphi = ctx.velocity_d
        fx, fy = self.kx * (xd - xe), self.ky * (yd - ye)
        if self.detour is not None:
            ax, ay = self.detour.aim(ctx.x, ctx.y, xd, yd)
            if (ax, ay) != (xd, yd):  # blocked: same speed, towards the aim point
                ux, uy = ax - xe, ay - ye
                scale = math.hypot(fx, fy) / max(math.hypot(ux, uy), 1e-9 * self.unit)
                fx, fy = ux * scale, uy * scale
        if self.max_speed is not None:
            norm = math.hypot(fx, fy)
            if norm > self.max_speed:
                fx, fy = fx * self.max_speed / norm, fy * self.max_speed / norm
        e0, e1 = vx + fx, vy + fy
        # Wrapped: a pose 2 pi away is the same orientation.
        e2 = vphi + self.kphi * wrap_angle(phid - phie) if self.track_orientation else 0.0
        if self.demand_limit is not None:
            linear, angular = self.demand_limit
            e0, e1 = bounded_pair(e0, e1, linear)
            e2 = bounded(e2, angular)
        return e0, e1, e2

    def compute(self, ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
        """Rows: the end-effector Jacobian; target: feed-forward + clipped feedback; the
        position rows in ``unit`` (divided by it but for the ``v`` entry, which ``v /
        unit`` takes)."""
        unit = self.unit
        jac[:] = ctx.jac_e
        jac[:2, 1:] /= unit
        e0, e1, error[2] = self.targets(ctx)
        error[0], error[1] = e0 / unit, e1 / unit
        if not self.track_orientation:
            jac[2] = 0.0

    def compile(self, block: TaskBlock) -> Callable[[StepContext], None] | None:
        """Writer for the slack rows: the Jacobian's varying entries and the targets.

        ``track_orientation`` is read here (it fixes the phiE row); recompile after
        changing it (:meth:`QPProblem.refresh_weights`)."""
        if overrides(self, EndEffectorTask) or overrides(self, EndEffectorTask, "targets"):
            return None
        if not block.slack or any(scale != 1.0 for scale in block.scales):
            return None
        block.write_constant_rows([[0.0] * 4, [0.0] * 4, [0.0, 1.0, 1.0, 1.0]])
        if not self.track_orientation:
            block.write_constant_rows([[0.0] * 4, [0.0] * 4, [0.0] * 4])
        jac, (lower, upper) = block.jac, block.target_views
        r0, r1, _ = block.rows
        t0, t1, t2 = block.targets
        targets, unit = self.targets, self.unit

        def write(ctx: StepContext) -> None:
            dx_v, dx_w, dx_2, dy_v, dy_w, dy_2 = ctx.jac_e_rows
            dx_w, dx_2, dy_w, dy_2 = dx_w / unit, dx_2 / unit, dy_w / unit, dy_2 / unit
            jac[r0], jac[r0 + 1], jac[r0 + 2], jac[r0 + 3] = dx_v, dx_w, dx_w, dx_2
            jac[r1], jac[r1 + 1], jac[r1 + 2], jac[r1 + 3] = dy_v, dy_w, dy_w, dy_2
            e0, e1, e2 = targets(ctx)
            lower[t0] = upper[t0] = e0 / unit
            lower[t1] = upper[t1] = e1 / unit
            lower[t2] = upper[t2] = e2

        return write
