"""The clrrmc-cs reference q_d(t) over long runs and far lookups: bounded work and memory.

The reference integrates the augmented resolution along the trajectory as it is looked up.
These tests count its work in trajectory evaluations (deterministic) and its memory with
tracemalloc; the numbers are checked against references integrated in one go.
"""

import contextlib
import math
import signal
import tracemalloc

import numpy as np
import pytest

from ddwmmr import Ellipse, Rectangle, Robot, make_controller
from ddwmmr.resolution.reference import (
    MAX_LOOKUP_STEPS,
    ReferenceTrajectory,
    start_configuration,
)


class _Counting:
    """A trajectory without ``sample`` that counts its velocity evaluations."""

    def __init__(self, inner):
        self.inner = inner
        self.duration = inner.duration
        self.calls = 0

    def pose(self, t):
        return self.inner.pose(t)

    def velocity(self, t):
        self.calls += 1
        return self.inner.velocity(t)


@contextlib.contextmanager
def _hang_guard(seconds: float = 60.0):
    """Turn a hang into a failure (a guard against the old unbounded loop, not a speed
    check: the work is asserted by counting)."""

    def expire(signum, frame):
        raise TimeoutError(f"still running after {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


def _reference(trajectory, step=0.01, horizon=None, aux="shoulder"):
    robot = Robot()
    inner = getattr(trajectory, "inner", trajectory)
    return ReferenceTrajectory(
        robot,
        trajectory,
        start_configuration(robot, inner),
        aux,
        step,
        horizon=horizon,
    )


def test_a_far_lookup_does_bounded_work_and_stays_finite():
    trajectory = _Counting(Ellipse())
    reference = _reference(trajectory, horizon=trajectory.duration)
    for t in (1e9, 1e9 + 0.005, 1e12, 1e300):
        trajectory.calls = 0
        with _hang_guard():
            q, rate = reference(t)
        # Two velocity evaluations per RK4 step (middle and end), at most one stride of
        # MAX_LOOKUP_STEPS steps per lookup.
        assert trajectory.calls <= 2 * MAX_LOOKUP_STEPS
        assert all(math.isfinite(v) for v in q + rate)


def test_clrrmc_cs_command_at_a_huge_time_returns():
    robot, trajectory = Robot(), Ellipse()
    controller = make_controller("clrrmc-cs", robot)
    q = start_configuration(robot, trajectory)
    controller.reset(trajectory, q)
    with _hang_guard():
        u = controller.command(1e9, q, trajectory.pose(0.0), trajectory.velocity(0.0))
    assert np.all(np.isfinite(u))


def test_memory_does_not_grow_along_a_long_run():
    # A run's lookup pattern (every half step of dt, as the RK4 stages do), 75 periods: what
    # the lookups after the first 15 periods allocate and keep.
    trajectory = Ellipse(T=20.0)
    step, dt = 0.5, 1.0
    reference = _reference(trajectory, step=step, horizon=trajectory.duration)

    def run(steps: range) -> None:
        for k in steps:
            reference(k * dt)
            reference(k * dt + dt / 2)
            reference(k * dt + dt)

    run(range(300))
    tracemalloc.start()
    try:
        run(range(300, 1500))
        kept, _ = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # Keeping every segment costs ~1 kB each: these 2400 segments would be ~2.4 MB.
    assert kept < 50_000


def test_lookups_along_a_run_give_the_numbers_of_one_integration():
    # Pruned lookups in a run's order against a reference integrated up front to the end
    # (no lookup past its end, nothing dropped): same RK4 grid, same numbers.
    for trajectory, aux in ((Ellipse(T=10.0), "shoulder"), (Rectangle(T=10.0), "sum")):
        whole = _reference(trajectory, horizon=17.0, aux=aux)
        along = _reference(trajectory, horizon=trajectory.duration, aux=aux)
        dt = 0.04
        for k in range(400):
            for t in (k * dt, k * dt + dt / 2, k * dt + dt):
                q_a, rate_a = along(t)
                q_w, rate_w = whole(t)
                assert q_a == pytest.approx(q_w, abs=1e-12, rel=0)
                assert rate_a == pytest.approx(rate_w, abs=1e-12, rel=0)
                assert along.last_damped == whole.last_damped


def test_a_far_stride_integrates_the_same_motion():
    # One lookup 35 s ahead is 3500 steps: integrated in MAX_LOOKUP_STEPS longer RK4 steps
    # (0.14 s). It agrees with the fine integration to the stride's RK4 accuracy.
    trajectory = Ellipse()
    fine = _reference(trajectory, horizon=75.0)
    strided = _reference(trajectory, horizon=trajectory.duration)
    q_s, rate_s = strided(75.0)
    q_f, rate_f = fine(75.0)
    assert np.max(np.abs(np.subtract(q_s, q_f))) < 1e-4
    assert np.max(np.abs(np.subtract(rate_s, rate_f))) < 1e-3
    assert np.max(np.abs(np.subtract(q_s, q_f))) > 0.0  # the stride did happen


def test_a_lookup_back_before_the_kept_segments_integrates_afresh():
    trajectory = Ellipse()
    reference = _reference(trajectory, horizon=trajectory.duration)
    for t in np.arange(0.0, 60.0, 0.5).tolist():  # past the horizon: earlier ones dropped
        reference(t)
    fresh = _reference(trajectory, horizon=trajectory.duration)
    assert reference(3.0) == fresh(3.0)
    assert reference(-0.001) == fresh(-0.001)  # before t = 0: the first segment extended
