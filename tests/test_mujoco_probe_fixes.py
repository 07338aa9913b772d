"""MujocoPlant: rejected controls, blow-ups caught in their step, rocks that are no tips,
the engine options' physical ranges and the messages that name the cause."""

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, load_trajectory, simulate
from ddwmmr.commands import WheelForces
from ddwmmr.plants.base import PlantDivergedError
from ddwmmr.plants.mujoco import MujocoPlant
from ddwmmr.plants.mujoco.model import EngineOptions
from ddwmmr.plants.mujoco.plant import LIFT_TIME_S, UNLOADED_FRACTION, tip_time_s
from one_line import one_line

DT = 0.02
#: A 50 g base with 1 g links: too light for the default 2 ms engine step once it moves.
TINY = Robot(base_mass=0.05, wheel_mass=0.01, base_inertia=0.001, link_masses=(0.001, 0.001))


def test_a_control_mujoco_rejects_is_a_divergence_naming_it():
    """A finite wheel force whose torque F r passes MuJoCo's 1e10 limit made the engine
    zero every control, step after step, and the robot stood still without a word."""
    plant = MujocoPlant(Robot())
    plant.reset(np.array([0.0, 0.0, 0.0, -0.3, 0.6]), DT)
    with pytest.raises(PlantDivergedError) as error:
        plant.step(0.0, WheelForces(1e300, -1e300, 0.0, 0.0), DT)
    message = str(error.value)
    assert message.startswith(
        "MuJoCo rejected the control of wheel_left in control step 1 (t = 0 to 0.02 s)"
    )
    assert "9.75e+298 N m" in message and "\n" not in message


def test_a_blow_up_is_caught_in_its_step_and_numbered_as_the_run():
    """The tiny robot on the default robot's tyres (a stiffness for 12 kg, not scaled to
    its mass) blows up in step 11; MuJoCo's own checks fired only in step 18, with the
    base 300 m away, and the message's step was counted from 0."""
    result = simulate(
        TINY.with_payload(0.0),
        load_trajectory("ellipse"),
        "clrrmc-ts",
        plant="mujoco",
        plant_options={"tyre_stiffness": 5e4},
        duration=0.1,
        dt=0.002,
    )
    summary = result.summary
    assert summary["diverged_at_step"] == 11 and summary["steps"] == 10
    assert summary["diverged"].startswith(
        "MuJoCo state diverged in control step 11 (t = 0.02 to 0.022 s): base speed "
    )
    assert "beyond 10 times the fastest the motors drive it (14.6 m/s)" in summary["diverged"]
    assert "plant_options={'timestep': ...}" in summary["diverged"]
    # nothing of the blow-up was recorded: the base is still within 2 cm of its start
    x = result.timeseries["x"]
    assert np.max(np.abs(x - x[0])) < 0.02
    assert summary["max_wheel_slip_m_s"] < 1.0


#: Tilt (rad) every 0.02 s of a long-arm robot rocking onto an edge and back (recorded:
#: L1 = 0.7, L2 = 0.6, clrrmc-ts on the ellipse); the edge is unloaded from the 2nd to the
#: 9th sample.
ROCK_TILT = [3.408e-3, 4.557e-3, 5.522e-3, 6.211e-3, 6.629e-3, 6.774e-3, 6.645e-3, 6.239e-3,
             5.553e-3, 4.586e-3]  # fmt: skip


def test_a_rock_onto_an_edge_and_back_is_not_a_tip():
    weight = 400.0
    t = DT * np.arange(len(ROCK_TILT))
    load = np.full(len(t), 10.0)
    load[1:9] = 0.5 * UNLOADED_FRACTION * weight
    assert tip_time_s(t, load, np.array(ROCK_TILT), weight) is None
    # the same rise without slowing down tips, LIFT_TIME_S after the pivot began
    steady = ROCK_TILT[0] + 1.15e-3 * np.arange(len(t))
    assert tip_time_s(t, load, steady, weight) == pytest.approx(LIFT_TIME_S, abs=1e-9)


