"""The mpc's LQR terminal design with cost weights the options accept but double precision
cannot resolve (a positive weight far below the design's others): such a weight is left
out as a zero weight is, instead of ``control.dlqr`` raising LinAlgError at the run's
reset."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc import terminal
from ddwmmr.mpc.models import KinematicPrediction, ThesisPrediction
from ddwmmr.mpc.ocp import OCPConfig, Weights


def _design(model_name: str, position: float, orientation: float) -> terminal.TerminalDesign:
    robot = Robot()
    if model_name == "thesis":
        model = ThesisPrediction(robot, sym.ThesisDynamics.from_robot(robot))
    else:
        model = KinematicPrediction(robot)
    config = OCPConfig(
        intervals=10,
        control_interval=0.02,
        first_interval=0.05,
        horizon=1.0,
        weights=Weights(position=position, orientation=orientation),
    )
    return terminal.design(robot, model, config, default_pose(robot))


@pytest.mark.parametrize("model_name", ["kinematic", "thesis"])
@pytest.mark.parametrize(
    ("position", "orientation", "zero"),
    [(1e-300, 10.0, [0, 1]), (5e-324, 0.0, [0, 1, 2]), (100.0, 1e-40, [2]), (100.0, 5e-324, [2])],
)
def test_a_negligible_weight_is_left_out_as_a_zero_one(model_name, position, orientation, zero):
    found = _design(model_name, position, orientation)
    with_zeros = _design(
        model_name, 0.0 if 0 in zero else position, 0.0 if 2 in zero else orientation
    )
    np.testing.assert_array_equal(found.P, with_zeros.P)
    np.testing.assert_array_equal(found.K, with_zeros.K)
    assert not np.any(found.P[zero]) and np.all(np.isfinite(found.P))


def test_default_weights_keep_every_error_in_the_design():
    found = _design("kinematic", 100.0, 10.0)
    assert np.all(np.diag(found.P)[:3] > 0.0)


@pytest.mark.parametrize("option", [{"position_weight": 1e-300}, {"orientation_weight": 1e-40}])
def test_an_mpc_run_with_a_negligible_weight_completes(option):
    """Both used to end in LinAlgError from control.dlqr at the run's reset."""
    summary = simulate(Robot(), Ellipse(), "mpc", duration=0.2, **option).summary
    assert summary["steps"] == 10 and summary["mpc_fallbacks"] == 0
