"""Bad input to the trajectories (sampled times/points, non-finite t) raises a one-line
ParameterError naming the parameter; valid input keeps its exact results."""

import math

import numpy as np
import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.trajectories import Ellipse, Rectangle, SampledTrajectory, load_trajectory, read_csv
from ddwmmr.trajectories.sampled import MIN_STEP_FRACTION
from one_line import one_line

POINTS = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]


# -- 4. sampled trajectories ------------------------------------------------------------
@pytest.mark.parametrize(
    ("times", "points", "name"),
    [
        ([0, 1e-300, 2e-300], POINTS, r"times must span a duration in \[1e-06, 1e\+09\] s"),
        ([0, 2.5e-7, 5e-7], POINTS, r"times must span a duration in \[1e-06"),
        ([-6e8, 0, 6e8], POINTS, r"times must span a duration in .*1e\+09"),
        ([0, 1e-300, 1.0], POINTS, r"times must step by at least 1e-09 x the duration"),
        ([0.0, 1.0, 1.0], POINTS, r"times \(column t\) must be strictly increasing \(row 3"),
        ([2.0, 1.0, 3.0], POINTS, r"times \(column t\) must be strictly increasing \(row 2"),
        (["a", "b", "c"], POINTS, "times must be sample times .*strings"),
        (["0", "1", "2"], POINTS, "times must be sample times .*strings"),
        ([True, False, True], POINTS, "times must be sample times .*booleans"),
        # a boolean beside numbers: numpy made it 1 or 0 without a word
        ([0, True, 2], POINTS, r"^trajectory samples: times must be .*\(got booleans\)$"),
        ([0, 1, 2], [[True, False], [1, 0], [2, 0]], r"points must be .*\(got booleans\)$"),
        ([0, 1, 2], [[0, 0, True], [1, 0, 0], [2, 0, 0]], r"points must be .*\(got booleans\)"),
        (
            [0, 1, 2],
            [np.array([True, False]), np.array([1, 0]), np.array([2, 0])],
            r"points must be an \(n, 2\) or \(n, 3\) array \(m, rad\), numbers only \(got bool",
        ),
        ([0, 1, 10**400], POINTS, "times must be .*beyond float range"),
        ([0, 1, None], POINTS, "times must be .*non-numeric"),
        ([0, 1, math.nan], POINTS, "times must be finite numbers"),
        ([0, 1, 2e9], POINTS, r"times \|t\| must be <= 1e\+09 s"),
        ([[0, 1, 2]], POINTS, "times must be a 1-D sequence"),
        ([0, 1], POINTS[:2], "need at least 3 rows"),
        ([0, 1, 2], [[0, 0], [1], [2, 0]], "points must be .*ragged"),
        ([0, 1, 2], [[0, 0], [1, 10**400], [2, 0]], "points must be .*beyond float range"),
        ([0, 1, 2], [[0, 0], [1, "x"], [2, 0]], "points must be .*strings"),
        ([0, 1, 2], [[0, 0], [1, math.inf], [2, 0]], "points must be finite numbers"),
        ([0, 1, 2], [[0, 0], [1, 2e6], [2, 0]], r"points \|x\|, \|y\|, \|phi\| must be <= 1e\+06"),
        ([0, 1, 2], [0, 1, 2], r"points must be \(n, 2\) or \(n, 3\)"),
        ([0, 1, 2], [[0, 0, 0, 0]] * 3, r"points must be \(n, 2\) or \(n, 3\)"),
        ([0, 1, 2, 3], POINTS, r"points must be .*n = 4 rows"),
    ],
)
def test_sampled_trajectory_refuses_bad_samples(times, points, name):
    with pytest.raises(ParameterError, match=name) as info:
        SampledTrajectory(times=times, points=points)
    one_line(info)


def test_sampled_trajectory_name_must_be_a_string():
    with pytest.raises(ParameterError, match="name must be a string"):
        SampledTrajectory([0, 1, 2], POINTS, name=3)


