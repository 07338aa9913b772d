"""The verdict of a qp or mpc run whose plant clipped a joint at its position limit while
the controller held a wheel at its speed limit inside its own bounds, and the warning of a
run that started below its own stability floor (docs/cli.md, "Verdict")."""

from __future__ import annotations

import warnings

import pytest

from ddwmmr.model import Robot
from ddwmmr.sim.simulate import simulate
from ddwmmr.sim.verdict import (
    BELOW_FLOOR,
    SATURATED_THROUGHOUT,
    SATURATION,
    STARTED_BELOW_FLOOR,
    floor_warning,
    verdict,
)
from ddwmmr.trajectories import Ellipse

#: Far off the path at the end: a run that did not track, whatever else it did.
FAILED = {
    "final_position_error_m": 0.3,
    "rms_position_error_m": 0.3,
    "max_position_error_m": 0.4,
    "initial_offset_m": 0.0424,
}

#: A qp run (``qp_fallbacks`` in its summary) that held a wheel at its speed limit on 950
#: of 1000 steps within its own bounds while the plant stopped th2 at its position limit
#: on the same 950 steps: every clipped step is the joint limit's.
QP_AT_JOINT_LIMIT = {
    **FAILED,
    "steps": 1000,
    "saturated_steps": 950,
    "joint_limit_steps": 950,
    "joint_limit_held": "th2 = 0.3 rad",
    "wheel_limit_steps": 950,
    "joint_rate_limit_steps": 0,
    "qp_fallbacks": 0,
}


def _cause(summary: dict) -> str:
    return verdict(summary)["verdict"].split("; likely cause: ", 1)[1]


@pytest.mark.parametrize("controller_key", ["qp_fallbacks", "mpc_fallbacks"])
def test_a_wheel_held_in_bounds_does_not_take_the_joint_limits_clipping(controller_key):
    """The clipping was th2's position limit: the cause names it, with the 950 clipped
    steps, not the rate limits (neither "throughout" nor "most of the run")."""
    summary = {
        **{k: v for k, v in QP_AT_JOINT_LIMIT.items() if k != "qp_fallbacks"},
        controller_key: 0,
    }
    assert verdict(summary)["verdict_reasons"] == [
        "saturated_most_of_run",
        "final_error_above_limit",
        "rms_error_above_limit",
    ]
    cause = _cause(summary)
    assert cause not in (SATURATED_THROUGHOUT, SATURATION)
    assert cause.startswith(
        "the arm held at a joint limit (th2 = 0.3 rad) on 950 of 1000 steps, where the plant "
        "stops the joint"
    )
    assert "the plant clipped the commands on 950 of 1000 steps, saturated_steps" in cause


def test_rate_limits_clipped_beyond_the_joint_limit_still_read_as_throughout():
    """The same qp run with 960 of 1000 steps clipped and 10 at the joint limit: 950 steps
    were clipped at a rate limit (> 0.9 of the run), which stays saturation throughout."""
    summary = {**QP_AT_JOINT_LIMIT, "saturated_steps": 960, "joint_limit_steps": 10}
    assert _cause(summary) == SATURATED_THROUGHOUT


def test_a_resolution_method_clipped_at_its_wheel_limit_is_unchanged():
    """Without qp_fallbacks or mpc_fallbacks (a resolution method, whose commands the
    plant clips at the wheel limit) the wheel-limit steps count as clipped: throughout."""
    summary = {k: v for k, v in QP_AT_JOINT_LIMIT.items() if k != "qp_fallbacks"}
    assert _cause(summary) == SATURATED_THROUGHOUT


# -- a run started below its own stability floor ------------------------------------------
#: A qp run on the default ellipse that tracked from S = 2.178 below a floor of 2.3.
BELOW_FLOOR_TRACKED = {
    "steps": 2000,
    "final_position_error_m": 0.002,
    "rms_position_error_m": 0.004,
    "max_position_error_m": 0.0424,
    "initial_offset_m": 0.0424,
    "start_stability": 2.1776257294896024,
    "stability_min": 2.3,
    "min_stability": 2.1776257294896024,
    "qp_fallbacks": 0,
}


def test_a_qp_run_started_below_its_floor_tracks_with_a_warning():
    result = verdict(BELOW_FLOOR_TRACKED)
    assert result["verdict_reasons"] == []
    assert result["verdict"] == (
        "tracked; warning: the run started below its stability floor (start S = 2.17763 < "
        "stability_min 2.3; start_stability, stability_min), so the floor did not hold from "
        'the start: start above it or lower stability_min (see docs/qp.md, "Limitations")'
    )


def test_no_floor_warning_at_or_above_the_floor_or_without_the_numbers():
    at_floor = {**BELOW_FLOOR_TRACKED, "stability_min": 2.1776257294896024}
    assert verdict(at_floor)["verdict"] == "tracked"
    no_floor = {k: v for k, v in BELOW_FLOOR_TRACKED.items() if k != "stability_min"}
    assert verdict(no_floor)["verdict"] == "tracked"
    assert floor_warning(no_floor) == ""


def test_no_floor_warning_where_the_verdict_names_the_floor():
    """An mpc run has the reason below_floor_at_start, and a qp run that failed has the
    floor as its likely cause: neither repeats it as a warning."""
    mpc = {
        **{k: v for k, v in BELOW_FLOOR_TRACKED.items() if k != "qp_fallbacks"},
        "mpc_fallbacks": 0,
    }
    assert verdict(mpc)["verdict_reasons"] == ["below_floor_at_start"]
    assert "warning" not in verdict(mpc)["verdict"]
    failed = {**BELOW_FLOOR_TRACKED, **FAILED}
    text = verdict(failed)["verdict"]
    assert text.endswith(BELOW_FLOOR.format(start_stability="2.17763", stability_min="2.3"))
    assert "warning" not in text


def test_a_failed_run_whose_cause_is_another_keeps_the_floor_warning():
    """A qp run below its floor whose base entered an obstacle: the cause is the
    collision, and the warning still says where it started."""
    collided = {**BELOW_FLOOR_TRACKED, **FAILED, "min_obstacle_clearance_m": -0.01}
    text = verdict(collided)["verdict"]
    assert "likely cause: the controller's obstacle constraint gave way" in text
    assert text.endswith("; " + STARTED_BELOW_FLOOR.format(start="2.17763", floor="2.3"))


def test_a_real_qp_run_below_its_floor_warns():
    """The default ellipse with the qp's floor at 2.3 (start S = 2.178): it tracks, and
    says it started below the floor."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = simulate(Robot(), Ellipse(), method="qp", stability_min=2.3, duration=2.0)
    summary = result.summary
    assert summary["start_stability"] == pytest.approx(2.17763, abs=1e-5)
    assert summary["verdict_reasons"] == []
    assert summary["verdict"].startswith(
        "tracked; warning: the run started below its stability floor (start S = 2.17763 < "
        "stability_min 2.3;"
    )
