"""A limit counts as held, whatever its kind, only for more than ``HELD_MIN_STEPS`` steps as
well as ``HELD_CAUSE`` of the run: the few steps a start from rest spends at a limit are
more than 0.5 % of a short run and explain no error (docs/cli.md, "Verdict")."""

from __future__ import annotations

import math
import warnings

import pytest

from ddwmmr import Ellipse, simulate
from ddwmmr.sim.verdict import HELD_MIN_STEPS, verdict

#: A 4 s kinematic run (200 steps of 20 ms) that failed on its RMS error and never rose
#: above its start offset by more than the slack: nothing held explains it.
SHORT_RUN = {
    "plant": "kinematic",
    "steps": 200,
    "dt": 0.02,
    "duration": 4.0,
    "singular_steps": 0,
    "saturated_steps": 0,
    "initial_offset_m": math.hypot(0.03, 0.03),
    "max_position_error_m": 0.2,
    "final_position_error_m": 0.2,
    "rms_position_error_m": 0.2,
    "min_manipulability": 0.9,
}
NO_CONVERGENCE = "likely cause: the error did not converge"


@pytest.mark.parametrize(
    ("key", "words"),
    [
        ("wheel_limit_steps", "a wheel at its speed limit on 6 of 200 steps"),
        ("joint_rate_limit_steps", "a joint at its rate limit on 6 of 200 steps"),
    ],
)
def test_a_rate_limit_held_for_the_steps_of_a_start_is_not_the_cause(key, words):
    assert HELD_MIN_STEPS == 5
    # 3 steps are more than 0.5 % of 200, but no more than a start from rest holds
    short = verdict({**SHORT_RUN, key: 3})["verdict"]
    assert NO_CONVERGENCE in short
    assert "ran at a limit" not in short
    assert NO_CONVERGENCE in verdict({**SHORT_RUN, key: HELD_MIN_STEPS})["verdict"]
    held = verdict({**SHORT_RUN, key: HELD_MIN_STEPS + 1})["verdict"]
    assert f"likely cause: the robot ran at a limit ({words})" in held


def test_a_joint_at_a_position_limit_for_a_few_steps_is_not_named():
    short = verdict({**SHORT_RUN, "joint_limit_steps": 3, "joint_limit_held": "th2 = 0.3 rad"})
    assert NO_CONVERGENCE in short["verdict"] and "joint limit" not in short["verdict"]
    held = verdict({**SHORT_RUN, "joint_limit_steps": 6, "joint_limit_held": "th2 = 0.3 rad"})
    assert "the arm held at a joint limit (th2 = 0.3 rad) on 6 of 200 steps" in held["verdict"]


def test_a_short_mpc_run_on_the_thesis_plant_names_its_wheels_not_one_joint_step():
    """The default robot's mpc on the ellipse on the thesis plant for 1 s: its wheels at
    their force limit throughout, one of its 50 steps with a joint at its rate limit (2 %
    of the run, which alone named it)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        summary = dict(simulate(None, Ellipse(), "mpc", duration=1.0, plant="thesis").summary)
    assert (summary["steps"], summary["joint_rate_limit_steps"]) == (50, 1)
    assert summary["actuator_saturated_time_s"] == pytest.approx(1.0, abs=0.021)
    assert summary["rms_position_error_m"] == pytest.approx(0.142, abs=0.005)
    text = summary["verdict"]
    assert "likely cause: the robot ran at a limit (a wheel at its force limit for 1 of 1 s)" in (
        text
    )
    assert "rate limit" not in text
