"""Manipulability reward: raise ``eta = |sin th2|`` towards 1 (thesis 4.1.1).

With the end effector tracked, ``th2dot`` is fixed by the tracking rows: the arm is
mounted on the base's rotation centre, so the only free input direction is turning the
base while counter-rotating the shoulder (``w = -th1dot``). Manipulability then changes
through where the base drives: ``th2`` is set by the shoulder-to-end-effector distance
``rho`` (``rho^2 = L1^2 + L2^2 + 2 L1 L2 cos th2``). The task has two rows:

* **arm row** ``[0, 0, 0, d(eta^2)/d th2] u = gain (1 - eta^2)``: climb eta directly
  (acts when tracking leaves th2 free, e.g. position-only tracking). ``eta^2 = sin^2 th2``
  is used rather than eta: same maximisers, but a smooth gradient ``sin(2 th2)`` where
  eta's kink at th2 = 0 would make the row flip sign every step (chattering);
* **steering row** ``w = heading_gain * wrap_angle(psi* - phi)``: point the base along
  ``v_B* = Xd_dot + base_gain * grad_pB(eta^2) / 2``, the desired end-effector velocity
  plus the ascent direction of ``eta^2 = 1 - cos^2 th2`` with respect to the base
  position, ``grad_pB(eta^2) = 2 cos(th2) rho / (L1 L2) n`` (``n``: unit vector from the
  shoulder to the end effector). ``eta^2`` has the same maximiser as eta and, unlike eta,
  a bounded gradient at the stretched arm.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ddwmmr.errors import check_positive
from ddwmmr.gains import check_gain
from ddwmmr.model.kinematics import wrap_angle
from ddwmmr.qp.blocks import TaskBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.tasks.base import Task

#: Desired base speed (robot length units per second: m/s on the default robot,
#: :attr:`~ddwmmr.qp.tasks.base.Task.unit`) at which the steering row reaches full
#: weight; below it the row fades in proportion. Near the optimum th2 = pi/2 the ascent
#: direction flips as cos(th2) changes sign while its size goes to zero: a row switched
#: on at full strength there
#: alternated the base yaw every step (and, at dt = 0.02 s, kept the end effector ~1 cm
#: from its target).
FADE_SPEED = 0.05


def manipulability_gradient(th2: float) -> float:
    """``d eta / d th2`` of ``eta = |sin th2|`` (1/rad); at sin th2 = 0 the +th2 side."""
    s = math.sin(th2)
    return math.copysign(1.0, s) * math.cos(th2) if s else math.cos(th2)


def eta_squared_gradient(th2: float) -> float:
    """``d(eta^2)/d th2 = sin(2 th2)`` (1/rad), smooth everywhere."""
    return math.sin(2.0 * th2)


def base_gradient(L1: float, L2: float, ctx: StepContext) -> tuple[float, float]:
    """``grad_pB(eta^2)`` (1/m): gradient of eta^2 w.r.t. the base position (world frame)."""
    dx, dy = ctx.pose_e[0] - ctx.x, ctx.pose_e[1] - ctx.y
    rho = math.hypot(dx, dy)
    if rho == 0.0:
        return 0.0, 0.0
    factor = 2.0 * math.cos(ctx.th2) / (L1 * L2)  # 2 cos(th2) rho / (L1 L2) * (d / rho)
    return factor * dx, factor * dy


class ManipulabilityTask(Task):
    """Arm row and base-steering row (see module docstring); soft, low weight.

    ``arm_row=False`` zeroes the arm row's weight: with the orientation tracked, th2dot is
    fixed by tracking, so that row could only trade tracking accuracy for nothing.
    ``unit`` (m): the robot's length unit, in which the steering row measures the desired
    base velocity (its fade, :data:`FADE_SPEED`, and ``base_gain``, units^2/s); the rows
    themselves are on rates (rad/s).
    """

    rows = 2
    name = "manipulability"

    def __init__(
        self,
        weight: float = 1.0,
        gain: float = 2.0,
        base_gain: float = 0.02,
        heading_gain: float = 2.0,
        arm_row: bool = True,
        unit: float = 1.0,
    ) -> None:
        super().__init__(weight)
        self.unit: float = check_positive("unit", unit)
        self.arm_row = bool(arm_row)
        self.gain = check_gain("manipulability gain", gain)
        self.base_gain = check_gain("manipulability base_gain", base_gain)
        self.heading_gain = check_gain("manipulability heading_gain", heading_gain)

    def row_weights(self) -> np.ndarray:
        """``(weight, weight)``, or ``(0, weight)`` without the arm row."""
        return np.array([self.weight if self.arm_row else 0.0, self.weight])

    def values(self, ctx: StepContext) -> tuple[float, float, float, float]:
        """The varying entries ``(J[0, 3], e[0], J[1, 1], e[1])`` (unweighted)."""
        th2 = ctx.th2
        arm_slope = eta_squared_gradient(th2)
        arm_target = self.gain * math.cos(th2) ** 2  # 1 - eta^2
        unit = self.unit
        gx, gy = base_gradient(ctx.L1, ctx.L2, ctx)
        half_base_gain = 0.5 * self.base_gain
        vx = ctx.velocity_d[0] / unit + half_base_gain * (gx * unit)  # units per second
        vy = ctx.velocity_d[1] / unit + half_base_gain * (gy * unit)
        fade = math.hypot(vx, vy) / FADE_SPEED
        fade = fade if fade < 1.0 else 1.0  # min(1, fade), without a call
        if fade == 0.0:
            return arm_slope, arm_target, 0.0, 0.0
        return (
            arm_slope,
            arm_target,
            fade,
            fade * self.heading_gain * wrap_angle(math.atan2(vy, vx) - ctx.phi),
        )

    def compute(self, ctx: StepContext, jac: np.ndarray, error: np.ndarray) -> None:
        """Row 0 on th2dot, row 1 on w."""
        jac[:] = 0.0
        jac[0, 3], error[0], jac[1, 1], error[1] = self.values(ctx)

    def compile(self, block: TaskBlock) -> Callable[[StepContext], None] | None:
        """Writer for the two weighted rows from :meth:`values` (zeros elsewhere are
        constant)."""
        if overrides(self, ManipulabilityTask) or overrides(self, ManipulabilityTask, "values"):
            return None
        block.write_constant_rows([[0.0] * 4, [0.0] * 4])
        jac, (target,) = block.jac, block.target_views
        arm, steer = block.rows[0] + 3, block.rows[1] + 1
        t0, t1 = block.targets
        w0, w1 = block.scales
        values = self.values

        def write(ctx: StepContext) -> None:
            arm_slope, arm_target, fade, turn = values(ctx)
            jac[arm] = arm_slope * w0
            target[t0] = arm_target * w0
            jac[steer] = fade * w1
            target[t1] = turn * w1

        return write
