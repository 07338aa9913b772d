"""A sampled trajectory outside its time range holds still: the pose stays at the first or
last sample and the velocity, its time derivative, is zero (scalar and vectorised alike);
a closed-loop run past the end settles on the held point."""

import numpy as np
import pytest

from ddwmmr import Robot, SampledTrajectory, simulate

TIMES = [0.0, 0.1, 5.0, 5.05, 10.0]
POINTS_XY = [[0.0, 0.0], [0.01, 0.0], [0.5, 0.1], [0.505, 0.1], [1.0, 0.0]]
POINTS_PHI = [
    [0.0, 0.0, 0.1],
    [0.01, 0.0, 0.12],
    [0.5, 0.1, 0.5],
    [0.505, 0.1, 0.51],
    [1.0, 0.0, 0.9],
]


def _trajectories() -> list[SampledTrajectory]:
    shifted = np.array(TIMES) + 3.7  # times need not start at 0
    return [
        SampledTrajectory(TIMES, POINTS_XY, name="xy"),
        SampledTrajectory(TIMES, POINTS_PHI, name="phi"),
        SampledTrajectory(shifted, POINTS_XY, name="shifted"),
    ]


@pytest.mark.parametrize("trajectory", _trajectories(), ids=lambda tr: tr.name)
def test_velocity_is_zero_where_the_pose_is_held(trajectory: SampledTrajectory) -> None:
    end = trajectory.duration
    for t in (end + 1e-6, end + 0.5, end + 5.0, end + 1e6, -1e-6, -0.5, -5.0):
        assert np.array_equal(trajectory.velocity(t), np.zeros(3)), t
    np.testing.assert_array_equal(trajectory.pose(end + 5.0), trajectory.pose(end))
    np.testing.assert_array_equal(trajectory.pose(-5.0), trajectory.pose(0.0))
    # the derivative of the held pose, by central differences, is the zero velocity
    for t in (end + 1.0, -1.0):
        slope = (trajectory.pose(t + 1e-3) - trajectory.pose(t - 1e-3)) / 2e-3
        np.testing.assert_allclose(slope, trajectory.velocity(t), atol=1e-12)


@pytest.mark.parametrize("trajectory", _trajectories(), ids=lambda tr: tr.name)
def test_velocity_inside_keeps_the_end_speeds(trajectory: SampledTrajectory) -> None:
    end = trajectory.duration
    # 0.1 m/s along x at the last secant (0.495 m over 4.95 s), the first the same
    np.testing.assert_allclose(trajectory.velocity(end)[0], 0.1, rtol=1e-12)
    np.testing.assert_allclose(trajectory.velocity(0.0)[0], 0.1, rtol=1e-12)
    # inside, the velocity is the pose's derivative
    for t in (0.05, 2.0, end - 0.01):
        slope = (trajectory.pose(t + 1e-6) - trajectory.pose(t - 1e-6)) / 2e-6
        np.testing.assert_allclose(slope, trajectory.velocity(t), atol=1e-6)


@pytest.mark.parametrize("trajectory", _trajectories(), ids=lambda tr: tr.name)
def test_sample_matches_pose_and_velocity_outside_too(trajectory: SampledTrajectory) -> None:
    end = trajectory.duration
    past = end + 2e-9 * end  # beyond the 1e-9 x duration kept for rounding
    times = np.array([-5.0, -2e-8, 0.0, 1e-9, 3.3, end - 1e-9, end, end + 1e-12, past, end + 5.0])
    poses, velocities = trajectory.sample(times)
    for k, t in enumerate(times.tolist()):
        assert np.array_equal(poses[k], trajectory.pose(t)), t
        assert np.array_equal(velocities[k], trajectory.velocity(t)), t
    assert np.all(velocities[[0, 1, 8, 9]] == 0.0)
    assert velocities[6, 0] > 0.09 and velocities[7, 0] > 0.09


def test_a_time_grid_rounded_past_the_end_keeps_the_end_speed() -> None:
    # 3000 steps of 0.02 s: the RK4 stage at the end of the last one is at
    # 2999 x 0.02 + 0.02 = 60.00000000000001 s, past the last sample by rounding
    trajectory = SampledTrajectory(6.0 * np.array(TIMES), POINTS_XY, name="xy")
    stage = 2999 * 0.02 + 0.02
    assert stage > trajectory.duration == 60.0
    np.testing.assert_array_equal(
        trajectory.velocity(stage), trajectory.velocity(trajectory.duration)
    )
    np.testing.assert_array_equal(trajectory.pose(stage), trajectory.pose(trajectory.duration))


def test_closed_loop_run_past_the_end_settles_on_the_held_point() -> None:
    trajectory = SampledTrajectory(TIMES, POINTS_XY, name="xy")
    summary = simulate(Robot(), trajectory, "clrrmc-ts", duration=20.0).summary
    # 10 s holding still with tau = 0.5 s: the error decays by exp(-20); with the end
    # speed kept (0.1 m/s) it would settle at tau v = 50 mm from the held point
    assert summary["end_position_error_m"] < 1e-6
    assert summary["verdict"] == "tracked"
