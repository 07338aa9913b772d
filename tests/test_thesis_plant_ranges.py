"""The thesis plant's constants have finite ranges (``ddwmmr.plants.thesis.CONSTANT_RANGES``):
c1, c2, force_limit, joint_speed and velocity_bandwidth took any positive float (c1 =
1e300, c2 = 5e-324: a base that could not move or whose ``1 / c2`` overflowed). Each range
holds what the plant derives for every robot within ``Robot``'s ranges, and at its ends
the plant's step stays exact and finite on the lightest and the heaviest robot."""

from __future__ import annotations

import decimal
import itertools
import math
import warnings

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.cli.track import main as track
from ddwmmr.commands import WheelForces
from ddwmmr.errors import ParameterError
from ddwmmr.model.thesis_base import robot_constants
from ddwmmr.plants.thesis import CONSTANT_RANGES, ThesisPlant, first_order_step

#: The heaviest and largest robot ``Robot``'s ranges allow (400 t, links of 1 km), and the
#: lightest and smallest (1 ug, every length 1 um).
HEAVIEST = Robot(
    L1=1e3,
    L2=1e3,
    base_mass=1e5,
    link_masses=(1e5, 1e5),
    payload=1e5,
    base_inertia=1e6,
    wheel_radius=1e-6,
    wheel_torque_limit=1e6,
    wheel_mass=1.0,
    track_width=1e3,
    base_length=1e3,
    base_width=1e3,
    base_height=1e3,
    arm_height=1e3,
)
LIGHTEST = Robot(
    L1=1e-6,
    L2=1e-6,
    base_mass=1e-9,
    link_masses=(0.0, 0.0),
    payload=0.0,
    base_inertia=1e-9,
    wheel_radius=1e3,
    wheel_torque_limit=1e-6,
    wheel_mass=1e-10,
    track_width=1e-6,
    base_length=1e-6,
    base_width=1e-6,
    base_height=1e-6,
    arm_height=1e-6,
)


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        ("c1", "1e300", "c1 must be in [1e-20, 1e+13] N s/m (got 1e+300)"),
        ("c1", "-1", "c1 must be in [1e-20, 1e+13] N s/m (got -1)"),
        ("c2", "5e-324", "c2 must be in [1e-20, 1e+13] N m s/rad (got 4.94066e-324)"),
        ("force_limit", "1e300", "force_limit must be in [1e-10, 1e+12] N (got 1e+300)"),
        ("joint_speed", "1e300", "joint_speed must be in [1e-06, 1e+06] rad/s (got 1e+300)"),
        (
            "velocity_bandwidth",
            "5e-324",
            "velocity_bandwidth must be in [1e-09, 10000] 1/s (got 4.94066e-324)",
        ),
    ],
)
def test_a_constant_out_of_its_range_is_one_line(tmp_path, capsys, name, value, message):
    out = tmp_path / "run"
    argv = ["--method", "pi", "--traj", "ellipse", "--plant", "thesis", "--duration", "0.2"]
    argv += ["--plant-option", f"{name}={value}", "--no-progress", "--out", str(out)]
    assert track(argv) == 2
    assert capsys.readouterr().err == f"error: {message}\n"
    assert not out.exists()


@pytest.mark.parametrize("robot", [HEAVIEST, LIGHTEST, Robot()])
def test_every_robots_own_constants_are_within_the_ranges(robot):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        own = robot_constants(robot)
        for name, value in own.items():
            low, high, _ = CONSTANT_RANGES[name]
            assert low <= value <= high, name
        ThesisPlant(robot, **own)  # given as they are derived: taken


def exact(x0, u, gain, tau, dt):
    """The step's closed form in 300-digit decimal arithmetic (at ``dt / tau`` = 1e-35
    its integral cancels some 70 digits)."""
    with decimal.localcontext() as context:
        context.prec = 300
        x0, u, gain, tau, dt = (decimal.Decimal(v) for v in (x0, u, gain, tau, dt))
        x_ss, decay = gain * u, (-dt / tau).exp()
        return float(x_ss + (x0 - x_ss) * decay), float(x_ss * dt + (x0 - x_ss) * tau * (1 - decay))


@pytest.mark.parametrize("damping", [CONSTANT_RANGES["c1"][0], CONSTANT_RANGES["c1"][1]])
def test_the_first_order_step_is_exact_at_the_dampings_ends(damping):
    """From the lightest robot's mass to the heaviest's, steps from 1e-12 s to 1000 s and
    forces from 1e-10 N to 2e12 N: the series (dt / tau down to 1e-37) and the closed form
    (up to 1e34) both to 1e-12."""
    masses, steps, forces = (1e-9, 13.25, 4e5), (1e-12, 1e-6, 0.02, 1e3), (1e-10, 20.0, 2e12)
    for mass, dt, u in itertools.product(masses, steps, forces):
        step = first_order_step(0.3, u, 1.0 / damping, mass / damping, dt)
        assert step == pytest.approx(exact(0.3, u, 1.0 / damping, mass / damping, dt), rel=1e-12)


@pytest.mark.parametrize("robot", [HEAVIEST, LIGHTEST, Robot()])
@pytest.mark.parametrize(("damped", "forced"), [(0, 0), (0, 1), (1, 0), (1, 1)])
def test_a_plant_at_the_ranges_ends_steps_finitely(robot, damped, forced):
    """Each damping, force and servo constant at an end of its range (the dampings'
    ``damped``, the others' ``forced``): the envelope the qp gets is finite and > 0, and
    steps under wheel forces and through the velocity servo stay finite."""
    ends = {name: bounds[forced] for name, bounds in CONSTANT_RANGES.items()}
    constants = {**ends, "c1": CONSTANT_RANGES["c1"][damped], "c2": CONSTANT_RANGES["c2"][damped]}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plant = ThesisPlant(robot, **constants)
    envelope = plant.velocity_envelope()
    assert all(math.isfinite(v) and v > 0.0 for v in envelope.values())
    plant.reset(np.array([0.0, 0.0, 0.0, 0.3, 1.2]), 0.02)
    force = constants["force_limit"]
    for dt in (1e-9, 0.02, 10.0):
        plant.step(0.0, WheelForces(force, -force, 0.5, 1.0), dt)
        plant.step(0.0, np.array([0.1, 0.2, 0.3, -0.3]), dt)  # the velocity servo
    assert all(math.isfinite(v) for v in (*plant.state.q, plant.state.v, plant.state.w))


def test_a_given_constant_outside_its_range_is_refused_by_the_api():
    with pytest.raises(ParameterError, match=r"^c2 must be in \[1e-20, 1e\+13\] N m s/rad"):
        ThesisPlant(Robot(), c2=1e14)
    with pytest.raises(ParameterError, match=r"^velocity_bandwidth must be in \[1e-09, 10000\]"):
        ThesisPlant(Robot(), velocity_bandwidth=2e4)
