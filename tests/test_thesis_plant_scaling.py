"""The thesis plant's default constants are the robot's own: the thesis model's 10 N per
wheel, c1 = 15 N s/m and c2 = 4 N m s/rad scaled by the robot's motors' force, own mass and
own yaw inertia (docs/thesis.md, "What is simulated"). The thesis robot keeps them exactly;
a robot of another size tracks its scaled trajectory when its motors can drive it, and the
verdict names the force limit when they cannot."""

from __future__ import annotations

import inspect
import warnings

import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.bounds.lower import Prices
from ddwmmr.commands import FORCE, PlantTraits
from ddwmmr.model import symbolic as sym
from ddwmmr.model import thesis_base
from ddwmmr.mpc.options import MPCOptions, planned_force
from ddwmmr.plants import thesis as thesis_plant
from ddwmmr.plants.thesis import ThesisPlant, robot_constants
from scaled_robots import TEN_TIMES, TWENTIETH

#: 30 N m motors on 0.2 m wheels (150 N per wheel), the thesis robot's masses otherwise.
STRONG_MOTORS = Robot(wheel_radius=0.2, wheel_torque_limit=30.0)


def _constants(plant: ThesisPlant) -> tuple[float, float, float]:
    return plant.force_limit, plant.c1, plant.c2


@pytest.mark.parametrize("payload", [0.0, 1.25, 3.0])
def test_the_thesis_robot_gets_exactly_the_thesis_constants_silently(payload):
    robot = Robot().with_payload(payload)
    assert robot_constants(robot) == {"force_limit": 10.0, "c1": 15.0, "c2": 4.0}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert _constants(ThesisPlant(robot)) == (10.0, 15.0, 4.0)


def test_the_defaults_are_chosen_from_the_robot():
    """The signature says None (the robot's own), not the thesis robot's numbers."""
    parameters = inspect.signature(ThesisPlant).parameters
    assert [parameters[name].default for name in ("c1", "c2", "force_limit")] == [None] * 3


@pytest.mark.parametrize(
    ("robot", "expected"),
    [
        # motors 20000 N m / 0.975 m = 1000 x 20.5 N; own mass 12000 kg = 1000 x 12 kg;
        # own stretched yaw inertia 79833 kg m^2 = 1e5 x 0.79833 kg m^2
        (TEN_TIMES, (1e4, 1.5e4, 4e5)),
        # motors, mass / 8000; inertia / 3.2e6
        (TWENTIETH, (1.25e-3, 1.875e-3, 1.25e-6)),
    ],
)
def test_a_scaled_robot_gets_the_thesis_constants_scaled_to_it(robot, expected):
    with pytest.warns(UserWarning, match=r"^thesis plant: force_limit = .* derived"):
        plant = ThesisPlant(robot)
    assert _constants(plant) == pytest.approx(expected, rel=1e-12)
    assert plant.force_limit < robot.motor_force_limit  # never more than its motors


def test_the_rule_has_one_home_in_the_model_layer():
    """The plant uses the model layer's rule (the controllers' models may not import a
    plant); ``ddwmmr.plants.thesis.robot_constants`` is that same function."""
    assert thesis_plant.robot_constants is thesis_base.robot_constants


