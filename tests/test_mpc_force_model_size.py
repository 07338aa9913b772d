"""The ``mpc`` on the thesis plant at other robot sizes (docs/mpc.md, "Robot size").

The robot there is scaled as a physical robot is: lengths by ``s``, masses by ``s^3``, the
base's yaw inertia by ``s^5`` and the wheel motors' torque by ``s^5`` (forces ``~ s^4``),
so the thesis plant's derived constants scale alike (c1 by ``s^3``, c2 by ``s^5``, the force
limit by ``s^4``). The kinematic model, which plans in the robot's length unit, then runs
the default robot's steps with ``s`` times its errors; the force model, which plans in SI
units, does not. The robot with masses kept and wheel torques ``~ s^5`` is another robot
(tests/test_mpc_stiff_base.py): it tracks, on a force limit that never binds."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.plants.thesis import robot_constants
from scaled_robots import mpc_on_scaled_ellipse, scaled_robot

DEFAULT = Robot()


def physical_robot(factor: float) -> Robot:
    """The default robot ``factor`` times as long, its masses by ``factor^3``, its base's
    yaw inertia by ``factor^5`` and its wheel and joint torque limits by ``factor^5``."""
    return replace(
        scaled_robot(factor),
        base_mass=DEFAULT.base_mass * factor**3,
        base_inertia=DEFAULT.base_inertia * factor**5,
        link_masses=tuple(mass * factor**3 for mass in DEFAULT.link_masses),
        payload=DEFAULT.payload * factor**3,
        wheel_mass=DEFAULT.wheel_mass * factor**3,
        wheel_torque_limit=DEFAULT.wheel_torque_limit * factor**5,
        joint_torque_limits=tuple(limit * factor**5 for limit in DEFAULT.joint_torque_limits),
    )


def run(robot: Robot, factor: float, model: str, duration: float) -> dict:
    """The ``mpc`` with ``model`` on the thesis plant of ``robot``, tracking the ellipse
    and start offset scaled by ``factor`` for ``duration`` s: the summary, with the
    per-step position errors divided by ``factor`` (m) as ``"errors"``."""
    result = mpc_on_scaled_ellipse(robot, factor, duration, plant="thesis", model=model)
    errors = np.asarray(result.timeseries["position_error_m"]) / factor
    return {**result.summary, "errors": errors}


#: The force model's robots of docs/mpc.md, "Robot size": (robot, scale).
FORCE_MODEL_ROBOTS = {
    "default": (DEFAULT, 1.0),
    "0.5x": (physical_robot(0.5), 0.5),
    "8x": (physical_robot(8.0), 8.0),
    "8x masses kept": (replace(scaled_robot(8.0), wheel_torque_limit=2.0 * 8.0**5), 8.0),
}


@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_the_derived_constants_scale_with_the_physical_robot(factor):
    constants = robot_constants(physical_robot(factor))
    assert constants["c1"] == pytest.approx(15.0 * factor**3, rel=1e-12)
    assert constants["c2"] == pytest.approx(4.0 * factor**5, rel=1e-12)
    assert constants["force_limit"] == pytest.approx(10.0 * factor**4, rel=1e-12)


@pytest.mark.parametrize("factor", [0.5, 8.0])
def test_the_kinematic_model_runs_the_default_robots_steps_scaled(factor):
    default = run(DEFAULT, 1.0, "kinematic", 2.0)["errors"]
    scaled = run(physical_robot(factor), factor, "kinematic", 2.0)["errors"]
    np.testing.assert_array_equal(scaled, default)


@pytest.mark.parametrize(
    ("name", "rms_mm", "final_mm", "tracked"),
    [
        ("default", 7.24, 0.31, True),
        ("0.5x", 17.6, 1.84, True),
        ("8x", 212.0, 439.0, False),
        ("8x masses kept", 3.17, 0.0031, True),
    ],
)
def test_the_force_models_errors_over_6_s_of_the_ellipse(name, rms_mm, final_mm, tracked):
    """RMS and final position errors divided by the scale, as docs/mpc.md quotes them."""
    robot, factor = FORCE_MODEL_ROBOTS[name]
    summary = run(robot, factor, "thesis", 6.0)
    rms_mm_measured = 1e3 * summary["rms_position_error_m"] / factor
    assert rms_mm_measured == pytest.approx(rms_mm, rel=5e-3)
    assert 1e3 * summary["errors"][-1] == pytest.approx(final_mm, rel=2e-2)
    assert (summary["verdict"] == "tracked") is tracked
    assert summary["mpc_fallbacks"] == 0
