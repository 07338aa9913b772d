"""The verdict on a robot that would tip over, a joint held at a position limit, and a
run that converged after a transient at a rate limit (docs/cli.md, "Verdict")."""

from __future__ import annotations

import pytest

from ddwmmr.model import Robot
from ddwmmr.sim.simulate import simulate
from ddwmmr.sim.verdict import FOLDED_ARM, NOT_CLIPPED, WOULD_TIP, verdict
from ddwmmr.trajectories import Ellipse, Rectangle

NARROW = Robot(joint_limits=((-0.8, 0.8), (0.3, 1.2)), home_pose=(-0.3, 0.6))
BIG = Robot(
    L1=1.0,
    L2=0.9,
    wheel_radius=0.2,
    track_width=0.8,
    base_length=1.2,
    base_width=0.9,
    base_mass=80.0,
    base_inertia=10.0,
    link_masses=(8.0, 6.0),
    payload=5.0,
    wheel_mass=4.0,
    base_height=0.4,
    arm_height=0.8,
    wheel_torque_limit=30.0,
    joint_torque_limits=(300.0, 150.0),
)


def _cause(summary: dict) -> str:
    return summary["verdict"].split("; likely cause: ", 1)[1]


def test_a_run_the_robot_would_have_tipped_over_in_does_not_track():
    """pi on the rectangle with a 5 kg payload: S falls to 0.976 on the kinematic plant,
    which does not judge tipping; it tracked by its errors alone."""
    summary = simulate(Robot(payload=5.0), Rectangle(), "pi", duration=15.0).summary
    assert summary["min_stability"] == pytest.approx(0.976, abs=0.001)
    assert summary["verdict_reasons"] == ["stability_below_1"]
    assert summary["verdict"].startswith(
        "did not track: the robot would have tipped over (min S = 0.976)"
    )
    assert _cause(summary) == WOULD_TIP


def test_tipping_is_named_before_the_singularity():
    """The same payload with ap: the singularity drags the arm out to S = 0.769."""
    summary = simulate(Robot(payload=5.0), Rectangle(), "ap", duration=15.0).summary
    assert summary["min_stability"] == pytest.approx(0.769, abs=0.001)
    assert summary["verdict_reasons"][:2] == ["stability_below_1", "singular_most_of_run"]
    assert _cause(summary) == WOULD_TIP


def test_a_physics_plant_and_a_tipped_start_judge_tipping_themselves():
    tracked = {"steps": 100, "final_position_error_m": 0.0, "rms_position_error_m": 0.0}
    low = {**tracked, "min_stability": 0.5}
    assert verdict(low)["verdict_reasons"] == ["stability_below_1"]
    assert verdict({**low, "min_stability": 1.0})["verdict_reasons"] == ["stability_below_1"]
    assert verdict({**low, "min_stability": 1.001})["verdict_reasons"] == []
    assert verdict({**low, "tipped": False})["verdict_reasons"] == []
    assert verdict({**low, "tipped": True})["verdict_reasons"] == ["tipped_over"]
    started = verdict({**low, "start_tipped": True, "start_stability": 0.5})
    assert started["verdict_reasons"] == ["tipped_at_start"]


def test_a_joint_held_at_a_position_limit_is_named_not_the_rate_limits():
    """pi on the rectangle with th2 in [0.3, 1.2]: every clipped command is the elbow
    stopped at 0.3 rad, none a rate limit."""
    summary = simulate(NARROW, Rectangle(), "pi", duration=15.0).summary
    assert summary["saturated_steps"] == 583
    assert summary["joint_limit_steps"] == 583
    assert summary["joint_rate_limit_steps"] == 0
    assert summary["joint_limit_held"] == "th2 = 0.3 rad"
    assert "saturated_most_of_run" in summary["verdict_reasons"]
    cause = _cause(summary)
    assert cause.startswith("the arm held at a joint limit (th2 = 0.3 rad) on 583 of 750 steps")
    assert "rate limits allow" not in cause


def test_a_joint_limit_is_named_where_the_run_did_not_converge():
    """ats on the rectangle, same robot: 207 steps at the limit, not most of the run."""
    summary = simulate(NARROW, Rectangle(), "ats", duration=15.0).summary
    assert summary["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert summary["joint_limit_steps"] == 207
    assert _cause(summary).startswith("the arm held at a joint limit (th2 = 0.3 rad) on 207 of 750")


def test_the_default_folded_arm_stays_a_folded_arm():
    """ats on the default rectangle folds its elbow at th2 = pi, a joint limit too."""
    summary = simulate(Robot(), Rectangle(), "ats").summary
    assert summary["joint_limit_steps"] == 427
    assert _cause(summary) == FOLDED_ARM.format(methods="ats, clrrmc-cs")


def test_a_corner_transient_at_a_joint_rate_limit_is_not_a_failure_to_converge():
    """clrrmc-ts on the rectangle with the large robot ends 0.18 mm off; its RMS fails on
    the corners, where a joint ran at its rate limit (clipped by the plant)."""
    # from the default robot's offset: its own, 2.9 times as far, doubles the error limit
    summary = simulate(
        BIG, Rectangle(), "clrrmc-ts", duration=15.0, initial_offset=(-0.03, -0.03)
    ).summary
    assert summary["verdict_reasons"] == ["rms_error_above_limit"]
    assert summary["joint_rate_limit_steps"] == 31
    cause = _cause(summary)
    assert cause.startswith(
        "the robot ran at a limit (a joint at its rate limit on 31 of 750 steps)"
    )
    assert "(the plant clipped the commands on 31 of 750 steps, saturated_steps)" in cause
    assert "settled-end RMS position error 0.178 mm, within the limit" in cause
    assert "up to 729 mm at a corner" in cause
    assert "did not converge" not in cause


def test_a_joint_rate_limit_held_is_named_with_the_plants_clipping():
    """clrrmc-ts on the rectangle with 0.5 rad/s joints: 250 clipped steps, every one a
    joint at its rate limit; the parenthesis counts them instead of saying none count."""
    robot = Robot(joint_speed_limit=0.5)
    summary = simulate(robot, Rectangle(), "clrrmc-ts", duration=15.0).summary
    assert (summary["saturated_steps"], summary["joint_rate_limit_steps"]) == (250, 250)
    assert summary["wheel_limit_steps"] == 131
    cause = _cause(summary)
    assert "a joint at its rate limit on 250 of 750 steps" in cause
    assert "(the plant clipped the commands on 250 of 750 steps, saturated_steps)" in cause
    assert NOT_CLIPPED not in cause


def test_a_qp_within_its_own_joint_rate_bound_says_nothing_was_clipped():
    """The qp on the rectangle with th2 in [0.3, 1.2]: it keeps a joint at its rate limit
    itself on 12 steps; converged (2.4 mm), RMS 90.9 mm from the corners."""
    summary = simulate(NARROW, Rectangle(), "qp", duration=15.0).summary
    assert summary["verdict_reasons"] == ["rms_error_above_limit"]
    assert summary["saturated_steps"] == 0
    cause = _cause(summary)
    assert "(a joint at its rate limit on 12 of 750 steps)" in cause
    assert f"({NOT_CLIPPED})" in cause
    assert "up to 218 mm at a corner" in cause


def test_the_ellipse_of_the_narrow_robot_tracks_and_counts_no_limit():
    summary = simulate(NARROW, Ellipse(), "clrrmc-ts", duration=15.0).summary
    assert summary["verdict"] == "tracked"
    assert summary["joint_limit_steps"] == 0
    assert summary["joint_limit_held"] is None
