"""Actuator commands: what a controller hands to a plant (through the simulation loop).

Controllers and plants never import each other; both import this neutral module. A plant
accepts one or both of two command interfaces (``Plant.interfaces``):

* ``"velocity"``: ``u = (v, w, th1dot, th2dot)`` as a float array of shape (4,): forward
  speed (m/s) along the base heading, yaw rate (rad/s) and the joint rates (rad/s). Every
  kinematic controller (pi, ats, ap, clrrmc-*, qp, mpc) speaks it; a plant with dynamics
  tracks it with its own velocity servos (and may lag, slip or saturate).
* ``"force"``: :class:`WheelForces`, the thesis plant's actuation (thesis ch. 3): a
  traction force per wheel (N, along the heading) and joint position targets (rad) for the
  arm servo. Force-level controllers (the thesis behaviour controller, ``mpc`` with the
  thesis model) speak it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

#: The command interfaces, by name.
VELOCITY, FORCE = "velocity", "force"
INTERFACES = (VELOCITY, FORCE)


@dataclass(slots=True)
class WheelForces:
    """Force-level actuation: wheel forces (N) and arm joint targets (rad); read-only by
    convention (one is made every control step; frozen would triple its cost).

    Attributes:
        left, right: traction force of the left / right wheel along the base heading (N).
        th1_target, th2_target: joint position targets of the arm servo (rad).
    """

    left: float
    right: float
    th1_target: float
    th2_target: float


def interface_of(command: object) -> str:
    """``"force"`` for a :class:`WheelForces`, else ``"velocity"`` (an array-like u)."""
    return FORCE if isinstance(command, WheelForces) else VELOCITY


@dataclass(frozen=True)
class PlantTraits:
    """What a controller may know of the plant it is about to command: plain facts, handed
    over by the simulation loop (``adopt_plant``; the controller never sees the plant).

    Attributes:
        interfaces: the command interfaces the plant accepts (``"velocity"``, ``"force"``).
        judges_tipping: the plant judges tipping over by its own physics (contact forces:
            ``Plant.tip_time``).
        joint_time_constant: the lag (s) with which its joints follow their rate targets,
            None if they follow at once.
        base_damping: the viscous damping of its base's motion, ``(c1 N s/m, c2 N m
            s/rad)`` (``(0, 0)``: none), None when the plant does not say.
        wheel_force_limit: the largest traction force (N) each wheel's motor can apply
            (a force command beyond it is clipped), None when the plant does not say.
        wheel_lever: the lever arm (m) of each wheel's traction force about the base
            centre, half the distance between the wheels; None when the plant does not
            say.
        joint_acceleration_limit: the largest angular accelerations (rad/s^2) the arm's
            motors give the shoulder and the elbow (with the arm stretched and the payload
            at the tip, the most they have to move), None when the plant does not say.
    """

    interfaces: tuple[str, ...]
    judges_tipping: bool
    joint_time_constant: float | None
    base_damping: tuple[float, float] | None = None
    wheel_force_limit: float | None = None
    wheel_lever: float | None = None
    joint_acceleration_limit: tuple[float, float] | None = None


def traits_of(plant: Any) -> PlantTraits:
    """The :class:`PlantTraits` of a plant (read from its attributes; pairs as tuples of
    floats, whatever sequence the plant gives, so the traits are hashable)."""

    def pair(value: Any) -> tuple[float, ...] | None:
        return None if value is None else tuple(float(v) for v in value)

    def number(value: Any) -> float | None:
        return None if value is None else float(value)

    return PlantTraits(
        tuple(plant.interfaces),
        hasattr(plant, "tip_time"),
        number(getattr(plant, "joint_time_constant", None)),
        pair(getattr(plant, "damping", None)),  # type: ignore[arg-type]
        number(getattr(plant, "wheel_force_limit", None)),
        number(getattr(plant, "wheel_lever", None)),
        pair(getattr(plant, "joint_acceleration_limit", None)),  # type: ignore[arg-type]
    )
