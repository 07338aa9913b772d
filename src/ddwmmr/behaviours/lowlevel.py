"""Low-level controllers (thesis 4.4): PD base movement, brake, wheel-force mixer, arm mover.

Base movement (thesis 4.4.1, Table 4.2). For a drive target at base-frame offset
``(lx, ly)`` the translation error is the signed distance along the heading ``e_t = lx``
(negative: drive backwards, the thesis treats reversing as equal) and the rotation error is
``alpha = atan(ly / lx)`` in [-90, 90] deg (the heading, or its reverse, toward the
target). Then::

    F_t = P_t e_t - D_t v          (N;  P_t = 8 N/m)
    F_r = P_r alpha - D_r w        (N;  P_r = 0.6 N/deg, alpha and w in degrees)
    F_left = F_t/2 - F_r/2,  F_right = F_t/2 + F_r/2        (thesis eqs 4.8, 4.9)

Units and the derivative gains are our reading of Table 4.2, which gives no units: the
rotation error is in degrees (the thesis's code works in degrees; in radians the base could
not turn faster than 0.08 rad/s), and the derivative gains act on the per-sample error
difference of a discrete PD with the thesis's 0.01 s sample time, i.e. ``D_t = 150 x 0.01 =
1.5 N s/m``, ``D_r = 1 x 0.01 N s/deg``. Only that reading meets the thesis's stated design
criterion (rise time about 3 s for small errors, no overshoot): with D = 150 N s/m
the translation loop would have a 20 s time constant. The derivative acts on the measured
velocity (no kick when a behaviour moves the target). The brake (P 100) drives v (m/s) and
w (rad/s) to zero; its D term (1 x 0.01 s) is negligible and omitted.

Mixer: each wheel is limited to +-10 N; rotation has priority (|F_r| <= 20 N, then
|F_t| <= 20 N - |F_r|) so a saturated translation cannot remove steering authority.

Arm mover (thesis 4.4.2): passes the selected joint targets, clamped to the joint limits,
to the arm servo (the plant's pseudo-controller, eq. 4.10).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ddwmmr.behaviours.base import BRAKE, DRIVE, TURN, Percept, Proposal
from ddwmmr.errors import shown
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import wrap_angle
from ddwmmr.model.robot import clamp_joints

_DEG = 180.0 / math.pi


@dataclass(frozen=True)
class PDGains:
    """Thesis Table 4.2 gains and the sample time the derivative gains refer to (s)."""

    translation_p: float = 8.0
    translation_d: float = 150.0
    rotation_p: float = 0.6
    rotation_d: float = 1.0
    brake_p: float = 100.0
    brake_d: float = 1.0
    sample_time: float = 0.01


class BaseMover:
    """PD base movement and brake controllers with the wheel-force mixer (thesis 4.4.1)."""

    def __init__(self, gains: PDGains | None = None, force_limit: float = 10.0) -> None:
        self.gains = gains if gains is not None else PDGains()
        g = self.gains
        self._dt_gain = g.translation_d * g.sample_time  # N s/m
        self._dr_gain = g.rotation_d * g.sample_time  # N s/deg
        self.force_limit = force_limit

    def mix(self, f_t: float, f_r: float) -> tuple[float, float]:
        """Left/right wheel forces (N) from translation and rotation forces, rotation first."""
        total = 2.0 * self.force_limit
        f_r = min(total, max(-total, f_r))
        room = total - abs(f_r)
        f_t = min(room, max(-room, f_t))
        return 0.5 * f_t - 0.5 * f_r, 0.5 * f_t + 0.5 * f_r

    def drive_forces(self, p: Percept, tx: float, ty: float) -> tuple[float, float]:
        """Translation and rotation forces (N) toward world point (tx, ty)."""
        g = self.gains
        lx, ly = p.to_base(tx, ty)
        if abs(lx) < 1e-9 and abs(ly) < 1e-9:
            alpha = 0.0
        else:
            alpha = math.atan2(ly, lx)
            if lx < 0.0:  # target behind: point the rear at it and reverse
                alpha = wrap_angle(alpha + math.pi)
        f_t = g.translation_p * lx - self._dt_gain * p.v
        f_r = g.rotation_p * alpha * _DEG - self._dr_gain * p.w * _DEG
        return f_t, f_r

    def turn_forces(self, p: Percept, heading: float) -> tuple[float, float]:
        """Forces (N) turning in place to world heading (rad), braking any translation."""
        g = self.gains
        alpha = wrap_angle(heading - p.phi)
        return -g.brake_p * p.v, g.rotation_p * alpha * _DEG - self._dr_gain * p.w * _DEG

    def brake_forces(self, p: Percept) -> tuple[float, float]:
        """Forces (N) bringing v and w to zero."""
        return -self.gains.brake_p * p.v, -self.gains.brake_p * p.w

    def wheel_forces(self, p: Percept, proposal: Proposal) -> tuple[float, float]:
        """Left/right wheel forces (N) executing the proposal's base part."""
        if proposal.mode == DRIVE:
            f_t, f_r = self.drive_forces(p, proposal.bx, proposal.by)
        elif proposal.mode == TURN:
            f_t, f_r = self.turn_forces(p, proposal.heading)
        elif proposal.mode == BRAKE:
            f_t, f_r = self.brake_forces(p)
        else:
            raise ValueError(f"unknown base mode {shown(proposal.mode)}")
        return self.mix(f_t, f_r)


class ArmMover:
    """Joint targets for the arm servo, clamped to the joint limits (rad)."""

    def __init__(self, robot: Robot) -> None:
        self.limits = robot.joint_limits

    def targets(self, proposal: Proposal) -> tuple[float, float]:
        """The proposal's joint targets (rad) within the joint limits
        (:func:`~ddwmmr.model.robot.clamp_joints`)."""
        a1, a2 = proposal.arm
        return clamp_joints(a1, a2, self.limits)
