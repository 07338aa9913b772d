"""The mpc's stall rule measures progress in the robot's length unit (``L1 / 0.35 m``): 1 mm
of net end-effector motion on the default robot, s mm on a robot s times its size
(docs/mpc.md, "Robot size")."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ddwmmr import make_controller
from ddwmmr.mpc.stall import STALL_PROGRESS, STALL_TIME, StallWatch
from scaled_robots import scaled_robot

DT = 0.01


def firings(watch: StallWatch, creep: float, steps: int = 120) -> list[int]:
    """The steps at which ``watch``'s progress rule fires for an end effector moving
    ``creep`` (m) along x each step of :data:`DT`, short of a fixed target."""
    return [k for k in range(steps) if watch.stuck(k * DT, (k * creep, 0.0), k == 0)]


@pytest.mark.parametrize("unit", [0.05, 1.0, 10.0])
def test_progress_is_counted_in_the_robots_length_unit(unit):
    # over STALL_TIME the end effector moves 0.4 of the progress distance: a stall
    slow = 0.4 * STALL_PROGRESS * unit * DT / STALL_TIME
    assert firings(StallWatch(unit), slow) == [51, 102]
    # 1.2 of the distance over STALL_TIME is progress, on a robot of any size
    assert firings(StallWatch(unit), 3.0 * slow) == []


def test_the_default_watch_counts_one_millimetre():
    assert STALL_PROGRESS == 1e-3
    assert firings(StallWatch(), 0.4e-3 * DT / STALL_TIME) == [51, 102]
    assert firings(StallWatch(), 1.2e-3 * DT / STALL_TIME) == []


#: A waypoint 3.2 m ahead of the default robot with a 0.3 m post on the way (m).
TARGET, POST = (3.2, 0.0), (1.5, 0.05, 0.3)


def waypoint_run(factor: float, steps: int = 400) -> tuple[np.ndarray, int]:
    """Configurations (positions divided by ``factor``) and stall restarts of the mpc
    (kinematic model, 10 ms steps) on the robot scaled by ``factor`` driving to the target
    round the post, both scaled alike, its commands integrated by Euler steps."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a scaled robot's lengths look like unit mistakes
        controller = make_controller(
            "mpc",
            scaled_robot(factor),
            dt=DT,
            track_orientation=False,
            obstacles=[tuple(factor * value for value in POST)],
            obstacle_margin=0.05 * factor,
        )
    q = np.array([0.0, 0.0, 0.0, -0.4, 1.2])
    controller.reset(None, q.copy())
    target = np.array([factor * TARGET[0], factor * TARGET[1], 0.0])
    path = []
    for k in range(steps):
        u = np.asarray(controller.command(k * DT, q, target, np.zeros(3)))
        q = q + DT * np.array([u[0] * np.cos(q[2]), u[0] * np.sin(q[2]), *u[1:]])
        path.append(q.copy())
    scaled = np.array(path)
    scaled[:, :2] /= factor
    return scaled, controller.restarts


def test_a_power_of_two_robot_restarts_where_the_default_robot_does():
    """In front of the post the default robot's end effector stalls at 2.69, 3.2 and 3.71 s;
    the 8x robot's moves 8 times as far, which counted in metres was progress at 2.69 s
    (then 2 restarts, its path up to 25 mm off the default's in default lengths)."""
    reference, restarts = waypoint_run(1.0)
    assert restarts == 3
    path, scaled_restarts = waypoint_run(8.0)
    assert scaled_restarts == 3
    np.testing.assert_array_equal(path, reference)
