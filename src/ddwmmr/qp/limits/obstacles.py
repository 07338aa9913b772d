"""Circular obstacles and the clearance of the rectangular base footprint.

The footprint is the ``base_length x base_width`` rectangle centred on the base position
(x, y) and aligned with the heading phi. The clearance of a circle is the distance from
the rectangle to the circle's edge (m, negative when they overlap). Its rate under the
inputs is, with ``p`` the circle centre in the base frame and ``n`` the unit normal from
the rectangle towards it (base frame),

    d_dot = -n_x v + (n_x p_y - n_y p_x) w

(the arm does not enter). :class:`ObstacleLimit` keeps ``d_dot >= -gain (d - margin)``
for every circle within ``influence`` of the footprint (a velocity damper); where no input
changes that clearance to first order, ``d_dot >= min(that, 0)`` (:meth:`ObstacleLimit.row`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ddwmmr.errors import (
    LENGTH_RANGE_M,
    MAX_COORDINATE_M,
    MAX_OBSTACLES,
    ParameterError,
    as_path,
    check_finite,
    check_nonnegative,
    check_positive,
    check_range,
    iterable,
    load_toml,
    shown,
    texts_apart,
)
from ddwmmr.gains import check_gain
from ddwmmr.model import Robot
from ddwmmr.qp.blocks import LimitBlock, overrides
from ddwmmr.qp.context import StepContext
from ddwmmr.qp.limits.base import INF, Limit
from ddwmmr.trajectories.files import find_obstacle_file

if TYPE_CHECKING:
    import numpy.typing as npt

#: A circle's row is degenerate when its top clearance rate ``|dd/dv| v_max + |dd/dw|
#: w_max`` is below this share of ``v_max``, the rate driving straight at the circle: level
#: with the middle of a side of the footprint no input changes the clearance to first
#: order (:meth:`ObstacleLimit.row`).
DEGENERATE_SHARE = 1e-3
#: Clearance within which the qp acts on a circle by default: the ``influence`` of
#: :class:`ObstacleLimit` (its rows switch on) and of
#: :class:`~ddwmmr.qp.tasks.avoidance.ObstacleSteeringTask` (it steers round), in the
#: robot's length unit (m on the default robot; docs/qp.md, "Robot size").
INFLUENCE_M = 0.6
#: Clearance kept from every obstacle when ``obstacle_margin`` is not given, by the qp and
#: the mpc, in the robot's length unit (m on the default robot; docs/qp.md, "Robot size").
MARGIN = 0.05


def robot_margin(margin: float | None, unit: float) -> float:
    """The ``obstacle_margin`` (m) of a robot whose length unit is ``unit`` (m,
    :func:`~ddwmmr.resolution.kernels.length_unit`): ``margin`` as given (m, in [0,
    :data:`~ddwmmr.errors.MAX_COORDINATE_M`], as an obstacle's own coordinates), None for
    :data:`MARGIN` of the unit (the robot's own), else a one-line
    :class:`ParameterError`. The mpc takes it as it is; the qp also needs it below its
    obstacle influence (:func:`check_margin_in_influence`)."""
    if margin is None:
        return MARGIN * unit
    value = check_nonnegative("obstacle_margin", margin)
    if value > MAX_COORDINATE_M:  # the mpc squares it: 1e300 overflowed building the OCP
        raise ParameterError(
            f"obstacle_margin must be in [0, {MAX_COORDINATE_M:g}] m (got {value:g})"
        )
    return value


def check_margin_in_influence(margin: float, unit: float) -> float:
    """``margin`` (m) if it is below the qp's obstacle influence, :data:`INFLUENCE_M` of
    the robot's length ``unit`` (m), where :class:`ObstacleLimit` switches its rows on,
    else a one-line :class:`ParameterError` naming ``obstacle_margin`` and its range for
    this robot: a clearance kept beyond the influence would never be acted on."""
    influence = INFLUENCE_M * unit
    if margin < influence:
        return margin
    got, (top,) = texts_apart(margin, influence)
    raise ParameterError(
        f"obstacle_margin must be in [0, {top}) m: below the qp's obstacle influence, "
        f"{INFLUENCE_M:g} of the robot's length unit {unit:g} m (got {got})"
    )


@dataclass(frozen=True)
class Circle:
    """A circular obstacle: centre (x, y) in the world frame (m), radius (m, > 0)."""

    x: float
    y: float
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "x", check_finite("obstacle x", self.x))
        object.__setattr__(self, "y", check_finite("obstacle y", self.y))
        object.__setattr__(self, "radius", check_positive("obstacle radius", self.radius))


def check_obstacle_count(count: int, source: str = "") -> int:
    """``count`` (circles of one run) if it is at most :data:`MAX_OBSTACLES`, else a
    one-line :class:`ParameterError` naming ``obstacles``, the count and the allowed range.
    ``source``: the file they were read from, for the message ("": given as a list)."""
    if count <= MAX_OBSTACLES:
        return count
    where = f" {source} has" if source else ""
    lowest = 1 if source else 0  # a file without [[obstacle]] tables is refused as such
    raise ParameterError(
        f"obstacles:{where} {count} obstacles, more than allowed ({lowest} to "
        f"{MAX_OBSTACLES}; each is checked at every control step)"
    )


#: A line holding an ``[[obstacle]]`` table header (the key bare or quoted, a comment after
#: it, the line ended by LF or CRLF): the tables :func:`load_obstacles` counts before the
#: file is parsed.
_OBSTACLE_HEADER = re.compile(
    r"""^[ \t]*\[\[[ \t]*(?:obstacle|"obstacle"|'obstacle')[ \t]*\]\][ \t]*(?:#.*)?\r?$""",
    re.MULTILINE,
)
#: A comment (``#`` to the end of its line): taken out before the inline tables of
#: ``obstacle = [{x = .., y = .., radius = ..}, ...]`` are counted by their ``{``.
_COMMENT = re.compile(r"#[^\n]*")


def load_obstacles(path: str | Path) -> list[Circle]:
    """Read circles from a TOML file of ``[[obstacle]]`` tables with x, y, radius (m) (or
    one array of inline tables, ``obstacle = [{x = 1, y = 0, radius = 0.3}, ...]``): one
    to :data:`MAX_OBSTACLES` of them (:func:`check_obstacle_count`)."""
    path = as_path(path, "obstacles")

    def count_tables(text: str) -> None:
        # a file of 100,000 tables took seconds to parse before its count was refused;
        # the [[obstacle]] headers and the inline tables' "{" outside comments, counted
        # in the text, refuse it at once. Exact for every file that loads: its only
        # strings are the keys obstacle, x, y, radius (no "{" or "#"), and an obstacle
        # holds numbers only. A file with such text in a string (a header line in a
        # multi-line string) is no obstacle file: counted too, it is refused either way;
        # a header spelt otherwise is counted when parsed.
        headers = len(_OBSTACLE_HEADER.findall(text))
        check_obstacle_count(headers + _COMMENT.sub("", text).count("{"), str(path))

    data = load_toml(path, "obstacles", count_tables)
    tables = data.get("obstacle")
    unknown = sorted(set(data) - {"obstacle"})
    if unknown:
        raise ParameterError(
            f"obstacles: {path}: unknown key {shown(unknown[0])} (expected [[obstacle]])"
        )
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables or [None]):
        raise ParameterError(f"obstacles: {path} needs [[obstacle]] tables with x, y, radius in m")
    check_obstacle_count(len(tables), str(path))
    circles = []
    for i, table in enumerate(tables, start=1):
        keys = set(table)
        if keys != {"x", "y", "radius"}:
            raise ParameterError(
                f"obstacles: {path}: obstacle {i} needs exactly x, y, radius in m "
                f"(got {sorted(keys)})"
            )
        for key in ("x", "y", "radius"):
            value = table[key]
            if not isinstance(value, int | float) or isinstance(value, bool):
                raise ParameterError(
                    f"obstacles: {path}: obstacle {i}: {key} must be a number in m "
                    f"(got {shown(value)})"
                )
        try:
            circles.append(within_limits(table["x"], table["y"], table["radius"]))
        except ParameterError as exc:
            raise ParameterError(f"obstacles: {path}: obstacle {i}: {exc}") from None
    return circles


def within_limits(x: float, y: float, radius: float) -> Circle:
    """The circle (m) if it is within the command-line limits (docs/cli.md, "Limits"; as
    for trajectory files): centre within +-MAX_COORDINATE_M, radius in LENGTH_RANGE_M,
    else a one-line :class:`ParameterError`. Obstacle files and recorded runs pass it
    alike."""
    check_range("obstacle x", x, -MAX_COORDINATE_M, MAX_COORDINATE_M, "m")
    check_range("obstacle y", y, -MAX_COORDINATE_M, MAX_COORDINATE_M, "m")
    check_range("obstacle radius", radius, *LENGTH_RANGE_M, "m")
    return Circle(x, y, radius)


def as_circles(obstacles: Sequence[Circle | Sequence[float]] | str | Path) -> list[Circle]:
    """Normalise the ``obstacles`` option: circles, (x, y, radius) triples, or a TOML file:
    a path, or a shipped or folder name such as ``ellipse_post`` looked up as ``track
    --obstacles`` does (:func:`~ddwmmr.trajectories.files.find_obstacle_file`). At most
    :data:`~ddwmmr.errors.MAX_OBSTACLES` circles (:func:`check_obstacle_count`)."""
    if obstacles is None:
        return []
    if isinstance(obstacles, str | Path):
        return load_obstacles(find_obstacle_file(obstacles))
    if not iterable(obstacles):
        raise ParameterError(
            f"obstacles must be circles, (x, y, radius) triples or a TOML file "
            f"(got {shown(obstacles)})"
        )
    circles = []
    for item in obstacles:
        if isinstance(item, Circle):
            circles.append(item)
            continue
        if isinstance(item, Mapping):  # an obstacle file's table: unpacking gave its keys
            raise ParameterError(
                f"obstacles are Circle(x, y, radius) or (x, y, radius) triples, not tables "
                f"(got {shown(item)}); a file of [[obstacle]] tables goes in by its path"
            )
        if isinstance(item, str | bytes):  # three letters unpack as a triple
            raise ParameterError(
                f"obstacles must be Circle(x, y, radius) or (x, y, radius) triples"
                f" (got {shown(item)})"
            )
        try:
            x, y, radius = item
        except (TypeError, ValueError):
            raise ParameterError(
                f"obstacles must be Circle(x, y, radius) or (x, y, radius) triples"
                f" (got {shown(item)})"
            ) from None
        circles.append(Circle(x, y, radius))
    check_obstacle_count(len(circles))
    return circles


def clearance_and_rate(
    half_length: float, half_width: float, x: float, y: float, phi: float, circle: Circle
) -> tuple[float, float, float]:
    """``(d, dd/dv, dd/dw)``: footprint-to-circle clearance (m) and its input rates."""
    dx, dy = circle.x - x, circle.y - y
    c, s = math.cos(phi), math.sin(phi)
    px, py = c * dx + s * dy, -s * dx + c * dy  # circle centre in the base frame
    qx = min(max(px, -half_length), half_length)
    qy = min(max(py, -half_width), half_width)
    ex, ey = px - qx, py - qy
    dist = math.hypot(ex, ey)
    if dist > 0.0:
        nx, ny = ex / dist, ey / dist
        d = dist - circle.radius
    else:  # centre inside the footprint: leave through the nearest side
        depth_x, depth_y = half_length - abs(px), half_width - abs(py)
        if depth_x < depth_y:
            nx, ny, depth = math.copysign(1.0, px), 0.0, depth_x
        else:
            nx, ny, depth = 0.0, math.copysign(1.0, py), depth_y
        d = -depth - circle.radius
    return d, -nx, nx * py - ny * px


def footprint_clearances(
    half_length: float,
    half_width: float,
    x: np.ndarray,
    y: np.ndarray,
    phi: np.ndarray,
    circles: Sequence[Circle],
) -> np.ndarray:
    """Smallest clearance (m) over ``circles`` at each pose; vectorised over poses.

    Same convention as :func:`clearance_and_rate`: negative when the circle overlaps.
    """
    x, y, phi = (np.asarray(a, dtype=float) for a in (x, y, phi))
    best = np.full(np.broadcast(x, y, phi).shape, np.inf)
    c, s = np.cos(phi), np.sin(phi)
    for circle in circles:
        dx, dy = circle.x - x, circle.y - y
        px, py = c * dx + s * dy, -s * dx + c * dy
        ex = px - np.clip(px, -half_length, half_length)
        ey = py - np.clip(py, -half_width, half_width)
        depth = np.minimum(half_length - np.abs(px), half_width - np.abs(py))
        outside = np.hypot(ex, ey)
        d = np.where(outside > 0.0, outside, -depth) - circle.radius
        best = np.minimum(best, d)
    return best


def check_start_clear(
    robot: Robot, circles: Sequence[Circle], q: Sequence[float] | npt.NDArray[np.float64]
) -> None:
    """Refuse (one-line :class:`ParameterError`) a start pose ``q`` whose base footprint
    overlaps one of ``circles``: the run would start in a collision."""
    half_length, half_width = 0.5 * robot.base_length, 0.5 * robot.base_width
    for number, circle in enumerate(circles, start=1):
        d = clearance_and_rate(half_length, half_width, q[0], q[1], q[2], circle)[0]
        if d < 0.0:
            raise ParameterError(
                f"obstacles: obstacle {number} (x {circle.x:g} m, y {circle.y:g} m, radius "
                f"{circle.radius:g} m) overlaps the robot's start pose by {-d:.3g} m; move it"
            )


def run_clearance(
    robot: Robot, circles: Sequence[Circle], timeseries: dict[str, np.ndarray]
) -> float | None:
    """Smallest footprint clearance (m) from ``circles`` over a recorded run (columns x, y,
    phi); None without circles (the ``min_obstacle_clearance_m`` summary key)."""
    if not circles or not all(k in timeseries for k in ("x", "y", "phi")):
        return None
    return float(
        np.min(
            footprint_clearances(
                0.5 * robot.base_length,
                0.5 * robot.base_width,
                timeseries["x"],
                timeseries["y"],
                timeseries["phi"],
                circles,
            )
        )
    )


class ObstacleLimit(Limit):
    """One damper row per circle: ``d_dot >= -gain (d - margin)`` when ``d < influence``.

    Args:
        robot: gives the footprint and the base speed limits (to keep rows feasible).
        circles: the obstacles.
        margin: clearance kept from every circle (m); None: :data:`MARGIN` of ``unit``.
        influence: rows farther than this are switched off (in ``unit``).
        gain: damper gain (1/s).
        unit: the length unit (m) of the rows (:attr:`Limit.unit`): each row is the
            clearance rate in units per second, with ``v`` taken as ``v / unit``.
    """

    name = "obstacles"

    def __init__(
        self,
        robot: Robot,
        circles: Sequence[Circle],
        margin: float | None = None,
        influence: float = INFLUENCE_M,
        gain: float = 2.0,
        unit: float = 1.0,
    ) -> None:
        self.unit: float = check_positive("unit", unit)
        self.circles = list(circles)
        self.rows = len(self.circles)
        self.half_length, self.half_width = 0.5 * robot.base_length, 0.5 * robot.base_width
        self.margin = (
            MARGIN * unit if margin is None else check_nonnegative("obstacle margin", margin)
        )
        self.influence = check_positive("obstacle influence", influence)
        if self.influence * unit <= self.margin:
            raise ParameterError(
                f"obstacle influence must be > margin ({margin:g} m) in units of {unit:g} m"
                f" (got {influence:g})"
            )
        self.gain = check_gain("obstacle gain", gain)
        r, lw, limit = robot.wheel_radius, robot.track_width, robot.wheel_speed_limit
        self.v_max, self.w_max = r * limit, 2.0 * r * limit / lw

    def row(self, ctx: StepContext, circle: Circle) -> tuple[float, float, float]:
        """``(dd/dv, dd/dw, lower bound)`` of one circle's row (-INF when far), in ``unit``:
        the clearance rate in units per second, ``v`` taken as ``v / unit``.

        The lower bound is the damper's ``-gain (d - margin)``, capped at a quarter
        of the top clearance rate ``|dd/dv| v_max + |dd/dw| w_max`` so the row stays
        feasible. A degenerate row, whose top clearance rate is below
        :data:`DEGENERATE_SHARE` of ``v_max`` (a circle level with the middle of a side:
        to first order no input moves the footprint towards or away from it), is scaled
        to a unit gradient (the same half-plane) with the bound ``min(damper, 0)``: no
        approach, and no demanded escape. As it was, with coefficients like 1e-8 m and a
        positive bound, it asked for a quarter of the top yaw rate to gain 1e-8 m/s of
        clearance, a row below the solvers' tolerances that they answered differently
        (DAQP found no solution on every step, others spun the base or not).
        """
        unit = self.unit
        d, a_v, a_w = clearance_and_rate(
            self.half_length, self.half_width, ctx.x, ctx.y, ctx.phi, circle
        )
        a_w /= unit
        if d >= self.influence * unit:
            return a_v, a_w, -INF
        damper = -self.gain * (d - self.margin) / unit
        v_max = self.v_max / unit
        reach = abs(a_v) * v_max + abs(a_w) * self.w_max
        if reach < DEGENERATE_SHARE * v_max:
            norm = math.hypot(a_v, a_w)
            if norm == 0.0:  # no rate at all: the row reads 0 >= min(damper, 0)
                return a_v, a_w, min(damper, 0.0)
            return a_v / norm, a_w / norm, min(damper, 0.0) / norm
        return a_v, a_w, min(damper, 0.25 * reach)

    def compute(
        self,
        ctx: StepContext,
        G: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        lb: np.ndarray,
        ub: np.ndarray,
    ) -> None:
        """Rows ``[dd/dv, dd/dw, 0, 0]`` for circles within ``influence``."""
        for row, circle in enumerate(self.circles):
            G[row, 0], G[row, 1], lower[row] = self.row(ctx, circle)
            G[row, 2] = G[row, 3] = 0.0
            upper[row] = INF

    def compile(self, block: LimitBlock) -> Callable[[StepContext], None] | None:
        """Writer for each circle's two rates and bound; the rest is constant."""
        if overrides(self, ObstacleLimit) or overrides(self, ObstacleLimit, "row"):
            return None
        block.write_constant_rows([[0.0] * 4] * self.rows)
        block.write_constant_bounds((-INF,) * self.rows, (INF,) * self.rows)
        G, lower, row = block.matrix, block.lower, self.row
        slots = list(zip(self.circles, block.rows, block.bounds))

        def write(ctx: StepContext) -> None:
            for circle, entry, bound in slots:
                G[entry], G[entry + 1], lower[bound] = row(ctx, circle)

        return write
