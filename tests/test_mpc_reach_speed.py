"""The mpc's ``reach_speed`` has a least value for the robot, 1e-6 of its length unit per
second (``MPCOptions.robot_reach_speed``): its reciprocal is the reach cost's weight, and
1e-300 m/s (which ``> 0`` let through) made every waypoint step fall back to the qp."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ddwmmr import Robot, make_controller
from ddwmmr.cli.track import main as track
from ddwmmr.commands import traits_of
from ddwmmr.errors import ParameterError
from ddwmmr.plants import make_plant
from scaled_robots import TWENTIETH


def test_a_reach_speed_below_the_robots_least_is_one_line(tmp_path, capsys):
    out = tmp_path / "run"
    argv = ["--method", "mpc", "--traj", "ellipse", "--duration", "0.2", "--no-progress"]
    assert track([*argv, "--option", "reach_speed=1e-300", "--out", str(out)]) == 2
    assert capsys.readouterr().err == (
        "error: reach_speed must be >= 1e-06 m/s for this robot, 1e-06 of its length unit "
        "(1 m) per second: its reciprocal weighs the distance left, at most 1e+06 s per unit "
        "as every cost weight (got 1e-300)\n"
    )
    assert not out.exists()


def test_the_least_reach_speed_follows_the_robots_size():
    """1e-6 of the length unit per second: 5e-8 m/s for the 1/20 robot, whose own default
    is 0.0025 m/s."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a small robot's lengths look like unit mistakes
        make_controller("mpc", TWENTIETH, reach_speed=5e-8)
        with pytest.raises(
            ParameterError, match=r"^reach_speed must be >= 5e-08 m/s .*\(0\.05 m\)"
        ):
            make_controller("mpc", TWENTIETH, reach_speed=4e-8)
    make_controller("mpc", Robot(), reach_speed=1e-6)
    with pytest.raises(ParameterError, match=r"\(got 9\.99999e-07\)$"):
        make_controller("mpc", Robot(), reach_speed=9.99999e-7)


@pytest.mark.parametrize("model", ["kinematic", "thesis"])
def test_waypoint_steps_at_the_least_reach_speed_do_not_fall_back(model):
    robot = Robot()
    plant = make_plant(model, robot)
    controller = make_controller("mpc", robot, model=model, reach_speed=1e-6)
    controller.adopt_plant(traits_of(plant))
    q0, target = np.array([0.0, 0.0, 0.0, 0.3, 1.2]), np.array([2.0, 1.0, 0.0])
    plant.reset(q0, 0.02)
    controller.reset(None, q0)
    for step in range(10):
        seen = plant.observe()
        base = {"base_velocity": (seen.v, seen.w)} if model == "thesis" else {}
        command = controller.command(0.02 * step, np.array(seen.q), target, np.zeros(3), **base)
        plant.step(0.02 * step, command, 0.02)
    assert controller.fallbacks == 0
    assert np.hypot(*(np.array(plant.observe().q[:2]))) > 0.0  # it moved
