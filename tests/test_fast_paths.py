"""The simulation's fast paths give the numbers of the plain paths they stand in for.

* each closed-form controller's float-level ``law`` (used at RK4 stages) equals its
  validated ``command``;
* a parametric or sampled trajectory's vectorised ``sample`` equals ``pose``/``velocity``;
* the tracking task's precomputed reference table equals evaluating the trajectory;
* the kinematic plant's saturation equals the textbook form (max over both wheels,
  clip of each joint rate);
* the 4x4 reduction behind ``max_condition_number`` has J's condition number;
* the ``clrrmc-cs`` reference integrated with sampled velocities equals the one
  integrated call by call.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr import Robot, simulate
from ddwmmr.controllers import make_controller
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.resolution.reference import ReferenceTrajectory, start_configuration
from ddwmmr.sim.simulate import max_condition_number
from ddwmmr.sim.tracking import ReferenceBlocks, TrackingTask
from ddwmmr.trajectories import Ellipse, Rectangle, SampledTrajectory, load_trajectory

CLOSED_FORM = ("pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs")
TRAJECTORIES = (
    Ellipse(),
    Rectangle(),
    Ellipse(x0=0.3, y0=-1.0, a=1.2, b=2.5, beta=0.7, T=13.0),
    Rectangle(beta=-1.1, a=1.0, b=2.0, T=7.0),
    Ellipse(orientation="constant", phi=0.4),
)


class _Scalar:
    """A trajectory with only pose/velocity (no ``sample``): the call-by-call path."""

    def __init__(self, inner):
        self.inner = inner
        self.duration = inner.duration
        self.samples = inner.samples

    def pose(self, t):
        return self.inner.pose(t)

    def velocity(self, t):
        return self.inner.velocity(t)


def _sampled_trajectories():
    rng = np.random.default_rng(8)
    times = np.cumsum(rng.uniform(0.1, 1.0, 30))
    still = np.repeat(rng.normal(0.0, 1.0, (10, 2)), 3, axis=0)  # stops: zero speed
    return [
        load_trajectory("figure8"),
        load_trajectory("sideways_reach"),
        SampledTrajectory(times, rng.normal(0.0, 1.0, (30, 3)), name="with-phi"),
        SampledTrajectory(times, still, name="stops"),
    ]


@pytest.mark.parametrize("trajectory", _sampled_trajectories(), ids=lambda tr: tr.name)
def test_sampled_trajectory_sample_equals_pose_and_velocity_bit_for_bit(trajectory):
    # Before the start, across every knot, past the end (clamped), and on a fine grid.
    times = np.concatenate(
        [np.linspace(-1.0, trajectory.duration + 1.0, 4001), trajectory.times - trajectory.times[0]]
    )
    poses, velocities = trajectory.sample(times)
    expected_p = np.array([trajectory.pose(t) for t in times.tolist()])
    expected_v = np.array([trajectory.velocity(t) for t in times.tolist()])
    assert poses.tobytes() == expected_p.tobytes()
    assert velocities.tobytes() == expected_v.tobytes()


@pytest.mark.parametrize("method", CLOSED_FORM)
def test_law_equals_command(method):
    robot = Robot()
    trajectory = Ellipse()
    controller = make_controller(method, robot)
    controller.reset(trajectory, start_configuration(robot, trajectory))
    rng = np.random.default_rng(3)
    for _ in range(300):
        t = float(rng.uniform(0.0, 40.0))
        q = start_configuration(robot, trajectory) + rng.normal(0.0, [0.3, 0.3, 0.5, 1.0, 1.0])
        q[3] = rng.choice([q[3], 0.5 * math.pi + rng.normal(0.0, 1e-4)])  # near the singularity
        pose_d, velocity_d = trajectory.pose(t), trajectory.velocity(t)
        command = controller.command(t, q, pose_d, velocity_d)
        u, singular = controller.law(t, q.tolist(), pose_d.tolist(), velocity_d.tolist())
        assert type(u) is tuple and len(u) == 4
        assert list(u) == command.tolist()
        assert singular == controller.last.singular


@pytest.mark.parametrize("trajectory", TRAJECTORIES, ids=lambda tr: f"{tr.name}-{tr.T:g}")
def test_sample_equals_pose_and_velocity(trajectory):
    times = np.concatenate([np.arange(1201) * 0.0125, np.arange(1201) * 0.0125 + 0.00625])
    poses, velocities = trajectory.sample(times)
    assert poses.shape == velocities.shape == (len(times), 3)
    expected_p = np.array([trajectory.pose(t) for t in times.tolist()])
    expected_v = np.array([trajectory.velocity(t) for t in times.tolist()])
    # Bit for bit where numpy's sin/cos are the C library's (as on the reference machine);
    # an ulp is the most a different libm could change.
    np.testing.assert_allclose(poses, expected_p, rtol=0.0, atol=1e-14)
    np.testing.assert_allclose(velocities, expected_v, rtol=0.0, atol=1e-14)


def test_reference_blocks_match_the_trajectory_at_sample_and_stage_times(monkeypatch):
    monkeypatch.setattr(ReferenceBlocks, "BLOCK", 64)  # 1000 steps: 16 blocks
    robot = Robot()
    trajectory = Rectangle(T=10.0)
    dt, steps = 0.01, 1000  # 0.01 makes k dt + dt and (k + 1) dt differ now and then
    task = TrackingTask(trajectory, KinematicPlant(robot), grid=(dt, steps))
    plain = TrackingTask(_Scalar(trajectory), KinematicPlant(robot), grid=(dt, steps))
    evaluated = []
    task._pose = lambda t: evaluated.append(t) or trajectory.pose(t)
    differ = sum(k * dt + dt != (k + 1) * dt for k in range(steps))
    assert differ > 0  # the case the blocks cover separately
    for k in range(steps):
        t = k * dt
        for stage in (t, t + 0.5 * dt, t + dt, (k + 1) * dt):  # as the loop and RK4 ask
            pose, velocity = task.reference(stage, None)
            pose_ref, velocity_ref = plain.reference(stage, None)
            assert pose.tolist() == pytest.approx(pose_ref.tolist(), abs=1e-14, rel=0)
            assert velocity.tolist() == pytest.approx(velocity_ref.tolist(), abs=1e-14, rel=0)
            assert not pose.flags.writeable  # shared rows are read-only
    assert evaluated == []  # every one came from a block
    assert len(task._table) <= 3 * 64  # one block in memory at a time
    assert task.reference(0.123456, None)[0].tolist() == trajectory.pose(0.123456).tolist()
    assert evaluated == [0.123456]  # off the grid: evaluated on its own


def _textbook_saturation(robot, th1, th2, u):
    v, w, t1, t2 = u
    # Wheel speeds v / r -+ (Lw / 2r) w, with the plant's two factors.
    per_v, per_w = 1.0 / robot.wheel_radius, 0.5 * robot.track_width / robot.wheel_radius
    peak = max(abs(v * per_v - w * per_w), abs(v * per_v + w * per_w))
    saturated = False
    if peak > robot.wheel_speed_limit:
        scale = robot.wheel_speed_limit / peak
        v, w, saturated = v * scale, w * scale, True
    speed = robot.joint_speed_limit
    rates = []
    for angle, rate, (low, high) in zip((th1, th2), (t1, t2), robot.joint_limits):
        clipped = min(max(rate, -speed), speed)
        if (angle >= high and clipped > 0) or (angle <= low and clipped < 0):
            clipped = 0.0
        saturated = saturated or clipped != rate
        rates.append(clipped)
    return (v, w, *rates), saturated


def test_saturation_equals_the_textbook_form():
    robot = Robot()
    plant = KinematicPlant(robot)
    (low1, high1), (low2, high2) = robot.joint_limits
    rng = np.random.default_rng(5)
    for _ in range(3000):
        u = tuple(float(a) for a in rng.normal(0.0, [1.0, 3.0, 3.0, 3.0]))
        th1 = float(rng.choice([rng.uniform(low1, high1), low1, high1]))
        th2 = float(rng.choice([rng.uniform(low2, high2), low2, high2]))
        got = plant._saturate(th1, th2, u)
        assert got == _textbook_saturation(robot, th1, th2, u)
        assert plant._saturate(th1, th2, np.array(u)) == got
        assert plant._saturate(th1, th2, list(u)) == got


def test_max_condition_number_equals_the_svd_of_the_jacobian():
    robot = Robot()
    rng = np.random.default_rng(11)
    q = rng.uniform(-4.0, 4.0, (500, 5))
    q[:50, 3] = 0.5 * math.pi + rng.normal(0.0, 1e-3, 50)  # ill-conditioned: cond ~ 1e3
    for row in q:
        sv = np.linalg.svd(robot.jacobian(row), compute_uv=False)
        expected = sv[0] / sv[-1]
        assert max_condition_number(robot, row[None, :]) == pytest.approx(expected, rel=1e-9)
    every = [np.linalg.cond(robot.jacobian(row)) for row in q]
    assert max_condition_number(robot, q) == pytest.approx(max(every), rel=1e-9)


def test_clrrmc_reference_with_sampled_velocities_equals_call_by_call():
    robot = Robot()
    trajectory = Ellipse(T=20.0)
    start = start_configuration(robot, trajectory)
    sampled = ReferenceTrajectory(robot, trajectory, start)
    plain = ReferenceTrajectory(robot, _Scalar(trajectory), start)
    for t in np.linspace(0.0, 25.0, 401).tolist():  # past the end: extended lazily
        q_a, rate_a = sampled(t)
        q_b, rate_b = plain(t)
        assert q_a == pytest.approx(q_b, abs=1e-12, rel=0)
        assert rate_a == pytest.approx(rate_b, abs=1e-12, rel=0)
    assert sampled.singular_nodes == plain.singular_nodes


def test_an_unrelated_sample_method_falls_back_to_pose_and_velocity():
    class Odd(_Scalar):
        def sample(self, count):  # e.g. random points: not the vectorised reference
            return list(range(3))

    robot = Robot()
    trajectory = Ellipse(T=4.0)
    odd = TrackingTask(Odd(trajectory), KinematicPlant(robot), grid=(0.02, 200))
    pose, velocity = odd.reference(0.5, None)
    assert not odd._blocks.enabled and odd._table == {}
    assert pose.tolist() == trajectory.pose(0.5).tolist()
    assert velocity.tolist() == trajectory.velocity(0.5).tolist()


def test_a_subclass_changing_command_is_not_bypassed_by_law():
    from ddwmmr.controllers.resolved_rate import AugmentedTaskSpaceController
    from ddwmmr.sim.loop import stage_law

    calls = []

    class Halved(AugmentedTaskSpaceController):
        def command(self, t, q, pose_d, velocity_d):
            calls.append(t)
            return 0.5 * super().command(t, q, pose_d, velocity_d)

    class OwnLaw(AugmentedTaskSpaceController):
        def law(self, t, q, pose_d, velocity_d):
            calls.append(t)
            u, singular = super().law(t, q, pose_d, velocity_d)
            return tuple(0.5 * value for value in u), singular

    robot = Robot()
    assert stage_law(Halved(robot)) is None
    assert stage_law(OwnLaw(robot)) is not None
    assert stage_law(make_controller("ats", robot)) is not None
    trajectory = Ellipse(T=4.0)
    halved = simulate(robot, trajectory, Halved(robot), duration=1.0, dt=0.02)
    assert len(calls) == 4 * 50 + 1  # command at every RK4 stage, as the subclass asks
    calls.clear()
    own = simulate(robot, trajectory, OwnLaw(robot), duration=1.0, dt=0.02)
    assert len(calls) == 4 * 50 + 1  # command calls law once a step, the stages three times
    for name in ("x", "y", "phi", "th1", "th2"):
        np.testing.assert_array_equal(halved.timeseries[name], own.timeseries[name])


def test_a_trajectory_subclass_changing_pose_is_not_bypassed_by_sample():
    from ddwmmr.trajectories.base import sampler

    class Shifted(Ellipse):
        def pose(self, t):
            return super().pose(t) + np.array([0.1, 0.0, 0.0])

    class OwnSample(Ellipse):
        def sample(self, times):
            return super().sample(times)

    assert sampler(Shifted()) is None and sampler(_Scalar(Ellipse())) is None
    assert sampler(OwnSample()) is not None and sampler(Ellipse()) is not None
    task = TrackingTask(Shifted(), KinematicPlant(Robot()), grid=(0.02, 100))
    pose, _ = task.reference(0.5, None)
    assert pose.tolist() == Shifted().pose(0.5).tolist()
