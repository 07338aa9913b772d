"""Hard constraints of the QP controller, one module each (see :class:`Limit`)."""

from ddwmmr.qp.limits.base import INF, Limit
from ddwmmr.qp.limits.base_motion import BaseMotionLimit, SpeedBudgetLimit
from ddwmmr.qp.limits.joints import JointLimit
from ddwmmr.qp.limits.obstacles import (
    Circle,
    ObstacleLimit,
    as_circles,
    clearance_and_rate,
    footprint_clearances,
    load_obstacles,
    run_clearance,
)
from ddwmmr.qp.limits.singularity import ShoulderSingularityLimit
from ddwmmr.qp.limits.stability import (
    StabilityLimit,
    exact_stability,
    full_step_is_safe,
    safe_arm_scale,
    stability_terms_gradient,
)
from ddwmmr.qp.limits.wheels import WheelSpeedLimit

__all__ = [
    "INF",
    "BaseMotionLimit",
    "Circle",
    "JointLimit",
    "Limit",
    "ObstacleLimit",
    "ShoulderSingularityLimit",
    "SpeedBudgetLimit",
    "StabilityLimit",
    "WheelSpeedLimit",
    "as_circles",
    "clearance_and_rate",
    "exact_stability",
    "footprint_clearances",
    "full_step_is_safe",
    "load_obstacles",
    "run_clearance",
    "safe_arm_scale",
    "stability_terms_gradient",
]
