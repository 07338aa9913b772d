"""Robots at other sizes than the default, scaled as a physical robot scales: lengths by
``s``, masses by ``s^3``, the base's yaw inertia by ``s^5``, torque limits by ``s^4``."""

import warnings
from dataclasses import replace
from typing import Any

from ddwmmr import Ellipse, Robot, simulate

#: The default robot ten times as long, 1000 times as heavy (its motors scaled to match).
TEN_TIMES = Robot(
    L1=3.5,
    L2=3.0,
    wheel_radius=0.975,
    track_width=3.5,
    base_length=4.5,
    base_width=3.5,
    base_mass=10000.0,
    base_inertia=50000.0,
    link_masses=(1000.0, 1000.0),
    payload=1250.0,
    wheel_mass=500.0,
    base_height=2.0,
    arm_height=3.5,
    wheel_torque_limit=20000.0,
    joint_torque_limits=(200000.0, 100000.0),
)
#: The default robot a twentieth as long (masses scaled by length cubed).
TWENTIETH = Robot(
    L1=0.0175,
    L2=0.015,
    wheel_radius=0.004875,
    track_width=0.0175,
    base_length=0.0225,
    base_width=0.0175,
    base_mass=0.00125,
    base_inertia=1.5625e-07,
    link_masses=(0.000125, 0.000125),
    payload=0.00015625,
    wheel_mass=6.25e-05,
    base_height=0.01,
    arm_height=0.0175,
    wheel_torque_limit=1.25e-05,
    joint_torque_limits=(0.000125, 6.25e-05),
)


def scaled_options(options: dict, factor: float, metre_options: tuple[str, ...]) -> dict:
    """A controller's ``options`` for the robot scaled by ``factor``: the options named in
    ``metre_options`` (m, m/s), the obstacles' ``(x, y, r)`` and ``speed_budget``'s linear
    speed scaled; every other option as given."""
    scaled = {
        key: value * factor if key in metre_options else value for key, value in options.items()
    }
    if "obstacles" in options:
        scaled["obstacles"] = [
            (factor * x, factor * y, factor * r) for x, y, r in options["obstacles"]
        ]
    if "speed_budget" in options:
        v_top, w_top = options["speed_budget"]
        scaled["speed_budget"] = (factor * v_top, w_top)
    return scaled


#: The robot's fields that are lengths, scaled by :func:`scaled_robot`.
LENGTHS = (
    "L1",
    "L2",
    "wheel_radius",
    "track_width",
    "base_length",
    "base_width",
    "base_height",
    "arm_height",
)


def scaled_robot(factor: float) -> Robot:
    """The default robot with every length ``factor`` times as long (masses kept: the
    kinematic plant does not use them, and the tip-over measure depends on their ratios).
    A power-of-two ``factor`` scales exactly in floating point."""
    default = Robot()
    return replace(default, **{name: getattr(default, name) * factor for name in LENGTHS})


#: Start offset (m) on the default robot, along both end-effector axes (scaled with it).
OFFSET = -0.03


def mpc_on_scaled_ellipse(robot: Robot, factor: float, duration: float, **options: Any) -> Any:
    """``simulate``'s result of the ``mpc`` on ``robot`` tracking the ellipse and the start
    offset (:data:`OFFSET`) scaled by ``factor`` for ``duration`` s, with ``options`` for
    ``simulate`` (the plant, the controller's). Warnings are silenced: a scaled robot's
    lengths and derived plant constants warn."""
    ellipse = Ellipse()
    task = replace(ellipse, a=factor * ellipse.a, b=factor * ellipse.b)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(
            robot,
            task,
            "mpc",
            duration=duration,
            initial_offset=(factor * OFFSET, factor * OFFSET),
            **options,
        )
