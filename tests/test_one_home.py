"""One home for three things defined twice: the slack range of a sampled trajectory
(computed once, with the trajectory), the joint clamp (the plants and the arm mover use
:func:`ddwmmr.model.robot.clamp_joints`) and the naming of the bounds cache (the matcher
of :func:`ddwmmr.bounds.batch.cache_entry` parses exactly the names
:func:`~ddwmmr.bounds.batch.cache_names` builds)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ddwmmr.behaviours.base import BRAKE, Proposal
from ddwmmr.behaviours.lowlevel import ArmMover
from ddwmmr.bounds import batch
from ddwmmr.bounds.search import Settings
from ddwmmr.model import Robot
from ddwmmr.model.robot import clamp_joints
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.plants.thesis import ThesisPlant
from ddwmmr.scenarios.generator import generate
from ddwmmr.trajectories import sampled
from ddwmmr.trajectories.sampled import SampledTrajectory

LIMITS = ((-1.0, 0.5), (0.2, 2.0))
ROBOT = Robot(joint_limits=LIMITS)


# -- the sampled trajectory's slack range -------------------------------------------------
def _line() -> SampledTrajectory:
    """A straight line at 0.5 m/s along x over 4 s (duration 4 s)."""
    times = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    return SampledTrajectory(times, np.column_stack([0.5 * times, np.zeros(5)]))


def test_the_slack_range_is_fixed_when_the_trajectory_is_made(monkeypatch):
    """The range is the trajectory's own, computed once: a later change of the module's
    MIN_STEP_FRACTION (a recomputation would read it) does not move where it holds."""
    line = _line()
    monkeypatch.setattr(sampled, "MIN_STEP_FRACTION", 0.5)
    inside = 4.0 * (1.0 + 0.5e-9)  # within 1e-9 of the duration past the end
    assert line.velocity(inside).tolist() == pytest.approx([0.5, 0.0, 0.0], abs=1e-12)
    for t in (4.4, 5.0, -0.4):  # beyond the slack of 4e-9 s (0.5 x 4 s would reach them)
        assert line.velocity(t).tolist() == [0.0, 0.0, 0.0]
    _, velocities = line.sample(np.array([inside, 4.4, 5.0, -0.4]))
    assert velocities[:, 0].tolist() == pytest.approx([0.5, 0.0, 0.0, 0.0], abs=1e-12)


def test_the_slack_range_widens_each_end_by_the_step_fraction():
    """The velocity is the end's speed within 1e-9 x duration past either end, zero
    beyond, for a trajectory that starts at t = 10 s (absolute)."""
    times = np.array([10.0, 11.0, 12.0, 13.0])
    line = SampledTrajectory(times, np.column_stack([2.0 * times, np.ones(4)]))
    d = line.duration
    for t, speed in ((-0.5e-9 * d, 2.0), (d * (1 + 0.5e-9), 2.0), (-2e-9 * d, 0.0)):
        assert line.velocity(t)[0] == pytest.approx(speed, abs=1e-12)
    assert line.velocity(d * (1 + 2e-9))[0] == 0.0


# -- the joint clamp ----------------------------------------------------------------------
@pytest.mark.parametrize(
    ("th1", "th2", "expected"),
    [
        (0.1, 1.0, (0.1, 1.0)),  # both inside
        (-1.5, 1.0, (-1.0, 1.0)),  # th1 below
        (0.9, 1.0, (0.5, 1.0)),  # th1 above
        (0.1, 0.1, (0.1, 0.2)),  # th2 below
        (0.1, 2.5, (0.1, 2.0)),  # th2 above
        (-7.0, 9.0, (-1.0, 2.0)),  # th1 below, th2 above
        (4.0, -4.0, (0.5, 0.2)),  # th1 above, th2 below
        (-1.0, 2.0, (-1.0, 2.0)),  # at the limits
        (-math.inf, math.inf, (-1.0, 2.0)),
    ],
)
def test_the_clamp_keeps_each_joint_within_its_limits(th1, th2, expected):
    assert clamp_joints(th1, th2, LIMITS) == pytest.approx(expected, abs=0.0)


def test_a_nan_angle_is_not_turned_into_a_limit():
    th1, th2 = clamp_joints(math.nan, 1.5, LIMITS)
    assert math.isnan(th1) and th2 == 1.5


#: Angles of each joint: inside, below, above, at both ends, far out, NaN.
ANGLES = (
    (0.1, -1.5, 0.9, -1.0, 0.5, -1e6, math.nan),
    (1.0, 0.1, 2.5, 0.2, 2.0, 1e6, math.nan),
)


def _same(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """Equal to the bit (NaN equals NaN)."""
    return np.array(a).tobytes() == np.array(b).tobytes()


def test_the_thesis_plant_clips_targets_with_the_one_clamp():
    plant = ThesisPlant(ROBOT)
    for a1, a2 in zip(*ANGLES):
        assert _same(plant.clip_targets(a1, a2), clamp_joints(a1, a2, LIMITS))


def test_the_arm_mover_clamps_targets_with_the_one_clamp():
    mover = ArmMover(ROBOT)
    for a1, a2 in zip(*ANGLES):
        assert _same(mover.targets(Proposal(BRAKE, (a1, a2))), clamp_joints(a1, a2, LIMITS))


def test_the_kinematic_plant_clamps_the_joints_after_a_step_with_the_one_clamp():
    """A zero joint rate leaves the angle as given; the step then clamps it."""
    plant = KinematicPlant(ROBOT, integrator="euler")
    held = np.zeros(4)
    for a1, a2 in zip(*ANGLES):
        q = np.array([0.0, 0.0, 0.0, a1, a2])
        new, _, _ = plant.integrate(0.0, q, 0.01, None, first_command=held, saturated=True)
        assert _same(tuple(new[3:].tolist()), clamp_joints(a1, a2, LIMITS))


# -- the naming of the bounds cache -------------------------------------------------------
@pytest.mark.parametrize("index", [1, 7, 999, 1000, 100_000])
def test_every_name_the_cache_builds_is_recognised(index):
    for part, name in batch.cache_names(index).items():
        assert batch.cache_entry(name) == (index, part)
    assert batch.cached_numbers(list(batch.cache_names(index).values())) == {index}


@pytest.mark.parametrize(
    "name",
    [
        "cache/scenario-1-best.json",  # too few digits
        "cache/scenario-0001-best.json",  # a leading zero cache_names does not write
        "cache/scenario-001-lower.npz",  # no such part
        "cache/scenario-001-best.json.tmp",
        "scenario-001-best.json",  # outside the cache folder
        "other/scenario-001-lower.json",
        "cache/scenario-abc-best.json",
        "cache/scenario-001-worst.json",
        "bounds.csv",
    ],
)
def test_a_name_the_cache_does_not_build_is_not_recognised(name):
    assert batch.cache_entry(name) is None
    assert batch.cached_numbers([name]) == set()


def _record(folder, index: int, payload: float) -> list[str]:
    """Scenario ``index``'s lower-bound record for ``payload`` (seed 0) in ``folder``."""
    scenario = generate(index, 0)[index - 1]
    key = batch.keys(scenario, payload, Settings())["lower"]
    return batch.store(folder, {"index": index, "lower": {"key": key, "lower_bound_s": 1.0}})


def test_the_kept_cache_is_judged_by_the_scenarios_passed_in(tmp_path):
    """Scenario 1's record matches; 2's was made for another payload; 3 is not among the
    scenarios passed in; a file not named by the cache is left out of both lists."""
    names = [*_record(tmp_path, 1, 3.0), *_record(tmp_path, 2, 2.0), *_record(tmp_path, 3, 3.0)]
    assert names == [f"cache/scenario-00{i}-lower.json" for i in (1, 2, 3)]
    stray = tmp_path / "cache" / "scenario-0001-lower.json"
    stray.write_text(json.dumps({"key": {}}))
    known = {s.index + 1: s for s in generate(2, 0)}
    kept, dropped = batch.reusable_cache(
        tmp_path, [*names, "cache/scenario-0001-lower.json"], known, 3.0
    )
    assert kept == ["cache/scenario-001-lower.json"]
    assert dropped == [2, 3]
