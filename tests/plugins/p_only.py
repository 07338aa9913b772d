"""A controller plug-in in one file: task-space P control, no feed-forward."""

import numpy as np

from ddwmmr.controllers import StepInfo, register_controller
from ddwmmr.resolution import kernels


@register_controller("p-only", tasks=("tracking", "waypoints"))
class ProportionalOnly:
    """Task-space P control without feed-forward: qdot = J_aug^-1 [K (Xd - X); 0; 0]."""

    def __init__(self, robot, gain=2.0):
        self.robot, self.gain, self.last = robot, gain, StepInfo()

    @classmethod
    def waypoint_options(cls, run):
        """Options for a scenario run (``run``: a ddwmmr.controllers.WaypointRun)."""
        return {"gain": 1.0}

    def reset(self, trajectory, q0):
        self.last = StepInfo()

    def command(self, t, q, pose_d, velocity_d):
        error = pose_d - self.robot.fk(q)  # world frame, m and rad
        rates = self.gain * error
        u, singular = kernels.ats(self.robot.L1, self.robot.L2, q[2], q[3], q[4], *rates)
        self.last = StepInfo(singular=singular)
        return np.array(u)
