"""The mpc's QP through bound buffers against the keyword call it replaces."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc.models import ThesisPrediction
from ddwmmr.mpc.ocp import OCPConfig, ShootingOCP, Weights
from ddwmmr.mpc.solvers import GaussNewtonSQP, _compiled_qp

HEAVY = Robot().with_payload(3.0)


def _reach_ocp() -> ShootingOCP:
    model = ThesisPrediction(HEAVY, sym.ThesisDynamics.from_robot(HEAVY))
    config = OCPConfig(
        intervals=6,
        control_interval=0.05,
        first_interval=0.2,
        horizon=1.5,
        reach=True,
        track_orientation=False,
        huber=0.01,
        weights=Weights(position=50.0, manipulability=0.5, input=0.01, terminal=0.0),
    )
    return ShootingOCP(HEAVY, model, config)


@pytest.mark.parametrize("qp_solver", ["hpipm", "daqp"])
def test_buffered_qp_steps_equal_the_keyword_call_at_every_iteration(qp_solver):
    """Each Gauss-Newton step through the bound buffers is the step of CasADi's keyword
    call (fresh matrices in, fresh out) on the same data, to the last bit, over a whole
    solve: no state carried from one call to the next changes a step."""
    ocp = _reach_ocp()
    x0 = np.array([0.0, 0.0, 0.2, *default_pose(HEAVY), 0.3, -0.1])
    node = np.concatenate([x0, [ocp.config.horizon]])[: ocp.nx]
    w = ocp.pack(np.tile(node, (ocp.N + 1, 1)), np.zeros((ocp.N, ocp.nu)))
    p = ocp.parameters(np.tile([1.5, 0.8, 0.0], (ocp.N, 1)), np.zeros(4))
    lbw, ubw = ocp.bounds(x0)
    data, qp = _compiled_qp(ocp, qp_solver, 0.0)
    sqp = GaussNewtonSQP(ocp, qp_solver, iterations=1)
    steps = 0
    for _ in range(8):
        hessian, gradient, jacobian, g = data(w, p)
        g = np.asarray(g).ravel()
        keyword = qp(
            h=hessian,
            g=gradient,
            a=jacobian,
            lba=ocp.lbg - g,
            uba=ocp.ubg - g,
            lbx=lbw - w,
            ubx=ubw - w,
        )
        expected = np.asarray(keyword["x"]).ravel()
        buffered = sqp.solve(w, p, lbw, ubw, ocp.lbg, ocp.ubg)
        np.testing.assert_array_equal(buffered - w, w + expected - w)
        lam_a, lam_x = sqp.last_multipliers
        np.testing.assert_array_equal(lam_a, np.asarray(keyword["lam_a"]).ravel())
        np.testing.assert_array_equal(lam_x, np.asarray(keyword["lam_x"]).ravel())
        steps += np.max(np.abs(expected)) > 1e-9
        w = buffered
    assert steps >= 3  # the iterations moved: the comparison covered real steps
