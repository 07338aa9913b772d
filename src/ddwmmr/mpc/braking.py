"""The braking step: what the force-level mpc sends when its plan cannot meet its own
stability rows.

On a physics plant a plan that needs the rows' slack is one the model itself predicts to
cross the dynamic floor; its first input is then the least bad of a bad plan, and on the
MuJoCo plant that was what tipped the robot (full-force spins on a light wheel, every plan
needing slack for 50 ms before the tip; docs/mpc.md, "The physics plant: tipping while
moving"). The braking step instead sheds the motion that moves the centre of pressure:
the base's speed and turn decay together with one time constant, within the wheel force
limit, and each joint slows within its acceleration limit.
"""

from __future__ import annotations

import math

import numpy as np

from ddwmmr.model import symbolic as sym

#: Time constant (s) with which the braking step asks the base to shed v and w.
BRAKE_TIME = 0.5
#: Default ``brake_slack`` (m) where the lagged arm has a joint acceleration limit (a
#: physics plant): a plan whose stability rows' largest slack (m,
#: ``ShootingOCP.max_stability_slack``) exceeds it is replaced by the braking step.
BRAKE_SLACK = 5e-3
#: Below this speed (m/s, rad/s: base speed, yaw rate, joint rates) the robot is at rest
#: and the braking step is not taken.
AT_REST = 0.05


def should_brake(
    brake_slack: float | None,
    stability_slack: float,
    velocity: tuple[float, float],
    joint_rates: tuple[float, float],
) -> bool:
    """Whether the step brakes: braking is on (``brake_slack`` m, None: off), the plan's
    stability rows need more slack than that, and the robot moves (base ``velocity`` m/s,
    rad/s or the lagged ``joint_rates`` rad/s faster than :data:`AT_REST`): at rest there
    is nothing to brake, and a plan that needs slack there (a pose at the floor) must be
    let move the arm back."""
    if brake_slack is None or not stability_slack > brake_slack:
        return False
    speed = max(abs(velocity[0]), abs(velocity[1]), abs(joint_rates[0]), abs(joint_rates[1]))
    return speed > AT_REST


def braked_velocity(
    dynamics: sym.ThesisDynamics,
    state: np.ndarray,
    forces: tuple[float, float] | np.ndarray,
    dt: float,
) -> tuple[float, float]:
    """``(v, w)`` (m/s, rad/s) ``dt`` (s) after the braking ``forces`` (N) from the force
    model's ``state`` ``[q, v, w]`` (one Euler step; the joints held)."""
    rate = np.asarray(dynamics.rhs(state, np.r_[forces, 0.0, 0.0]), dtype=float).ravel()
    return float(state[5] + dt * rate[5]), float(state[6] + dt * rate[6])


def braking_input(
    dynamics: sym.ThesisDynamics,
    th2: float,
    velocity: tuple[float, float],
    joint_rates: tuple[float, float],
    acceleration_limit: tuple[float, float],
    arm_time_constant: float,
    brake_time: float = BRAKE_TIME,
) -> np.ndarray:
    """The force model's input ``(F_left, F_right, th1dot, th2dot)`` (N, N, rad/s, rad/s)
    that brakes base and arm.

    Args:
        dynamics: the force-level model (mass, yaw inertia, damping, lever, force limit).
        th2: elbow angle (rad); the yaw inertia depends on it.
        velocity: the base's ``(v, w)`` (m/s, rad/s), measured (or the controller's own
            prediction when the loop gives none).
        joint_rates: the lagged joints' present rates (rad/s).
        acceleration_limit: the joints' acceleration limits (rad/s^2).
        arm_time_constant: the joints' lag (s).
        brake_time: time constant (s) of the base's braking.

    The wheel forces ask for ``vdot = -v / brake_time`` and ``wdot = -w / brake_time``
    with the damping compensated, scaled down together (so the base decelerates along its
    present motion) until neither wheel exceeds the force limit. The arm's reaction on the
    yaw while it brakes is not compensated: the physics plant turns the base by it, so
    ``w`` decays only roughly with ``brake_time`` while the joints slow. Each joint rate
    command leads its rate down by ``a tau`` (the lag then decelerates it at ``a`` at the
    start of the step, less as the command is held:
    :meth:`ddwmmr.mpc.models.LaggedArmPrediction.stopping_configuration`), or to zero when
    it is slower than that.
    """
    v, w = velocity
    inertia = float(dynamics.inertia(th2))
    push = dynamics.c1 * v - dynamics.mass * v / brake_time  # F_left + F_right, N
    turn = (dynamics.c2 * w - inertia * w / brake_time) / dynamics.half_width  # F_r - F_l
    left, right = 0.5 * (push - turn), 0.5 * (push + turn)
    excess = max(abs(left), abs(right)) / dynamics.force_limit
    if excess > 1.0:
        left, right = left / excess, right / excess
    rates = [
        rate - math.copysign(min(abs(rate), limit * arm_time_constant), rate)
        for rate, limit in zip(joint_rates, acceleration_limit)
    ]
    return np.array([left, right, *rates])
