"""Base motion envelope: speed caps and slew (acceleration) limits on ``v`` and ``w``.

A force-limited base cannot reach any ``(v, w)`` within one step: its velocity changes at
most ``a_max dt`` per step and settles at a top speed set by force limit and damping. A
QP that ignores this asks for commands the plant cannot follow and, from one step to the
next, can alternate between far-apart commands that the plant averages to nothing. This
limit keeps each command within the plant's envelope around the previous command:

    max(-v_max, v_prev - a dt) <= v <= min(v_max, v_prev + a dt)
    max(-w_max, w_prev - alpha dt) <= w <= min(w_max, w_prev + alpha dt)

``v_prev, w_prev`` is the controller's previous command (``StepContext.previous_command``);
the slew part is skipped on the first step after a reset.

The caps are a box, but a damped base with a force limit per wheel cannot hold its top
speed and its top yaw rate at once: in steady state the left and right wheel forces are
``(c1 v -+ c2 w / (width/2)) / 2``, so both stay within the limit exactly when

    |v| / v_top + |w| / w_top <= 1,    v_top = 2 F / c1,  w_top = 2 F (width/2) / c2

(:class:`SpeedBudgetLimit`, two constant rows). Whether a command at a corner of the box
does harm depends on the plant's velocity servo: wheel-speed servos that saturate each
wheel on its own (the MuJoCo plant) lose the yaw there and the base drives in wide loops,
a servo that gives rotation priority (the thesis plant) turns and gives up speed.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from ddwmmr.errors import ParameterError, check_positive, length_of, shown
from ddwmmr.qp.blocks import CONSTANT, LimitBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import Limit

if TYPE_CHECKING:
    import numpy as np


class BaseMotionLimit(Limit):
    """Box bounds on v (m/s) and w (rad/s): caps and per-step slew around the last command.

    Args:
        max_speed: |v| cap (m/s); max_yaw_rate: |w| cap (rad/s).
        max_acceleration: |dv/dt| (m/s^2); max_yaw_acceleration: |dw/dt| (rad/s^2);
            None leaves that slew unbounded.
        unit: the length unit (m) of the box on ``v`` (:attr:`Limit.unit`): it bounds
            ``v / unit``; :meth:`envelope` stays in m/s.
    """

    rows = 0
    name = "base motion"

    def __init__(
        self,
        max_speed: float,
        max_yaw_rate: float,
        max_acceleration: float | None = None,
        max_yaw_acceleration: float | None = None,
        unit: float = 1.0,
    ) -> None:
        self.unit: float = check_positive("unit", unit)
        self.max_speed = check_positive("max_base_speed", max_speed)
        self.max_yaw_rate = check_positive("max_yaw_rate", max_yaw_rate)
        self.max_acceleration = (
            None
            if max_acceleration is None
            else check_positive("max_acceleration", max_acceleration)
        )
        self.max_yaw_acceleration = (
            None
            if max_yaw_acceleration is None
            else check_positive("max_yaw_acceleration", max_yaw_acceleration)
        )

    def envelope(self, ctx: StepContext) -> tuple[float, float, float, float]:
        """``(v_low, v_high, w_low, w_high)`` allowed this step (m/s, rad/s)."""
        low_v, high_v = -self.max_speed, self.max_speed
        low_w, high_w = -self.max_yaw_rate, self.max_yaw_rate
        previous = ctx.previous_command
        if previous is not None:
            v_prev, w_prev = previous
            if self.max_acceleration is not None:
                step = self.max_acceleration * ctx.dt
                low_v, high_v = max(low_v, v_prev - step), min(high_v, v_prev + step)
            if self.max_yaw_acceleration is not None:
                step = self.max_yaw_acceleration * ctx.dt
                low_w, high_w = max(low_w, w_prev - step), min(high_w, w_prev + step)
        # A previous command beyond a cap (e.g. a cap lowered mid-run) must not empty the box.
        return min(low_v, high_v), max(low_v, high_v), min(low_w, high_w), max(low_w, high_w)

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Tighten the (v, w) box; no general rows."""
        low_v, high_v, low_w, high_w = self.envelope(ctx)
        unit = self.unit
        lb[0], ub[0] = max(lb[0], low_v / unit), min(ub[0], high_v / unit)
        lb[1], ub[1] = max(lb[1], low_w), min(ub[1], high_w)

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Writer tightening the Python box (no rows)."""
        if overrides(self, BaseMotionLimit) or overrides(self, BaseMotionLimit, "envelope"):
            return None
        box, envelope, unit = block.box, self.envelope, self.unit

        def write(ctx: StepContext) -> None:
            low_v, high_v, low_w, high_w = envelope(ctx)
            box[0], box[4] = max(box[0], low_v / unit), min(box[4], high_v / unit)
            box[1], box[5] = max(box[1], low_w), min(box[5], high_w)

        return write


#: Least top speed (m/s) and yaw rate (rad/s) of :class:`SpeedBudgetLimit`: its rows'
#: coefficients are their inverses, and far smaller tops (1e-300) gave coefficients the
#: solvers cannot hold (DAQP dropped the rows, OSQP failed to factorise).
MIN_TOP = 1e-6


class SpeedBudgetLimit(Limit):
    """Two rows: ``v`` and ``w`` share the wheels' force budget, ``|v|/v_top + |w|/w_top <= 1``.

    Args:
        speeds: ``(v_top, w_top)``, the steady-state top speed (m/s, all the force driving)
            and top yaw rate (rad/s, all the force turning) of the base; for a damped base
            with force limit F per wheel ``(2 F / c1, 2 F (width/2) / c2)``
            (:func:`ddwmmr.plants.thesis.damped_base_envelope` with ``speed_budget=True``),
            each at least :data:`MIN_TOP`.
        unit: the length unit (m) in which the rows take ``v`` (:attr:`Limit.unit`).
    """

    rows = 2
    name = "speed budget"

    def __init__(self, speeds: tuple[float, float], unit: float = 1.0) -> None:
        self.unit: float = check_positive("unit", unit)
        if isinstance(speeds, str) or length_of(speeds) != 2:
            raise ParameterError(
                f"speed_budget must be two numbers > 0, (v_top m/s, w_top rad/s)"
                f" (got {shown(speeds)})"
            )
        v_top = check_positive("speed_budget v_top", speeds[0])
        w_top = check_positive("speed_budget w_top", speeds[1])
        for name, top, unit_name in (("v_top", v_top, "m/s"), ("w_top", w_top, "rad/s")):
            if top < MIN_TOP:
                raise ParameterError(
                    f"speed_budget {name} must be >= {MIN_TOP:g} {unit_name}, a row the QP "
                    f"solvers can hold (got {top:g})"
                )
        self.speeds = (v_top, w_top)
        # |v|/v_top + |w|/w_top <= 1 is the pair of rows -1 <= v/v_top +- w/w_top <= 1.
        self.rows_vw = ((unit / v_top, 1.0 / w_top), (unit / v_top, -1.0 / w_top))

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Constant rows; written every step because the arrays are shared views."""
        for row, (a_v, a_w) in enumerate(self.rows_vw):
            G[row, 0], G[row, 1], G[row, 2], G[row, 3] = a_v, a_w, 0.0, 0.0
            lower[row], upper[row] = -1.0, 1.0

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Everything is constant: written once."""
        if overrides(self, SpeedBudgetLimit):
            return None
        block.write_constant_rows([(a_v, a_w, 0.0, 0.0) for a_v, a_w in self.rows_vw])
        block.write_constant_bounds((-1.0, -1.0), (1.0, 1.0))
        return CONSTANT
