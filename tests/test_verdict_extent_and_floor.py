"""The verdict tells the truth where it did not: a limit held inside a controller or a
plant, the folded arm of a method that does not integrate Xd_dot, a trajectory much
smaller than the absolute error limit, and an mpc started below its own floor."""

import math

import numpy as np
import pytest

from ddwmmr import Ellipse, Rectangle, Robot, load_trajectory, simulate
from ddwmmr.sim.verdict import verdict

#: A closed-loop run 104.5 mm RMS off (limit 84.85 mm) with no cause of its own.
OFF_TRACK = {
    "steps": 2000,
    "duration": 40.0,
    "singular_steps": 0,
    "saturated_steps": 0,
    "initial_offset_m": math.hypot(0.03, 0.03),
    "final_position_error_m": 0.0001,
    "rms_position_error_m": 0.1045,
    "min_manipulability": 0.9,
}
GENERIC = "likely cause: the error did not converge"


# -- a limit held without clipping ------------------------------------------------------


def test_a_wheel_held_at_its_speed_limit_is_named_as_the_cause():
    held = verdict({**OFF_TRACK, "wheel_limit_steps": 684})["verdict"]
    assert "likely cause: the robot ran at a limit (a wheel at its speed limit on 684 of 2000" in (
        held
    )
    # 10 of 2000 steps (0.5 %) is not "more than 0.5 %": the generic cause stays
    assert GENERIC in verdict({**OFF_TRACK, "wheel_limit_steps": 10})["verdict"]
    assert "speed limit on 11 of" in verdict({**OFF_TRACK, "wheel_limit_steps": 11})["verdict"]


def test_an_actuator_held_at_its_limit_is_named_by_the_plant():
    thesis = {**OFF_TRACK, "plant": "thesis", "actuator_saturated_time_s": 7.38}
    assert "(a wheel at its force limit for 7.38 of 40 s)" in verdict(thesis)["verdict"]
    mujoco = {**thesis, "plant": "mujoco"}
    assert "(a motor at its torque limit for 7.38 of 40 s)" in verdict(mujoco)["verdict"]
    for other in ("my_plant", None, ["not", "a", "name"]):
        text = verdict({**thesis, "plant": other})["verdict"]
        assert "(an actuator at its limit for 7.38 of 40 s)" in text
    both = verdict({**thesis, "wheel_limit_steps": 100})["verdict"]
    assert "(a wheel at its speed limit on 100 of 2000 steps and a wheel at its force" in both
    assert GENERIC in verdict({**thesis, "actuator_saturated_time_s": 0.2})["verdict"]
    # what the summary records, nothing more: the reasons are the same
    assert verdict(thesis)["verdict_reasons"] == ["rms_error_above_limit"]


def test_a_qp_at_its_wheel_speed_bound_names_it_though_nothing_was_clipped():
    """The default ellipse in 8 s instead of 40: the qp keeps both wheels within its bound
    (nothing clipped), falls behind and ends 4.5 m off; the cause was the generic text."""
    summary = simulate(Robot(), Ellipse(T=8.0, N=400), "qp").summary
    assert summary["saturated_steps"] == 0
    assert summary["max_wheel_speed_rad_s"] == pytest.approx(15.0, abs=1e-3)
    assert summary["wheel_limit_steps"] == pytest.approx(342, abs=5)
    assert summary["final_position_error_m"] == pytest.approx(4.48, abs=0.05)
    assert (
        f"a wheel at its speed limit on {summary['wheel_limit_steps']} of 400 steps"
        in (summary["verdict"])
    )


