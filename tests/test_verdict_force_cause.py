"""A wheel at its force limit for most of the run is named as the likely cause before what
the arm did: the base lags commands it cannot produce the force for, and the arm
stretches after it (a fold, a singularity). The ten-times robot on its 20 m x 15 m ellipse
in 40 s (10 times its motors' pace) shows it on the thesis plant; given ten times the
force limit, ats tracks it with no fold."""

from __future__ import annotations

import warnings

import pytest

from ddwmmr import Ellipse, Robot, load_trajectory, simulate
from ddwmmr.sim.verdict import (
    FOLDED_ARM,
    FOLDING_METHODS,
    FORCE_LIMIT_CAUSE,
    SINGULAR_DRIFT,
    verdict,
)
from scaled_robots import TEN_TIMES

FORCE_CAUSE = "likely cause: the robot ran at a limit (a wheel at its force limit for "


def _ten_times(method: str, plant_options: dict | None = None) -> dict:
    ellipse = Ellipse(a=20.0, b=15.0, T=40.0, N=2000)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the thesis plant's constants derived from the robot
        result = simulate(
            TEN_TIMES,
            ellipse,
            method,
            plant="thesis",
            initial_offset=(0.3, 0.3),
            plant_options=plant_options,
        )
    return result.summary


@pytest.mark.parametrize(
    ("method", "at_limit_s", "arm"),
    [
        ("ats", 40.0, "the arm folded to a joint limit (min manipulability 0), which may follow"),
        ("pi", 32.1, "the arm was singular (damped) on 866 of 2000 steps, which may follow"),
    ],
)
def test_a_robot_too_weak_for_its_trajectory_names_its_force_limit(method, at_limit_s, arm):
    """The arm folds (ats) or goes singular (pi) while a wheel is at its force limit for
    most of the run: the force limit is named, and the arm's part after it."""
    summary = _ten_times(method)
    assert summary["actuator_saturated_time_s"] == pytest.approx(at_limit_s, abs=0.05)
    assert summary["min_manipulability"] < 1e-6
    text = summary["verdict"]
    assert text.startswith("did not track")
    assert f"{FORCE_CAUSE}{at_limit_s:.3g} of 40 s" in text
    assert arm in text
    assert "so fix this first: a slower trajectory, a smaller dt or a higher limit" in text
    assert "integrates Xd_dot" not in text and "cos th1 = 0" not in text


def test_with_the_force_it_needs_ats_tracks_without_folding():
    """The evidence for the order: ten times the force limit and the fold is gone."""
    summary = _ten_times("ats", {"force_limit": 1e5})
    assert summary["verdict"] == "tracked"
    assert summary["min_manipulability"] > 0.25
    assert summary["actuator_saturated_time_s"] < 0.2


#: ats on the rectangle on the thesis plant (default robot): its arm folds on its own,
#: with a wheel at its force limit for 1.12 of 40 s.
FOLDED_ON_THESIS = {
    "method": "ats",
    "plant": "thesis",
    "steps": 2000,
    "duration": 40.0,
    "singular_steps": 0,
    "saturated_steps": 427,
    "joint_limit_steps": 427,
    "joint_limit_held": "th2 = -3.14159 rad",
    "initial_offset_m": 0.0424,
    "max_position_error_m": 0.5,
    "final_position_error_m": 0.2575,
    "rms_position_error_m": 0.1334,
    "min_manipulability": 0.0,
    "actuator_saturated_time_s": 1.12,
}


def _cause(summary: dict) -> str:
    return verdict(summary)["verdict"].split("; likely cause: ", 1)[1]


@pytest.mark.parametrize(
    ("at_limit_s", "force_named"),
    [(1.12, False), (FORCE_LIMIT_CAUSE * 40.0, False), (20.02, True), (40.0, True)],
)
def test_the_force_limit_comes_first_only_for_most_of_the_run(at_limit_s, force_named):
    cause = _cause({**FOLDED_ON_THESIS, "actuator_saturated_time_s": at_limit_s})
    folded = FOLDED_ARM.format(methods=", ".join(FOLDING_METHODS))
    assert cause.startswith("the robot ran at a limit (a wheel at its force limit") is force_named
    assert (cause == folded) is not force_named