def test_shortest_duration_and_step_are_accepted():
    SampledTrajectory([0.0, 0.5e-6, 1e-6], POINTS)  # the documented 1e-6 s minimum
    t = SampledTrajectory([0.0, MIN_STEP_FRACTION * 1.5, 1.5], POINTS)
    assert t.duration == 1.5
    assert np.all(np.isfinite(t.velocity(0.0)))


def test_the_rule_is_invariant_under_stretching_time():
    # the GUI stretches a file to T >= 1e-6 s: every shipped file stays valid at that T
    for name in ("figure8", "sideways_reach"):
        base = load_trajectory(name)
        times = (base.times - base.times[0]) * (1e-6 / base.duration)
        SampledTrajectory(times, base.points)


def test_valid_samples_keep_their_arrays_and_results():
    times = np.array([0.0, 0.5, 1.25, 2.0])
    points = np.array([[0.0, 0.0], [1.0, 0.5], [1.5, -0.5], [0.2, 0.1]])
    t = SampledTrajectory(times, points)
    assert t.times is times and t.points is points  # no copy, as before
    from_lists = SampledTrajectory(times.tolist(), points.tolist())
    assert from_lists.pose(0.7).tobytes() == t.pose(0.7).tobytes()
    ints = SampledTrajectory([0, 1, 2], [[0, 0], [1, 0], [2, 1]])
    assert ints.times.dtype == float and ints.duration == 2.0


def test_csv_errors_name_the_file_and_column(tmp_path):
    path = tmp_path / "tiny.csv"
    path.write_text("t,x,y\n0,0,0\n1e-300,1,0\n2e-300,2,0\n")
    with pytest.raises(ParameterError, match=r"^traj: .*tiny.csv: .*times must span a duration"):
        read_csv(path)
    path.write_text("t,x,y\n0,0,0\n1,1,0\n1,2,0\n")
    with pytest.raises(ParameterError, match=r"strictly increasing \(row 3: 1.0 then 1.0\)"):
        read_csv(path)


# -- 6. non-finite t -------------------------------------------------------------------------
TRAJECTORIES = {
    "ellipse": Ellipse(),
    "rectangle": Rectangle(),
    "ellipse-constant": Ellipse(orientation="constant", phi=0.3),
    "figure8": load_trajectory("figure8"),
    "with-phi": SampledTrajectory([0, 1, 2], [[0, 0, 0], [1, 0, 1], [2, 1, 0]]),
}
BAD_T = {
    "inf": math.inf,
    "-inf": -math.inf,
    "nan": math.nan,
    "np.nan": np.float64("nan"),
    "string": "1.0",
    "None": None,
    "bool": True,
    "huge int": 10**5000,
    "array": np.array([1.0, 2.0]),
}


@pytest.mark.parametrize("trajectory", TRAJECTORIES.values(), ids=list(TRAJECTORIES))
@pytest.mark.parametrize("t", BAD_T.values(), ids=list(BAD_T))
@pytest.mark.parametrize("method", ["pose", "velocity"])
def test_pose_and_velocity_refuse_a_non_finite_t(trajectory, t, method):
    with pytest.raises(ParameterError, match=r"^t must be a (finite )?number") as info:
        getattr(trajectory, method)(t)
    one_line(info)


@pytest.mark.parametrize("trajectory", TRAJECTORIES.values(), ids=list(TRAJECTORIES))
def test_valid_t_keeps_pose_velocity_and_sample(trajectory):
    times = np.linspace(-1.0, trajectory.duration + 1.0, 257)
    poses, velocities = trajectory.sample(times)
    for i, t in enumerate(times.tolist()):  # equal to the last bit or within an ulp
        np.testing.assert_allclose(trajectory.pose(t), poses[i], rtol=1e-15, atol=1e-15)
        np.testing.assert_allclose(trajectory.velocity(t), velocities[i], rtol=1e-15, atol=1e-15)
    # ints and numpy scalars are times too (the slow path only checks them)
    assert trajectory.pose(2).tobytes() == trajectory.pose(2.0).tobytes()
    assert trajectory.velocity(np.float64(0.5)).tobytes() == trajectory.velocity(0.5).tobytes()
    assert trajectory.pose(np.int64(1)).tobytes() == trajectory.pose(1.0).tobytes()