def test_a_qp_at_the_thesis_plants_force_limit_names_it():
    """sideways_reach on the thesis plant: 196 mm off at the end, a wheel at its 10 N
    force limit for 3.4 of the 8 s (with a 1000 N limit the same run tracks)."""
    reach = load_trajectory("trajectories/sideways_reach.csv")
    summary = simulate(Robot(payload=1.25), reach, "qp", plant="thesis").summary
    assert summary["saturated_steps"] == 0
    assert summary["actuator_saturated_time_s"] == pytest.approx(3.4, abs=0.05)
    assert summary["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert "(a wheel at its force limit for 3.4 of 8 s)" in summary["verdict"]


# -- the folded arm names the run's method ----------------------------------------------

FOLDED = {**OFF_TRACK, "final_position_error_m": 0.36, "min_manipulability": 0.0}


@pytest.mark.parametrize("method", ["qp", "mpc", "clrrmc-ts", "MyController"])
def test_a_folded_arm_names_no_method_that_did_not_run(method):
    text = verdict({**FOLDED, "method": method})["verdict"]
    assert f"the arm folded to a joint limit (min manipulability 0) in this {method} run" in text
    assert "ats" not in text and "clrrmc-cs" not in text and "Xd_dot" not in text


def test_a_folded_arm_of_a_method_that_integrates_xd_dot_keeps_its_explanation():
    both = "a resolution that only integrates Xd_dot (ats, clrrmc-cs) loses the orientation"
    for method in ("ats", "clrrmc-cs", None):  # the default runs' text, unchanged
        assert both in verdict({**FOLDED, "method": method})["verdict"]
    ap = verdict({**FOLDED, "method": "ap"})["verdict"]
    assert "a resolution that only integrates Xd_dot (ap) loses" in ap
    assert "ats" not in ap


def test_a_qp_whose_arm_folded_at_a_large_step_names_the_qp():
    """dt = 5 s on the default ellipse: the elbow folds (manipulability 1e-16); the cause
    named ats and clrrmc-cs."""
    summary = simulate(Robot(), load_trajectory("ellipse"), "qp", dt=5.0).summary
    assert summary["min_manipulability"] < 1e-6
    assert "in this qp run" in summary["verdict"]
    assert "ats" not in summary["verdict"]


# -- the error limit is relative to the trajectory's size too ---------------------------


def test_the_error_limit_is_at_most_a_fifth_of_the_extent_and_at_least_10_mm():
    from ddwmmr.sim.verdict import error_limit

    tiny = {**OFF_TRACK, "rms_position_error_m": 0.0424, "final_position_error_m": 0.0424}
    assert verdict(tiny)["verdict"] == "tracked"  # no extent recorded: as before
    assert verdict({**tiny, "trajectory_extent_m": 5.0})["verdict"] == "tracked"
    small = verdict({**tiny, "trajectory_extent_m": 0.002828})
    assert small["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert (
        "settled-end RMS position error 42.4 mm (limit 10 mm for a trajectory 2.828 mm across)"
        in (small["verdict"])
    )
    assert error_limit({**tiny, "trajectory_extent_m": 0.2}) == pytest.approx(0.04)
    assert error_limit({**tiny, "trajectory_extent_m": 0.0}) == pytest.approx(0.01)
    assert error_limit({**tiny, "trajectory_extent_m": 0.5}) == pytest.approx(0.0848528, 1e-6)
    held_point = {**tiny, "trajectory_extent_m": 0.0, "final_position_error_m": 0.0}
    assert verdict({**held_point, "rms_position_error_m": 0.0099})["verdict"] == "tracked"
    assert verdict({**held_point, "rms_position_error_m": 0.0101})["verdict_reasons"] == [
        "rms_error_above_limit"
    ]


def test_an_open_loop_run_42_mm_off_a_2_mm_square_does_not_track():
    """ats keeps its 42.4 mm start offset: on a 2 mm square that is 15 times the path's
    size, and the 84.85 mm absolute limit read it as tracked."""
    summary = simulate(Robot(), Rectangle(a=0.001, b=0.001), "ats", duration=4.0).summary
    assert summary["trajectory_extent_m"] == pytest.approx(0.002 * math.sqrt(2), rel=1e-6)
    assert summary["final_position_error_m"] == pytest.approx(0.0424, abs=5e-4)
    assert summary["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert "(limit 10 mm for a trajectory 2.828 mm across)" in summary["verdict"]


def test_the_extent_is_the_whole_trajectorys_not_the_part_a_short_run_covers():
    summary = simulate(Robot(), load_trajectory("ellipse"), "clrrmc-ts", duration=0.2).summary
    assert summary["trajectory_extent_m"] == pytest.approx(5.0, abs=1e-6)
    assert summary["verdict"] == "tracked"


@pytest.mark.parametrize(
    ("name", "extent"),
    [
        ("ellipse", 5.0),
        ("rectangle", 5.0),
        ("trajectories/figure8.csv", 6.708),
        ("trajectories/sideways_reach.csv", 0.45),
    ],
)
def test_on_the_shipped_trajectories_the_absolute_limit_alone_decides(name, extent):
    """A fifth of each shipped trajectory's extent is above the default runs' 84.85 mm
    limit, so the relative limit changes no default run's verdict."""
    from ddwmmr.sim.simulate import trajectory_extent
    from ddwmmr.sim.verdict import EXTENT_FRACTION

    empty = {"xE_d": np.zeros(0), "yE_d": np.zeros(0)}
    found = trajectory_extent(load_trajectory(name), empty)
    assert found == pytest.approx(extent, abs=1e-3)
    assert EXTENT_FRACTION * found > 2.0 * math.hypot(0.03, 0.03)


# -- an mpc started below its own floor -------------------------------------------------

CLEAN_MPC = {
    **OFF_TRACK,
    "rms_position_error_m": 0.003,
    "mpc_fallbacks": 0,
    "start_stability": 2.1776,
    "stability_min": 2.5,
}


def test_an_mpc_started_below_its_floor_did_not_track():
    found = verdict(CLEAN_MPC)
    assert found["verdict_reasons"] == ["below_floor_at_start"]
    assert found["verdict"].startswith(
        "did not track: the mpc started below its stability floor (start S = 2.1776 < "
        "stability_min 2.5), breaking its constraint from the first step; likely cause: the "
        "run starts below its stability floor"
    )
    assert verdict({**CLEAN_MPC, "stability_min": 1.25})["verdict"] == "tracked"
    # the qp's recovery from below its floor is its documented behaviour: tracked
    qp = {**CLEAN_MPC, "mpc_fallbacks": None, "qp_fallbacks": 0}
    assert verdict(qp)["verdict_reasons"] == []
    assert verdict(qp)["verdict"].startswith(
        "tracked; warning: the run started below its stability floor (start S = 2.1776 < "
        "stability_min 2.5;"
    )


def test_an_mpc_run_from_below_its_floor_says_so():
    """stability_min 2.5 from the default start's S = 2.18: the mpc raises S after a few
    steps and then tracks within 3 mm; it read "tracked"."""
    result = simulate(Robot(), load_trajectory("ellipse"), "mpc", duration=2.0, stability_min=2.5)
    summary = result.summary
    assert summary["start_stability"] == pytest.approx(2.1776, abs=1e-4)
    assert summary["stability_violations"] > 0
    assert summary["verdict_reasons"] == ["below_floor_at_start"]
