"""Physical constants of the thesis's base (thesis Table 3.1, 4.4.2).

They describe the thesis's robot, not a simulator: the thesis plant
(:mod:`ddwmmr.plants.thesis`) simulates with them, the physics plant can add the same drive
damping, and the MPC's force-level prediction model (:mod:`ddwmmr.model.symbolic`) predicts
with them. Keeping them in the model layer lets controllers use them without importing a
plant.

Which of them a :class:`~ddwmmr.model.Robot` carries (docs/thesis.md, "What is simulated"):
the arm servo's speed is the robot's ``joint_speed_limit`` (2 rad/s for the default robot,
the thesis's value), and the thesis plant takes it from the robot. The damping c1, c2 are
the thesis model's: viscous stand-ins for the base's rolling resistance and drive friction,
fitted to the thesis's robot, with no field in ``Robot``. The wheel force limit is the
thesis robot's too: the default robot's motors (``wheel_torque_limit / wheel_radius``,
2 N m / 0.0975 m = 20.5 N) do not reproduce its 10 N. For another robot the thesis plant
scales the three in proportion to its motors' force, own mass and own yaw inertia
(:func:`robot_constants`, the one home of that rule: the plant, the force-level model and
the MPC's planned force use it) unless told otherwise.
"""

from __future__ import annotations

from ddwmmr.model.robot import Robot

#: Translational damping of the base (N s/m), thesis Table 3.1: the thesis model's.
C1_DEFAULT = 15.0
#: Rotational damping of the base (N m s/rad), thesis Table 3.1: the thesis model's.
C2_DEFAULT = 4.0
#: Force limit per wheel (N), thesis Table 3.1: the thesis robot's (for the default
#: ``Robot``; not its motors' 20.5 N).
FORCE_LIMIT_DEFAULT = 10.0

#: The thesis model's constants by name (the thesis robot's: ``Robot``'s defaults).
THESIS_CONSTANTS = {"force_limit": FORCE_LIMIT_DEFAULT, "c1": C1_DEFAULT, "c2": C2_DEFAULT}
#: Units of :data:`THESIS_CONSTANTS`.
UNITS = {"force_limit": "N", "c1": "N s/m", "c2": "N m s/rad"}
#: What each constant of :data:`THESIS_CONSTANTS` is proportional to, in words and units
#: (:func:`drive_facts`).
SCALES_WITH = {
    "force_limit": ("its motors' force", "N"),
    "c1": ("its own mass", "kg"),
    "c2": ("its own yaw inertia", "kg m^2"),
}


def drive_facts(robot: Robot) -> dict[str, float]:
    """What each thesis constant is proportional to, for ``robot``: its motors' wheel force
    (``motor_force_limit``, N), its own mass (kg) and its own yaw inertia with the arm
    stretched (kg m^2), both without the payload."""
    return {
        "force_limit": robot.motor_force_limit,
        "c1": robot.own_mass,
        "c2": robot.with_payload(0.0).yaw_inertia.at(0.0),
    }


#: :func:`drive_facts` of the thesis robot (20.5 N, 12 kg, 0.798 kg m^2).
THESIS_FACTS = drive_facts(Robot())


def scaled_constant(name: str, fact: float) -> float:
    """The thesis model's constant ``name`` (a key of :data:`THESIS_CONSTANTS`) for a robot
    whose :func:`drive_facts` entry ``name`` is ``fact``: the thesis's value times
    ``fact / THESIS_FACTS[name]`` (exactly the thesis's value for the thesis robot's fact)."""
    return THESIS_CONSTANTS[name] * (fact / THESIS_FACTS[name])


def motors_share(motor_force: float) -> float:
    """The per-wheel force limit (N) the thesis model gives motors of ``motor_force`` N per
    wheel: the thesis robot's share of its motors, 10 N of 20.5 N (48.75 %); exactly 10 N
    for the thesis robot's motors."""
    return scaled_constant("force_limit", motor_force)


def robot_constants(robot: Robot) -> dict[str, float]:
    """The thesis plant's default constants for ``robot``: ``{"force_limit": N per wheel,
    "c1": N s/m, "c2": N m s/rad}``, the thesis model's scaled by ``robot``'s own drive.

    The force limit keeps the thesis's share of the motors (:func:`motors_share`: 10 N of
    the thesis robot's ``motor_force_limit`` 20.5 N), so the plant never gives more than
    ``robot``'s motors; c1 keeps the translational time constant ``m / c1`` and c2 the yaw
    time constant ``I / c2``, with the robot's own mass and its own yaw inertia at the
    stretched arm (th2 = 0), both without the payload: the drive is built for the robot,
    not for what it carries (docs/thesis.md, "What is simulated"). Exactly the thesis's
    10, 15, 4 for a robot with the thesis robot's motors, masses and inertia, at any
    payload.
    """
    facts = drive_facts(robot)
    return {name: scaled_constant(name, facts[name]) for name in THESIS_CONSTANTS}
