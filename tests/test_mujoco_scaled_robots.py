"""The MuJoCo plant on robots far from the default size (tyres scaled to the robot, wheels
wider than half the track, short links) and the verdict's causes for a tilt-only tip-over
and for an arm folded on a trajectory without corners."""

from dataclasses import replace

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, load_trajectory, simulate
from ddwmmr.plants.mujoco import MujocoPlant
from ddwmmr.plants.mujoco.model import (
    DEFAULT_TYRE_STIFFNESS,
    LINK_RADIUS,
    EngineOptions,
    build_model,
    mjcf,
    tyre_stiffness,
)
from ddwmmr.sim.verdict import TIPPED, likely_cause
from scaled_robots import TEN_TIMES, TWENTIETH

LARGE, SMALL = TEN_TIMES, TWENTIETH


def test_the_default_robot_keeps_its_tyre_stiffness_at_any_payload():
    for payload in (0.0, 1.25, 3.0, 0.1):
        robot = Robot().with_payload(payload)
        assert tyre_stiffness(robot, EngineOptions()) == DEFAULT_TYRE_STIFFNESS
    assert tyre_stiffness(LARGE, EngineOptions(tyre_stiffness=1e4)) == 1e4


def test_the_tyre_stiffness_scales_with_the_robot_s_own_weight_over_its_track():
    # 1000 times the own mass (12 kg -> 12000 kg) on 10 times the track: 100 times 5e4
    assert tyre_stiffness(LARGE, EngineOptions()) == pytest.approx(5e6, rel=1e-12)
    model = build_model(LARGE)
    assert model.jnt_stiffness[model.joint("tyre_left").id] == pytest.approx(5e6, rel=1e-12)


def test_a_large_robot_no_longer_tips_over_on_its_soft_tyres():
    """With the fixed 5e4 N/m tyres it tipped at 1.64 s (tilt 0.35 rad, every edge loaded,
    min S_phys 1.28); with tyres scaled to it the base tilts 2 mrad."""
    ellipse = Ellipse(a=20.0, b=15.0, T=40.0, N=2000)
    summary = simulate(
        LARGE, ellipse, "clrrmc-ts", plant="mujoco", duration=2.0, initial_offset=(-0.3, -0.3)
    ).summary
    assert summary["tipped"] is False
    assert summary["max_base_tilt_rad"] < 0.01


@pytest.mark.parametrize("radius", [0.25, 0.4])
def test_wheels_wider_than_half_the_track_touch_the_floor_only(radius):
    """Wheel spheres of radius > track_width / 2 overlapped, and their contact flipped the
    robot at the start from about 0.34 m (0.4 m: tipped at 0.02 s, tilt 2 rad)."""
    robot = replace(Robot(), wheel_radius=radius)
    plant = MujocoPlant(robot)
    plant.reset(np.array([0.0, 0.0, 0.0, -0.3, 0.6]), 0.02)
    data, model = plant.data, plant.model
    wheels = {model.geom("wheel_left").id, model.geom("wheel_right").id}
    pairs = {frozenset((c.geom1, c.geom2)) for c in data.contact[: data.ncon]}
    assert frozenset(wheels) not in pairs
    summary = simulate(robot, load_trajectory("rectangle"), "ats", plant="mujoco", duration=0.5)
    assert summary.summary["tipped"] is False
    assert summary.summary["max_base_tilt_rad"] < 1e-3


def test_short_links_build_with_a_radius_a_quarter_of_their_length():
    model = build_model(SMALL)
    link1 = model.body("link1").id
    m1 = SMALL.link_masses[0]
    axial = 0.5 * m1 * (SMALL.L1 / 4.0) ** 2
    assert model.body_inertia[link1][0] == pytest.approx(axial, rel=1e-12)
    assert f'size="{LINK_RADIUS:.17g}"' in mjcf(Robot())  # the default links keep 2 cm


def test_a_small_robot_tracks_on_mujoco():
    ellipse = Ellipse(a=0.1, b=0.075, T=40.0, N=2000)
    summary = simulate(
        SMALL, ellipse, "ats", plant="mujoco", duration=2.0, initial_offset=(-0.003, -0.003)
    ).summary
    assert summary["tipped"] is False
    assert summary["max_base_tilt_rad"] < 0.01


def _tip_summary(**changes):
    summary = {
        "tipped": True,
        "unloaded_time_s": 0.0,
        "min_physics_stability": 1.28,
        "max_base_tilt_rad": 0.348,
        "plant": "mujoco",
    }
    return {**summary, **changes}


def test_a_tip_over_by_the_tilt_alone_blames_soft_contacts_not_the_payload():
    cause = likely_cause(_tip_summary(), ["tipped_over"])
    assert cause.startswith(
        "the base tilted past the tip rule's angle (max_base_tilt_rad 0.348) with every edge "
        "of the support polygon loaded (unloaded_time_s 0, min_physics_stability 1.28 > 1)"
    )
    assert "payload" in cause and "tyre_stiffness" in cause


@pytest.mark.parametrize(
    "changes", [{"unloaded_time_s": 0.04}, {"min_physics_stability": 0.9}, {"tipped": None}]
)
def test_a_tip_over_with_an_edge_unloaded_still_names_the_centre_of_pressure(changes):
    summary = _tip_summary(**changes)
    if changes.get("tipped", True) is None:
        summary = {"tipped": True}  # a summary without the physics keys
    assert likely_cause(summary, ["tipped_over"]) == TIPPED


def _folded(**changes):
    summary = {
        "method": "pi",
        "dt": 2.0,
        "steps": 20,
        "min_manipulability": 1.2e-16,
        "corner_position_error_m": None,
    }
    return {**summary, **changes}


def test_an_arm_folded_on_a_trajectory_without_corners_names_the_step():
    cause = likely_cause(_folded(), ["final_error_above_limit"])
    assert "corners at" not in cause
    assert "(this one has no corners): a smaller dt (this run's: 2 s)" in cause
    assert "integrates Xd_dot (pi)" in cause


def test_an_arm_folded_on_a_rectangle_keeps_the_corner_explanation():
    cause = likely_cause(_folded(corner_position_error_m=0.4), ["final_error_above_limit"])
    assert "loses the orientation steps at corners" in cause
    no_key = _folded()
    del no_key["corner_position_error_m"]
    assert "at corners" in likely_cause(no_key, ["final_error_above_limit"])


def test_a_coarse_pi_run_on_the_ellipse_names_the_step_not_corners():
    summary = simulate(Robot(), load_trajectory("ellipse"), "pi", dt=2.0, duration=40.0).summary
    assert summary["min_manipulability"] < 1e-6
    assert "a smaller dt (this run's: 2 s)" in summary["verdict"]
    assert "at corners" not in summary["verdict"]
