"""Mass properties of the whole robot: its mass and its yaw inertia about the base centre.

The one home of these formulas; the plants, the symbolic model and the stability margin
read them from here (:attr:`ddwmmr.model.Robot.total_mass`,
:attr:`ddwmmr.model.Robot.yaw_inertia`).

The arm lies horizontally in its plane (docs/theory.md, "Tip-over stability"): each link
is a uniform rod of its mass, the payload a point mass at the end effector, the base a body
of ``base_mass`` (the wheels included) with yaw inertia ``base_inertia`` about the base
centre (the axle midpoint, where the shoulder is mounted). About that vertical axis::

    I(th2) = base_inertia + m1 L1^2 / 12 + m2 L2^2 / 12           (own inertias)
             + m1 (L1 / 2)^2 + m2 d2(th2)^2 + mp de(th2)^2          (parallel axis)
    d2^2 = L1^2 + L2^2 / 4 + L1 L2 cos th2                          (link 2's midpoint)
    de^2 = L1^2 + L2^2 + 2 L1 L2 cos th2                            (end effector)

which collects to ``I(th2) = fixed + k cos th2`` with ``k = (m2 + 2 mp) L1 L2``. The
shoulder angle does not enter (the arm turns about the axis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any


def total_mass(base_mass: float, m1: float, m2: float, payload: float) -> float:
    """Whole robot's mass (kg): base (wheels included), both links and the payload."""
    return base_mass + m1 + m2 + payload


@dataclass(frozen=True)
class YawInertia:
    """The constants of the yaw inertia ``I(th2)`` about the base centre (kg m^2, m^2, kg).

    Attributes:
        own: pose-independent part before the pose-dependent masses: the base, both
            links about their own centres and link 1's midpoint (kg m^2).
        link2_mass, payload: the masses whose distance depends on th2 (kg).
        link2_fixed, link2_cos: ``d2^2 = link2_fixed + link2_cos cos th2`` (m^2).
        tip_fixed, tip_cos: ``de^2 = tip_fixed + tip_cos cos th2`` (m^2).
        fixed, cos: the collected form ``I = fixed + cos * cos th2`` (kg m^2).
        shoulder, elbow: the arm's levers about the base centre for its own motion
            (kg m^2): link 1 about the shoulder with link 2 and the payload as points at
            the elbow, ``m1 L1^2 / 3 + (m2 + mp) L1^2``; link 2 and the payload about the
            elbow, ``m2 L2^2 / 3 + mp L2^2``.
    """

    own: float
    link2_mass: float
    link2_fixed: float
    link2_cos: float
    payload: float
    tip_fixed: float
    tip_cos: float
    fixed: float
    cos: float
    shoulder: float
    elbow: float

    @classmethod
    def of(cls, robot: Any) -> YawInertia:
        """The constants of a :class:`~ddwmmr.model.Robot`."""
        m1, m2 = robot.link_masses
        mp, L1, L2 = robot.payload, robot.L1, robot.L2
        own = robot.base_inertia + m1 * L1**2 / 12.0 + m2 * L2**2 / 12.0 + m1 * 0.25 * L1**2
        link2_fixed, tip_fixed = L1**2 + 0.25 * L2**2, L1**2 + L2**2
        return cls(
            own=own,
            link2_mass=m2,
            link2_fixed=link2_fixed,
            link2_cos=L1 * L2,
            payload=mp,
            tip_fixed=tip_fixed,
            tip_cos=2.0 * L1 * L2,
            fixed=own + m2 * link2_fixed + mp * tip_fixed,
            cos=(m2 + 2.0 * mp) * L1 * L2,
            shoulder=m1 * L1**2 / 3.0 + (m2 + mp) * L1**2,
            elbow=m2 * L2**2 / 3.0 + mp * L2**2,
        )

    def at(self, th2: float) -> float:
        """``I(th2)`` (kg m^2) at the elbow angle th2 (rad), evaluated per body (the
        squared distances first), as the thesis plant integrates it."""
        c2 = math.cos(th2)
        return (
            self.own
            + self.link2_mass * (self.link2_fixed + self.link2_cos * c2)
            + self.payload * (self.tip_fixed + self.tip_cos * c2)
        )
