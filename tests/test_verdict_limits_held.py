"""A force-level mpc held at the wheel force it plans with names that bound; a motor held at
its limit for the few steps of a start from rest is not named; the "did not converge" text
asks to check only what the run had (the ten-times robot's mpc on MuJoCo, the long-arm
robot's ats on MuJoCo: docs/cli.md, "Verdict")."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr import Robot, make_controller
from ddwmmr.sim.verdict import NO_CONVERGENCE, verdict

#: The ten-times robot's mpc on its 10x rectangle on MuJoCo, 6 s from a 0.3 m offset: the
#: motors never saturate, the wheels sit at the mpc's 10 kN bound (48.75 % of the motors).
TEN_MPC = {
    "method": "mpc",
    "plant": "mujoco",
    "integrator": None,
    "steps": 300,
    "dt": 0.02,
    "duration": 6.0,
    "length_unit_m": 10.0,
    "trajectory_extent_m": 50.0,
    "initial_offset_m": 0.4243,
    "max_position_error_m": 7.407,
    "final_position_error_m": 7.157,
    "rms_position_error_m": 4.925,
    "min_manipulability": 0.0015,
    "singular_steps": 0,
    "saturated_steps": 0,
    "actuator_saturated_time_s": 0.0,
    "wheel_saturated_time_s": 0.0,
    "mpc_fallbacks": 0,
    "stability_min": 1.25,
    "start_stability": 2.18,
    "mpc_wheel_force_limit_n": 10000.0,
    "mpc_wheel_force_bound_time_s": 4.76,
}
#: The long-arm robot's ats on the ellipse on MuJoCo, 6 s: a motor at its torque limit for
#: two steps at the start; with ten times the torque it ends as far off.
LONGARM_ATS = {
    "method": "ats",
    "plant": "mujoco",
    "integrator": None,
    "steps": 300,
    "dt": 0.02,
    "duration": 6.0,
    "length_unit_m": 2.0,
    "trajectory_extent_m": 3.0,
    "initial_offset_m": 0.0424,
    "max_position_error_m": 0.13,
    "final_position_error_m": 0.1162,
    "rms_position_error_m": 0.08,
    "min_manipulability": 0.3,
    "singular_steps": 0,
    "saturated_steps": 0,
    "actuator_saturated_time_s": 0.04,
    "wheel_saturated_time_s": 0.04,
}


def _cause(summary: dict) -> str:
    return verdict(summary)["verdict"].split("; likely cause: ", 1)[1]


def test_an_mpc_held_at_its_planned_wheel_force_names_that_bound():
    cause = _cause(TEN_MPC)
    assert cause.startswith(
        "the robot ran at a limit (a wheel at the force the mpc plans with "
        "(mpc_wheel_force_limit_n 10000 N, its own bound below the motors; --option "
        "wheel_force_limit=N raises it, never above the motors' wheel_torque_limit / "
        "wheel_radius) for 4.76 of 6 s)"
    )


def test_the_planned_bound_that_is_the_plant_s_limit_is_named_once():
    """The thesis plant's limit is the mpc's bound by default: its own words name it."""
    summary = {**TEN_MPC, "plant": "thesis", "actuator_saturated_time_s": 4.76}
    del summary["wheel_saturated_time_s"]
    cause = _cause(summary)
    assert cause.startswith("the robot ran at a limit (a wheel at its force limit for 4.76 of 6 s)")
    assert "plans with" not in cause


def test_a_short_planned_hold_is_not_named():
    summary = {**TEN_MPC, "mpc_wheel_force_bound_time_s": 0.1}  # 5 steps
    assert "plans with" not in _cause(summary)


def test_a_motor_at_its_limit_for_two_steps_is_not_the_cause():
    cause = _cause(LONGARM_ATS)
    assert cause.startswith("the error did not converge")
    held = _cause({**LONGARM_ATS, "actuator_saturated_time_s": 0.12})  # 6 steps
    assert held.startswith("the robot ran at a limit (a motor at its torque limit for 0.12 of 6 s)")


def test_did_not_converge_asks_only_for_what_the_run_had():
    assert _cause(LONGARM_ATS).startswith(
        "the error did not converge: an open-loop method (pi, ats, ap) never removes it; for "
        "a closed-loop one check tau and dt (see"
    )
    mpc = {**TEN_MPC, "mpc_wheel_force_bound_time_s": 0.0}
    assert "one check position_weight, horizon and dt (see" in _cause(mpc)
    kinematic = {**LONGARM_ATS, "plant": "kinematic", "integrator": "euler"}
    kinematic["actuator_saturated_time_s"] = kinematic["wheel_saturated_time_s"] = None
    assert _cause(kinematic) == NO_CONVERGENCE


def test_the_mpc_counts_the_time_its_wheels_sit_at_its_planned_force():
    """``mpc_wheel_force_bound_time_s`` from either plant's wheel forces: the thesis plant's
    in N, MuJoCo's as a share of the motors' torque (10 N of the default robot's 20.5 N)."""
    controller = make_controller("mpc", Robot(), model="thesis")
    bound = controller.dynamics.force_limit
    t = np.arange(6) * 0.02
    thesis = {"t": t, "force_left_n": np.array([0, bound, -bound, 5, 0, 0.9 * bound])}
    thesis["force_right_n"] = np.array([0, 0, 0, bound, 0, 0])
    assert controller._force_bound_time(thesis) == pytest.approx(3 * 0.02)
    share = bound / Robot().motor_force_limit
    mujoco = {"t": t, "wheel_torque_use": np.array([0, share, share, 1.0, 0.5 * share, 0])}
    assert controller._force_bound_time(mujoco) == pytest.approx(3 * 0.02)
    assert controller._force_bound_time({"t": t}) is None
    assert make_controller("mpc", Robot())._force_bound_time(thesis) is None  # kinematic
