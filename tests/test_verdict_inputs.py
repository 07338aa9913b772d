"""The verdict refuses a summary whose numbers no run writes (negative errors, lengths,
times and counts, counts above ``steps``, fractional counts, flags that are not booleans)
in one line naming the key and its range, and still reads every summary a run writes,
live or read back from its ``summary.json``; the GUI's physics words name a lost support."""

from __future__ import annotations

import json
import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.gui.app import _physics_verdict, _summary_line
from ddwmmr.sim.result import json_safe
from ddwmmr.sim.verdict import (
    STEP_COUNT_KEYS,
    TRACKED,
    check_summary,
    lost_support,
    support_warning,
    verdict,
)

#: A run that tracked: 10 steps, errors within the 50 mm limit of a 5 m trajectory.
GOOD = {
    "steps": 10,
    "duration": 0.2,
    "singular_steps": 0,
    "saturated_steps": 0,
    "rms_position_error_m": 0.01,
    "final_position_error_m": 0.005,
    "max_position_error_m": 0.02,
    "initial_offset_m": 0.02,
    "trajectory_extent_m": 5.0,
    "min_stability": 2.18,
    "start_stability": 2.18,
    "start_tipped": False,
}


def _refusal(**changes: object) -> str:
    with pytest.raises(ParameterError) as info:
        verdict({**GOOD, **changes})
    message = str(info.value)
    assert "\n" not in message
    return message


def test_the_good_summary_tracks() -> None:
    assert verdict(GOOD) == {"verdict": TRACKED, "verdict_reasons": []}


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"steps": -5}, "summary: steps must be a whole number of steps from 0 (got -5)"),
        ({"steps": 2.5}, "summary: steps must be a whole number of steps from 0 (got 2.5)"),
        ({"steps": "nan"}, "summary: steps must be a whole number of steps from 0 (got 'nan')"),
        (
            {"singular_steps": 10**9},
            "summary: singular_steps must be a whole number of steps from 0 to steps = 10 "
            "(got 1000000000)",
        ),
        (
            {"qp_fallbacks": 11},
            "summary: qp_fallbacks must be a whole number of steps from 0 to steps = 10 (got 11)",
        ),
        (
            {"saturated_steps": -1},
            "summary: saturated_steps must be a whole number of steps from 0 to steps = 10 "
            "(got -1)",
        ),
        (
            {"joint_limit_steps": 0.5},
            "summary: joint_limit_steps must be a whole number of steps from 0 to steps = 10 "
            "(got 0.5)",
        ),
        (
            {"rms_position_error_m": -1},
            "summary: rms_position_error_m must be >= 0 m, 'nan', 'inf' or None (got -1)",
        ),
        (
            {"trajectory_extent_m": -1},
            "summary: trajectory_extent_m must be >= 0 m, 'nan', 'inf' or None (got -1)",
        ),
        (
            {"final_position_error_m": "-inf"},
            "summary: final_position_error_m must be >= 0 m, 'nan', 'inf' or None (got '-inf')",
        ),
        (
            {"unloaded_time_s": -0.1},
            "summary: unloaded_time_s must be >= 0 s, 'nan', 'inf' or None (got -0.1)",
        ),
        ({"duration": -2}, "summary: duration must be >= 0 s, 'nan', 'inf' or None (got -2)"),
        (
            {"start_tipped": "yes"},
            "summary: start_tipped must be True, False (or 1, 0) or None (got 'yes')",
        ),
        ({"tipped": 2}, "summary: tipped must be True, False (or 1, 0) or None (got 2)"),
        (
            {"support_lost": "no"},
            "summary: support_lost must be True, False (or 1, 0) or None (got 'no')",
        ),
    ],
)
def test_nonsense_numbers_and_flags_are_refused_naming_the_key(
    changes: dict, expected: str
) -> None:
    assert _refusal(**changes) == expected


def test_every_step_count_is_held_to_steps() -> None:
    for key in STEP_COUNT_KEYS:
        assert verdict({**GOOD, key: 10})  # all of the steps: a count a run can write
        assert f"summary: {key} must be a whole number of steps from 0 to steps = 10" in (
            _refusal(**{key: 11})
        )


def test_what_a_summary_json_holds_is_still_read() -> None:
    """NaN errors spelt as a summary.json spells them, numpy counts and booleans, whole
    counts as floats, and None all pass; a NaN error does not track."""
    spelt = {**GOOD, "rms_position_error_m": "nan", "final_position_error_m": "inf"}
    assert verdict(spelt)["verdict_reasons"] == [
        "final_error_above_limit",
        "rms_error_above_limit",
    ]
    numpy = {
        **GOOD,
        "steps": np.int64(10),
        "singular_steps": np.int64(10),
        "saturated_steps": 3.0,
        "start_tipped": np.bool_(False),
        "tipped": None,
        "duration": None,
    }
    assert verdict(numpy)["verdict_reasons"] == ["singular_most_of_run"]
    assert check_summary({"steps": 0, "singular_steps": 0}) == {"steps": 0, "singular_steps": 0}


