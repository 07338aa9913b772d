"""Trajectory inputs that break their contract quietly: a rounded atan2 heading log, a
heading column in degrees, a custom ``sample`` or ``velocity`` that is not what ``pose``
says."""

import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Rectangle, Robot, simulate
from ddwmmr.sim.tracking import DIFFERENCE_STEP, SPOT_FRACTIONS, checked_trajectory
from ddwmmr.trajectories import SampledTrajectory, load_trajectory, read_csv

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from custom_trajectory import SineWave


def rounded_circle_csv(path: Path, decimals: int) -> Path:
    """One counter-clockwise lap of radius 2 m in 60 s (241 rows), heading along the
    travel wrapped by atan2, every number written with ``decimals`` decimals: the row at
    a quarter lap holds atan2's pi rounded up (3.141593 with 6 decimals)."""
    times = np.linspace(0.0, 60.0, 241)
    a = 2 * math.pi * times / 60.0
    phi = np.arctan2(np.cos(a), -np.sin(a))  # a + pi/2 wrapped
    rows = ["t,x,y,phi"] + [
        f"{t:.2f},{2 * math.cos(v):.{decimals}f},{2 * math.sin(v):.{decimals}f},{p:.{decimals}f}"
        for t, v, p in zip(times, a, phi)
    ]
    path.write_text("\n".join(rows) + "\n")
    return path


def no_warnings():
    return warnings.catch_warnings(record=True)


# -- 1. a rounded atan2 column is unwrapped --------------------------------------------


@pytest.mark.parametrize("decimals", [6, 3])
def test_a_rounded_atan2_log_is_unwrapped(tmp_path, decimals):
    text = rounded_circle_csv(tmp_path / "c.csv", decimals).read_text()
    assert f",{math.pi:.{decimals}f}\n" in text  # the premise: pi rounded up, beyond pi
    trajectory = read_csv(tmp_path / "c.csv")
    phi = trajectory.points[:, 2]
    assert np.max(np.abs(np.diff(phi))) == pytest.approx(2 * math.pi / 240, abs=2e-3)
    assert phi[-1] == pytest.approx(0.5 * math.pi + 2 * math.pi, abs=2e-3)
    poses = trajectory.sample(np.linspace(0.0, 60.0, 6001))[0]
    assert np.max(np.abs(np.diff(poses[:, 2]))) < 0.01  # no whole turn between rows


def test_a_rounded_atan2_log_is_tracked_as_the_exact_one(tmp_path):
    # Not unwrapped, the 6-decimal log turned the end effector a whole circle between
    # two rows: 530 mm max error.
    trajectory = read_csv(rounded_circle_csv(tmp_path / "c.csv", 6))
    summary = simulate(Robot(), trajectory, "ats").summary
    assert summary["max_position_error_m"] < 0.05


def test_a_column_beyond_the_rounding_tolerance_stays_continuous():
    # 3.145 is 3.4e-3 beyond pi, more than a log's rounding: kept as given, bit for bit.
    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 3.145], [2.0, 0.0, -0.1]])
    trajectory = SampledTrajectory(np.array([0.0, 1.0, 2.0]), points)
    assert trajectory.points.tobytes() == points.tobytes()


# -- 2. a heading column in degrees ----------------------------------------------------


def quarter_circle(degrees: bool) -> SampledTrajectory:
    """A quarter circle of radius 1 m in 20 s, heading along the travel (0 to 90 deg)."""
    times = np.linspace(0.0, 20.0, 201)
    a = 0.5 * math.pi * times / 20.0
    heading = np.degrees(a) if degrees else a
    return SampledTrajectory(times, np.column_stack([np.sin(a), 1 - np.cos(a), heading]), "q")


def test_a_heading_column_in_degrees_draws_one_warning():
    with pytest.warns(UserWarning) as caught:
        quarter_circle(degrees=True)
    assert len(caught) == 1
    text = str(caught[0].message)
    assert "\n" not in text
    assert text.startswith("trajectory q: column phi turns 90 rad in total")
    assert "turns 1.56 rad" in text and "radians" in text


