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
(:func:`ddwmmr.plants.thesis.robot_constants`) unless told otherwise.
"""

#: Translational damping of the base (N s/m), thesis Table 3.1: the thesis model's.
C1_DEFAULT = 15.0
#: Rotational damping of the base (N m s/rad), thesis Table 3.1: the thesis model's.
C2_DEFAULT = 4.0
#: Force limit per wheel (N), thesis Table 3.1: the thesis robot's (for the default
#: ``Robot``; not its motors' 20.5 N).
FORCE_LIMIT_DEFAULT = 10.0