RUNS = [(method, "ellipse", "kinematic", 2.0) for method in ("pi", "ats", "ap", "clrrmc-ts")]
RUNS += [
    ("clrrmc-cs", "rectangle", "kinematic", 20.0),
    ("qp", "figure8", "kinematic", 2.0),
    ("mpc", "sideways_reach", "kinematic", 1.0),
    ("qp", "rectangle", "thesis", 2.0),
    ("mpc", "ellipse", "thesis", 1.0),
    ("ats", "figure8", "mujoco", 1.0),
    ("qp", "sideways_reach", "mujoco", 1.0),
]


@pytest.mark.parametrize(("method", "trajectory", "plant", "duration"), RUNS)
def test_real_runs_and_their_summary_json_are_accepted(
    method: str, trajectory: str, plant: str, duration: float
) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        summary = simulate(
            Robot(), load_trajectory(trajectory), method, plant=plant, duration=duration
        ).summary
    read_back = json.loads(json.dumps(json_safe(summary)))
    for each in (summary, read_back):
        again = verdict(each)
        assert again["verdict"] == summary["verdict"]
        assert again["verdict_reasons"] == summary["verdict_reasons"]


#: The physics keys of a MuJoCo run that stood.
STOOD = {
    "rms_position_error_m": 0.01,
    "max_position_error_m": 0.02,
    "rms_orientation_error_rad": 0.1,
    "max_wheel_speed_rad_s": 5.0,
    "min_stability": 1.3,
    "min_manipulability": 0.8,
    "saturated_steps": 0,
    "fallback_steps": 0,
    "duration": 2.0,
    "tipped": False,
    "tip_time_s": None,
    "min_physics_stability": 1.21,
    "support_lost": False,
    "unloaded_time_s": 0.0,
}


def test_the_gui_line_says_the_support_was_lost() -> None:
    lost = {**STOOD, "support_lost": True, "unloaded_time_s": 0.08}
    assert lost_support(lost) and support_warning(lost).startswith("warning: an edge")
    assert _physics_verdict(lost) == (
        ", stood but LOST SUPPORT: an edge unloaded for 0.08 of 2 s "
        "(physics: min physics stability 1.21)"
    )
    line = _summary_line("qp", SimpleNamespace(summary=lost))
    assert line.endswith(
        "LOST SUPPORT: an edge unloaded for 0.08 of 2 s (physics: min physics stability 1.21)"
    )
    assert "stood (physics" not in line


def test_the_gui_line_of_a_run_that_kept_its_support_or_tipped_is_unchanged() -> None:
    assert _physics_verdict(STOOD) == ", stood (physics: min physics stability 1.21)"
    assert not lost_support(STOOD)
    tipped = {**STOOD, "tipped": True, "tip_time_s": 1.234, "support_lost": True}
    assert not lost_support(tipped)
    assert _physics_verdict(tipped) == ", TIPPED at 1.23 s (physics)"
    kinematic = {k: v for k, v in STOOD.items() if k not in ("tipped", "support_lost")}
    assert _physics_verdict(kinematic) == "" and not lost_support(kinematic)


def test_flags_may_be_the_integers_0_and_1() -> None:
    assert verdict({**GOOD, "tipped": 0})["verdict"] == verdict(GOOD)["verdict"]
    assert (
        verdict({**GOOD, "tipped": 1})["verdict_reasons"]
        == verdict({**GOOD, "tipped": True})["verdict_reasons"]
    )


def test_a_plug_in_summarize_the_verdict_cannot_read_names_the_plug_in() -> None:
    """A plug-in plant's summarize() key that no run writes stops the run with one line
    naming the plant, not the summary alone."""
    from ddwmmr import simulate
    from ddwmmr.errors import ParameterError
    from ddwmmr.model import Robot
    from ddwmmr.plants.kinematic import KinematicPlant
    from ddwmmr.trajectories import Ellipse

    class CountingPlant(KinematicPlant):
        name = "counting"

        def summarize(self, timeseries):
            return {**super().summarize(timeseries), "singular_steps": 10**6}

    CountingPlant.__module__ = "user_plants"  # a plug-in, as from_library sees it
    with pytest.raises(ParameterError) as info:
        simulate(Robot(), Ellipse(), "ats", duration=0.2, plant=CountingPlant(Robot()))
    message = str(info.value)
    assert message.startswith("plant: counting.summarize() returned summary: singular_steps")
    assert "\n" not in message
