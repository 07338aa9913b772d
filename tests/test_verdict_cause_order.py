"""The verdict's likely cause names what to fix first: a trajectory that saturates the
commands on almost every step before what the arm did, and a run that converged but
spent a short run removing its start offset as such, not as "did not converge"."""

import math
from pathlib import Path

import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.sim.verdict import (
    FOLDED_ARM,
    FOLDING_METHODS,
    NO_CONVERGENCE,
    SATURATED_THROUGHOUT,
    SLIDES_ROW,
    verdict,
)

FIGURE8 = Path(__file__).resolve().parents[1] / "trajectories" / "figure8.csv"
OFFSET = math.hypot(0.03, 0.03)  # the default start offset (m)

#: A failed run whose arm folded (min manipulability 0), saturated on ``saturated_steps``.
FOLDED = {
    "method": "ats",
    "steps": 3000,
    "duration": 60.0,
    "singular_steps": 0,
    "saturated_steps": 0,
    "initial_offset_m": OFFSET,
    "max_position_error_m": 2.0,
    "final_position_error_m": 0.7,
    "rms_position_error_m": 2.0,
    "min_manipulability": 0.0,
}


def _cause(summary: dict) -> str:
    return verdict(summary)["verdict"].split("; likely cause: ", 1)[1]


def _figure8_in_mm(folder: Path) -> Path:
    """figure8.csv with its positions written in mm where m are read (1000 times larger)."""
    lines = FIGURE8.read_text(encoding="utf-8").splitlines()
    out = []
    for line in lines:
        if line[:1].isdigit():
            t, x, y = line.split(",")
            line = f"{t},{1000.0 * float(x):.6f},{1000.0 * float(y):.6f}"
        out.append(line)
    path = folder / "f8mm.csv"
    path.write_text("\n".join(out) + "\n", encoding="utf-8")
    return path


def test_a_trajectory_in_mm_is_named_as_asking_too_much_not_as_a_folded_arm(tmp_path):
    """figure8 in mm: every one of the 3000 commands is clipped and the arm folds; the
    trajectory is what to fix."""
    summary = simulate(Robot(), load_trajectory(_figure8_in_mm(tmp_path)), "ats").summary
    assert summary["steps"] == 3000
    assert summary["saturated_steps"] == 3000
    assert summary["min_manipulability"] < 1e-6
    assert summary["verdict_reasons"] == [
        "saturated_most_of_run",
        "final_error_above_limit",
        "rms_error_above_limit",
    ]
    assert _cause(summary) == SATURATED_THROUGHOUT
    assert "folded" not in summary["verdict"]


@pytest.mark.parametrize(
    ("saturated", "expected"),
    [
        (0, FOLDED_ARM.format(methods=", ".join(FOLDING_METHODS))),
        (1740, FOLDED_ARM.format(methods=", ".join(FOLDING_METHODS))),  # 0.58: the arm
        (2700, FOLDED_ARM.format(methods=", ".join(FOLDING_METHODS))),  # 0.9 is not above
        (2701, SATURATED_THROUGHOUT),
        (3000, SATURATED_THROUGHOUT),
    ],
)
def test_saturation_comes_first_only_on_almost_every_step(saturated, expected):
    assert _cause({**FOLDED, "saturated_steps": saturated}) == expected


def test_the_slides_row_keeps_its_cause_at_its_saturation():
    """clrrmc-ts with the slides' settings on the rectangle: singular on 1641 and saturated
    on 1153 of 2000 steps (0.58, the most of any default run that fails): aux sum."""
    summary = {
        **FOLDED,
        "method": "clrrmc-ts",
        "aux": "sum",
        "steps": 2000,
        "singular_steps": 1641,
        "saturated_steps": 1153,
        "min_manipulability": 0.0005,
    }
    assert _cause(summary) == SLIDES_ROW
    assert _cause({**summary, "saturated_steps": 1801}) == SATURATED_THROUGHOUT


