"""Sampled trajectories whose phi column wraps at +-pi (as atan2 and loggers write it)."""

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, simulate
from ddwmmr.trajectories import SampledTrajectory, read_csv
from ddwmmr.trajectories.sampled import csv_text, unwrap_phi

RADIUS_M = 1.5
PERIOD_S = 40.0
ROWS = 81


def circle_samples(wrapped: bool) -> tuple[np.ndarray, np.ndarray]:
    """One counter-clockwise lap of radius 1.5 m in 40 s, heading along the travel:
    ``(times, points)`` with the heading a + pi/2 as it is (continuous, pi/2 to 5 pi/2)
    or wrapped into (-pi, pi] by atan2."""
    times = np.linspace(0.0, PERIOD_S, ROWS)
    a = 2 * math.pi * times / PERIOD_S
    phi = a + 0.5 * math.pi
    if wrapped:
        phi = np.arctan2(np.sin(phi), np.cos(phi))
    return times, np.column_stack([RADIUS_M * np.cos(a), RADIUS_M * np.sin(a), phi])


def circle(wrapped: bool) -> SampledTrajectory:
    return SampledTrajectory(*circle_samples(wrapped), name="circle")


def check_times_all_over():
    """Knots, midpoints, random times and times before the start and past the end (s)."""
    rng = np.random.default_rng(7)
    knots = np.linspace(0.0, PERIOD_S, ROWS)
    return np.concatenate(
        [knots, knots[:-1] + 0.25, rng.uniform(0.0, PERIOD_S, 400), [-3.0, PERIOD_S + 3.0]]
    )


def test_the_wrapped_column_jumps_where_the_unwrapped_one_does_not():
    # The premise of the other tests: the wrapped samples do jump by about 2 pi.
    wrapped, unwrapped = circle_samples(True)[1][:, 2], circle_samples(False)[1][:, 2]
    assert np.max(np.abs(np.diff(wrapped))) > 6.0
    assert np.max(np.abs(np.diff(unwrapped))) < 0.08


def test_wrapped_and_unwrapped_samples_give_the_same_pose_and_velocity():
    wrapped, unwrapped = circle(True), circle(False)
    np.testing.assert_allclose(wrapped.points, unwrapped.points, rtol=0, atol=1e-12)
    assert wrapped.points[-1, 2] == pytest.approx(2.5 * math.pi, abs=1e-12)
    for t in check_times_all_over().tolist():
        np.testing.assert_allclose(wrapped.pose(t), unwrapped.pose(t), rtol=0, atol=1e-12)
        np.testing.assert_allclose(wrapped.velocity(t), unwrapped.velocity(t), rtol=0, atol=1e-12)
    # Turning at 2 pi / 40 s throughout, never the long way round; held still outside.
    times = check_times_all_over()
    inside = (times >= 0.0) & (times <= PERIOD_S)
    rates = np.array([wrapped.velocity(t)[2] for t in times.tolist()])
    np.testing.assert_allclose(rates[inside], 2 * math.pi / PERIOD_S, rtol=0, atol=1e-3)
    assert np.all(rates[~inside] == 0.0)


def test_the_vectorised_sample_unwraps_alike():
    wrapped, unwrapped = circle(True), circle(False)
    times = check_times_all_over()
    poses, velocities = wrapped.sample(times)
    expected_poses, expected_velocities = unwrapped.sample(times)
    np.testing.assert_allclose(poses, expected_poses, rtol=0, atol=1e-12)
    np.testing.assert_allclose(velocities, expected_velocities, rtol=0, atol=1e-12)
    # and sample stays the same numbers as pose / velocity, to the bit
    for k, t in enumerate(times.tolist()):
        assert poses[k].tobytes() == wrapped.pose(t).tobytes()
        assert velocities[k].tobytes() == wrapped.velocity(t).tobytes()


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_step_from_3_1_to_minus_3_1_turns_the_short_way(sign):
    # Rows 1 s apart turning by 2 pi - 6.2 = 0.0832 rad each: 3.0168, 3.1, -3.1, -3.0168
    # (or the mirror image). Interpolated across the jump as numbers, the middle pose
    # was 0 and the rate -6.2 rad/s; the short way it is pi and +0.0832 rad/s.
    step = 2 * math.pi - 6.2
    phi = sign * np.array([3.1 - step, 3.1, -3.1, -3.1 + step])
    points = np.column_stack([np.arange(4.0), np.zeros(4), phi])
    trajectory = SampledTrajectory(np.arange(4.0), points)
    assert trajectory.pose(1.5)[2] == pytest.approx(sign * math.pi, abs=1e-12)
    assert trajectory.velocity(1.5)[2] == pytest.approx(sign * step, abs=1e-12)
    for t in np.linspace(0.0, 3.0, 31).tolist():
        assert trajectory.velocity(t)[2] == pytest.approx(sign * step, abs=1e-12)
    np.testing.assert_allclose(
        trajectory.points[:, 2], sign * (3.1 + step * np.arange(-1, 3)), rtol=0, atol=1e-12
    )


