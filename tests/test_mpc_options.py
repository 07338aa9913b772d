"""The mpc's options (ddwmmr.mpc.options): one frozen object, keyword options onto it, the
choices for the plant made in one place, printed whole in the run's summary."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, make_controller, simulate
from ddwmmr.commands import traits_of
from ddwmmr.controllers.base import method_options
from ddwmmr.mpc.braking import BRAKE_SLACK
from ddwmmr.mpc.options import GRID_DEFAULTS, MPCOptions, planned_force
from ddwmmr.plants import KinematicPlant, MujocoPlant, ThesisPlant

ROBOT = Robot().with_payload(3.0)
FIELDS = [f.name for f in dataclasses.fields(MPCOptions)]


def test_keyword_options_land_in_one_frozen_object():
    mpc = make_controller("mpc", ROBOT, horizon=2.0, stability_min=1.4, obstacles=[(1, 2, 0.3)])
    assert isinstance(mpc.options, MPCOptions)
    assert (mpc.options.horizon, mpc.options.stability_min) == (2.0, 1.4)
    assert mpc.stability_min == 1.4 and mpc.options.obstacles[0].radius == 0.3
    with pytest.raises(dataclasses.FrozenInstanceError):
        mpc.options.horizon = 3.0  # type: ignore[misc]
    assert mpc.options == MPCOptions(horizon=2.0, stability_min=1.4, obstacles=[(1, 2, 0.3)])


def test_every_option_is_listed_with_its_default():
    """make_controller, the CLIs and the app read the constructor's options: exactly the
    fields of MPCOptions, with their defaults."""
    listed = method_options("mpc")
    assert list(listed) == FIELDS
    assert listed == {f.name: f.default for f in dataclasses.fields(MPCOptions)}
    with pytest.raises(ParameterError, match="unknown option 'horizn'"):
        make_controller("mpc", ROBOT, horizn=2.0)


@pytest.mark.parametrize(
    "options, match",
    [
        ({"stability_min": 10.0}, r"stability_min must be in \(0, 10\)"),
        ({"model": "dynamic"}, "model must be one of kinematic, thesis"),
        ({"model": "kinematic", "arm_time_constant": 0.05}, "arm_time_constant needs model"),
        ({"horizon": 0.01}, "horizon must be > the control step"),
        ({"joint_acceleration_limit": (1.0, 2.0, 3.0)}, "one number or two"),
        ({"cold_iterations": 0}, r"cold_iterations must be an integer in \[1, 20\]"),
        ({"cold_iterations": 2.5}, r"cold_iterations must be an integer in \[1, 20\]"),
    ],
)
def test_bad_options_are_refused_when_the_object_is_made(options, match):
    with pytest.raises(ParameterError, match=match):
        MPCOptions(**options)


def test_choices_for_the_plant():
    """Before the plant is known, on the kinematic, the thesis and the physics plant."""
    alone = MPCOptions().adopt_plant(None)
    assert (alone.model, alone.dynamic_stability, alone.wheel_force_limit) == (
        "kinematic",
        False,
        None,
    )
    assert MPCOptions().adopt_plant(traits_of(KinematicPlant(ROBOT))) == alone
    thesis = MPCOptions(model="thesis").adopt_plant(traits_of(ThesisPlant(ROBOT)))
    assert (thesis.model, thesis.dynamic_stability, thesis.arm_time_constant) == (
        "thesis",
        False,
        0.0,
    )
    assert thesis.wheel_force_limit == ThesisPlant(ROBOT).force_limit
    physics_plant = MujocoPlant(ROBOT)
    traits = traits_of(physics_plant)
    physics = MPCOptions().adopt_plant(traits)
    assert physics.model == "thesis" and physics.dynamic_stability is True
    assert physics.arm_time_constant == physics_plant.joint_time_constant
    assert physics.joint_acceleration_limit == traits.joint_acceleration_limit
    assert physics.brake_slack == BRAKE_SLACK
    # a frozen plan's cold start is off where the braking step is on
    assert (alone.frozen_restart, thesis.frozen_restart, physics.frozen_restart) == (
        True,
        True,
        False,
    )
    assert MPCOptions(frozen_restart=True).adopt_plant(traits).frozen_restart is True
    # without the braking step the physics plant restarts frozen plans too
    assert MPCOptions(brake_slack=0).adopt_plant(traits).frozen_restart is True
    with pytest.raises(ParameterError, match="frozen_restart must be"):
        MPCOptions(frozen_restart="yes")
    assert physics.wheel_force_limit == planned_force(traits) == 10.0
    assert physics.adopt_plant(traits) == physics  # resolving again changes nothing
    given = MPCOptions(arm_time_constant=0, brake_slack=0, wheel_force_limit=8.0)
    kept = given.adopt_plant(traits)
    assert (kept.arm_time_constant, kept.brake_slack, kept.wheel_force_limit) == (0.0, 0.0, 8.0)
    assert kept.joint_acceleration_limit == ()  # no lag: nothing to bound
    with pytest.raises(ParameterError, match="wheel_force_limit must be <= the plant's motors"):
        MPCOptions(wheel_force_limit=1e3).adopt_plant(traits)


def test_the_summary_prints_the_options_whole():
    """Every option, with the value the run used (resolved for the plant, the grid of its
    objective, its control step)."""
    result = simulate(ROBOT, Ellipse(T=20.0, N=1000), "mpc", duration=0.1, horizon=2.0)
    printed = result.summary["mpc_options"]
    assert list(printed) == FIELDS
    intervals, _, _ = GRID_DEFAULTS["tracking"]
    assert (printed["model"], printed["horizon"], printed["intervals"]) == (
        "kinematic",
        2.0,
        intervals,
    )
    assert printed["dt"] == pytest.approx(0.02) and printed["position_weight"] == 100.0
    assert None not in (printed["dynamic_stability"], printed["arm_time_constant"])


def test_the_scenario_tool_records_the_options_its_runs_use():
    from ddwmmr.scenarios import RunConfig, generate
    from ddwmmr.scenarios.protocol import controller_options_record

    record = controller_options_record(RunConfig(controller="mpc"), generate(1, 0)[0])
    assert set(record) == set(FIELDS) - {"obstacles"}
    assert (record["model"], record["track_orientation"], record["dt"]) == ("thesis", False, 0.01)
    assert record["horizon"] == GRID_DEFAULTS["reach"][2] and record["huber"] == 0.01


@pytest.mark.parametrize("cold_iterations", [1, 2, 5])
def test_a_cold_start_takes_at_most_cold_iterations_qps_and_later_steps_one(cold_iterations):
    """A new target starts cold: that step solves ``cold_iterations`` QPs from the
    standing guess (while the plan still moves, as it does 1.5 m from the target), every
    later step of the real-time iteration one; the next new target starts cold again."""
    controller = make_controller("mpc", ROBOT, cold_iterations=cold_iterations, dt=0.05)
    q = np.array([0.0, 0.0, 0.0, 0.3, 1.2])
    qps = []
    for k, target in enumerate([(1.5, 0.8)] * 4 + [(-1.0, 1.5)] * 3):
        controller.command(0.05 * k, q, np.array([*target, 0.0]), np.zeros(3))
        qps.append(controller.last.extra["mpc_iterations"])
    assert qps == [cold_iterations, 1, 1, 1, cold_iterations, 1, 1]


def test_a_large_robots_planned_wheel_force_can_be_set():
    """The planned force's range fits robots of any size (the motors bound it per plant):
    the ten-times robot plans 1e4 N by default and may be given more."""
    assert MPCOptions(model="thesis", wheel_force_limit=15000.0).wheel_force_limit == 15000.0
    assert MPCOptions(model="thesis", wheel_force_limit=0.001).wheel_force_limit == 0.001
    with pytest.raises(ParameterError, match=r"wheel_force_limit must be in \[1e-06, 1e\+07\]"):
        MPCOptions(model="thesis", wheel_force_limit=1e8)
