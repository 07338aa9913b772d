"""Shared set-up of the mpc tests: a reach plan of the force model solved to convergence."""

from __future__ import annotations

import numpy as np

from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP, Weights
from ddwmmr.mpc.solvers import GaussNewtonSQP


def converged_reach_plan(robot, model, x0: np.ndarray, target) -> tuple[ShootingOCP, np.ndarray]:
    """``(ocp, w)``: the minimum-time reach OCP of ``model`` (10 intervals, 2 s horizon,
    every edge kept loaded, no position or manipulability cost beyond reaching) from state
    ``x0`` towards the end-effector ``target`` (x, y in m), solved by Gauss-Newton SQP to
    1e-10 from the standing guess with a 1 s horizon."""
    config = OCPConfig(
        intervals=10,
        control_interval=0.01,
        first_interval=0.05,
        horizon=2.0,
        reach=True,
        track_orientation=False,
        huber=0.01,
        dynamic_stability=True,
        weights=Weights(position=0.0, manipulability=0.0, input=0.01, terminal=0.0),
    )
    ocp = ShootingOCP(robot, model, config)
    node = np.concatenate([x0, [1.0]])
    guess = ocp.pack(np.tile(node, (ocp.N + 1, 1)), np.zeros((ocp.N, ocp.nu)))
    p = ocp.parameters(np.tile([*target, 0.0], (ocp.N, 1)), np.zeros(4), horizon_prev=1.0)
    lbw, ubw = ocp.bounds(x0)
    sqp = GaussNewtonSQP(ocp, "hpipm", iterations=200, tolerance=1e-10)
    return ocp, sqp.solve(guess, p, lbw, ubw, ocp.lbg, ocp.ubg)
