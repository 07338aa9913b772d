"""The docs/qp.md demonstrations, with a 3 kg payload (docs/theory.md, "Tip-over stability":
a full sideways stretch then reaches S = 1 exactly)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.qp.limits import load_obstacles
from footprint import footprint_outline

ROBOT = Robot().with_payload(3.0)
ROOT = Path(__file__).resolve().parents[1]
OBSTACLES = ROOT / "trajectories" / "obstacles" / "ellipse_post.toml"


@pytest.fixture(scope="module")
def reach():
    """The sideways reach and its intended start (arm already to the left)."""
    trajectory = load_trajectory("sideways_reach")
    return trajectory, ROBOT.base_for_end_effector(trajectory.pose(0.0), 1.0, 1.6)


@pytest.mark.parametrize("method", ["ats", "clrrmc-ts", "pi", "ap"])
def test_jacobian_methods_let_stability_fall_below_the_floor(reach, method):
    trajectory, q0 = reach
    result = simulate(ROBOT, trajectory, method, q0=q0)
    assert result.summary["min_stability"] < 1.2
    assert np.sum(result.timeseries["stability"] < 1.25) > 100  # of 401 steps


@pytest.mark.parametrize("mode", ["weighted", "hierarchical"])
def test_qp_keeps_stability_at_every_step_and_still_tracks(reach, mode):
    trajectory, q0 = reach
    summary = simulate(ROBOT, trajectory, "qp", q0=q0, mode=mode).summary
    assert summary["min_stability"] >= 1.25
    assert summary["stability_violations"] == 0
    assert summary["qp_fallbacks"] == 0
    assert summary["rms_position_error_m"] < 1e-3
    assert summary["max_position_error_m"] < 2e-3


def test_qp_beats_clrrmc_ts_on_manipulability_with_comparable_tracking():
    trajectory = load_trajectory("ellipse")
    baseline = simulate(ROBOT, trajectory, "clrrmc-ts").summary
    qp = simulate(ROBOT, trajectory, "qp").summary
    assert qp["mean_manipulability"] > baseline["mean_manipulability"] + 0.1
    assert qp["rms_position_error_m"] < 1.1 * baseline["rms_position_error_m"]
    assert qp["rms_orientation_error_rad"] < 1.2 * baseline["rms_orientation_error_rad"]
    assert qp["stability_violations"] == 0 and qp["qp_fallbacks"] == 0


def _brute_clearance(ts: dict, circle, n: int = 1001) -> np.ndarray:
    """Footprint-to-circle clearance (m) at every recorded pose, by brute force: the
    distance from the circle centre to points sampled densely on the footprint outline,
    minus the radius, negative (-1) when the centre lies inside the footprint or the
    circle reaches past the outline. Independent of ddwmmr.qp.limits.obstacles."""
    hl, hw = 0.5 * ROBOT.base_length, 0.5 * ROBOT.base_width
    outline = footprint_outline(hl, hw, n)
    c, si = np.cos(ts["phi"]), np.sin(ts["phi"])
    dx, dy = circle.x - ts["x"], circle.y - ts["y"]
    px, py = c * dx + si * dy, -si * dx + c * dy  # centre in the base frame
    dist = np.hypot(px[:, None] - outline[None, :, 0], py[:, None] - outline[None, :, 1])
    clearance = dist.min(axis=1) - circle.radius
    inside = (np.abs(px) <= hl) & (np.abs(py) <= hw)
    return np.where(inside | (clearance < 0.0), -1.0, clearance)


def test_base_footprint_never_touches_an_obstacle_on_its_path():
    trajectory = load_trajectory("ellipse")
    (circle,) = load_obstacles(OBSTACLES)
    free = simulate(ROBOT, trajectory, "clrrmc-ts").timeseries
    # Without the limit the base drives right through the post.
    assert _brute_clearance(free, circle).min() < 0.0
    result = simulate(ROBOT, trajectory, "qp", obstacles=[circle])
    summary, ts = result.summary, result.timeseries
    brute = _brute_clearance(ts, circle)
    assert brute.min() > 0.3  # docs/qp.md: the footprint stays 0.33 m clear
    # The summary's own clearance (exact rectangle distance) matches to the sampling error.
    assert summary["min_obstacle_clearance_m"] == pytest.approx(brute.min(), abs=1e-6)
    assert summary["rms_position_error_m"] < 0.03  # the arm reaches around the post
    assert summary["stability_violations"] == 0 and summary["qp_fallbacks"] == 0


def test_summary_gains_the_qp_keys():
    trajectory = load_trajectory("ellipse", T=4.0, N=200)
    summary = simulate(ROBOT, trajectory, "qp", solver="quadprog").summary
    for key in (
        "stability_min",
        "stability_violations",
        "qp_fallbacks",
        "min_obstacle_clearance_m",
    ):
        assert key in summary
    assert summary["min_obstacle_clearance_m"] is None
    assert summary["qp_solver"] == "quadprog"


def test_docs_page_snippets_run():
    """The python blocks of docs/qp.md run top to bottom in one namespace."""
    text = (ROOT / "docs" / "qp.md").read_text()
    blocks = [part.split("```", 1)[0] for part in text.split("```python\n")[1:]]
    assert len(blocks) >= 2
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "docs/qp.md", "exec"), namespace)
    controller = namespace["controller"]
    assert [type(t).__name__ for t in controller.tasks][-1] == "SpinTask"
    assert type(controller.limits[-1]).__name__ == "SlowBase"