def test_the_first_row_keeps_its_angle_and_whole_turns_follow():
    points = np.column_stack([np.arange(5.0), np.zeros(5), [-3.0, 3.0, -3.0, 3.0, 1.0]])
    phi = unwrap_phi(points)[:, 2]
    two_pi = 2 * math.pi
    np.testing.assert_allclose(
        phi, [-3.0, 3.0 - two_pi, -3.0, 3.0 - two_pi, 1.0 - two_pi], rtol=0, atol=1e-15
    )


def test_a_continuous_phi_column_is_kept_bit_for_bit():
    # Steps up to pi exactly (numpy.unwrap's boundary: not a jump), a -0.0: nothing moves.
    phi = [-0.0, math.pi, 0.0, -math.pi, 0.0, 3.0, 0.5, 3.6]
    n = len(phi)
    points = np.column_stack([np.arange(float(n)), np.zeros(n), phi])
    # its heading spins 21 rad on a still path: read in radians, with the degrees warning
    with pytest.warns(UserWarning, match="phi is read in radians"):
        trajectory = SampledTrajectory(np.arange(float(n)), points)
    assert trajectory.points.tobytes() == points.tobytes()
    assert math.copysign(1.0, trajectory.points[0, 2]) == -1.0
    assert unwrap_phi(points) is points
    positions = points[:, :2]
    assert unwrap_phi(positions) is positions


def test_a_wrapped_csv_reads_as_the_unwrapped_one(tmp_path):
    paths = []
    for wrapped in (True, False):
        times, points = circle_samples(wrapped)
        rows = ["t,x,y,phi"] + [
            ",".join(map(repr, (t, *p))) for t, p in zip(times.tolist(), points.tolist())
        ]
        paths.append(tmp_path / f"circle_{wrapped}.csv")
        paths[-1].write_text("\n".join(rows) + "\n")
    from_wrapped, from_unwrapped = read_csv(paths[0]), read_csv(paths[1])
    np.testing.assert_allclose(from_wrapped.points, from_unwrapped.points, rtol=0, atol=1e-12)
    poses, velocities = from_wrapped.sample(check_times_all_over())
    expected = from_unwrapped.sample(check_times_all_over())
    np.testing.assert_allclose(poses, expected[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(velocities, expected[1], rtol=0, atol=1e-12)
    # csv_text writes the unwrapped column, which reads back bit for bit.
    again = tmp_path / "again.csv"
    again.write_text(csv_text(from_wrapped))
    assert read_csv(again).points.tobytes() == from_wrapped.points.tobytes()


def test_a_wrapped_circle_is_tracked_as_the_unwrapped_one():
    # The wrapped file made clrrmc-ts spin the end effector a full turn: 940 mm max error.
    runs = [simulate(Robot(), circle(w), "clrrmc-ts").summary for w in (True, False)]
    for key in ("rms_position_error_m", "max_position_error_m", "max_orientation_error_rad"):
        assert runs[0][key] == pytest.approx(runs[1][key], rel=1e-6, abs=1e-12)
    assert runs[0]["rms_position_error_m"] < 0.005
    assert runs[0]["max_position_error_m"] < 0.05


def test_an_unwrapped_angle_beyond_the_documented_bound_is_refused():
    # 340,000 rows turning by 3 rad each, wrapped: every sample is within pi, but the
    # turning angle unwrapped reaches 1.02e6 rad.
    n = 340_000
    phi = np.arange(n) * 3.0
    points = np.column_stack([np.zeros(n), np.zeros(n), np.arctan2(np.sin(phi), np.cos(phi))])
    with pytest.raises(ParameterError) as info:
        SampledTrajectory(np.arange(float(n)), points)
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith("trajectory samples: points phi, unwrapped")
    assert "|phi| <= 1e+06 rad" in text


def test_a_column_beyond_pi_is_continuous_already_and_kept():
    """Rows 0, 4, 8 rad (a fast spin sampled coarsely, written unwrapped) step by more than
    pi, but an angle beyond pi says the column is not wrapped: it is kept as given."""
    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 4.0], [2.0, 0.0, 8.0]])
    assert unwrap_phi(points) is points
    trajectory = SampledTrajectory(np.array([0.0, 1.0, 2.0]), points)
    assert trajectory.points[:, 2].tolist() == [0.0, 4.0, 8.0]


def test_an_unwrapped_column_read_back_is_not_unwrapped_again(tmp_path):
    """csv_text writes the unwrapped heading (beyond pi): reading it back keeps it."""
    first = circle(wrapped=True)
    path = tmp_path / "again.csv"
    path.write_text(csv_text(first))
    again = read_csv(path)
    assert np.max(np.abs(first.points[:, 2])) > math.pi
    assert np.array_equal(again.points, first.points)
