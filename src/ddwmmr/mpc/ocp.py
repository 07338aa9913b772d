"""The receding-horizon optimal control problem, by multiple shooting (built once, solved
every control step).

Two objectives share one structure:

* **tracking** (a trajectory is given): follow the previewed end-effector poses at the
  nodes; horizon fixed;
* **reach** (waypoint mode, only a target): reach the target as early as possible. The
  horizon ``T`` is a decision variable (a free final time, kept as a constant extra state
  so the stage structure survives) between ``min_horizon`` and ``horizon``: when the target
  can be reached within ``horizon``, the plan is a minimum-time manoeuvre that passes
  through it; when it cannot, ``T = horizon`` and the plan gets as close as it can (each
  metre left costs ``1/reach_speed`` seconds).
* **reach through** (waypoint mode with the next target known, ``second_leg_intervals >
  0``): two legs of free duration, ``T1`` to the current target (its reach cost at the
  leg's last node) and ``T2`` from there to the next one (its reach cost at the last
  node, and ``T2`` charged, both scaled by ``second_leg_weight``): the plan arrives at the
  current target moving the way the next leg wants (docs/mpc.md, "Planning through the
  next waypoint").

Grid: the first interval is the control step ``dt`` (the command is held exactly that
long); the other ``N - 1`` grow geometrically from ``first_interval`` to fill the rest of
the ``horizon`` (uniform when they are all ``first_interval``), scaled to fill ``T - dt``
in reach mode: fine steps where the command is decided, coarse ones where only the
direction of the plan matters; a second leg's intervals are equal shares of ``T2``.
Each interval is integrated with RK4 in sub-steps of at most :data:`MAX_SUBSTEP`.
Decision vector, in the stage-wise order that structure-exploiting
solvers (HPIPM, FATROP) expect::

    w = [x_0, u_0, x_1, u_1, ..., x_{N-1}, u_{N-1}, x_N]

with the physical part of ``x_0`` pinned to the measured state by its bounds; ``u_k`` is
the model's input followed by this stage's slacks ``sigma_k >= 0``. Constraints, stage by
stage (``gap_k`` then ``path_k``)::

    gap_k:   x_{k+1} - RK4(x_k, u_k, h_k) = 0                        (the prediction model)
    path_k:  -hl/S <= x_com(q_{k+1}) +- sigma_lon,   -hw/S <= y_com(q_{k+1}) +- sigma_lat
             |p_{k+1} - o_j|^2 + sigma_obs >= (R_j + r_base + margin)^2   (every circle j)
             th_lo <= th_i,{k+1} +- sigma_i <= th_hi   (each lagged joint i, see below)
             wheel speeds in +-wheel_speed_limit

written through ``x_{k+1} = RK4(x_k, u_k, h_k)`` so that each row involves one stage's
variables only. ``S = stability_min + stability_margin``; the box on the centre of mass is
the exact condition ``S_lon, S_lat >= S`` (see :func:`ddwmmr.model.symbolic.
stability_bounds`): the nonlinear stability margin at every node, not a linearisation. On a
support polygon other than the rectangle the box is one row per edge, ``n_e . c -
sigma_term <= d_e / S`` (:func:`ddwmmr.model.symbolic.stability_edges`), the same exact
condition.
With ``dynamic_stability`` (force-level model only) every edge e of the support polygon
keeps a least normal load, at both ends of every interval under that interval's input (so
``u_0`` itself is bounded at the measured state)::

    d_e(c) + sigma >= min_edge_load D_e,    d_e(c) = L_e D_e / W

with ``L_e`` the edge load of the motion (:func:`ddwmmr.model.symbolic.edge_loads`: the
centre of pressure ``c`` with the inertial forces of the base's acceleration, turn and the
arm's motion), ``D_e`` the polygon's depth behind e and ``W`` the weight: the row in
metres, the centre of pressure's distance from the edge line, so that it shares the
stability terms' slacks (and their braking threshold).
The slacks carry an exact L1 penalty (:data:`SLACK_WEIGHT`): whenever the constraints can
be met they are met (a hard constraint), and a linearisation that cannot be met in one
iteration still gives a solvable QP. Input box (forces or rates), joint-position box on
the states. Where the joints lag their commands (``joints_stop_at_once`` false: the
physical arm) the joint box is a path row with its own slack instead: a joint turning
towards its limit needs its braking distance to stop, and MuJoCo lets a joint overrun its
range by a few mrad, so the next node can be out of the box's reach. With the box as
bounds such a QP is infeasible and HPIPM gives up on it (docs/mpc.md, "The joint box as a
row with a slack"). With the lagged arm and a joint acceleration limit, rows
(without slack: the stage's input can always meet them) bound the lag's acceleration
``(u_rates - rates) / tau`` at the start of every interval, where it is largest, and the
last node holds the centre of mass of its *stopping pose* (each joint moved on by its
braking distance at that limit) in the stability box too: a plan may not end in a swing
the arm cannot brake before the floor. With ``dynamic_stability`` the last node also keeps
every edge loaded once the arm has braked to rest (the model's ``stopped_arm_motion``):
the arm's angular momentum then turns the base, and that turn's sideways acceleration
``v w`` must leave each edge ``min_edge_load`` (the same rows and slacks as the path's
edge rows).

Cost: ``0.5 ||r(w, p)||^2 + c' w`` with the residual ``r`` stacked from, weighted by the
interval lengths:

* end-effector position error at the nodes (tracking; optional in reach mode)
  ``sqrt(Wp) s(e) e``, ``e = p_E(q_k) - p_ref,k``. With a Huber scale ``delta`` the factor
  ``s(e) = sqrt(2 / (1 + sqrt(1 + |e|^2/delta^2)))`` makes the squared residual quadratic
  near the reference and linear far from it;
* orientation error ``sqrt(Wo) [cos phiE - cos phi_ref, sin phiE - sin phi_ref]`` (smooth
  through the wrap and through the rectangle's corner jumps);
* manipulability ``sqrt(Wm) cos th2`` (soft: ``1 - eta^2 = cos^2 th2``);
* inputs ``sqrt(Wu) u / u_scale``; at the first stage the change from the previous
  command ``sqrt(Wdu) (u_0 - u_prev) / u_scale``;
* terminal, tracking: ``L' z`` with ``z`` the terminal end-effector error in the terminal
  base frame (plus the base velocities for the force model) and ``P = L L'`` the LQR
  cost-to-go of the linearised error dynamics (:mod:`ddwmmr.mpc.terminal`);
* terminal, reach: the Huber distance to the target, ``|e_N| / reach_speed`` seconds far
  from it; the linear term ``c`` charges ``T`` itself (one unit per second) and the slacks;
* arrival, reach (``arrival_weight > 0``): the first leg's last state against an arrival
  state, ``sqrt(Wa) [cos phi - cos phi_a, sin phi - sin phi_a, x[3:] - x_a[3:]]`` (an
  offline plan's state at the target: how the plan of the whole task arrives there).

Parameters ``p``: per node ``(x, y, phi, weight)`` of the reference, the previous command,
the terminal factor ``L`` (row-major), with an arrival term its state and 1 (on) or 0
(off), and the previous horizon ``T`` (reach mode).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import casadi as ca
import numpy as np

from ddwmmr.errors import (
    ParameterError,
    check_int_at_least,
    check_positive,
    check_range,
    check_weight,
    round_significant,
)
from ddwmmr.gains import STABLE_GAIN_STEP
from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.stability import GRAVITY_M_S2, STABILITY_FLOOR, is_longitudinal
from ddwmmr.model.support_loads import DEFAULT_MIN_EDGE_LOAD, EdgeLoadModel
from ddwmmr.mpc.models import PredictionModel
from ddwmmr.qp.limits.obstacles import Circle

if TYPE_CHECKING:
    from ddwmmr.model.support_loads import SupportPolygon

#: Value used for "no bound" in the constraint vectors.
INF = math.inf
#: Exact-penalty weight of a path-constraint slack (per unit of violation) and its small
#: quadratic part (keeps the QP strictly convex). Large against every multiplier seen in
#: practice, so a feasible linearisation is solved exactly (hard constraint).
SLACK_WEIGHT = 1e4
SLACK_QUADRATIC = 1.0
#: Longest RK4 sub-step inside one shooting interval (s).
MAX_SUBSTEP = 0.2
#: Weight of the change of the free horizon T between two solves (1/s^2).
HORIZON_SMOOTHING = 1.0


@dataclass(frozen=True)
class Weights:
    """Cost weights (per second of horizon; positions in m, angles in rad).

    Attributes:
        position: end-effector position error at the nodes (1/(m^2 s)).
        orientation: end-effector orientation chord error (1/s); 0 disables it.
        manipulability: ``cos^2 th2`` (1/s).
        input: normalised inputs (1/s).
        input_change: change of the first input from the previous command (-).
        terminal: scale of the LQR terminal cost (tracking) (-); 0 disables it.
    """

    position: float = 100.0
    orientation: float = 1.0
    manipulability: float = 0.5
    input: float = 0.01
    input_change: float = 0.0
    terminal: float = 1.0

    def __post_init__(self) -> None:
        for name in (
            "position",
            "orientation",
            "manipulability",
            "input",
            "input_change",
            "terminal",
        ):
            object.__setattr__(self, name, check_weight(f"{name}_weight", getattr(self, name)))


@dataclass(frozen=True)
class OCPConfig:
    """What defines one OCP (the functions are rebuilt when any of it changes).

    Attributes:
        intervals: number N of shooting intervals; control_interval: the first one (the
            control step dt, s); first_interval: the second one's length (s); horizon: their
            sum (s), at least ``dt + (N - 1) first_interval``.
        reach: free-final-time reach objective (waypoint mode) instead of tracking.
        second_leg_intervals: reach mode: intervals of a second leg of free duration to
            the next target (0: none), each an equal share of it, at most
            ``second_leg_horizon`` (s) long in all; second_leg_weight: the weight of that
            leg's time and reach cost against the first leg's (1: the total time).
        min_horizon: lower bound on the free horizon T (s); reach_speed: m/s converting
            the distance left at T = horizon into seconds.
        arrival_weight: reach mode: the weight ``Wa`` of the cost ``0.5 Wa |e|^2`` (s),
            ``e`` the first leg's last state less an arrival state given with the
            parameters (an offline plan's state at the target): the heading as a chord,
            the joint angles (rad) and the base velocities (m/s, rad/s), position left
            out; 0 (default): no such term.
        stability_min: the floor S_min; stability_margin: the OCP keeps S >= S_min + margin.
        dynamic_stability: keep every edge of the support polygon loaded while moving,
            besides the static box on the centre of mass (the model must have base
            dynamics); min_edge_load: that least load as a share of the weight.
        track_orientation: cost on the end-effector orientation.
        huber: Huber scale (m) of the position error, None for a pure quadratic.
        obstacles: circles kept clear of the base's enclosing circle (radius
            ``base_radius``) by ``obstacle_margin`` (m).
        weights: the cost weights.
    """

    intervals: int = 20
    control_interval: float = 0.02
    first_interval: float = 0.05
    horizon: float = 3.0
    reach: bool = False
    second_leg_intervals: int = 0
    second_leg_weight: float = 1.0
    second_leg_horizon: float = 12.0
    min_horizon: float = 0.1
    reach_speed: float = 0.5
    arrival_weight: float = 0.0
    stability_min: float = STABILITY_FLOOR
    stability_margin: float = 0.01
    dynamic_stability: bool = False
    min_edge_load: float = DEFAULT_MIN_EDGE_LOAD
    track_orientation: bool = True
    huber: float | None = None
    obstacles: tuple[Circle, ...] = ()
    base_radius: float = 0.0
    obstacle_margin: float = 0.05
    weights: Weights = field(default_factory=Weights)

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "arrival_weight", check_weight("arrival_weight", self.arrival_weight)
        )

    @property
    def legs(self) -> int:
        """Legs of free duration: 2 with a second leg (reach mode), else 1."""
        return 2 if self.reach and self.second_leg_intervals > 0 else 1

    def interval_lengths(self) -> np.ndarray:
        """The interval lengths (s) at ``T = horizon`` (and ``T2 = second_leg_horizon``):
        :func:`shooting_grid` (dt, then ``first_interval r^k``), then the second leg's
        equal shares."""
        first = shooting_grid(
            self.intervals, self.control_interval, self.first_interval, self.horizon
        )
        count = self.second_leg_intervals if self.legs == 2 else 0
        second = np.full(count, self.second_leg_horizon / max(count, 1))
        return np.concatenate([first, second])

    def longest_horizons(self) -> list[float]:
        """The upper bounds (s) of the free horizons: ``[]`` tracking, ``[horizon]`` or
        ``[horizon, second_leg_horizon]``."""
        if not self.reach:
            return []
        return [self.horizon, self.second_leg_horizon][: self.legs]


class ShootingOCP:
    """The symbolic multiple-shooting problem (see module docstring) and its index maps.

    Attributes:
        w, p: decision and parameter symbols (SX); residual, g: cost residual, constraints.
        linear_cost: the cost's linear part ``c`` (slack penalty, horizon), (nw,).
        lbg, ubg: constraint bounds; w_lower, w_upper: decision bounds with ``x_0`` free
            (use :meth:`bounds` to pin it); ng: path rows per stage (N+1).
        nx, nu: node state and stage input sizes (model plus T / slacks).
        x_slices, u_slices: where each node's model state / model input sits in w.
        lengths: nominal interval lengths (s) at T = horizon (N,); fractions: the shares of
            intervals 1..N-1 in ``T - dt`` (N-1,).
        terminal_size: dimension of the tracking terminal error ``z``.
    """

    def __init__(self, robot: Robot, model: PredictionModel, config: OCPConfig) -> None:
        self.robot = robot
        self.model = model
        self.config = config
        self.lengths = config.interval_lengths()
        #: intervals of the first leg (all of them with one leg), and in all
        self.split = config.intervals
        n = self.N = len(self.lengths)
        self.dt = float(self.lengths[0])
        first = self.lengths[1 : self.split]
        self.fractions = first / first.sum()
        #: the second leg's intervals as shares of ``T2`` (empty with one leg)
        self.second_fractions = self.lengths[self.split :] / config.second_leg_horizon
        self.nxm, self.num = model.nx, model.nu
        #: the free horizons carried as constant states (none when tracking)
        self.n_horizons = len(config.longest_horizons())
        self.nx = model.nx + self.n_horizons
        #: the joint box is a slackened path row, not a bound (see the module docstring)
        self.soft_joints = not model.joints_stop_at_once
        # slacks: stability terms, obstacles, one per joint (a shared one would let the
        # elbow pass its limit for free while the shoulder is past its own)
        self.ns = 2 + (1 if config.obstacles else 0) + (2 if self.soft_joints else 0)
        #: where in a stage's slacks the joints' are, after all others (empty where the
        #: box is bounds)
        self.joint_slacks = slice(self.ns - 2 if self.soft_joints else self.ns, self.ns)
        self.nu = model.nu + self.ns
        # terminal error: the end-effector error, and the base velocities of a force model
        self.terminal_size = (3 if config.track_orientation else 2) + (
            2 if model.nx > sym.NQ else 0
        )
        self.x_slices, self.u_slices, self.slack_slices = [], [], []
        self._node_slices = []
        start = 0
        for k in range(n + 1):
            self._node_slices.append(slice(start, start + self.nx))
            self.x_slices.append(slice(start, start + self.nxm))
            start += self.nx
            if k < n:
                self.u_slices.append(slice(start, start + self.num))
                self.slack_slices.append(slice(start + self.num, start + self.nu))
                start += self.nu
        self.nw = start
        #: index in w of every stage's slacks (N, ns): one fancy index reads them all
        self.slack_index = np.array([np.arange(s.start, s.stop) for s in self.slack_slices])
        #: the arrival state's parameters (its state, then 1 on / 0 off; none without)
        self.arrival_size = self.nxm + 1 if config.reach and config.arrival_weight > 0 else 0
        self._arrival_start = 4 * n + self.num + self.terminal_size**2
        self.np = self._arrival_start + self.arrival_size + 1
        self.w = ca.SX.sym("w", self.nw)
        self.p = ca.SX.sym("p", self.np)
        self._build()

    # -- construction -------------------------------------------------------------------
    @property
    def horizon_index(self) -> int | None:
        """Index in w of the free horizon T of node 0 (reach mode), else None."""
        return self.nxm if self.config.reach else None

    def node_times(self, horizon: float, second: float | None = None) -> np.ndarray:
        """Node offsets from now (s) for a horizon T (N+1,), the second leg (if any)
        ``second`` s long after it (default: its longest)."""
        rest = np.cumsum(self.fractions * (horizon - self.dt))
        first = np.concatenate([[0.0, self.dt], self.dt + rest])
        leg = self.config.second_leg_horizon if second is None else second
        return np.concatenate([first, horizon + np.cumsum(self.second_fractions * leg)])

    def _interval(
        self, nodes: Sequence[sym.Symbolic], k: int, owner: int | None = None
    ) -> sym.Symbolic:
        """Length of interval k: dt for k = 0; fixed (tracking) or a share of ``T - dt``
        (reach, T read from node ``owner``, default k: every node carries the same T), or
        of ``T2`` on a second leg."""
        if k == 0:
            return self.dt
        if self.config.reach:
            node = nodes[k if owner is None else owner]
            if k >= self.split:
                return self.second_fractions[k - self.split] * node[self.nxm + 1]
            return self.fractions[k - 1] * (node[self.nxm] - self.dt)
        return float(self.lengths[k])

    def _integrate(
        self, x: sym.Symbolic, u: sym.Symbolic, h: sym.Symbolic, nominal: float
    ) -> sym.Symbolic:
        """The state after h (s) under u: the model's integration (RK4, or its own) in
        equal sub-steps, at most MAX_SUBSTEP long at the interval's nominal length (reach
        mode only shortens intervals)."""
        return self.model.integrate(x, u, h, substeps(nominal))

    def _build(self) -> None:
        config, model, robot = self.config, self.model, self.robot
        nodes = [self.w[s] for s in self._node_slices]
        xs = [self.w[s] for s in self.x_slices]
        us = [self.w[s] for s in self.u_slices]
        slacks = [self.w[s] for s in self.slack_slices]
        floor = config.stability_min + config.stability_margin
        edges = sym.stability_edges(robot, floor)  # None: the rectangle's box
        x_max, y_max = sym.stability_bounds(robot, floor) or (INF, INF)  # unused with edges
        clear = [
            (c.x, c.y, (c.radius + config.base_radius + config.obstacle_margin) ** 2)
            for c in config.obstacles
        ]
        g, lbg, ubg, ng = [], [], [], []
        self._first_loads: list[sym.Symbolic] = []  # the first interval's edge loads (N), both ends
        for k in range(self.N):
            x_next = self._integrate(xs[k], us[k], self._interval(nodes, k), float(self.lengths[k]))
            # the gap as x_{k+1} - F(x_k, u_k): the only form FATROP's structure detection
            # takes (F - x_{k+1} raised inside FATROP at every solve); HPIPM takes either
            if config.reach:
                g.append(nodes[k + 1] - ca.vertcat(x_next, nodes[k][self.nxm :]))
            else:
                g.append(nodes[k + 1] - x_next)
            lbg.extend([0.0] * self.nx)
            ubg.extend([0.0] * self.nx)
            # Path rows of node k+1, written through the stage's own variables (x_k, u_k)
            # so that each stage's slacks can relax them (see module docstring).
            slack = slacks[k]
            rows, low, high = [], [], []
            for point in self._stability_points(k, x_next):
                if edges is not None:
                    for n_x, n_y, bound, term in edges:
                        rows.append(n_x * point[0] + n_y * point[1] - slack[term])
                        low.append(-INF)
                        high.append(bound)
                    continue
                rows += [point[0] + slack[0], point[0] - slack[0]]
                rows += [point[1] + slack[1], point[1] - slack[1]]
                low += [-x_max, -INF, -y_max, -INF]
                high += [INF, x_max, INF, y_max]
            for distance, index, floor in self._edge_rows(k, xs[k], x_next, us[k]):
                rows.append(distance + slack[index])
                low.append(floor)
                high.append(INF)
            for ox, oy, radius2 in clear:
                rows.append((x_next[0] - ox) ** 2 + (x_next[1] - oy) ** 2 + slack[2])
                low.append(radius2)
                high.append(INF)
            if self.soft_joints:
                joints = model.configuration(x_next)[3:5]
                for i, (lo, hi) in enumerate(robot.joint_limits):
                    sigma = slack[self.joint_slacks.start + i]
                    rows += [joints[i] + sigma, joints[i] - sigma]
                    low += [lo, -INF]
                    high += [INF, hi]
            rows.append(model.wheel_rows(x_next, us[k]))
            low.extend([-model.wheel_limit] * 2)
            high.extend([model.wheel_limit] * 2)
            accelerations = model.acceleration_rows(xs[k], us[k])
            if accelerations is not None:  # no slack: u_k can always meet it
                row, limit = accelerations
                rows.append(row)
                low.extend([-limit[0], -limit[1]])
                high.extend([limit[0], limit[1]])
            g.append(ca.vertcat(*rows))
            ng.append(len(low))
            lbg.extend(low)
            ubg.extend(high)
        ng.append(0)
        #: the edge loads (N) the plan predicts at both ends of its first interval (the
        #: command's step), a function of (w, p); None without dynamic_stability
        self.first_edge_loads = (
            ca.Function("first_edge_loads", [self.w, self.p], [ca.vertcat(*self._first_loads)])
            if self._first_loads
            else None
        )
        self.g = ca.vertcat(*g)
        self.lbg, self.ubg = np.array(lbg), np.array(ubg)
        self.ng = ng
        self.residual = self._residual(nodes, xs, us, slacks)
        self._bounds_and_linear_cost()

    def _stability_points(self, k: int, x_next: sym.Symbolic) -> list[sym.Symbolic]:
        """The points held in the stability box for stage k: the centre of mass at node
        k+1, and at the last node also that of the pose where the joints, braked at their
        acceleration limit, come to rest."""
        robot, model = self.robot, self.model
        points = [sym.centre_of_mass(robot, model.configuration(x_next))]
        stop = model.stopping_configuration(x_next) if k == self.N - 1 else None
        if stop is not None:
            points.append(sym.centre_of_mass(robot, stop))
        return points

    def _edge_rows(
        self, k: int, x_k: sym.Symbolic, x_next: sym.Symbolic, u_k: sym.Symbolic
    ) -> list[tuple[Any, int, float]]:
        """(dynamic) Each edge's centre-of-pressure distance ``d_e = L_e D_e / W`` (m,
        :func:`ddwmmr.model.symbolic.edge_loads`) at both ends of interval k under u_k,
        as ``(expression, slack index, lower bound min_edge_load D_e)``: the edge's slack
        is the stability term's whose direction its normal is closest to. At the first
        stage without a joint lag the joints accelerate from the previous command's rates
        within the control step (the change of rates over dt), where an abrupt change of
        the arm's motion moves the centre of pressure most."""
        if not self.config.dynamic_stability:
            return []
        robot, model = self.robot, self.model
        polygon = EdgeLoadModel.from_robot(robot).polygon
        weight = robot.total_mass * GRAVITY_M_S2
        rows = []
        for end, x in enumerate((x_k, x_next)):
            motion = model.base_motion(x, u_k)
            if motion is None:
                raise ParameterError("dynamic_stability needs the force-level model (thesis)")
            v, w, v_dot, w_dot = motion
            joints = model.joint_motion(x, u_k)
            if joints is not None:
                rates, accelerations = joints  # the lagged arm: its own accelerations
            else:
                rates, accelerations = model.joint_rates(u_k), (0.0, 0.0)
                if k == 0 and end == 0:
                    previous = model.joint_rates(self.p[4 * self.N : 4 * self.N + self.num])
                    accelerations = (
                        (rates[0] - previous[0]) / self.dt,
                        (rates[1] - previous[1]) / self.dt,
                    )
            loads = sym.edge_loads(
                robot, model.configuration(x), rates, accelerations, (v_dot, v * w), w, w_dot
            )
            rows += self._edge_load_rows(polygon, loads, weight)
            if k == 0:
                self._first_loads += [loads[e] for e in range(len(polygon.depths))]
        stopped = model.stopped_arm_motion(x_next) if k == self.N - 1 else None
        if stopped is not None:
            # the last node's arm braked to rest: its momentum turns the base, and the
            # turn's sideways acceleration v w must leave every edge loaded too
            q_stop, v, w = stopped
            loads = sym.edge_loads(robot, q_stop, (0.0, 0.0), (0.0, 0.0), (0.0, v * w), w, 0.0)
            rows += self._edge_load_rows(polygon, loads, weight)
        return rows

    def _edge_load_rows(
        self, polygon: SupportPolygon, loads: sym.Symbolic, weight: float
    ) -> list[tuple[Any, int, float]]:
        """One ``(expression, slack index, lower bound)`` row per edge of ``polygon``: the
        edge's load ``loads[e]`` (N) scaled by ``depth / weight`` (m, the centre of mass's
        margin it is worth) at least ``min_edge_load * depth``; the slack of the
        longitudinal (0) or lateral (1) stability box by the edge's normal."""
        rows = []
        for e, (normal, depth) in enumerate(zip(polygon.normals, polygon.depths)):
            slack = 0 if is_longitudinal(normal[0], normal[1]) else 1
            lever = float(depth) / weight
            rows.append((loads[e] * lever, slack, self.config.min_edge_load * float(depth)))
        return rows

    def _bounds_and_linear_cost(self) -> None:
        config, model = self.config, self.model
        lower, upper = np.zeros(self.nw), np.zeros(self.nw)
        linear = np.zeros(self.nw)
        for k, s in enumerate(self._node_slices):
            low = np.concatenate([model.x_lower, [config.min_horizon] * self.n_horizons])
            high = np.concatenate([model.x_upper, config.longest_horizons()])
            if k == 0:
                low[: self.nxm], high[: self.nxm] = -INF, INF
            elif self.soft_joints:  # a path row of the stage before holds them
                low[3:5], high[3:5] = -INF, INF
            lower[s], upper[s] = low, high
        for s in self.u_slices:
            lower[s], upper[s] = model.u_lower, model.u_upper
        for s in self.slack_slices:
            lower[s], upper[s] = 0.0, INF
            linear[s] = SLACK_WEIGHT
        if config.reach:
            linear[self.horizon_index] = 1.0  # one unit of cost per second of horizon
        if config.legs == 2:
            linear[self.nxm + 1] = config.second_leg_weight
        self.w_lower, self.w_upper = lower, upper
        self.linear_cost = linear

    def _huber_scale(self, error: ca.SX, delta: float | None) -> ca.SX | float:
        if delta is None:
            return 1.0
        scale: ca.SX = ca.sqrt(2.0 / (1.0 + ca.sqrt(1.0 + ca.sumsqr(error) / delta**2)))
        return scale

    def _residual(
        self,
        nodes: Sequence[sym.Symbolic],
        xs: Sequence[sym.Symbolic],
        us: Sequence[sym.Symbolic],
        slacks: Sequence[sym.Symbolic],
    ) -> ca.SX:
        config, model, robot = self.config, self.model, self.robot
        weights, n, nu = config.weights, self.N, self.num
        refs = ca.reshape(self.p[: 4 * n], 4, n)  # x, y, phi, weight of nodes 1..N
        u_prev = self.p[4 * n : 4 * n + nu]
        nz = self.terminal_size
        factor = ca.reshape(self.p[4 * n + nu : 4 * n + nu + nz * nz], nz, nz).T  # row-major
        horizon_prev = self.p[-1]
        scale = np.asarray(model.u_scale, dtype=float)
        parts = []
        for k in range(n):
            h_k = self._interval(nodes, k)
            parts.append(ca.sqrt(weights.input * h_k) * us[k] / scale)
            parts.append(math.sqrt(SLACK_QUADRATIC) * slacks[k])
        if weights.input_change > 0.0:
            parts.append(math.sqrt(weights.input_change) * (us[0] - u_prev) / scale)
        poses = []
        for k in range(1, n + 1):
            q = model.configuration(xs[k])
            pose = sym.forward_kinematics(robot, q)
            poses.append(pose)
            ref = refs[:, k - 1]
            # The weight of node k uses node k's own copy of T (stage-wise structure).
            h_k = self._interval(nodes, k - 1, owner=k)
            error = pose[:2] - ref[:2]
            if weights.position > 0.0:
                # Nominal (unscaled) node weights: as T shrinks near the target the nodes
                # crowd towards now and the same weights make the approach more urgent.
                parts.append(
                    math.sqrt(weights.position * float(self.lengths[k - 1]))
                    * ca.sqrt(ref[3])
                    * self._huber_scale(error, config.huber)
                    * error
                )
            if config.track_orientation and weights.orientation > 0.0:
                parts.append(
                    ca.sqrt(weights.orientation * h_k)
                    * ca.vertcat(ca.cos(pose[2]) - ca.cos(ref[2]), ca.sin(pose[2]) - ca.sin(ref[2]))
                )
            if weights.manipulability > 0.0:
                parts.append(ca.sqrt(weights.manipulability * h_k) * ca.cos(q[4]))
        pose = poses[-1]  # node n's (n >= 2 intervals)
        target = refs[:, n - 1]
        error = pose[:2] - target[:2]
        if config.reach:
            parts.append(self._reach_cost(poses[self.split - 1], refs[:, self.split - 1], 1.0))
            if config.legs == 2:
                parts.append(self._reach_cost(pose, target, config.second_leg_weight))
            parts.append(math.sqrt(HORIZON_SMOOTHING) * (nodes[0][self.nxm] - horizon_prev))
            if self.arrival_size:
                parts.append(self._arrival_cost(xs[self.split]))
        elif weights.terminal > 0.0:
            z = self._terminal_error(xs[n], pose, target)
            parts.append(
                math.sqrt(weights.terminal)
                * ca.sqrt(target[3])
                * self._huber_scale(error, config.huber)
                * (factor.T @ z)
            )
        residual: ca.SX = ca.vertcat(*parts)
        return residual

    def _reach_cost(self, pose: sym.Symbolic, target: sym.Symbolic, weight: float) -> ca.SX:
        """The residual of a leg's reach cost at its last node's end-effector ``pose``:
        ``0.5 r^2 = weight huber(|e|) / reach_speed``, ``weight |e| / reach_speed`` seconds
        far from ``target``."""
        config = self.config
        error = pose[:2] - target[:2]
        delta = config.huber if config.huber is not None else 0.01
        gain = math.sqrt(weight) / math.sqrt(delta * config.reach_speed)
        residual: ca.SX = gain * self._huber_scale(error, delta) * error
        return residual

    def _arrival_cost(self, x: sym.Symbolic) -> ca.SX:
        """The residual of the first leg's last state ``x`` against the arrival state of
        the parameters: ``sqrt(arrival_weight) on [cos phi - cos phi_a, sin phi - sin
        phi_a, x[3:] - x_a[3:]]`` (joint angles, then velocities), ``on`` 1 or 0."""
        start = self._arrival_start
        target, on = self.p[start : start + self.nxm], self.p[start + self.nxm]
        heading = ca.vertcat(ca.cos(x[2]) - ca.cos(target[2]), ca.sin(x[2]) - ca.sin(target[2]))
        error = ca.vertcat(heading, x[3 : self.nxm] - target[3:])
        residual: ca.SX = math.sqrt(self.config.arrival_weight) * on * error
        return residual

    def _terminal_error(self, x_n: sym.Symbolic, pose: sym.Symbolic, ref: sym.Symbolic) -> ca.SX:
        """End-effector error in the terminal base frame (and the base velocities)."""
        phi = x_n[2]
        c, s = ca.cos(phi), ca.sin(phi)
        ex, ey = pose[0] - ref[0], pose[1] - ref[1]
        parts = [c * ex + s * ey, -s * ex + c * ey]
        if self.config.track_orientation:
            parts.append(ca.sin(pose[2] - ref[2]))
        if self.nxm > sym.NQ:
            parts.extend([x_n[5], x_n[6]])
        error: ca.SX = ca.vertcat(*parts)
        return error

    # -- numbers per solve ----------------------------------------------------------------
    def parameters(
        self,
        references: np.ndarray,
        u_prev: np.ndarray,
        terminal_factor: np.ndarray | None = None,
        node_weights: np.ndarray | None = None,
        horizon_prev: float | None = None,
        arrival: np.ndarray | None = None,
    ) -> np.ndarray:
        """Parameter vector: node references (N, 3), previous command (model input), ``L``
        (tracking), node tracking weights (N,; default 1), previous horizon (reach), the
        arrival state (model state; None: that term off) where the OCP has one."""
        n = self.N
        block = np.ones((n, 4))
        block[:, :3] = references
        if node_weights is not None:
            block[:, 3] = node_weights
        nz = self.terminal_size
        factor = np.eye(nz) if terminal_factor is None else terminal_factor
        previous = self.config.horizon if horizon_prev is None else horizon_prev
        parts = [block.ravel(), np.ravel(u_prev), np.ravel(factor)]
        if arrival is not None and np.size(arrival) != self.nxm:
            raise ValueError(f"arrival must be a state of {self.nxm} numbers")
        if self.arrival_size:
            on = arrival is not None
            state = np.ravel(arrival) if arrival is not None else np.zeros(self.nxm)
            parts += [state, np.array([float(on)])]
        return np.concatenate([*parts, [previous]]).astype(float)

    def bounds(self, x0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Decision bounds with the model state of node 0 pinned to the measured ``x0``."""
        lower, upper = self.w_lower.copy(), self.w_upper.copy()
        s = self.x_slices[0]
        lower[s] = upper[s] = x0
        return lower, upper

    def max_slack(self, w: np.ndarray) -> float:
        """The largest slack of the stability and obstacle rows of a solution (0: all
        met). The joint box's slack is left out: it is the measured joint past its limit
        (MuJoCo lets a joint overrun its range by a few mrad) or its braking distance,
        which no restart of the plan changes (:meth:`max_joint_slack`)."""
        return float(np.max(w[self.slack_index[:, : self.joint_slacks.start]]))

    def max_joint_slack(self, w: np.ndarray) -> float:
        """The largest slack of the joint box (rad, either joint; 0 where the box is
        bounds)."""
        if not self.soft_joints:
            return 0.0
        return float(np.max(w[self.slack_index[:, self.joint_slacks]]))

    def max_stability_slack(self, w: np.ndarray) -> float:
        """The largest slack of the stability rows (m, in the box on the centre of mass
        and the zero moment point; the obstacle rows' slack, in m^2, left out)."""
        return float(np.max(w[self.slack_index[:, :2]]))

    def first_input(self, w: np.ndarray) -> np.ndarray:
        """``u_0`` of a solution (the model's input, without slacks)."""
        return np.asarray(w[self.u_slices[0]], dtype=float)

    def horizon_of(self, w: np.ndarray) -> float:
        """The horizon T (s) of a solution (the fixed horizon in tracking mode; the first
        leg's with two)."""
        index = self.horizon_index
        return self.config.horizon if index is None else float(w[index])

    def second_leg_of(self, w: np.ndarray) -> float | None:
        """The second leg's duration ``T2`` (s) of a solution, None with one leg."""
        return float(w[self.nxm + 1]) if self.config.legs == 2 else None

    def trajectories(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Node states (N+1, nx) and stage inputs with slacks (N, nu) of a solution."""
        w = np.asarray(w, dtype=float).ravel()
        nx, nu, n = self.nx, self.nu, self.N
        xs = np.empty((n + 1, nx))
        body = w[: n * (nx + nu)].reshape(n, nx + nu)
        xs[:n] = body[:, :nx]
        xs[n] = w[n * (nx + nu) :]
        return xs, body[:, nx:].copy()

    def pack(self, xs: np.ndarray, us: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`trajectories`."""
        n = self.N
        body = np.hstack([xs[:n], us])
        return np.concatenate([body.ravel(), xs[n]])


#: Bounds of the shooting grid: interval count, shortest interval and longest horizon (s).
MAX_INTERVALS, MIN_INTERVAL, MAX_HORIZON = 200, 1e-4, 100.0


def shooting_grid(intervals: int, dt: float, first: float, horizon: float) -> np.ndarray:
    """The ``intervals`` lengths (s) of the shooting grid: the control step ``dt``, then
    ``intervals - 1`` lengths growing geometrically from ``first`` to fill the rest of
    ``horizon`` (:func:`grid_intervals`; with ``intervals = 2`` the one length after ``dt``
    is that whole rest, at least ``first``).

    The one check of a grid, for the options (:meth:`ddwmmr.mpc.options.MPCOptions.grid`)
    and the OCP alike: ``intervals`` an integer in [2, :data:`MAX_INTERVALS`], ``dt`` > 0,
    ``first`` and ``horizon`` in [:data:`MIN_INTERVAL`, :data:`MAX_HORIZON`] s,
    ``horizon > dt`` and ``horizon >= dt + (intervals - 1) first``; else a one-line
    :class:`ParameterError` naming the parameter (:func:`check_step_in_horizon` first).
    """
    n = check_int_at_least("intervals", intervals, 2, MAX_INTERVALS)
    horizon = check_range("horizon", horizon, MIN_INTERVAL, MAX_HORIZON, "s")
    dt = check_step_in_horizon(dt, horizon, n)
    first = check_range("first_interval", first, MIN_INTERVAL, MAX_HORIZON, "s")
    least = dt + (n - 1) * first
    if horizon - dt < (n - 1) * first * (1.0 - 1e-9):
        raise ParameterError(
            f"horizon must be >= dt + (intervals - 1) x first_interval = {least:g} s "
            f"(got {horizon:g})"
        )
    rest = horizon - dt
    if rest <= (n - 1) * first * (1.0 + 1e-12):  # equal lengths (within rounding: no ratio)
        return np.concatenate([[dt], np.full(n - 1, rest / (n - 1))])
    return np.concatenate([[dt], grid_intervals(n - 1, first, rest)])


def check_step_in_horizon(dt: float, horizon: float, intervals: int) -> float:
    """The control step ``dt`` (s, at least :data:`MIN_INTERVAL`, as every interval of
    the plan: the OCP's first interval is ``dt``) if it leaves room in ``horizon`` (s) for
    the ``intervals - 1`` later intervals of at least :data:`MIN_INTERVAL` each, else a
    one-line :class:`ParameterError` naming ``dt``.

    Checked before ``first_interval``: the controller derives that from the horizon's
    rest, ``(horizon - dt) / (intervals - 1)`` when it is shorter, so a loop step as long
    as the horizon would otherwise be refused as a first interval the user never set.
    """
    dt = check_positive("dt", dt)
    if dt < MIN_INTERVAL:
        raise ParameterError(
            f"dt: the mpc's step must be >= {MIN_INTERVAL:g} s, the least interval of its "
            f"plan (got {dt:g})"
        )
    if not horizon > dt:
        raise ParameterError(
            f"dt: the mpc's step must be < its horizon, {horizon:g} s (got {dt:g})"
        )
    if (horizon - dt) / (intervals - 1) < MIN_INTERVAL:
        room = horizon - (intervals - 1) * MIN_INTERVAL
        raise ParameterError(
            f"dt: the mpc's step must leave its {intervals - 1} later intervals at least "
            f"{MIN_INTERVAL:g} s each of its {horizon:g} s horizon, <= {room:g} s (got {dt:g})"
        )
    return dt


def grid_intervals(intervals: int, first: float, horizon: float) -> np.ndarray:
    """``intervals`` lengths ``first r^k`` (s), r >= 1 chosen so that they sum to
    ``horizon`` (``intervals`` = 1: ``[horizon]``, which must be >= ``first``)."""
    n = check_int_at_least("intervals", intervals, 1, MAX_INTERVALS)
    first = check_range("first_interval", first, MIN_INTERVAL, MAX_HORIZON, "s")
    horizon = check_range("horizon", horizon, MIN_INTERVAL, MAX_HORIZON, "s")
    if horizon < n * first * (1.0 - 1e-9):
        raise ParameterError(
            f"horizon must be >= intervals x first_interval = {n * first:g} s (got {horizon:g})"
        )
    if n == 1 or horizon <= n * first * (1.0 + 1e-12):
        return np.full(n, horizon / n)
    low, high = 1.0, 2.0
    while first * (high**n - 1.0) / (high - 1.0) < horizon:
        high *= 2.0
    for _ in range(200):  # bisection on the geometric sum
        ratio = 0.5 * (low + high)
        if first * (ratio**n - 1.0) / (ratio - 1.0) < horizon:
            low = ratio
        else:
            high = ratio
    lengths = first * (0.5 * (low + high)) ** np.arange(n)
    scaled: np.ndarray = lengths * (horizon / lengths.sum())
    return scaled


def substeps(length: float) -> int:
    """The RK4 sub-steps of an interval of nominal ``length`` (s): the fewest equal ones
    at most :data:`MAX_SUBSTEP` long (a reach plan's free horizon only shortens them)."""
    return max(1, math.ceil(length / MAX_SUBSTEP - 1e-9))


def longest_substep(lengths: Sequence[float] | np.ndarray) -> float:
    """The longest RK4 sub-step (s) of intervals of nominal ``lengths`` (s)."""
    return max(float(length) / substeps(float(length)) for length in lengths)


def largest_cosine(low: float, high: float) -> float:
    """The largest ``cos th`` over ``th`` in [low, high] (rad): 1 where the range holds a
    multiple of 2 pi, else the cosine at the end nearer one."""
    turn = 2.0 * math.pi
    if turn * math.ceil(low / turn) <= high:
        return 1.0
    return max(math.cos(low), math.cos(high))


def base_time_constants(
    dynamics: sym.ThesisDynamics, elbow: tuple[float, float]
) -> tuple[float, float]:
    """The force model's time constants (s): ``m / c1`` of the base's speed and the
    longest ``I / c2`` of its yaw rate over the elbow's joint range ``elbow`` (rad), at its
    largest yaw inertia ``I(th2) = inertia_fixed + inertia_cos cos th2`` (``inertia_cos >=
    0``: the arm stretched as far as the range allows); infinite for an undamped motion
    (c = 0)."""
    inertia = dynamics.inertia_fixed + dynamics.inertia_cos * largest_cosine(*elbow)
    return (
        dynamics.mass / dynamics.c1 if dynamics.c1 > 0.0 else math.inf,
        inertia / dynamics.c2 if dynamics.c2 > 0.0 else math.inf,
    )


def check_integrable(
    dynamics: sym.ThesisDynamics, elbow: tuple[float, float], substep: float
) -> None:
    """Refuse, in one line naming c1 and/or c2, their time constants and the sub-step, a
    base damped too stiffly for the force model's RK4 at sub-steps up to ``substep`` (s,
    :func:`longest_substep` of the plan's intervals).

    The damping makes the base's speeds first-order lags, ``v' = (F - c1 v) / m`` and
    ``w' = (T - c2 w) / I(th2)`` (the lagged arm's yaw momentum ``L = I w + H`` alike,
    ``L' = T - c2 (L - H) / I``), with time constants ``tau = m / c1`` and ``I / c2``;
    every other state integrates these or moves at a commanded rate. One RK4 sub-step
    ``h`` scales such a lag's own response by ``R(-h / tau)``, ``R(z) = 1 + z + z^2/2 +
    z^3/6 + z^4/24``, which stays within [0.27, 1] up to ``h / tau = 2.785``
    (:data:`~ddwmmr.gains.STABLE_GAIN_STEP` ``"rk4"``, the real root of ``x^3 - 4 x^2 + 12
    x - 24``, where R is 1 again) and exceeds 1 beyond it: the predicted speed then grows
    every sub-step instead of decaying. A lag at the limit or within it is taken. The
    yaw's time constant depends on the elbow; it is taken at the pose of largest yaw
    inertia (:func:`base_time_constants`), so that only a base the model cannot follow at
    any pose of the elbow's range is refused: one unstable near the folded arm only runs,
    as its plans keep away from that pose (docs/mpc.md, "python-control: the linear
    designs", its stiff-base item). Sub-steps are at most :data:`MAX_SUBSTEP` (0.2 s),
    so a time constant of 0.072 s or more is always taken: the thesis's base has 0.88 s
    and 0.15-0.33 s (``Robot()``, c1 = 15 N s/m, c2 = 4 N m s/rad), and the damping the
    thesis plant derives for another robot keeps its time constants (docs/thesis.md,
    "Another robot's constants")."""
    limit = STABLE_GAIN_STEP["rk4"]
    tau_v, tau_w = base_time_constants(dynamics, elbow)
    stiff = [
        (name, value, unit, what, tau)
        for name, value, unit, what, tau in (
            ("c1", dynamics.c1, "N s/m", "m / c1", tau_v),
            ("c2", dynamics.c2, "N m s/rad", "I / c2", tau_w),
        )
        if substep > limit * tau
    ]
    if not stiff:
        return
    dampings = " and ".join(f"{name} = {value:g} {unit}" for name, value, unit, _, _ in stiff)
    constants = " and ".join(f"{what} = {tau:.3g} s" for _, _, _, what, tau in stiff)
    most = " and ".join(  # the damping whose time constant is substep / limit
        f"{name} <= {round_significant(value * tau * limit / substep, 3, math.floor):g} {unit}"
        for name, value, unit, _, tau in stiff
    )
    longest = round_significant(limit * min(tau for *_, tau in stiff), 3, math.floor)
    finer = (
        f", a plan whose intervals are all at most {longest:g} s (dt, horizon, "
        "intervals, first_interval)"
        if longest >= MIN_INTERVAL
        else ""
    )
    verb, plural = ("make", "s") if len(stiff) > 1 else ("makes", "")
    raise ParameterError(
        f"mpc: the force model cannot plan for this base: {dampings} {verb} its time "
        f"constant{plural} {constants}, and its RK4 sub-steps of up to {substep:.3g} s "
        f"follow a lag only up to {limit:.4g} time constants long; "
        f"give the plant {most}{finer} or use model='kinematic'"
    )