def test_a_converged_run_held_at_its_force_limit_keeps_its_transient():
    """Only the RMS failed and the error rose above its start: the transient is named as
    before, the arm's part after it."""
    summary = {
        **FOLDED_ON_THESIS,
        "final_position_error_m": 0.01,
        "actuator_saturated_time_s": 30.0,
    }
    cause = _cause(summary)
    assert cause.startswith(
        "the robot ran at a limit (a wheel at its force limit for 30 of 40 s and the arm at "
        "a joint limit (th2 = -3.14159 rad) on 427 of 2000 steps)"
    )
    assert (
        "; the error converged after it (settled-end RMS position error 10 mm, within the limit)"
        in cause
    )
    assert cause.endswith(
        "counts in the RMS; the arm folded to a joint limit (min manipulability 0) on the "
        "way, which may follow from the force limit too (the base lagged and the arm "
        "stretched after it): a slower trajectory, a smaller dt or a higher limit (see "
        'docs/cli.md, "Verdict")'
    )
    assert "fix this first" not in cause


#: A MuJoCo run's summary like FOLDED_ON_THESIS: a motor at its torque limit for 30 of
#: 40 s, the wheels' motors for ``wheel_saturated_time_s`` of it.
FOLDED_ON_MUJOCO = {**FOLDED_ON_THESIS, "plant": "mujoco", "actuator_saturated_time_s": 30.0}


@pytest.mark.parametrize(
    ("wheels_s", "force_named"), [(None, False), (0.0, False), (20.0, False), (30.0, True)]
)
def test_on_mujoco_only_the_wheels_at_their_limit_name_the_force_limit(wheels_s, force_named):
    """MuJoCo's ``actuator_saturated_time_s`` counts the arm's motors too: the base is
    blamed only where the wheels' motors were at their limit for most of the run
    (``wheel_saturated_time_s``; a summary without it cannot say)."""
    summary = dict(FOLDED_ON_MUJOCO)
    if wheels_s is not None:
        summary["wheel_saturated_time_s"] = wheels_s
    cause = _cause(summary)
    assert ("the base lagged" in cause) is force_named
    folded = FOLDED_ARM.format(methods=", ".join(FOLDING_METHODS))
    assert (cause == folded) is not force_named


#: Shoulder and elbow motors of 0.03 and 0.015 N m, the wheels' 6 N m: on MuJoCo the arm's
#: motors hold their torque limits, the wheels' never do.
WEAK_ARM = Robot(joint_torque_limits=(0.03, 0.015), wheel_torque_limit=6.0).with_payload(1.0)


def test_an_arm_motor_at_its_limit_on_mujoco_does_not_blame_the_base():
    """ats on the ellipse with the weak arm: a motor at its limit for 39.3 of 40 s, the
    wheels' for 0; the shoulder singular on 669 of 2000 steps is the cause, not the base
    lagging (it read "a motor at its torque limit for 39.3 of 40 s ...; the arm was
    singular ..., which may follow from it (the base lagged ...)")."""
    summary = simulate(WEAK_ARM, load_trajectory("ellipse"), "ats", plant="mujoco").summary
    assert summary["actuator_saturated_time_s"] == pytest.approx(39.3, abs=0.1)
    assert summary["wheel_saturated_time_s"] == 0.0
    assert summary["singular_steps"] == pytest.approx(669, abs=20)
    assert _cause(summary) == SINGULAR_DRIFT


@pytest.mark.parametrize(("method", "trajectory"), [("pi", "ellipse"), ("ap", "rectangle")])
def test_a_default_robot_s_singular_run_on_the_thesis_plant_keeps_its_cause(method, trajectory):
    """pi and ap drift into the singularity on their own (their wheels at the force limit
    for 0.1 and 2.12 of 40 s): the singularity stays the cause."""
    summary = simulate(Robot(), load_trajectory(trajectory), method, plant="thesis").summary
    assert summary["actuator_saturated_time_s"] < 0.06 * summary["duration"]
    assert summary["verdict"].endswith(f"; likely cause: {SINGULAR_DRIFT}")


def test_a_default_robot_s_folded_run_on_the_thesis_plant_keeps_its_cause():
    summary = simulate(Robot(), load_trajectory("rectangle"), "ats", plant="thesis").summary
    assert summary["actuator_saturated_time_s"] == pytest.approx(1.12, abs=0.01)
    assert _cause(summary) == FOLDED_ARM.format(methods=", ".join(FOLDING_METHODS))
