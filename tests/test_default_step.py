"""One default step for a CSV trajectory in every tool and the API: the rows' spacing,
made no coarser than 0.02 s (the rows are data, not a control step)."""

import json
import math

import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.cli.track import main as track
from ddwmmr.trajectories.base import resolution_step


def _write_s_curve(path, spacing, duration=60.0):
    """The tutorial's S-curve (0.1 m/s along x), one row every ``spacing`` s."""
    rows = ["t,x,y"]
    for k in range(round(duration / spacing) + 1):
        t = spacing * k
        rows.append(f"{t!r},{0.1 * t!r},{0.4 * math.sin(2 * math.pi * t / 60.0)!r}")
    path.write_text("\n".join(rows) + "\n")
    return path


def test_a_csv_with_rows_half_a_second_apart_runs_at_0_02_s_in_track_and_the_api(tmp_path):
    source = _write_s_curve(tmp_path / "s_curve.csv", 0.5)
    trajectory = load_trajectory(source)
    assert trajectory.samples == 120 and trajectory.default_step == 0.02
    api = simulate(Robot(), trajectory, "clrrmc-ts").summary
    out = tmp_path / "run"
    argv = ["--method", "clrrmc-ts", "--traj", str(source), "--no-plots", "--no-progress"]
    assert track([*argv, "--out", str(out)]) == 0
    cli = json.loads((out / "summary.json").read_text())
    assert api["dt"] == cli["dt"] == cli["run"]["dt"] == 60.0 / 3000
    assert api["steps"] == cli["steps"] == 3000
    assert api["rms_position_error_m"] == cli["rms_position_error_m"]
    # the coarse step the rows' spacing gave before: a different (worse) run
    coarse = simulate(Robot(), trajectory, "clrrmc-ts", dt=0.5).summary
    assert coarse["rms_position_error_m"] > 1.2 * api["rms_position_error_m"]


@pytest.mark.parametrize(
    ("spacing", "duration", "step"),
    [
        (0.01, 60.0, 0.01),  # rows finer than 0.02 s: their spacing
        (0.02, 8.0, 0.02),  # exactly 0.02 s: unchanged
        (0.25, 60.0, 0.02),  # figure8's rows: 3000 steps
        (0.3, 0.9, 0.9 / 45),  # the fewest whole steps of at most 0.02 s
    ],
)
def test_the_default_step_is_the_spacing_no_coarser_than_0_02_s(tmp_path, spacing, duration, step):
    trajectory = load_trajectory(_write_s_curve(tmp_path / "c.csv", spacing, duration))
    assert resolution_step(trajectory) == pytest.approx(step, rel=1e-12)
    assert resolution_step(trajectory) <= 0.02 + 1e-15
    steps = trajectory.duration / resolution_step(trajectory)
    assert steps == pytest.approx(round(steps), abs=1e-9)  # a whole number of steps


def test_the_shipped_csv_trajectories_run_at_0_02_s():
    for name, steps in (("figure8", 3000), ("sideways_reach", 400)):
        trajectory = load_trajectory(name)
        assert resolution_step(trajectory) == 0.02
        assert round(trajectory.duration / resolution_step(trajectory)) == steps
