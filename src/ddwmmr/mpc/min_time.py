"""The physical limit of a scenario: minimum time under the thesis plant's force limits.

A free-final-time optimal control problem over the scenario's waypoints, solved offline
with CasADi/IPOPT. Leg ``i`` (start or waypoint ``i-1`` -> waypoint ``i``) has its own
duration ``T_i`` and ``M`` shooting intervals of length ``T_i / M``; the thesis plant's
force-level model (:class:`~ddwmmr.model.symbolic.ThesisDynamics`) is integrated with RK4
under piecewise-constant wheel forces and joint rates::

    minimise    sum_i T_i
    subject to  x_{k+1} = RK4(x_k, u_k, T_i / M)                 (every interval of leg i)
                |p_E(x_end of leg i) - waypoint_i| <= tolerance   (the end effector reaches it)
                S(q) >= S_min at every node and 3 points inside every interval (exact,
                    as a box on the centre of mass)
                |F_left|, |F_right| <= force limit, |th_i dot| <= joint speed,
                joint limits, wheel speeds, x_0 = start at rest.

The arm's reach is part of the problem (the end effector, not the base, must reach each
waypoint). The problem is non-convex (heading, elbow branch), so IPOPT returns a local
optimum: the time of a feasible trajectory of the model, i.e. an upper bound on the true
minimum. Started from the trajectories of the controllers being compared (and from a
straight-line guess), it is never worse than any of them; ``solve_minimum_time`` keeps the
best of its starts.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ddwmmr.errors import ParameterError, check_positive
from ddwmmr.model import Robot
from ddwmmr.model import symbolic as sym
from ddwmmr.model.stability import STABILITY_FLOOR, check_stability_floor

#: Points inside each shooting interval where S is checked as well as at the nodes.
INTERIOR_CHECKS = 3


@dataclass(frozen=True)
class Guess:
    """A trajectory to start from: node times (s), states (n, 7), inputs (n, 4), and the
    times (s) at which each waypoint was reached."""

    times: np.ndarray
    states: np.ndarray
    inputs: np.ndarray
    arrivals: np.ndarray


@dataclass(frozen=True)
class MinimumTime:
    """Result: total time (s), leg durations (s), success flag, node times/states/inputs."""

    total: float
    legs: np.ndarray
    success: bool
    times: np.ndarray
    states: np.ndarray
    inputs: np.ndarray
    start: str


class MinimumTimeProblem:
    """The NLP for one set of waypoints (build once per scenario, solve from several starts).

    Args:
        robot: robot with payload; dynamics: the plant model (default: thesis constants).
        waypoints: end-effector targets (m, world) in order.
        start: start state ``[x, y, phi, th1, th2, v, w]`` (at rest).
        intervals_per_leg: M.
        stability_min: floor on S; tolerance: waypoint radius (m).
    """

    def __init__(
        self,
        robot: Robot,
        waypoints: Sequence[tuple[float, float]],
        start: Sequence[float],
        dynamics: sym.ThesisDynamics | None = None,
        intervals_per_leg: int = 30,
        stability_min: float = STABILITY_FLOOR,
        tolerance: float = 0.01,
    ) -> None:
        if intervals_per_leg < 2:
            raise ParameterError(f"intervals_per_leg must be >= 2 (got {intervals_per_leg})")
        self.robot = robot
        self.dynamics = dynamics or sym.ThesisDynamics.from_robot(robot)
        self.waypoints = [tuple(map(float, w)) for w in waypoints]
        self.start = np.asarray(start, dtype=float)
        self.M = int(intervals_per_leg)
        self.legs = len(self.waypoints)
        self.tolerance = check_positive("tolerance", tolerance)
        self.stability_min = check_stability_floor(stability_min)
        self._build()

    def _build(self) -> None:
        nx, nu = sym.NX_FORCE, sym.NU_FORCE
        n = self.legs * self.M
        d, robot = self.dynamics, self.robot
        X = ca.MX.sym("X", nx, n + 1)
        U = ca.MX.sym("U", nu, n)
        T = ca.MX.sym("T", self.legs)
        xs, us = ca.SX.sym("x", nx), ca.SX.sym("u", nu)
        hs = ca.SX.sym("h")
        step = ca.Function("step", [xs, us, hs], [sym.rk4_step(d.rhs, xs, us, hs)])
        com = ca.Function("com", [xs], [sym.centre_of_mass(robot, xs[:5])])
        fk = ca.Function("fk", [xs], [sym.forward_kinematics(robot, xs[:5])[:2]])
        wheels = ca.Function("wheels", [xs], [sym.wheel_speeds(robot, xs[5], xs[6])])
        h_all = ca.repmat(T.T / self.M, self.M, 1)  # (M, legs): interval lengths, leg-major
        h_row = ca.reshape(h_all, 1, n)
        gaps = step.map(n)(X[:, :-1], U, h_row) - X[:, 1:]
        x_max, y_max = sym.stability_bounds(robot, self.stability_min)
        coms = com.map(n + 1)(X)
        # Between nodes the joint angles move linearly (constant rates): S is also checked
        # at INTERIOR_CHECKS points inside every interval, so it holds along the motion.
        interior = []
        for frac in np.arange(1, INTERIOR_CHECKS + 1) / (INTERIOR_CHECKS + 1):
            offset = ca.repmat(frac * h_row, 2, 1) * U[2:4, :]
            moved = ca.vertcat(X[:3, :-1], X[3:5, :-1] + offset, X[5:, :-1])
            interior.append(ca.vec(com.map(n)(moved)))
        wheel = wheels.map(n + 1)(X)
        reach = []
        for i, (wx, wy) in enumerate(self.waypoints):
            e = fk(X[:, (i + 1) * self.M]) - ca.DM([wx, wy])
            reach.append(ca.sumsqr(e))
        g = ca.vertcat(ca.vec(gaps), ca.vec(coms), *interior, ca.vec(wheel), *reach)
        limit = robot.wheel_speed_limit
        boxes = n + 1 + INTERIOR_CHECKS * n
        self.lbg = np.concatenate(
            [
                np.zeros(nx * n),
                np.tile([-x_max, -y_max], boxes),
                np.full(2 * (n + 1), -limit),
                np.zeros(self.legs),
            ]
        )
        self.ubg = np.concatenate(
            [
                np.zeros(nx * n),
                np.tile([x_max, y_max], boxes),
                np.full(2 * (n + 1), limit),
                np.full(self.legs, self.tolerance**2),
            ]
        )
        w = ca.vertcat(ca.vec(X), ca.vec(U), T)
        self._X, self._U, self._T = X, U, T
        self.n = n
        regular = 1e-6 * ca.sumsqr(U / ca.DM([d.force_limit, d.force_limit, 1.0, 1.0]))
        nlp = {"x": w, "f": ca.sum1(T) + regular, "g": g}
        self.solver = ca.nlpsol(
            "min_time",
            "ipopt",
            nlp,
            {
                "print_time": False,
                "ipopt.print_level": 0,
                "ipopt.sb": "yes",
                "ipopt.max_iter": 3000,
                "ipopt.tol": 1e-7,
                "error_on_fail": False,
            },
        )
        lower_x = np.full((nx, n + 1), -np.inf)
        upper_x = np.full((nx, n + 1), np.inf)
        (lo1, hi1), (lo2, hi2) = robot.joint_limits
        lower_x[3], upper_x[3] = lo1, hi1
        lower_x[4], upper_x[4] = lo2, hi2
        lower_x[:, 0] = upper_x[:, 0] = self.start
        rate = min(d.joint_speed, robot.joint_speed_limit)
        u_lim = np.array([d.force_limit, d.force_limit, rate, rate])
        lower_u = np.tile(-u_lim[:, None], (1, n))
        upper_u = np.tile(u_lim[:, None], (1, n))
        self.lbw = np.concatenate(
            [lower_x.ravel(order="F"), lower_u.ravel(order="F"), np.full(self.legs, 0.05)]
        )
        self.ubw = np.concatenate(
            [upper_x.ravel(order="F"), upper_u.ravel(order="F"), np.full(self.legs, 120.0)]
        )

    # -- initial guesses ----------------------------------------------------------------
    def straight_line_guess(
        self, speed: float = 0.9, turn_time: float = 1.5, reverse: str = "never", elbow: float = 1.0
    ) -> Guess:
        """Base along the straight legs between the waypoints at ``speed`` (m/s).

        ``reverse``: ``"never"`` (drive forwards), ``"always"`` (backwards) or ``"turn"``
        (per leg, whichever needs the smaller heading change). ``elbow`` (+-1) is the sign
        of th2 in the guess (the arm keeps the start pose's |th2|).
        """
        points = [self.start[:2], *[np.array(w) for w in self.waypoints]]
        arrivals, headings, signs, t = [], [], [], 0.0
        heading_prev = float(self.start[2])
        for a, b in itertools.pairwise(points):
            t += float(np.linalg.norm(b - a)) / speed + turn_time
            arrivals.append(t)
            forward = math.atan2(b[1] - a[1], b[0] - a[0])
            backward = forward + math.pi
            change_f = abs(math.remainder(forward - heading_prev, 2 * math.pi))
            change_b = abs(math.remainder(backward - heading_prev, 2 * math.pi))
            back = reverse == "always" or (reverse == "turn" and change_b < change_f)
            heading = backward if back else forward
            headings.append(heading)
            signs.append(-1.0 if back else 1.0)
            heading_prev = heading
        times = np.linspace(0.0, t, 400)
        states = np.zeros((len(times), sym.NX_FORCE))
        th1, th2 = self.start[3], math.copysign(abs(self.start[4]), elbow)
        for j, tj in enumerate(times):
            leg = min(int(np.searchsorted(arrivals, tj)), self.legs - 1)
            t0 = 0.0 if leg == 0 else arrivals[leg - 1]
            frac = min(1.0, (tj - t0) / (arrivals[leg] - t0))
            a, b = points[leg], points[leg + 1]
            states[j, :2] = a + frac * (b - a)
            states[j, 2] = headings[leg]
            states[j, 3:5] = (th1 if elbow > 0 else -th1), th2
            states[j, 5] = signs[leg] * speed
        states[:, 2] = np.unwrap(states[:, 2])
        return Guess(times, states, np.zeros((len(times), sym.NU_FORCE)), np.array(arrivals))

    def _initial(self, guess: Guess) -> np.ndarray:
        arrivals = np.asarray(guess.arrivals, dtype=float)[: self.legs]
        legs = np.diff(np.concatenate([[0.0], arrivals]))
        node_times = np.concatenate(
            [t0 + legs[i] * np.arange(self.M) / self.M for i, t0 in enumerate(arrivals - legs)]
            + [[arrivals[-1]]]
        )
        states = np.column_stack(
            [np.interp(node_times, guess.times, guess.states[:, i]) for i in range(sym.NX_FORCE)]
        )
        states[0] = self.start
        inputs = np.column_stack(
            [
                np.interp(node_times[:-1], guess.times, guess.inputs[:, i])
                for i in range(sym.NU_FORCE)
            ]
        )
        return np.concatenate([states.T.ravel(order="F"), inputs.T.ravel(order="F"), legs])

    # -- solve --------------------------------------------------------------------------
    def solve(self, guess: Guess, label: str = "guess") -> MinimumTime:
        """Solve from one initial guess."""
        w0 = np.clip(self._initial(guess), self.lbw, self.ubw)
        solution = self.solver(x0=w0, lbx=self.lbw, ubx=self.ubw, lbg=self.lbg, ubg=self.ubg)
        success = bool(self.solver.stats().get("success", False))
        w = np.asarray(solution["x"], dtype=float).ravel()
        nx, nu, n = sym.NX_FORCE, sym.NU_FORCE, self.n
        states = w[: nx * (n + 1)].reshape(n + 1, nx)
        inputs = w[nx * (n + 1) : nx * (n + 1) + nu * n].reshape(n, nu)
        legs = w[-self.legs :]
        node_times = np.concatenate([[0.0], np.cumsum(np.repeat(legs / self.M, self.M))])
        return MinimumTime(float(legs.sum()), legs, success, node_times, states, inputs, label)


def solve_minimum_time(
    problem: MinimumTimeProblem, guesses: dict[str, Guess] | None = None
) -> MinimumTime:
    """Best successful solution over the straight-line guess and ``guesses``.

    Raises :class:`RuntimeError` if no start converges.
    """
    starts = {
        f"straight-{reverse}-{'up' if elbow > 0 else 'down'}": problem.straight_line_guess(
            reverse=reverse, elbow=elbow
        )
        for reverse in ("never", "turn")
        for elbow in (1.0, -1.0)
    }
    starts.update(guesses or {})
    best: MinimumTime | None = None
    for label, guess in starts.items():
        result = problem.solve(guess, label)
        if result.success and (best is None or result.total < best.total):
            best = result
    if best is None:
        raise RuntimeError("minimum-time OCP: no start converged")
    return best


def minimum_time(
    robot: Robot,
    waypoints: Sequence[tuple[float, float]],
    start: Sequence[float],
    guesses: dict[str, Guess] | None = None,
    **options,
) -> MinimumTime:
    """Minimum time (s) to take the end effector through ``waypoints`` in order from the
    ``start`` state ``[x, y, phi, th1, th2, v, w]`` under the thesis plant's force limits
    and ``S >= stability_min``: the best local optimum over the straight-line starts and
    ``guesses`` (see the module docstring). ``options`` go to :class:`MinimumTimeProblem`."""
    problem = MinimumTimeProblem(robot, waypoints, start, **options)
    return solve_minimum_time(problem, guesses)


def verify(problem: MinimumTimeProblem, result: MinimumTime) -> dict[str, float]:
    """Independent check of a solution by re-integrating its inputs on a fine grid.

    Returns the largest waypoint miss (m, at the leg ends), the smallest S over the fine
    grid and the largest force and joint rate used.
    """
    d, robot = problem.dynamics, problem.robot
    x, u = ca.SX.sym("x", sym.NX_FORCE), ca.SX.sym("u", sym.NU_FORCE)
    h = ca.SX.sym("h")
    step = ca.Function("step", [x, u, h], [sym.rk4_step(d.rhs, x, u, h)])
    state = np.asarray(result.states[0], dtype=float)
    refine = 10
    lowest_s, misses = math.inf, []
    for k, command in enumerate(result.inputs):
        length = (result.times[k + 1] - result.times[k]) / refine
        for _ in range(refine):
            state = np.asarray(step(state, command, length), dtype=float).ravel()
            lowest_s = min(lowest_s, robot.stability(state[:5])[2])
        if (k + 1) % problem.M == 0:
            leg = (k + 1) // problem.M - 1
            xe, ye, _ = robot.fk(state[:5])
            wx, wy = problem.waypoints[leg]
            misses.append(math.hypot(xe - wx, ye - wy))
    return {
        "max_miss_m": float(max(misses)),
        "min_stability": float(lowest_s),
        "max_force_n": float(np.max(np.abs(result.inputs[:, :2]))),
        "max_joint_rate": float(np.max(np.abs(result.inputs[:, 2:]))),
    }
