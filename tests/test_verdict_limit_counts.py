"""Which limit the verdict names when the clipping is shared between a rate limit and a
joint's position limit, "saturation throughout" only where commands were clipped, and the
joint rates counted where the controller sent wheel forces (docs/cli.md, "Output" and
"Verdict")."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr.model import Robot
from ddwmmr.sim.simulate import joint_rates, limit_counts, simulate
from ddwmmr.sim.verdict import JOINT_LIMIT, SATURATED_THROUGHOUT, SATURATION, verdict
from ddwmmr.trajectories import Ellipse

#: Far off the path at the end: a run that did not track, whatever else it did.
FAILED = {
    "final_position_error_m": 1.0,
    "rms_position_error_m": 1.0,
    "max_position_error_m": 1.0,
    "initial_offset_m": 0.0,
}


def _cause(summary: dict) -> str:
    return verdict(summary)["verdict"].split("; likely cause: ", 1)[1]


def test_a_few_steps_at_a_joint_limit_do_not_take_the_cause_from_the_rate_limits():
    """510 of 1000 steps clipped, 20 of them at a joint's position limit: the other 490
    were clipped at a rate limit, so the rate limits are the cause."""
    summary = {
        **FAILED,
        "steps": 1000,
        "saturated_steps": 510,
        "joint_limit_steps": 20,
        "joint_limit_held": "th2 = 0.3 rad",
    }
    assert verdict(summary)["verdict_reasons"][0] == "saturated_most_of_run"
    assert _cause(summary) == SATURATION


def test_clipping_mostly_at_a_joint_limit_names_the_joint_limit():
    """The same 510 clipped steps, 300 of them at the joint limit: 300 > 210 at a rate
    limit."""
    summary = {
        **FAILED,
        "steps": 1000,
        "saturated_steps": 510,
        "joint_limit_steps": 300,
        "joint_limit_held": "th2 = 0.3 rad",
    }
    assert _cause(summary).startswith(
        "the arm held at a joint limit (th2 = 0.3 rad) on 300 of 1000 steps"
    )
    assert _cause(summary).startswith(JOINT_LIMIT.split("(", 1)[0])


def test_a_wheel_held_inside_a_controllers_bounds_is_not_saturation_throughout():
    """A qp or mpc held a wheel at its limit on 380 of 400 steps and the plant clipped
    nothing: the held limit is named, with nothing clipped."""
    summary = {**FAILED, "steps": 400, "saturated_steps": 0, "wheel_limit_steps": 380}
    cause = _cause(summary)
    assert cause != SATURATED_THROUGHOUT
    assert cause.startswith(
        "the robot ran at a limit (a wheel at its speed limit on 380 of 400 steps)"
    )
    assert "the commands' clipping, saturated_steps, does not count it" in cause


def test_commands_clipped_at_a_rate_limit_on_almost_every_step_are_saturation_throughout():
    """The same run clipped on 370 of 400 steps (> 0.9), none at a joint limit."""
    summary = {**FAILED, "steps": 400, "saturated_steps": 370, "wheel_limit_steps": 380}
    assert _cause(summary) == SATURATED_THROUGHOUT
    clipped_at_joint_limits = {**summary, "joint_limit_steps": 370, "wheel_limit_steps": 0}
    assert _cause(clipped_at_joint_limits) != SATURATED_THROUGHOUT


def test_joint_rates_of_wheel_force_rows_are_the_rates_the_joints_moved_at():
    """Rows with NaN commanded rates (wheel forces sent) take |dth| / dt over their step;
    rows with a velocity command keep it; the last sample starts no step."""
    ts = {
        "t": np.array([0.0, 0.1, 0.2, 0.3]),
        "th1": np.array([0.0, 0.2, 0.2, 0.25]),
        "th2": np.array([1.0, 1.0, 0.9, 0.9]),
        "th1dot": np.array([math.nan, math.nan, 0.7, math.nan]),
        "th2dot": np.array([math.nan, math.nan, -0.3, math.nan]),
    }
    rates = joint_rates(ts)
    assert rates[:3] == pytest.approx([2.0, 1.0, 0.7], abs=1e-12)
    assert math.isnan(rates[3])


def test_a_thesis_plant_mpc_sending_wheel_forces_counts_its_joints_at_their_rate_limit():
    """mpc with its force model on the thesis plant (3 s of the ellipse from a 0.2 m
    offset): the commanded-rate columns are NaN, and the joints move at the 2 rad/s limit
    (within the mpc's bounds) on 16 of 150 steps while it removes the offset."""
    result = simulate(
        None,
        Ellipse(),
        "mpc",
        plant="thesis",
        model="thesis",
        duration=3.0,
        initial_offset=(-0.2, -0.2),
    )
    summary, ts = result.summary, result.timeseries
    assert summary["command_interface"] == "force"
    assert np.all(np.isnan(ts["th1dot"]))
    assert summary["steps"] == 150
    assert summary["joint_rate_limit_steps"] == 16
    moved = joint_rates(ts)[:-1]
    assert np.max(moved) == pytest.approx(Robot().joint_speed_limit, rel=1e-3)
    assert limit_counts(ts, Robot())["joint_rate_limit_steps"] == 16


# -- a controller of one's own reporting fallbacks (StepInfo.fallback) -------------------
def test_fallbacks_of_a_plugin_controller_are_the_cause():
    summary = {**FAILED, "method": "fb85", "steps": 500, "fallback_steps": 449}
    assert _cause(summary).startswith(
        "the controller fb85 used its safe fallback on 449 of 500 steps"
    )


def test_a_few_fallbacks_are_not_the_cause():
    summary = {**FAILED, "method": "fb85", "steps": 500, "fallback_steps": 250}
    assert "safe fallback" not in _cause(summary)


def test_the_qp_keeps_its_own_fallback_cause():
    summary = {**FAILED, "method": "qp", "steps": 500, "fallback_steps": 400, "qp_fallbacks": 400}
    assert _cause(summary).startswith("the qp found no solution on 400 of 500 steps")
