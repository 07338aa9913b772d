"""The verdict's likely cause of a run that left its trajectory to go round an obstacle."""

import math

import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.qp.limits import Circle
from ddwmmr.qp.limits.obstacles import ObstacleLimit
from ddwmmr.qp.tasks.avoidance import ObstacleSteeringTask
from ddwmmr.sim.verdict import OBSTACLE_NEAR_M, verdict

#: A closed-loop run 104.5 mm RMS off (limit 84.85 mm), nothing else wrong with it.
OFF_TRACK = {
    "steps": 2000,
    "singular_steps": 0,
    "saturated_steps": 0,
    "initial_offset_m": math.hypot(0.03, 0.03),
    "final_position_error_m": 0.0001,
    "rms_position_error_m": 0.1045,
    "min_manipulability": 0.9,
    "qp_fallbacks": 0,
}
NO_CONVERGENCE = (
    "did not track: RMS error 104.5 mm (limit 84.85 mm); likely cause: the error did not "
    "converge: an open-loop method (pi, ats, ap) never removes it; for a closed-loop one "
    'check tau, dt and the integrator (see docs/comparing.md, "Studies")'
)


def test_a_qp_going_round_a_post_on_the_path_is_blamed_on_the_post():
    """A 0.2 m post on the default ellipse's end-effector path: the qp keeps its footprint
    91.1 mm clear, never falls back, and ends 104.5 mm RMS off: the post is the cause."""
    result = simulate(Robot(), load_trajectory("ellipse"), "qp", obstacles=[Circle(0.0, 1.5, 0.2)])
    summary = result.summary
    assert summary["qp_fallbacks"] == 0
    assert summary["min_obstacle_clearance_m"] == pytest.approx(0.0911, abs=5e-4)
    assert summary["verdict_reasons"] == ["rms_error_above_limit"]
    assert summary["verdict"] == (
        "did not track: RMS error 104.5 mm (limit 84.85 mm); likely cause: the base went "
        "round an obstacle on or near the path (closest footprint clearance 91.1 mm, under "
        "the 600 mm within which the qp steers round obstacles) and left the trajectory to "
        'keep clear of it: a trajectory clear of the obstacles tracks (see docs/qp.md, "Obstacle '
        'on the path")'
    )


@pytest.mark.parametrize("clearance", [None, 0.6, 2.5, "nan"])
def test_without_an_obstacle_near_the_cause_is_unchanged(clearance):
    """No obstacles (None), or none within 600 mm: the verdict of a run without them."""
    summary = {**OFF_TRACK, "min_obstacle_clearance_m": clearance}
    assert verdict(summary)["verdict"] == verdict(OFF_TRACK)["verdict"] == NO_CONVERGENCE


def test_a_near_obstacle_is_the_cause_only_when_nothing_else_is():
    summary = {**OFF_TRACK, "min_obstacle_clearance_m": 0.012}  # close, not inside
    assert "closest footprint clearance 12 mm" in verdict(summary)["verdict"]
    fallbacks = {**summary, "qp_fallbacks": 1500}  # limits in conflict come first
    assert "the qp found no solution on 1500 of 2000 steps" in verdict(fallbacks)["verdict"]
    saturated = {**summary, "saturated_steps": 1500}
    assert "wheel and joint rate limits" in verdict(saturated)["verdict"]
    assert verdict({**summary, "rms_position_error_m": 0.01})["verdict"] == "tracked"


def test_a_clearance_that_is_no_number_is_refused_by_name():
    from ddwmmr.errors import ParameterError

    with pytest.raises(ParameterError, match=r"summary: min_obstacle_clearance_m must be a"):
        verdict({**OFF_TRACK, "min_obstacle_clearance_m": "close"})


def test_near_is_the_distance_within_which_the_qp_acts_on_obstacles():
    assert ObstacleLimit(Robot(), []).influence == OBSTACLE_NEAR_M
    assert ObstacleSteeringTask([], 0.3, 0.2).influence == OBSTACLE_NEAR_M


def test_a_footprint_inside_an_obstacle_does_not_track_whatever_the_error():
    """The mpc's soft obstacle constraint let a start 5 mm from a circle end 44 mm inside
    it, and the verdict spoke of convergence only: a negative clearance is a reason."""
    inside = {**OFF_TRACK, "rms_position_error_m": 0.001, "min_obstacle_clearance_m": -0.044}
    result = verdict(inside)
    assert result["verdict_reasons"] == ["collided"]
    assert result["verdict"].startswith(
        "did not track: the base entered an obstacle (footprint clearance -44 mm); likely "
        "cause: the controller's obstacle constraint gave way"
    )
    touching = verdict({**inside, "min_obstacle_clearance_m": 0.0})
    assert touching == {"verdict": "tracked", "verdict_reasons": []}  # touching is not in


def test_an_mpc_that_fell_back_on_most_steps_names_its_fallback():
    """qp_solver=osqp: the mpc's solver failed on every step and its qp commanded; the
    cause named convergence, tau and the integrator."""
    fell_back = {**OFF_TRACK, "qp_fallbacks": None, "mpc_fallbacks": 2000}
    assert verdict(fell_back)["verdict"].endswith(
        "likely cause: the mpc's solver failed on 2000 of 2000 steps and its qp fallback "
        "commanded them: the mpc's options (solver, qp_solver, grid) or limits the start "
        'cannot meet (see docs/mpc.md, "Options")'
    )
    assert verdict({**fell_back, "mpc_fallbacks": 1000})["verdict"] == NO_CONVERGENCE
