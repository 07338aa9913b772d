"""The verdict's absolute error limits follow the robot's size (docs/cli.md, "Verdict").

A robot scaled by s in every length, on a trajectory scaled by s, is the default robot
seen in another length unit: its controllers are damped on the default robot's steps
(tests/test_damping_invariance.py) and it runs with s times the default run's errors. Its
verdict must be the default run's: the 50 mm and 10 mm limits are the default robot's, and
another robot's are as many of its length units (``length_unit_m`` in the summary). A
summary that does not record the unit is judged in metres, as before.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.sim.verdict import check_summary, error_limit, extent_limit, verdict
from scaled_robots import TEN_TIMES, TWENTIETH

#: (robot, its size relative to the default robot's)
SCALED = [(TWENTIETH, 0.05), (TEN_TIMES, 10.0)]
#: (method, options, ellipse, start offset (m) on the default robot) of a run that tracks
#: and one that does not, each scaled with the robot: clrrmc-ts from no offset with a large
#: step (dt = 1 s) tracks 7.67 mm RMS off (8.46 mm final); ats with the auxiliary row
#: th1dot + th2dot = 0 on the constant-orientation ellipse (the default offset) does not,
#: 1291 mm RMS and 611 mm final.
TRACKS = ("clrrmc-ts", {"dt": 1.0}, Ellipse(), 0.0)
FAILS = ("ats", {"aux": "sum"}, Ellipse(orientation="constant"), -0.03)
CASES = {"tracks": TRACKS, "fails": FAILS}


def run(robot: Robot, factor: float, case: str) -> dict:
    """The summary of ``CASES[case]`` on ``robot``, its ellipse and offset scaled by
    ``factor``."""
    method, options, ellipse, offset = CASES[case]
    trajectory = replace(ellipse, a=factor * ellipse.a, b=factor * ellipse.b)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a 0.05x robot's lengths look like unit mistakes
        start = (factor * offset, factor * offset)
        return simulate(robot, trajectory, method, initial_offset=start, **options).summary


def cause(summary: dict) -> str:
    """The verdict's likely cause (``""`` where it tracked)."""
    return summary["verdict"].partition("likely cause: ")[2]


@pytest.fixture(scope="module")
def default_runs() -> dict[str, dict]:
    return {case: run(Robot(), 1.0, case) for case in CASES}


def test_the_default_runs_are_the_documented_ones(default_runs):
    tracks, fails = default_runs["tracks"], default_runs["fails"]
    assert tracks["length_unit_m"] == 1.0
    assert tracks["verdict"] == "tracked"
    assert tracks["rms_position_error_m"] == pytest.approx(7.67e-3, abs=5e-5)
    assert tracks["final_position_error_m"] == pytest.approx(8.46e-3, abs=5e-5)
    assert fails["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert fails["final_position_error_m"] == pytest.approx(0.611, abs=5e-4)
    assert fails["rms_position_error_m"] == pytest.approx(1.29, abs=5e-3)
    assert "(limit 84.85 mm)" in fails["verdict"]
    assert "robot's size" not in fails["verdict"]


@pytest.mark.parametrize("case", ["tracks", "fails"])
@pytest.mark.parametrize(("robot", "factor"), SCALED, ids=["0.05x", "10x"])
def test_a_scaled_robot_gets_the_default_runs_verdict(default_runs, robot, factor, case):
    """In metres the 10x robot's tracking run (76.7 mm RMS) did not track, and the 0.05x
    robot's failing run passed its final error (30.5 mm, under 50 mm)."""
    reference = default_runs[case]
    summary = run(robot, factor, case)
    assert summary["length_unit_m"] == pytest.approx(factor, rel=1e-12)
    for key in ("rms_position_error_m", "final_position_error_m", "trajectory_extent_m"):
        assert summary[key] == pytest.approx(factor * reference[key], rel=1e-6)
    assert summary["verdict_reasons"] == reference["verdict_reasons"]
    assert cause(summary) == cause(reference)
    assert error_limit(summary) == pytest.approx(factor * error_limit(reference), rel=1e-12)


def test_the_limit_text_names_the_robots_size():
    far = {"trajectory_extent_m": 0.25, "final_position_error_m": 0.003, "length_unit_m": 0.05}
    assert (
        "settled-end RMS position error 3 mm "
        "(limit 2.5 mm for this robot's size (length_unit_m 0.05))" in (verdict(far)["verdict"])
    )
    point = {**far, "trajectory_extent_m": 0.0}
    assert (
        "(limit 0.5 mm for a trajectory 0 mm across and this robot's size (length_unit_m 0.05))"
    ) in verdict(point)["verdict"]
    offset = {**far, "initial_offset_m": 0.00125}  # 2 x offset = 2.5 mm: still the size's
    assert "(limit 2.5 mm for this robot's size" in verdict(offset)["verdict"]
    offset = {**far, "initial_offset_m": 0.0013}  # the offset sets it
    assert "(limit 2.6 mm);" in verdict(offset)["verdict"]


def test_a_summary_without_the_unit_is_judged_in_metres(default_runs):
    """A summary written before ``length_unit_m`` was: the 50 mm limit, as then."""
    tracked = {key: value for key, value in default_runs["tracks"].items() if key != "verdict"}
    scaled = {
        **tracked,
        **{key: 10.0 * tracked[key] for key in ("rms_position_error_m", "final_position_error_m")},
    }
    old = {key: value for key, value in scaled.items() if key != "length_unit_m"}
    assert error_limit(old) == 0.05
    assert verdict(old)["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert verdict({**scaled, "length_unit_m": 10.0})["verdict"] == "tracked"
    assert verdict({**old, "length_unit_m": None}) == verdict(old)


#: A held point (extent 0) 8 mm off at its end and 12 mm RMS on the default robot: the
#: 10 mm floor fails its RMS alone.
HELD_POINT = {
    "steps": 100,
    "duration": 2.0,
    "trajectory_extent_m": 0.0,
    "initial_offset_m": 0.0,
    "max_position_error_m": 0.02,
    "final_position_error_m": 0.008,
    "rms_position_error_m": 0.012,
}


@pytest.mark.parametrize("factor", [1e-3, 0.05, 10.0])
def test_a_summary_scaled_with_its_unit_keeps_its_verdict(factor):
    """At 1e-3 the robot's arm (0.65 mm) is shorter than the 10 mm floor in metres, which
    passed the scaled held point (12 um RMS)."""
    lengths = {key: factor * value for key, value in HELD_POINT.items() if key.endswith("_m")}
    scaled = {**HELD_POINT, **lengths, "length_unit_m": factor}
    assert extent_limit(scaled) == pytest.approx(0.01 * factor, rel=1e-12)
    assert verdict(scaled)["verdict_reasons"] == verdict(HELD_POINT)["verdict_reasons"]
    assert verdict(HELD_POINT)["verdict_reasons"] == ["rms_error_above_limit"]
    assert cause(verdict(scaled)) == cause(verdict(HELD_POINT))


@pytest.mark.parametrize(
    "value", [0.0, -1.0, "nan", "inf", math.inf, 1e9, 1e-9, "ten", True, [1.0]]
)
def test_a_bad_unit_is_refused_in_one_line(value):
    with pytest.raises(ParameterError, match="length_unit_m") as error:
        verdict({**HELD_POINT, "length_unit_m": value})
    assert "\n" not in str(error.value)
    with pytest.raises(ParameterError, match="length_unit_m"):
        check_summary({"length_unit_m": value})
