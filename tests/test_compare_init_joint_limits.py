"""compare's initial-offset study on a robot whose joint limits a large offset breaks."""

import math
import warnings

from ddwmmr import Ellipse, Robot
from ddwmmr.reports.compare import CompareConfig, execute, plan_runs
from ddwmmr.reports.compare.plan import study_offsets

#: An elbow limited to 0.95 rad: the 4x offset's start pose bends it to 1.03 rad.
LIMITED = Robot(joint_limits=((-math.pi, math.pi), (-math.pi, 0.95)))


def test_offsets_whose_start_breaks_a_joint_limit_are_left_out():
    def config(robot: Robot) -> CompareConfig:
        return CompareConfig(methods=("pi",), trajectories={"ellipse": Ellipse()}, robot=robot)

    assert len(study_offsets(config(Robot()))) == 5
    offsets = study_offsets(config(LIMITED))
    assert offsets == study_offsets(config(Robot()))[:4]


def test_the_study_runs_on_such_a_robot():
    config = CompareConfig(
        methods=("pi",),
        trajectories={"ellipse": Ellipse()},
        robot=LIMITED,
        duration=1.0,
        studies=("init",),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outputs = execute(config, plan_runs(config).all_specs())
    assert len(outputs) >= 4
