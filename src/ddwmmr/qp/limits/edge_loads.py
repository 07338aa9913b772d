"""Every edge of the support polygon keeps a least normal load while the robot moves.

The edge load ``L_e`` (N, :class:`~ddwmmr.model.support_loads.EdgeLoadModel`) is exactly
linear in the accelerations ``(a_x, a_y, w_dot, acc1, acc2)`` at a given configuration,
joint rates and yaw rate. This limit predicts those accelerations from the command
``u = (v, w, th1dot, th2dot)`` the way the plant's servos follow it: each rate approaches
its target with the first-order lag ``tau`` (``PlantTraits.joint_time_constant``), so over
one control step dt its mean acceleration is

    acc = (u - rate) k,    k = (1 - exp(-dt / tau)) / dt

from the measured rate (the base's ``v``, ``w``; the joints' rates from the same lag model
run on the previous commands, the plant does not report them). The base's lateral
acceleration ``v w`` is linearised at the measured ``(v, w)``; the velocity terms (the arm's
centripetal and Coriolis forces, the turn) are taken at the measured state. Each edge's row

    L_e(u) = L0_e + G_e . u >= min_edge_load W

is then exact for that prediction. ``(u - rate) / dt`` (the command jump over dt) is not:
the servos lag, and it missed the measured load by 3.2 N in the median (docs/physics.md).
The bound is capped at half of what the input box can reach for the row (as the stability
limit's), so the row alone is always feasible: an edge that a disturbance took below its
floor must be pushed back up at least that fast.

When the rows conflict with the other limits (no command meets them all: the QP has no
solution) the controller solves the step again with :attr:`EdgeLoadLimit.active` off (the
rows open, the joints' window too) and says so: the edge floor gives way before the hard
limits and before the QP's fallback.

The lag model holds while the servos do not saturate. With the motors' acceleration limits
``a`` (``PlantTraits.joint_acceleration_limit``) the limit also keeps each joint's command
within ``rate +- a tau`` (the servo's torque at the step's start, ``(u - rate)/tau`` times
the stretched arm's inertia, within the motor's): a command the motor cannot follow would
have the joint accelerate at its limit for several steps, which the one-step prediction
does not see (a reversing elbow lifted an edge the prediction had at 22 N).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from ddwmmr.errors import check_positive
from ddwmmr.model.support_loads import EdgeLoadModel, check_min_edge_load, edge_loads_at
from ddwmmr.qp.blocks import LimitBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import INF, Limit

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy as np

    from ddwmmr.model import Robot


class EdgeLoadLimit(Limit):
    """One row per edge of the support polygon: predicted edge load >= the floor.

    Args:
        robot: the robot (masses, support polygon).
        min_edge_load: the floor as a share of the weight, in [0, 0.5).
        time_constant: the servos' lag (s) with which the base and joint rates follow
            their targets.
        acceleration_limit: the joints' largest accelerations (rad/s^2, shoulder and
            elbow), None for none.
        unit: the length unit (m) in which the rows take ``v`` (:attr:`Limit.unit`); the
            loads stay in N (:meth:`rows_and_floors` and :meth:`predict` in SI).

    Call :meth:`observe` with the measured base velocities before each step's solve and
    :meth:`advance` with the command sent after it (the joints' rate estimate).
    """

    name = "edge load"

    def __init__(
        self,
        robot: Robot,
        min_edge_load: float,
        time_constant: float,
        acceleration_limit: tuple[float, float] | None = None,
        unit: float = 1.0,
    ) -> None:
        self.unit: float = check_positive("unit", unit)
        self.model = EdgeLoadModel.from_robot(robot)
        self.min_edge_load = check_min_edge_load(min_edge_load)
        self.floor_n = self.min_edge_load * self.model.weight
        self.time_constant = check_positive("joint_time_constant", time_constant)
        self.rows = len(self.model.polygon.depths)
        self.acceleration_limit = acceleration_limit
        #: False opens every row and the joints' window (a step whose rows conflict)
        self.active = True
        polygon, weight = self.model.polygon, self.model.weight
        origin = edge_loads_at(polygon, weight, 0.0, 0.0)
        # dL_e / d(centre of pressure): the edge loads are affine in it
        self._per_x = [a - b for a, b in zip(edge_loads_at(polygon, weight, 1.0, 0.0), origin)]
        self._per_y = [a - b for a, b in zip(edge_loads_at(polygon, weight, 0.0, 1.0), origin)]
        self.reset()

    def reset(self) -> None:
        """At rest: measured base velocities and joint rate estimates zero."""
        self.v = self.w = 0.0
        self.rates = (0.0, 0.0)
        self._last: tuple[list[list[float]], list[float]] = ([], [])

    def observe(self, v: float, w: float) -> None:
        """The measured forward speed v (m/s) and yaw rate w (rad/s) of this step."""
        self.v, self.w = float(v), float(w)

    def advance(self, command: Sequence[float] | np.ndarray, dt: float) -> None:
        """The joints' rates after holding ``command`` (its rates, rad/s) for dt (s): the
        lag's response, at most the acceleration limit times dt."""
        share = 1.0 - math.exp(-dt / self.time_constant)
        rates = []
        for j, rate in enumerate(self.rates):
            change = (command[2 + j] - rate) * share
            if self.acceleration_limit is not None:
                most = self.acceleration_limit[j] * dt
                change = min(max(change, -most), most)
            rates.append(rate + change)
        self.rates = (rates[0], rates[1])

    def joint_window(self) -> list[tuple[float, float]]:
        """Each joint's command window ``rate +- a tau`` (rad/s) the servo follows without
        saturating; unbounded without an acceleration limit."""
        if self.acceleration_limit is None:
            return [(-INF, INF), (-INF, INF)]
        return [
            (rate - a * self.time_constant, rate + a * self.time_constant)
            for rate, a in zip(self.rates, self.acceleration_limit)
        ]

    @staticmethod
    def tighten(box: list[float], window: list[tuple[float, float]]) -> None:
        """Tighten the joints' part of ``box`` (lower bounds, then upper bounds) to
        ``window``, never emptying it (a window outside the box leaves its nearest
        side)."""
        for j, (low, high) in enumerate(window, start=2):
            lower = min(max(box[j], low), box[4 + j])
            box[4 + j] = max(min(box[4 + j], high), lower)
            box[j] = lower

    def rows_and_floors(self, ctx: StepContext) -> tuple[list[list[float]], list[float]]:
        """Each edge's ``G_e`` (N per unit of u) and its bound ``floor - L0_e`` (N), the
        prediction's affine form ``L_e(u) = L0_e + G_e . u``."""
        model, th1, th2 = self.model, ctx.th1, ctx.th2
        v, w, (r1, r2) = self.v, self.w, self.rates
        k = (1.0 - math.exp(-ctx.dt / self.time_constant)) / ctx.dt
        rates = (r1, r2)
        still = (0.0, 0.0)
        x0, y0 = model.centre_of_pressure(th1, th2, rates, still, still, w, 0.0)
        lever = -model.terms.height_moment / model.weight  # d(centre)/d(a_x or a_y), m/(m/s^2)
        parts = (
            model.centre_of_pressure(th1, th2, rates, still, still, w, 1.0),
            model.centre_of_pressure(th1, th2, rates, (1.0, 0.0), still, w, 0.0),
            model.centre_of_pressure(th1, th2, rates, (0.0, 1.0), still, w, 0.0),
        )
        rows, floors = [], []
        origin = edge_loads_at(model.polygon, model.weight, x0, y0)
        for e, load in enumerate(origin):
            px, py = self._per_x[e], self._per_y[e]
            d_ax, d_ay = px * lever, py * lever
            d_yaw, d_1, d_2 = ((px * (x - x0) + py * (y - y0)) for x, y in parts)
            # a_x = k (u_v - v), a_y = v u_w + w u_v - v w, w_dot = k (u_w - w),
            # acc_i = k (u_i - rate_i)
            row = [d_ax * k + d_ay * w, d_ay * v + d_yaw * k, d_1 * k, d_2 * k]
            constant = load - d_ax * k * v - d_ay * v * w - d_yaw * k * w
            constant -= d_1 * k * r1 + d_2 * k * r2
            rows.append(row)
            floors.append(self.floor_n - constant)
        self._last = (rows, floors)
        return rows, floors

    def predict(self, command: Sequence[float] | np.ndarray) -> list[float]:
        """The predicted edge loads (N) of ``command`` in the step whose rows were built
        last (:meth:`rows_and_floors`)."""
        rows, floors = self._last
        return [
            self.floor_n - floor + sum(g * u for g, u in zip(row, command[:4]))
            for row, floor in zip(rows, floors)
        ]

    @staticmethod
    def capped(row: list[float], floor: float, box: list[float]) -> float:
        """The row's bound: ``floor``, at most half of what the box ``(lb..., ub...)``
        lets ``row . u`` reach (so the row alone is always feasible)."""
        if max(map(abs, box)) >= INF:
            return floor
        reach = sum(max(g * box[j], g * box[4 + j]) for j, g in enumerate(row))
        return min(floor, 0.5 * reach)

    def in_unit(self, rows: list[list[float]]) -> list[list[float]]:
        """``rows`` (N per SI unit of u) with the ``v`` entry per ``v / unit``."""
        unit = self.unit
        if unit == 1.0:
            return rows
        return [[row[0] * unit, row[1], row[2], row[3]] for row in rows]

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Rows ``G_e`` with the lower bound of :meth:`capped`."""
        rows, floors = self.rows_and_floors(ctx)
        rows = self.in_unit(rows)
        box = [*map(float, lb), *map(float, ub)]
        if self.active:
            self.tighten(box, self.joint_window())
            lb[:], ub[:] = box[:4], box[4:]
        for e, (row, floor) in enumerate(zip(rows, floors)):
            G[e, 0], G[e, 1], G[e, 2], G[e, 3] = row
            lower[e] = self.capped(row, floor, box) if self.active else -INF
            upper[e] = INF

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Writer for every row and its lower bound (upper bounds constant)."""
        if any(overrides(self, EdgeLoadLimit, name) for name in ("compute", "rows_and_floors")):
            return None
        block.write_constant_bounds([-INF] * self.rows, [INF] * self.rows)
        matrix, lower, starts, bounds = block.matrix, block.lower, block.rows, block.bounds
        box, values, capped = block.box, self.rows_and_floors, self.capped
        tighten, window, in_unit = self.tighten, self.joint_window, self.in_unit

        def write(ctx: StepContext) -> None:
            active = self.active
            if active:
                tighten(box, window())
            rows, floors = values(ctx)
            rows = in_unit(rows)
            for e, (row, floor) in enumerate(zip(rows, floors)):
                start = starts[e]
                matrix[start], matrix[start + 1] = row[0], row[1]
                matrix[start + 2], matrix[start + 3] = row[2], row[3]
                lower[bounds[e]] = capped(row, floor, box) if active else -INF

        return write
