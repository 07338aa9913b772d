"""The mpc's force model on a base damped far beyond the thesis's.

A time constant ``m / c1`` or ``I / c2`` below 1 / 2.785 of the OCP's longest RK4 sub-step
(0.196 s on the default tracking grid) makes the prediction's speeds grow every sub-step:
c1 = 1e6 N s/m on ``Robot()`` ran, every step falling back to the qp, and only the verdict
reported it; now the run is refused before it starts, in one line naming the damping, its
time constant and the sub-step. c1 = 1e12 N s/m ended in a traceback from python-control's
Riccati solver before that (c1 = 1e50: "array must not contain infs or NaNs"); the terminal
design still turns such a failure into one line (docs/mpc.md, "Options")."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, make_controller
from ddwmmr.cli.track import main as track
from ddwmmr.commands import traits_of
from ddwmmr.errors import ParameterError
from ddwmmr.gains import STABLE_GAIN_STEP
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc import terminal
from ddwmmr.mpc.models import ThesisPrediction
from ddwmmr.mpc.ocp import OCPConfig, largest_cosine, longest_substep
from ddwmmr.plants.thesis import ThesisPlant
from scaled_robots import scaled_robot

PREFIX = "mpc: the force model cannot plan for this base: "
Q0 = np.array([0.0, 0.0, 0.0, 0.3, 1.2])
#: The longest RK4 sub-step (s) of the default tracking grid at dt = 0.02 s: its last
#: interval, 0.196 s, in one sub-step.
TRACKING_SUBSTEP = 0.1959778751025238


def prepared(robot: Robot, tracking: bool = True, **plant_options):
    """The mpc's force model on the thesis plant of ``robot`` with ``plant_options``,
    reset for the ellipse (``tracking``) or waypoint mode at the default step."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # another robot's derived constants, its start's S
        plant = ThesisPlant(robot, **plant_options)
        controller = make_controller("mpc", robot, model="thesis")
        controller.adopt_plant(traits_of(plant))
        controller.adopt_control_step(0.02)
        controller.reset(Ellipse() if tracking else None, Q0)
    return controller