@pytest.mark.parametrize("robot", [TEN_TIMES, TWENTIETH, STRONG_MOTORS])
def test_the_force_level_model_is_the_plant_s_for_any_robot(robot):
    """``ThesisDynamics.from_robot(robot)`` is the model of ``ThesisPlant(robot)``: the same
    derived constants (it had the thesis robot's 15, 4 and 10 N for every robot)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plant = ThesisPlant(robot)
    model = sym.ThesisDynamics.from_robot(robot)
    assert (model.force_limit, model.c1, model.c2) == _constants(plant)
    given = sym.ThesisDynamics.from_robot(robot, 15.0, 4.0, 10.0)  # given values still win
    assert (given.force_limit, given.c1, given.c2) == (10.0, 15.0, 4.0)


def test_the_default_robot_s_model_keeps_the_thesis_constants_exactly():
    model = sym.ThesisDynamics.from_robot(Robot().with_payload(3.0))
    assert (model.force_limit, model.c1, model.c2) == (10.0, 15.0, 4.0)
    parameters = inspect.signature(sym.ThesisDynamics.from_robot).parameters
    assert [parameters[name].default for name in ("c1", "c2", "force_limit")] == [None] * 3


def test_the_lower_bound_prices_the_robot_s_own_plant():
    """150 N motors: the plant's force limit is 73.125 N, so driving costs c1 / (2 F) =
    15 / 146.25 s/m (it priced 15 / 20 s/m, the thesis robot's 10 N)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plant = ThesisPlant(STRONG_MOTORS)
    assert plant.force_limit == pytest.approx(73.125, rel=1e-3)
    prices = Prices.from_robot(STRONG_MOTORS)
    assert prices.drive == pytest.approx(plant.c1 / (2.0 * plant.force_limit), rel=1e-12)
    assert prices.drive == pytest.approx(15.0 / 146.25, rel=1e-3)


def _physics_traits(motors: float) -> PlantTraits:
    return PlantTraits((FORCE, "velocity"), True, 0.02, (0.0, 0.0), motors, 0.175)


@pytest.mark.parametrize("robot", [Robot(), STRONG_MOTORS, TWENTIETH])
def test_the_mpc_plans_with_the_robot_s_share_of_its_motors_on_a_physics_plant(robot):
    """On a plant that judges tipping the force model plans with the force limit the thesis
    plant derives for the same robot (10 N of the thesis robot's 20.5 N; 73.125 N of
    150 N; 1.25e-3 N of a twentieth's 2.56e-3 N), not with min(10 N, motors)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = ThesisPlant(robot).force_limit
    traits = _physics_traits(robot.motor_force_limit)
    assert planned_force(traits) == expected < robot.motor_force_limit
    assert MPCOptions().adopt_plant(traits).wheel_force_limit == expected
    assert planned_force(_physics_traits(Robot().motor_force_limit)) == 10.0  # exactly


def test_given_constants_win_over_the_robot_s_own():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing derived: nothing to warn about
        plant = ThesisPlant(TEN_TIMES, c1=15.0, c2=4.0, force_limit=10.0)
    assert _constants(plant) == (10.0, 15.0, 4.0)


def _run(robot, scale, period, method):
    ellipse = Ellipse(a=2.0 * scale, b=1.5 * scale, T=period, N=2000)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(
            robot, ellipse, method, plant="thesis", initial_offset=(0.03 * scale, 0.03 * scale)
        ).summary


@pytest.mark.parametrize(("method", "final_mm"), [("ats", 1.6), ("qp", 0.085)])
def test_a_twentieth_robot_tracks_its_scaled_ellipse(method, final_mm):
    """On the thesis's 15 N s/m and 4 N m s/rad the 1.5 g robot could hardly turn (37 mm
    off at the end on a 0.1 m ellipse); on its own constants it tracks as the default
    robot does on its ellipse, at a twentieth of the error (ats 1.55 mm, qp 0.0799 mm)."""
    summary = _run(TWENTIETH, 0.05, 40.0, method)
    assert summary["verdict"] == "tracked"
    assert summary["final_position_error_m"] < final_mm * 1e-3


def test_the_qp_on_a_twentieth_robot_has_a_twentieth_of_the_default_robots_error():
    """The qp solves in the robot's length unit and the derived constants keep the thesis
    robot's time constants, so the twentieth robot's run is the default robot's scaled."""
    default = _run(Robot(), 1.0, 40.0, "qp")["final_position_error_m"]
    small = _run(TWENTIETH, 0.05, 40.0, "qp")["final_position_error_m"]
    assert small == pytest.approx(0.05 * default, rel=1e-6)


def test_a_ten_times_robot_tracks_its_ellipse_at_its_motors_pace():
    """Motors scaled with the mass give the default robot's top speed, so the 20 m x 15 m
    ellipse tracks in 400 s (its speeds those of the default robot's ellipse in 40 s):
    0.41 mm at the end (10 m on the thesis robot's 10 N)."""
    summary = _run(TEN_TIMES, 10.0, 400.0, "qp")
    assert summary["verdict"] == "tracked"
    assert summary["final_position_error_m"] < 2e-3


def test_a_ten_times_robot_too_weak_for_its_ellipse_in_40_s_says_force_limit():
    """In 40 s the ellipse asks 10 times the speed its motors' share gives (top speed
    2 F / c1 = 1.33 m/s): it does not track, and the cause is its own force limit."""
    summary = _run(TEN_TIMES, 10.0, 40.0, "qp")
    assert summary["max_wheel_force_n"] == pytest.approx(1e4, rel=1e-9)
    assert summary["actuator_saturated_time_s"] > 39.0
    assert summary["verdict"].startswith("did not track")
    assert (
        "likely cause: the robot ran at a limit (a wheel at its force limit" in (summary["verdict"])
    )
