"""The step-time instrumentation of the mpc floor (:mod:`ddwmmr.bench.mpc_floor`)."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr import Robot, make_controller
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.bench.mpc_floor import FLOOR_PHASES, floor_summary, instrumented
from ddwmmr.mpc import controller as controller_module
from ddwmmr.mpc.controller import MPCController
from ddwmmr.mpc.problem import Problem
from ddwmmr.plants.thesis import ThesisPlant, ThesisState

HEAVY = Robot().with_payload(3.0)


def _thesis_run(steps: int, targets: list[tuple[float, float]]) -> MPCController:
    controller = make_controller("mpc", HEAVY, model="thesis", track_orientation=False, dt=0.01)
    plant = ThesisPlant(HEAVY)
    state = ThesisState(0.0, 0.0, 0.0, *default_pose(HEAVY))
    controller.reset(None, np.array(state.q))
    for k in range(steps):
        target = targets[0] if k < steps // 2 else targets[-1]
        command = controller.command(
            k * 0.01,
            np.array(state.q),
            np.array([*target, 0.0]),
            np.zeros(3),
            base_velocity=(state.v, state.w),
        )
        plant.advance(
            state, command.left, command.right, (command.th1_target, command.th2_target), 0.01
        )
    return controller


def test_the_floor_instrumentation_splits_every_step_and_leaves_nothing_behind():
    originals = (
        MPCController.command,
        MPCController._problem,
        Problem.solve,
        controller_module.safe_arm_scale,
    )
    with instrumented() as log:
        _thesis_run(20, [(1.5, 0.5), (0.5, 1.5)])
    assert originals == (
        MPCController.command,
        MPCController._problem,
        Problem.solve,
        controller_module.safe_arm_scale,
    )
    table = log.table()
    assert table["step"].size == 20
    # HPIPM's share is known but for the first QP on a conic that ran outside the
    # instrumentation before (an earlier test's controller on the same shared OCP)
    split = ~np.isnan(table["hpipm"])
    assert np.sum(~split) <= 2
    # the phases are a partition of the step (each measured, none negative beyond the
    # clock's resolution of the HPIPM statistic, 1 us)
    total = sum(table[phase][split] for phase in FLOOR_PHASES)
    np.testing.assert_allclose(total, table["step"][split], rtol=1e-9)
    for phase in FLOOR_PHASES:
        assert np.all(table[phase][split] >= -2e3), phase
    assert np.all(table["hpipm"][split] > 0.0) and np.all(table["hpipm_iterations"] >= 1)
    assert table["iterations"][0] > 1  # the first step starts cold
    summary = floor_summary(log)
    assert summary["steps"] == 20 and summary["cold_steps"] >= 1
    assert summary["split_steps"] == int(np.sum(split))
    assert summary["max_us"] >= summary["p99_us"] >= summary["median_us"] > 0.0
    shares = sum(summary[f"{phase}_share"] for phase in FLOOR_PHASES)
    assert shares == pytest.approx(1.0, rel=1e-9)
    with instrumented() as again:  # nothing carried over: a new log, no double wrapping
        _thesis_run(4, [(1.0, 0.0)])
    assert again.table()["step"].size == 4 and len(log.steps) == 20
