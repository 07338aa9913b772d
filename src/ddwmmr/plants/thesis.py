"""The thesis plant: force-driven differential-drive base plus a rate-limited arm servo.

Base (thesis eqs 3.1-3.4, SPEC §5), along the base heading (robot frame R) and about z::

    m xddot_R + c1 xdot_R = F,      F = F1 + F2                (N, m/s)
    I thddot  + c2 thdot  = T,      T = (F2 - F1) width / 2    (N m, rad/s)

``F1``/``F2`` are the left/right wheel forces (N), each clipped to ``+-force_limit``. ``m``
is the whole robot's mass (base + links + payload) and ``I`` its yaw inertia about the base
centre, which depends on the arm pose (links as uniform rods, payload as a point mass at
the end effector, thesis 3.4). The forces are held constant over a step (zero-order hold)
and the two linear first-order equations are integrated *exactly* over it, so the step
size only affects how often the controller acts, not the accuracy of the base motion.
The travelled distance is applied along the mean heading of the step (thesis eqs 3.5-3.7).

Arm: the thesis's pseudo-controller (4.4.2, eqs 4.10-4.11). Given joint targets, the joint
with the largest error moves at ``joint_speed`` (2 rad/s) and every other joint at the
speed scaled by its error / the largest error, so all joints arrive together; a joint never
passes its target. The plant knows nothing about controllers: it receives wheel forces and
joint targets from a simulation loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ddwmmr.errors import check_positive
from ddwmmr.model import Robot

#: Thesis Table 3.1 damping constants: translation (N s/m) and rotation (N m s/rad).
C1_DEFAULT = 15.0
C2_DEFAULT = 4.0
#: Thesis Table 3.1 force limit per wheel (N).
FORCE_LIMIT_DEFAULT = 10.0
#: Thesis 4.4.2 maximum joint speed (rad/s).
JOINT_SPEED_DEFAULT = 2.0


@dataclass(slots=True)
class ThesisState:
    """Plant state: configuration ``q`` (world frame) and base velocities.

    Attributes:
        x, y: base centre (m, world); phi: heading (rad); th1, th2: joints (rad).
        v: forward speed along the heading (m/s); w: yaw rate (rad/s).
    """

    x: float = 0.0
    y: float = 0.0
    phi: float = 0.0
    th1: float = 0.0
    th2: float = 0.0
    v: float = 0.0
    w: float = 0.0

    @property
    def q(self) -> tuple[float, float, float, float, float]:
        """Configuration ``(x, y, phi, th1, th2)``."""
        return (self.x, self.y, self.phi, self.th1, self.th2)

    def copy(self) -> ThesisState:
        """An independent copy."""
        return ThesisState(self.x, self.y, self.phi, self.th1, self.th2, self.v, self.w)


def first_order_step(
    x0: float, u: float, gain: float, tau: float, dt: float
) -> tuple[float, float]:
    """Exact step of ``tau xdot + x = gain u`` with u held over dt.

    Returns ``(x(dt), integral of x over [0, dt])``; used for v (integral: distance) and w
    (integral: heading change).
    """
    x_ss = gain * u
    decay = math.exp(-dt / tau)
    return x_ss + (x0 - x_ss) * decay, x_ss * dt + (x0 - x_ss) * tau * (1.0 - decay)


def arm_step(
    th1: float, th2: float, target1: float, target2: float, speed: float, dt: float
) -> tuple[float, float]:
    """Joint angles after dt under the pseudo-controller of thesis eq. 4.10 (rad).

    Each joint moves by ``error_i * min(1, speed dt / max|error|)``: the largest error moves
    at ``speed`` and the joints stay synchronised; the target is never overshot.
    """
    e1, e2 = target1 - th1, target2 - th2
    largest = max(abs(e1), abs(e2))
    if largest == 0.0:
        return th1, th2
    fraction = min(1.0, speed * dt / largest)
    return th1 + e1 * fraction, th2 + e2 * fraction


class ThesisPlant:
    """Force-driven base dynamics with the arm pseudo-controller (thesis ch. 3 and 4.4.2).

    Args:
        robot: geometry and masses (``Robot().with_payload(3.0)`` in the benchmark).
        c1: translational damping (N s/m); c2: rotational damping (N m s/rad).
        force_limit: per-wheel force limit (N).
        joint_speed: maximum joint speed of the arm servo (rad/s).
    """

    def __init__(
        self,
        robot: Robot,
        c1: float = C1_DEFAULT,
        c2: float = C2_DEFAULT,
        force_limit: float = FORCE_LIMIT_DEFAULT,
        joint_speed: float = JOINT_SPEED_DEFAULT,
    ) -> None:
        self.robot = robot
        self.c1 = check_positive("c1", c1)
        self.c2 = check_positive("c2", c2)
        self.force_limit = check_positive("force_limit", force_limit)
        self.joint_speed = check_positive("joint_speed", joint_speed)
        m1, m2 = robot.link_masses
        self.mass = robot.base_mass + m1 + m2 + robot.payload
        # Pose-independent part of the yaw inertia: base plus each link about its own centre.
        self._inertia_fixed = robot.base_inertia + (m1 * robot.L1**2 + m2 * robot.L2**2) / 12.0
        self._half_width = 0.5 * robot.base_width

    def inertia(self, th1: float, th2: float) -> float:
        """Yaw inertia of the whole robot about the base centre at arm pose (th1, th2) (kg m^2).

        Links are uniform rods (parallel-axis term at their midpoints), the payload a point
        mass at the end effector; the arm lies horizontally (SPEC §1).
        """
        r = self.robot
        m1, m2 = r.link_masses
        c2 = math.cos(th2)
        # squared distances from the base centre of link-2 midpoint and end effector
        mid2 = r.L1**2 + 0.25 * r.L2**2 + r.L1 * r.L2 * c2
        tip = r.L1**2 + r.L2**2 + 2.0 * r.L1 * r.L2 * c2
        return self._inertia_fixed + m1 * 0.25 * r.L1**2 + m2 * mid2 + r.payload * tip

    def velocity_envelope(self, fraction: float = 0.8) -> dict[str, float]:
        """What a velocity command can ask of this base, as ``fraction`` of the physics.

        Top speeds where the full force balances damping (``2 F / c1`` m/s,
        ``2 F (width/2) / c2`` rad/s) and accelerations from rest with the largest yaw
        inertia (arm stretched). Keys match the ``qp`` controller's options.
        """
        total = 2.0 * self.force_limit
        torque = total * self._half_width
        stretched = self.inertia(0.0, 0.0)
        return {
            "max_base_speed": fraction * total / self.c1,
            "max_yaw_rate": fraction * torque / self.c2,
            "max_acceleration": fraction * total / self.mass,
            "max_yaw_acceleration": fraction * torque / stretched,
        }

    def clip_force(self, force: float) -> float:
        """A wheel force limited to ``+-force_limit`` (N)."""
        return min(self.force_limit, max(-self.force_limit, force))

    def step(
        self,
        state: ThesisState,
        f_left: float,
        f_right: float,
        arm_target: tuple[float, float],
        dt: float,
    ) -> None:
        """Advance ``state`` in place by dt (s) under wheel forces (N) and joint targets (rad).

        The inertia is evaluated at the arm pose at the start of the step.
        """
        f1 = self.clip_force(f_left)
        f2 = self.clip_force(f_right)
        inertia = self.inertia(state.th1, state.th2)
        v, distance = first_order_step(state.v, f1 + f2, 1.0 / self.c1, self.mass / self.c1, dt)
        torque = (f2 - f1) * self._half_width
        w, turn = first_order_step(state.w, torque, 1.0 / self.c2, inertia / self.c2, dt)
        heading = state.phi + 0.5 * turn  # mean heading over the step (thesis eq. 3.5)
        state.x += distance * math.cos(heading)
        state.y += distance * math.sin(heading)
        state.phi += turn
        state.v, state.w = v, w
        state.th1, state.th2 = arm_step(
            state.th1, state.th2, arm_target[0], arm_target[1], self.joint_speed, dt
        )
