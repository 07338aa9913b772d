"""Physical constants of the thesis's base (thesis Table 3.1, 4.4.2).

They describe the robot, not a simulator: the thesis plant (:mod:`ddwmmr.plants.thesis`)
simulates with them, the physics plant can add the same drive damping, and the MPC's
force-level prediction model (:mod:`ddwmmr.model.symbolic`) predicts with them. Keeping them
in the model layer lets controllers use them without importing a plant.
"""

#: Translational damping of the base (N s/m), thesis Table 3.1.
C1_DEFAULT = 15.0
#: Rotational damping of the base (N m s/rad), thesis Table 3.1.
C2_DEFAULT = 4.0
#: Force limit per wheel (N), thesis Table 3.1.
FORCE_LIMIT_DEFAULT = 10.0
#: Maximum joint speed of the arm servo (rad/s), thesis 4.4.2.
JOINT_SPEED_DEFAULT = 2.0