@pytest.mark.parametrize(("name", "value"), [("c1", "1e6"), ("c1", "1e12"), ("c2", "1e12")])
def test_a_damping_the_force_model_cannot_integrate_is_one_line(tmp_path, capsys, name, value):
    out = tmp_path / "run"
    argv = ["--method", "mpc", "--traj", "ellipse", "--plant", "thesis", "--duration", "0.2"]
    argv += ["--plant-option", f"{name}={value}", "--option", "model=thesis"]
    assert track([*argv, "--no-progress", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {PREFIX}{name} = {float(value):g} ")
    assert "RK4 sub-steps of up to 0.196 s" in err and "model='kinematic'" in err
    assert err.count("\n") == 1
    assert not out.exists()


def test_c1_is_refused_just_beyond_rk4s_limit_and_taken_at_it():
    """m / c1 against the tracking grid's 0.196 s: 188.3 N s/m is the limit on Robot()."""
    robot = Robot()
    limit = STABLE_GAIN_STEP["rk4"] * robot.total_mass / TRACKING_SUBSTEP
    assert limit == pytest.approx(188.3, abs=0.1)
    prepared(robot, c1=limit * (1.0 - 1e-9))
    with pytest.raises(ParameterError) as error:
        prepared(robot, c1=limit * (1.0 + 1e-9))
    message = str(error.value)
    assert message.startswith(f"{PREFIX}c1 = {limit * (1.0 + 1e-9):g} N s/m makes its time ")
    assert "m / c1 = 0.0704 s" in message and "give the plant c1 <= 188 N s/m" in message
    assert "intervals are all at most 0.195 s" in message and "\n" not in message


def test_c2_is_judged_at_the_arms_pose_of_largest_yaw_inertia():
    """I / c2 with the arm stretched (1.33 kg m^2 on Robot()): the plan may keep the elbow
    there; folded (0.59 kg m^2) the same c2 would be refused at 2.3 times less."""
    robot = Robot()
    stretched = robot.yaw_inertia.at(0.0)
    limit = STABLE_GAIN_STEP["rk4"] * stretched / TRACKING_SUBSTEP
    assert limit == pytest.approx(18.85, abs=0.01)
    prepared(robot, c2=limit * (1.0 - 1e-9))
    with pytest.raises(ParameterError, match=r"c2 = 18\.85\d* N m s/rad makes its time constant"):
        prepared(robot, c2=limit * (1.0 + 1e-9))


def test_both_dampings_are_named_when_both_are_too_stiff():
    with pytest.raises(ParameterError) as error:
        prepared(Robot(), c1=1e6, c2=1e6)
    message = str(error.value)
    assert "c1 = 1e+06 N s/m and c2 = 1e+06 N m s/rad make its time constants m / c1" in message
    assert "give the plant c1 <= 188 N s/m and c2 <= 18.8 N m s/rad" in message
    # no grid gets every interval down to a few microseconds: no advice on it
    assert "intervals are all at most" not in message


def test_waypoint_mode_is_judged_on_its_own_grid():
    """The reach grid's longest sub-step, 0.193 s (its long intervals in 0.2 s pieces)."""
    with pytest.raises(ParameterError, match=r"sub-steps of up to 0\.193 s"):
        prepared(Robot(), tracking=False, c1=1e6)
    prepared(Robot(), tracking=False, c1=185.0)


def test_a_finer_grid_takes_a_stiffer_base():
    """Intervals of 0.02 s (horizon 0.2 s in 10): c1 = 1000 N s/m (m / c1 = 13 ms) runs."""
    robot = Robot()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plant = ThesisPlant(robot, c1=1000.0)
        controller = make_controller("mpc", robot, model="thesis", horizon=0.2)
    controller.adopt_plant(traits_of(plant))
    controller.reset(Ellipse(), Q0)  # the ellipse's step, 0.02 s
    assert longest_substep(controller._config("tracking").interval_lengths()) == pytest.approx(0.02)


@pytest.mark.parametrize(
    "robot",
    [
        Robot(),
        Robot().with_payload(3.0),
        Robot(L1=0.6, L2=0.6, link_masses=(4.0, 4.0)),
        # lengths 8 times, masses kept, motors ~ s^5 (docs/mpc.md, "Robot size"): I / c2 is
        # 0.065 s folded, beyond the limit, and 0.54 s stretched
        replace(scaled_robot(8.0), wheel_torque_limit=2.0 * 8.0**5),
        scaled_robot(0.05),
    ],
)
@pytest.mark.parametrize("tracking", [True, False])
def test_the_thesis_damping_and_every_robots_own_are_taken(robot, tracking):
    prepared(robot, tracking)
    prepared(robot, tracking, c1=15.0, c2=4.0)


def test_the_largest_cosine_over_a_range():
    for low, high in [(-math.pi, math.pi), (0.5, 2.0), (4.0, 5.0), (-7.0, -6.0), (3.2, 3.3)]:
        grid = np.cos(np.linspace(low, high, 100_001))
        assert largest_cosine(low, high) == pytest.approx(grid.max(), abs=1e-9)


@pytest.mark.parametrize(("c1", "c2"), [(1e50, 4.0), (1e300, 4.0), (15.0, 1e300)])
def test_a_terminal_design_that_fails_is_one_line(c1, c2):
    """Where the force model has no finite LQR (the API's model, past the plant's ranges),
    the terminal design names the dampings instead of python-control's error."""
    robot = Robot()
    model = ThesisPrediction(robot, sym.ThesisDynamics.from_robot(robot, c1, c2))
    with pytest.raises(ParameterError) as error:
        terminal.design(robot, model, OCPConfig(), (0.3, 1.2))
    assert str(error.value).startswith(PREFIX) and "model='kinematic'" in str(error.value)