def _still(folder: Path) -> Path:
    path = folder / "still.csv"
    path.write_text("t,x,y\n0,0,0\n1,0,0\n2,0,0\n", encoding="utf-8")
    return path


def test_a_short_held_point_that_converged_is_not_said_not_to_converge(tmp_path):
    """A held point for 2 s from the default 42.4 mm offset: clrrmc-ts ends 0.844 mm off,
    but removing the offset (tau 0.5 s) puts 15.2 mm in the RMS, above the 10 mm limit of a
    trajectory 0 mm across. The cause says so, and each remedy it names tracks."""
    trajectory = load_trajectory(_still(tmp_path))
    summary = simulate(Robot(), trajectory, "clrrmc-ts").summary
    assert summary["verdict_reasons"] == ["rms_error_above_limit"]
    assert summary["final_position_error_m"] == pytest.approx(0.000844, abs=2e-6)
    assert summary["rms_position_error_m"] == pytest.approx(0.01522, abs=5e-5)
    assert summary["max_position_error_m"] == pytest.approx(OFFSET, rel=1e-9)
    assert "did not converge" not in summary["verdict"]
    assert _cause(summary) == (
        "the error converged (settled-end RMS position error 0.844 mm, within the limit) "
        "but never rose above the start offset (42.4 mm), whose removal took a large part of "
        "this 2 s run and counts in its RMS: a longer run or a smaller start offset (track's "
        '--duration and --offset; see docs/cli.md, "Verdict")'
    )
    longer = simulate(Robot(), trajectory, "clrrmc-ts", duration=10.0).summary
    assert longer["verdict"] == "tracked"
    assert longer["rms_position_error_m"] == pytest.approx(0.00684, abs=5e-5)
    on_path = simulate(Robot(), trajectory, "clrrmc-ts", initial_offset=(0.0, 0.0)).summary
    assert on_path["verdict"] == "tracked"


def test_an_open_loop_method_on_a_held_point_keeps_its_offset_and_its_cause(tmp_path):
    """ats keeps the 42.4 mm offset: final and RMS above the 10 mm limit, not converged."""
    summary = simulate(Robot(), load_trajectory(_still(tmp_path)), "ats").summary
    assert summary["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert summary["final_position_error_m"] == pytest.approx(OFFSET, rel=1e-9)
    assert _cause(summary) == NO_CONVERGENCE


CONVERGED = {
    "steps": 100,
    "duration": 2.0,
    "singular_steps": 0,
    "saturated_steps": 0,
    "trajectory_extent_m": 0.0,
    "initial_offset_m": OFFSET,
    "max_position_error_m": OFFSET,
    "final_position_error_m": 0.000844,
    "rms_position_error_m": 0.0152,
    "min_manipulability": 0.57,
}


@pytest.mark.parametrize(
    ("change", "converged"),
    [
        ({}, True),
        ({"max_position_error_m": 1.0099 * OFFSET}, True),  # within the 1 % slack
        ({"max_position_error_m": 1.02 * OFFSET}, False),  # rose above its start
        ({"max_position_error_m": None}, False),  # not recorded: not known
        ({"initial_offset_m": 0.0, "max_position_error_m": 0.03}, False),
        ({"final_position_error_m": 0.02}, False),  # the final error failed too
    ],
)
def test_the_start_offset_is_named_only_when_it_alone_explains_the_rms(change, converged):
    summary = {**CONVERGED, **change}
    assert verdict(summary)["verdict_reasons"] != []
    assert _cause(summary).startswith("the error converged (settled-end RMS ") is converged
    if not converged:
        assert _cause(summary) == NO_CONVERGENCE


def test_a_summary_without_a_duration_drops_it_from_the_sentence():
    summary = {**CONVERGED, "duration": None}
    assert "took a large part of this run and counts" in _cause(summary)


def test_a_largest_error_that_is_no_number_is_refused_by_name():
    with pytest.raises(ParameterError, match=r"summary: max_position_error_m must be a"):
        verdict({**CONVERGED, "max_position_error_m": "big"})
