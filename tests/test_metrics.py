"""Run metrics: the final error is taken over a settled window, corners separately."""

import numpy as np
import pytest

from ddwmmr import Ellipse, Rectangle, Robot, simulate
from ddwmmr.reports.compare import corner_times as compare_corner_times
from ddwmmr.sim.simulate import summarize


def test_rectangle_final_error_excludes_the_corner_the_run_ends_on():
    """The default rectangle ends exactly on a corner (t = T): the last sample already sees
    the new orientation, so the error there is the start of the corner transient."""
    result = simulate(Robot(), Rectangle(), "clrrmc-ts")
    s, ts = result.summary, result.timeseries
    assert s["end_position_error_m"] == ts["position_error_m"][-1] > 2e-3
    assert s["final_position_error_m"] < 1e-5  # converged between the corners
    # Independent window: samples more than 4 s (0.1 T) after a corner at k T/4, and not
    # on one; the last 5 % of those.
    t, e = ts["t"], ts["position_error_m"]
    corners = [10.0, 20.0, 30.0, 40.0]
    keep = np.ones(len(t), dtype=bool)
    for c in corners:
        keep &= ~((t >= c - 1e-5) & (t <= c + 4.0))
    tail = e[keep][-round(0.05 * keep.sum()) :]
    assert s["final_position_error_m"] == pytest.approx(np.sqrt(np.mean(tail**2)), rel=1e-12)
    near = ~keep
    assert s["corner_position_error_m"] == pytest.approx(e[near].max(), rel=1e-12)
    assert s["corner_position_error_m"] > 0.1  # the corner spike is reported, separately


def test_ellipse_has_no_corners_and_final_error_is_the_tail_rms():
    result = simulate(Robot(), Ellipse(), "ats")
    s, e = result.summary, result.timeseries["position_error_m"]
    assert s["corner_position_error_m"] is None
    tail = e[-round(0.05 * len(e)) :]
    assert s["final_position_error_m"] == pytest.approx(np.sqrt(np.mean(tail**2)), rel=1e-12)


def test_corner_times_are_the_quarter_periods():
    rect = Rectangle(T=20.0)
    assert rect.corner_times(20.0) == [5.0, 10.0, 15.0, 20.0]
    assert rect.corner_times(12.0) == [5.0, 10.0]
    # alpha = k pi/2 is a corner: the unrotated offset is (+-a, +-b) there.
    for t in rect.corner_times(20.0):
        x, y, _ = rect.pose(t)
        assert (abs(x), abs(y)) == pytest.approx((rect.a, rect.b), abs=1e-12)


def test_the_compare_studies_take_the_corners_before_the_run_ends():
    """The corner study needs a window after each corner: one at the run's end is left out."""
    rect = Rectangle(T=20.0)
    assert compare_corner_times(rect, 20.0) == [5.0, 10.0, 15.0]
    assert compare_corner_times(rect, 12.0) == [5.0, 10.0]
    assert compare_corner_times(Rectangle(T=3.0), 7.5) == [0.75 * k for k in range(1, 10)]
    assert compare_corner_times(Ellipse(), 20.0) == []


def test_summary_when_every_sample_is_in_a_corner_window():
    ts = {k: np.zeros(3) for k in ("x", "y", "phi", "th1", "th2", "nonholonomic_residual_m_s")}
    ts.update(
        t=np.array([0.0, 0.1, 0.2]),
        position_error_m=np.array([0.0, 0.3, 0.4]),
        orientation_error_rad=np.zeros(3),
        wheel_left_rad_s=np.zeros(3),
        wheel_right_rad_s=np.zeros(3),
        manipulability=np.ones(3),
        stability=np.ones(3),
        singular=np.zeros(3),
        saturated=np.zeros(3),
        fallback=np.zeros(3),
        step_us=np.ones(3),
    )
    s = summarize(ts, Robot(), corner_windows=[(-1.0, 1.0)])
    assert s["final_position_error_m"] == pytest.approx(0.4)  # falls back to the tail
    assert s["corner_position_error_m"] == pytest.approx(0.4)