def test_headings_in_radians_draw_none(tmp_path):
    times = np.array([0.0, 10.0, 20.0])
    spin = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 6.28], [1.0, 0.0, 12.56]])  # two turns
    with no_warnings() as caught:
        warnings.simplefilter("always")
        quarter_circle(degrees=False)
        SampledTrajectory(times, spin)
        for name in ("figure8", "sideways_reach", "ellipse", "rectangle"):
            load_trajectory(name)
        SampledTrajectory(
            times=[0.0, 5.0, 10.0, 15.0], points=[[0, 0], [1, 0.2], [2, 0], [3, -0.2]]
        )
        read_csv(rounded_circle_csv(tmp_path / "c.csv", 6))
    assert [str(w.message) for w in caught] == []


# -- 3. a custom sample or velocity that is not pose's ---------------------------------


class ShiftedSample(SineWave):
    """sample() 0.5 m off in x from pose()."""

    def sample(self, times):
        poses, velocities = super().sample(times)
        return poses + np.array([0.5, 0.0, 0.0]), velocities


class DoubledVelocity(SineWave):
    """velocity() twice the derivative of pose(), sample() alike."""

    def velocity(self, t):
        return 2.0 * super().velocity(t)

    def sample(self, times):
        poses, velocities = super().sample(times)
        return poses, 2.0 * velocities


class Delegate:
    """A trajectory written outside the library, following ``inner`` ``shift`` s ahead."""

    def __init__(self, inner, shift: float = 0.0) -> None:
        self.inner, self.shift = inner, shift
        self.duration, self.samples = inner.duration, inner.samples

    def pose(self, t):
        return self.inner.pose(t + self.shift)

    def velocity(self, t):
        return self.inner.velocity(t + self.shift)


def test_a_sample_that_disagrees_with_pose_is_not_used():
    with pytest.warns(UserWarning, match="sample\\(times\\) disagrees with pose\\(t\\)") as caught:
        run = simulate(Robot(), ShiftedSample(), "clrrmc-ts", duration=3.0)
    assert len(caught) == 1 and "\n" not in str(caught[0].message)
    ts = run.timeseries
    expected = np.array([SineWave().pose(t)[0] for t in ts["t"].tolist()])
    np.testing.assert_allclose(ts["xE_d"], expected, rtol=0, atol=1e-12)
    assert ts["position_error_m"][-1] < 0.01  # the start and the references agree


def test_a_consistent_sample_draws_no_warning_and_stays_in_use():
    with no_warnings() as caught:
        warnings.simplefilter("always")
        checked = checked_trajectory(SineWave())
        for inner in (Rectangle(), Rectangle(a=1.0, b=1.0, T=4.0, N=400)):
            checked_trajectory(Delegate(inner))
    assert [str(w.message) for w in caught] == []
    assert "sample" in checked.__dict__


def test_a_velocity_that_is_not_the_derivative_of_pose_draws_a_warning():
    with pytest.warns(UserWarning) as caught:
        checked_trajectory(DoubledVelocity())
    text = str(caught[0].message)
    assert "\n" not in text
    assert "velocity(t) is not the time derivative of pose(t) at 6 of 6 checked times" in text


def test_a_rectangle_corner_on_a_checked_time_draws_no_warning():
    # The rectangle's first corner at t = 10 s is moved onto the second checked time.
    rectangle = Rectangle()
    checked_time = SPOT_FRACTIONS[1] * rectangle.duration
    shifted = Delegate(rectangle, shift=10.0 - checked_time)
    h = DIFFERENCE_STEP * rectangle.duration
    turn = shifted.pose(checked_time + h)[2] - shifted.pose(checked_time - h)[2]
    assert abs(turn) == pytest.approx(0.5 * math.pi, abs=1e-3)  # the premise: on the corner
    with no_warnings() as caught:
        warnings.simplefilter("always")
        checked_trajectory(shifted)
    assert [str(w.message) for w in caught] == []
