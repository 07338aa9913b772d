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
from ddwmmr.plants.thesis import ThesisPlant, robot_constants
from scaled_robots import TEN_TIMES, TWENTIETH


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


@pytest.mark.parametrize(("method", "final_mm"), [("ats", 1.6), ("qp", 0.06)])
def test_a_twentieth_robot_tracks_its_scaled_ellipse(method, final_mm):
    """On the thesis's 15 N s/m and 4 N m s/rad the 1.5 g robot could hardly turn (37 mm
    off at the end on a 0.1 m ellipse); on its own constants it tracks as the default
    robot does on its ellipse, at a twentieth of the error (ats 1.55 mm, qp 0.049 mm)."""
    summary = _run(TWENTIETH, 0.05, 40.0, method)
    assert summary["verdict"] == "tracked"
    assert summary["final_position_error_m"] < final_mm * 1e-3


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
