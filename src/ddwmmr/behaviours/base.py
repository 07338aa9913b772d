"""Common inputs and outputs of the high-level behaviours (thesis 4.6.1).

Every behaviour receives the same :class:`Percept` (the robot's state, its metrics, the
current task target and the end-effector hold point) and returns the same
:class:`Proposal` format: what the base should do (drive to a world point, turn to a world
heading, or brake) and the arm joint targets. A behaviour may also return ``None`` when it
is "off" (only obstacle avoidance does). Behaviours never call each other: an arbiter
(``ddwmmr.arbiters``) chooses whose proposal reaches the low-level controllers.

Frames: world frame for positions (m) and headings (rad); the base frame has its x axis
along the heading, origin at the base centre.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Protocol

from ddwmmr.model import Robot, stability

#: Base modes of a proposal.
DRIVE, TURN, BRAKE = "drive", "turn", "brake"
#: Every mode a :class:`Proposal` may have.
PROPOSAL_MODES = (DRIVE, TURN, BRAKE)


@dataclass(slots=True)
class Percept:
    """What every behaviour sees at one control instant; read-only by convention.

    (Not a frozen dataclass: one is built every control step, and a frozen one is several
    times dearer to build; docs/thesis.md, "Speed and scale-out".)

    Attributes:
        t: time (s).
        x, y, phi: base centre (m) and heading (rad), world frame.
        th1, th2: arm joints (rad); v: forward speed (m/s); w: yaw rate (rad/s).
        xe, ye: end effector (m, world).
        x_com, y_com: arm+payload+base centre of mass in the base frame (m).
        s_lon, s_lat, s: stability margins (docs/theory.md, "Tip-over stability"; > 1 is stable).
        eta: normalised manipulability ``|sin th2|``.
        target: current task point for the end effector (m, world), or None when done.
        hold: end-effector position latched when the current arbiter state was entered
            (m, world); behaviours that must keep the end effector still aim the arm there.
    """

    t: float
    x: float
    y: float
    phi: float
    th1: float
    th2: float
    v: float
    w: float
    xe: float
    ye: float
    x_com: float
    y_com: float
    s_lon: float
    s_lat: float
    s: float
    eta: float
    target: tuple[float, float] | None
    hold: tuple[float, float]

    def with_hold(self, hold: tuple[float, float]) -> Percept:
        """A copy with a new hold point."""
        return replace(self, hold=hold)

    def to_base(self, px: float, py: float) -> tuple[float, float]:
        """World point (m) expressed in the base frame (m)."""
        dx, dy = px - self.x, py - self.y
        c, s = math.cos(self.phi), math.sin(self.phi)
        return c * dx + s * dy, -s * dx + c * dy


def sense(
    robot: Robot,
    t: float,
    q: tuple[float, float, float, float, float],
    v: float,
    w: float,
    target: tuple[float, float] | None,
    hold: tuple[float, float] | None = None,
) -> Percept:
    """Build the :class:`Percept` for configuration q (plain floats, called every step).

    ``hold`` defaults to the current end-effector position.
    """
    x, y, phi, th1, th2 = q
    a1 = phi + th1
    a12 = a1 + th2
    xe = x + robot.L1 * math.cos(a1) + robot.L2 * math.cos(a12)
    ye = y + robot.L1 * math.sin(a1) + robot.L2 * math.sin(a12)
    k = robot.com_coefficients
    x_com = k.A * math.cos(th1) + k.B * math.cos(th1 + th2)
    y_com = k.A * math.sin(th1) + k.B * math.sin(th1 + th2)
    s_lon, s_lat, s = stability.margins(k, x_com, y_com)
    return Percept(
        t, x, y, phi, th1, th2, v, w, xe, ye, x_com, y_com, s_lon, s_lat, s,
        abs(math.sin(th2)), target, hold if hold is not None else (xe, ye),
    )  # fmt: skip


@dataclass(slots=True)
class Proposal:
    """The common output of every behaviour; read-only by convention (see Percept).

    Attributes:
        mode: ``"drive"`` to the world point (bx, by), ``"turn"`` in place to the world
            heading ``heading``, or ``"brake"``.
        bx, by: drive target (m, world); heading: turn target (rad, world).
        arm: joint targets ``(th1, th2)`` (rad).
        label: behaviour-specific sub-state (the objective says ``"base"`` or ``"arm"``).
    """

    mode: str
    arm: tuple[float, float]
    bx: float = 0.0
    by: float = 0.0
    heading: float = 0.0
    label: str = ""


class Behaviour(Protocol):
    """Structural type of a high-level behaviour."""

    name: str

    def propose(self, p: Percept) -> Proposal | None:  # pragma: no cover - protocol
        """The behaviour's proposal for percept p (None when the behaviour is off)."""
        ...


def elbow_of(th2: float) -> int:
    """Elbow branch (+1 / -1) of the current pose; kept so IK solutions do not flip."""
    return 1 if th2 >= 0.0 else -1


def reach_toward(robot: Robot, p: Percept, px: float, py: float) -> tuple[float, float]:
    """Joint targets putting the end effector at world point (px, py), or as near as possible.

    Uses the analytic two-link IK (``Robot.arm_ik``) in the base frame on the current
    elbow branch; a point out of the annulus ``|L1-L2| <= r <= L1+L2`` is replaced by the
    nearest point of the annulus on the same bearing.
    """
    dx, dy = p.to_base(px, py)
    r = math.hypot(dx, dy)
    inner, outer = abs(robot.L1 - robot.L2) + 1e-6, robot.reach - 1e-9
    if r < inner or r > outer:
        if r == 0.0:
            dx, dy, r = 1.0, 0.0, 1.0
        scale = min(max(r, inner), outer) / r
        dx, dy = dx * scale, dy * scale
    solution = robot.arm_ik(dx, dy, elbow_of(p.th2))
    assert solution is not None  # inside the annulus by construction
    return solution
