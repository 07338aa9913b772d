"""Soft objectives of the QP controller, one module each (see :class:`Task`)."""

from ddwmmr.qp.tasks.avoidance import Detour, ObstacleSteeringTask
from ddwmmr.qp.tasks.base import Task
from ddwmmr.qp.tasks.heading import HeadingTask
from ddwmmr.qp.tasks.manipulability import (
    ManipulabilityTask,
    eta_squared_gradient,
    manipulability_gradient,
)
from ddwmmr.qp.tasks.posture import PostureTask
from ddwmmr.qp.tasks.regularization import RegularizationTask
from ddwmmr.qp.tasks.tracking import EndEffectorTask, feedback_gains

__all__ = [
    "Detour",
    "EndEffectorTask",
    "HeadingTask",
    "ManipulabilityTask",
    "ObstacleSteeringTask",
    "PostureTask",
    "RegularizationTask",
    "Task",
    "eta_squared_gradient",
    "feedback_gains",
    "manipulability_gradient",
]