def test_the_long_arm_robot_rocks_and_tracks():
    robot = Robot(L1=0.7, L2=0.6)
    summary = simulate(  # from the offset docs/physics.md quotes, half the robot's default
        robot,
        load_trajectory("ellipse"),
        "clrrmc-ts",
        plant="mujoco",
        duration=1.0,
        dt=DT,
        initial_offset=(-0.03, -0.03),
    ).summary
    assert summary["support_lost"] and summary["unloaded_time_s"] == pytest.approx(0.22, abs=0.03)
    assert not summary["tipped"] and summary["tip_time_s"] is None
    assert summary["max_base_tilt_rad"] == pytest.approx(6.77e-3, abs=2e-4)


@pytest.mark.parametrize(
    ("option", "value", "refusal"),
    [
        ("friction", 1e-9, r"^friction must be in \[0.01, 5\] \(got 1e-09\)$"),
        ("friction", 1e9, r"^friction must be in \[0.01, 5\] \(got 1e\+09\)$"),
        ("servo_time_constant", 1e9, r"^servo_time_constant must be in \[0.001, 1\] s "),
        ("servo_time_constant", 1e-9, r"^servo_time_constant must be in \[0.001, 1\] s "),
        ("contact_time_constant", 1e9, r"^contact_time_constant must be in \[2e-05, 0.05\] s "),
        (
            "tyre_stiffness",
            1e-9,
            r"^tyre_stiffness must be 0 \(rigid wheels\) or in \[10000, 1e\+08\] N/m "
            r"\(got 1e-09\)$",
        ),
        ("tyre_stiffness", 1e12, r"^tyre_stiffness must be 0 \(rigid wheels\) or in "),
        ("base_damping", (1e9, 1e9), r"^base_damping\[1\] must be in \[0, 1000\] N s/m "),
        ("base_damping", (15.0, 1e9), r"^base_damping\[2\] must be in \[0, 1000\] N m s/rad "),
    ],
)
def test_engine_options_outside_their_physical_range_are_refused(option, value, refusal):
    with pytest.raises(ParameterError, match=refusal):
        MujocoPlant(Robot(), **{option: value})


@pytest.mark.parametrize("value", [1.0, (1.0,), (1, 2, 3), "ab", (True, 1), ("1", "2")])
def test_base_damping_not_two_numbers_is_refused_with_its_ranges(value):
    # Was "base_damping must be (N s/m, N m s/rad), two numbers >= 0" (no upper end), and
    # texts or booleans such as ("1", "2") passed as numbers.
    with pytest.raises(ParameterError) as info:
        MujocoPlant(Robot(), base_damping=value)
    assert one_line(info) == (
        "base_damping must be two numbers, translation in [0, 1000] N s/m and yaw in "
        f"[0, 1000] N m s/rad (got {value!r})"
    )


def test_engine_options_at_the_ends_of_their_ranges_build():
    for low_high in (
        {"friction": 0.01, "servo_time_constant": 1e-3, "tyre_stiffness": 1e4},
        {"friction": 5.0, "servo_time_constant": 1.0, "contact_time_constant": 0.05},
        {"tyre_stiffness": 0.0, "contact_time_constant": 0.004},
    ):
        options = EngineOptions(**low_high)
        assert all(getattr(options, k) == v for k, v in low_high.items())
    assert MujocoPlant(Robot(), base_damping=(1e3, 1e3)).damping == (1e3, 1e3)


def test_a_long_timestep_alone_names_the_contact_time_constant_default():
    with pytest.raises(ParameterError) as error:
        MujocoPlant(Robot(), timestep=0.007)
    assert str(error.value) == (
        "contact_time_constant must be >= 2 timesteps = 0.014 s (got 0.01, its default: set "
        "it along with the timestep)"
    )
    assert MujocoPlant(Robot(), timestep=0.007, contact_time_constant=0.014).timestep == 0.007


def test_a_tyre_too_stiff_to_settle_is_named():
    """The default robot on 1e8 N/m tyres cannot settle at 2 ms: its masses are fine, the
    stiffness is the cause, and the message said only "give it heavier parts"."""
    plant = MujocoPlant(Robot(), tyre_stiffness=1e8)
    with pytest.raises(ParameterError) as error:
        plant.reset(np.zeros(5), DT)
    message = str(error.value)
    assert message.startswith("MuJoCo cannot settle this robot at timestep 0.002 s")
    assert "tyre_stiffness 1e+08 N/m and contact_time_constant 0.01 s" in message
    assert "soften the tyres (lower tyre_stiffness, or 0 for rigid wheels)" in message
