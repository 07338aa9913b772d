"""One OCP of the ``mpc`` controller with its solvers, terminal cost and warm-start shift.

The OCP may plan in the robot's own length unit (docs/mpc.md, "Robot size"): its robot and
model are then the robot with every length divided by the unit, and :class:`Problem`
converts what crosses its boundary (the measured state, the references, the previous
command in; the command and the slacks out) between metres and that unit.
"""

from __future__ import annotations

from collections.abc import Hashable

import numpy as np

from ddwmmr.model import Robot
from ddwmmr.mpc import terminal
from ddwmmr.mpc.cache import shared_ocp
from ddwmmr.mpc.min_time import Guess
from ddwmmr.mpc.models import PredictionModel
from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP
from ddwmmr.mpc.solvers import make_solver

#: Gauss-Newton iterations of a cold start (first step, new target, after a fallback).
COLD_ITERATIONS = 5


class Problem:
    """One OCP (:func:`ddwmmr.mpc.cache.shared_ocp`) with its solvers, terminal design and
    warm-start shifting.

    Args:
        robot, choice, model, config: what the OCP is built from (see
            :func:`~ddwmmr.mpc.cache.shared_ocp`).
        solver, qp_solver, proximal: the ``mpc``'s solver options; a real-time iteration
            (``"rti"``) starts cold with ``cold_iterations`` Gauss-Newton iterations
            (default :data:`COLD_ITERATIONS`).
        unit: the length (m) the OCP measures lengths in (``robot`` and ``model`` already
            in it, :meth:`~ddwmmr.model.Robot.in_length_unit`); 1.0: metres. Only the
            kinematic model's state and input hold lengths it converts (positions, ``v``).
    """

    def __init__(
        self,
        robot: Robot,
        choice: Hashable,
        model: PredictionModel,
        config: OCPConfig,
        solver: str,
        qp_solver: str,
        proximal: float,
        cold_iterations: int = COLD_ITERATIONS,
        unit: float = 1.0,
    ) -> None:
        self.robot, self.model, self.unit = robot, model, unit
        self.ocp = shared_ocp(robot, choice, model, config)
        self.solver = make_solver(solver, self.ocp, qp_solver, proximal=proximal)
        self.cold = (
            make_solver("sqp", self.ocp, qp_solver, iterations=cold_iterations)
            if solver == "rti"
            else self.solver
        )
        self.terminal_factor: np.ndarray | None = None
        #: the parameters of the last solve (the plan's predictions are functions of them)
        self.last_parameters: np.ndarray | None = None

    def design_terminal(self, arm_pose: tuple[float, float]) -> None:
        """LQR terminal cost at the arm pose (tracking only)."""
        if self.ocp.config.reach:
            return
        design = terminal.design(self.robot, self.model, self.ocp.config, arm_pose)
        self.terminal_factor = design.factor

    def _initial(self, x0: np.ndarray) -> np.ndarray:
        ocp = self.ocp
        node = np.concatenate([x0, ocp.config.longest_horizons()])
        return ocp.pack(np.tile(node, (ocp.N + 1, 1)), np.zeros((ocp.N, ocp.nu)))

    def planned_start(self, x0: np.ndarray, plan: Guess, leg: int) -> tuple[np.ndarray, float]:
        """A cold start from ``plan``: its leg ``leg`` (0-based; with two legs also the
        next, or the longest second leg after the plan's last) re-sampled at this OCP's node
        times, each duration the plan's within the OCP's bounds, node 0 the measured
        ``x0``, no slack. ``x0`` and the plan in metres (m, m/s), ``w`` in the OCP's unit.
        Returns ``(w, T)``, T the first leg's duration (s)."""
        ocp, config = self.ocp, self.ocp.config
        durations = plan.legs
        horizon = float(np.clip(durations[leg], config.min_horizon, config.horizon))
        second = None
        if ocp.n_horizons == 2:
            following = durations[leg + 1] if leg + 1 < len(durations) else np.inf
            second = float(np.clip(following, config.min_horizon, config.second_leg_horizon))
        states, inputs = plan.leg_samples(leg, ocp.node_times(horizon, second))
        if self.unit != 1.0:
            x0, states = self._states_in_unit(x0), self._states_in_unit(states)
            inputs = self._inputs_in_unit(inputs)
        xs, us = np.zeros((ocp.N + 1, ocp.nx)), np.zeros((ocp.N, ocp.nu))
        xs[:, : ocp.nxm], us[:, : ocp.num] = states, inputs[:-1]
        xs[:, ocp.nxm] = horizon
        if second is not None:
            xs[:, ocp.nxm + 1] = second
        xs[0, : ocp.nxm] = x0
        return ocp.pack(xs, us), horizon

    def planned_arrival(self, plan: Guess, leg: int) -> np.ndarray | None:
        """The state ``plan`` reaches the end of leg ``leg`` (0-based) in, for this OCP's
        arrival term, in the OCP's unit (the plan in metres); None where the OCP has none or
        the leg is the plan's last (how the task's last waypoint is reached does not
        matter)."""
        if not self.ocp.arrival_size or leg + 1 >= len(plan.legs):
            return None
        state = plan.arrival_states[leg]
        return state if self.unit == 1.0 else self._states_in_unit(state)

    def _shifted(
        self, warm: np.ndarray, elapsed: float, x0: np.ndarray, source: ShootingOCP | None = None
    ) -> tuple[np.ndarray, float]:
        """The previous solution moved ``elapsed`` s forward (linear interpolation).

        ``source``: the two-leg OCP the solution came from when its first target was just
        reached (the hand-over to the next target): its second leg becomes this OCP's
        first, held at its end beyond; a new second leg starts at its longest."""
        ocp = self.ocp
        handover = source is not None
        source = source or ocp
        old_xs, us = source.trajectories(warm)
        old_horizon, second = source.horizon_of(warm), source.second_leg_of(warm)
        old_t = source.node_times(old_horizon, second)
        horizon = old_horizon
        if handover:  # the new second leg starts at its longest
            horizon, second = old_horizon + (second or 0.0), ocp.config.second_leg_horizon
        if ocp.config.reach:
            horizon = min(max(horizon - elapsed, ocp.config.min_horizon), ocp.config.horizon)
        new_t = ocp.node_times(horizon, second) + elapsed
        xs = np.empty((ocp.N + 1, ocp.nx))
        xs[:, : ocp.nxm] = interpolate_rows(old_t, old_xs[:, : ocp.nxm], new_t)
        us = interpolate_rows(old_t[:-1], us, new_t[:-1])
        if ocp.config.reach:
            xs[:, ocp.nxm] = horizon
        if ocp.n_horizons == 2:
            xs[:, ocp.nxm + 1] = second
        xs[0, : ocp.nxm] = x0
        return ocp.pack(xs, us), horizon

    def solve(
        self,
        t: float,
        x0: np.ndarray,
        references: np.ndarray,
        u_prev: np.ndarray,
        warm: np.ndarray | None,
        warm_time: float,
        source: ShootingOCP | None = None,
        start: tuple[np.ndarray, float] | None = None,
        arrival: np.ndarray | None = None,
    ) -> tuple[np.ndarray, int]:
        """Solve from the shifted warm start (or cold); returns (w, iterations). With a
        ``source`` (a hand-over, :meth:`_shifted`) the shifted plan starts the cold
        start's iterations; without a warm start, ``start`` (``(w, T)``,
        :meth:`planned_start`) does instead of the standing guess. ``arrival``: the state
        the first leg's arrival term pulls towards (:meth:`planned_arrival`), None: off.
        ``x0``, ``references`` and ``u_prev`` in metres (m, m/s); ``w`` in the OCP's unit
        (:meth:`first_input` reads the command from it)."""
        ocp = self.ocp
        if self.unit != 1.0:
            x0, references, u_prev = self._in_unit(x0, references, u_prev)
        if warm is None and start is not None:
            (guess, horizon), solver = start, self.cold
        elif warm is None:
            guess, horizon, solver = self._initial(x0), ocp.config.horizon, self.cold
        else:
            guess, horizon = self._shifted(warm, max(0.0, t - warm_time), x0, source)
            solver = self.solver if source is None else self.cold
        p = ocp.parameters(
            references, u_prev, self.terminal_factor, horizon_prev=horizon, arrival=arrival
        )
        self.last_parameters = p
        lbw, ubw = ocp.bounds(x0)
        w = solver.solve(guess, p, lbw, ubw, ocp.lbg, ocp.ubg)
        return w, solver.last_iterations

    def _in_unit(
        self, x0: np.ndarray, references: np.ndarray, u_prev: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The kinematic model's state, references (N, 3) and input with their positions
        (m) and ``v`` (m/s) in the OCP's unit."""
        return (
            self._states_in_unit(x0),
            self._states_in_unit(references),
            self._inputs_in_unit(u_prev),
        )

    def _states_in_unit(self, states: np.ndarray) -> np.ndarray:
        """A copy of a state or rows starting with a position (m, references, states) with
        the position in the OCP's unit."""
        states = np.array(states, dtype=float)
        states[..., :2] /= self.unit
        return states

    def _inputs_in_unit(self, inputs: np.ndarray) -> np.ndarray:
        """A copy of the kinematic model's input, or of rows of it, with ``v`` (m/s) in the
        OCP's unit."""
        inputs = np.array(inputs, dtype=float)
        inputs[..., 0] /= self.unit
        return inputs

    def first_input(self, w: np.ndarray) -> np.ndarray:
        """The model's input of a solution's first stage, ``v`` in m/s."""
        u = self.ocp.first_input(w)
        if self.unit != 1.0:
            u = u.copy()  # first_input may be a view of w, the next step's warm start
            u[0] *= self.unit
        return u

    def max_stability_slack(self, w: np.ndarray) -> float:
        """The largest slack of a solution's stability rows (m)."""
        return self.ocp.max_stability_slack(w) * self.unit

    def max_slack(self, w: np.ndarray) -> float:
        """The largest slack of a solution's stability rows (m) and obstacle rows (m^2),
        the joint box's left out (:meth:`ShootingOCP.max_slack
        <ddwmmr.mpc.ocp.ShootingOCP.max_slack>` in the OCP's unit, which the stall rule
        reads); the step's ``mpc_slack``."""
        ocp, unit = self.ocp, self.unit
        if unit == 1.0:
            return ocp.max_slack(w)
        obstacles = w[ocp.slack_index[:, 2 : ocp.joint_slacks.start]]
        stability = self.max_stability_slack(w)
        return max(stability, float(np.max(obstacles)) * unit**2) if obstacles.size else stability


def interpolate_rows(times: np.ndarray, rows: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Rows (one per time, increasing) linearly interpolated at ``at``, held beyond the ends
    (``np.interp`` on every column at once)."""
    # np.minimum/np.maximum rather than np.clip: the same values at a fraction of the
    # call's overhead (this runs twice in every mpc step)
    at = np.minimum(np.maximum(at, times[0]), times[-1])
    upper = np.minimum(np.maximum(np.searchsorted(times, at, side="right"), 1), len(times) - 1)
    lower = upper - 1
    span = times[upper] - times[lower]
    weight = np.where(span > 0.0, (at - times[lower]) / np.where(span > 0.0, span, 1.0), 0.0)
    interpolated: np.ndarray = rows[lower] + weight[:, None] * (rows[upper] - rows[lower])
    return interpolated
