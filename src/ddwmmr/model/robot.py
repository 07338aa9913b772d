"""The robot description: :class:`Robot`, a validated frozen dataclass.

``Robot()`` is the thesis robot (thesis Tables 3.1/3.2, planar arm; docs/theory.md, "Model").
Units are SI throughout: metres, kilograms, radians, seconds.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from ddwmmr.errors import (
    INERTIA_RANGE_KG_M2,
    LENGTH_RANGE_M,
    MASS_RANGE_KG,
    MAX_ANGLE_RAD,
    SPEED_RANGE_RAD_S,
    TORQUE_RANGE_N_M,
    ParameterError,
    bracketed,
    check_finite,
    check_positive,
    check_range,
    did_you_mean,
    list_items,
    load_toml,
    shown,
    texts_apart,
    unwrapped,
    xy_pairs,
)
from ddwmmr.model import kinematics, stability, support_loads
from ddwmmr.model.mass import YawInertia, total_mass
from ddwmmr.model.stability import ComCoefficients
from ddwmmr.user_warnings import warn_user

if TYPE_CHECKING:
    from collections.abc import Sequence

_PI = math.pi
#: Allowed range (low, high, unit) of each scalar field; see ddwmmr.errors for the caps.
_LENGTH, _MASS = (*LENGTH_RANGE_M, "m"), (*MASS_RANGE_KG, "kg")
_SPEED = (*SPEED_RANGE_RAD_S, "rad/s")
_RANGES = {
    "L1": _LENGTH,
    "L2": _LENGTH,
    "wheel_radius": _LENGTH,
    "track_width": _LENGTH,
    "base_length": _LENGTH,
    "base_width": _LENGTH,
    "base_mass": _MASS,
    "base_inertia": (*INERTIA_RANGE_KG_M2, "kg m^2"),
    "joint_speed_limit": _SPEED,
    "wheel_speed_limit": _SPEED,
    "wheel_mass": _MASS,
    "base_height": _LENGTH,
    "arm_height": _LENGTH,
    "wheel_torque_limit": (*TORQUE_RANGE_N_M, "N m"),
    "payload": _MASS,
}
#: Scalar fields that must be > 0 (every ranged one but the payload, which may be 0).
_POSITIVE = tuple(name for name in _RANGES if name != "payload")


def _open_below(name: str) -> bool:
    """Whether the scalar field ``name`` must be above its range's low end, not at it: a
    field that must be > 0 (:data:`_POSITIVE`) whose range starts at 0 (a mass)."""
    return name in _POSITIVE and _RANGES[name][0] <= 0


def _allowed(name: str) -> str:
    """The whole allowed range of the scalar field ``name``, as the messages give it:
    ``in [1e-06, 1000] m``, or ``in (0, 100000] kg`` for a mass that must be > 0."""
    low, high, unit = _RANGES[name]
    return f"in {'(' if _open_below(name) else '['}{low:g}, {high:g}] {unit}"


def _check_scalar(name: str, value: Any) -> float:
    """``value`` as a float if it is in the allowed range of the scalar field ``name``
    (:data:`_RANGES`; > 0 for the fields of :data:`_POSITIVE`), else a one-line
    :class:`ParameterError` naming the field and that whole range."""
    low, high, _ = _RANGES[name]
    allowed = _allowed(name)
    number = check_finite(name, value, allowed)
    above_low = low < number if _open_below(name) else low <= number
    if not (above_low and number <= high):
        raise ParameterError(f"{name} must be {allowed} (got {number:g})")
    return number


#: Largest distance of a caster from the base centre, in footprint half-diagonals
#: ``hypot(base_length, base_width) / 2``: 1 reaches the corners, 2 allows outriggers.
CASTER_REACH = 2.0
#: Top-level tables a robot TOML may hold: its fields, at the top or under ``[robot]``.
TOML_TABLES = ("robot",)
#: Largest length (m) taken without a warning: a mobile manipulator's links, wheels and
#: base are well below it, a length written in millimetres (a 350 mm link as 350) far above.
#: Lengths up to LENGTH_RANGE_M's top are accepted all the same: a giant robot may be meant.
PLAUSIBLE_LENGTH_M = 10.0
#: Largest |angle| (rad) of a joint limit or home angle taken without a warning: one turn.
#: Beyond it the angles were most likely written in degrees (180 for pi).
PLAUSIBLE_ANGLE_RAD = 2.0 * _PI
#: The scalar fields that are lengths (m).
_LENGTHS = tuple(name for name, (_, _, unit) in _RANGES.items() if unit == "m")
#: What the configuration ``q`` and its rate ``qdot`` hold (for messages).
_Q_ENTRIES = {"q": "[x, y, phi, th1, th2] (m, rad)", "qdot": "(m/s, rad/s)"}
_isfinite = math.isfinite
_MAX_Q_ANGLE = kinematics.MAX_CONFIGURATION_ANGLE_RAD


def clamp_joints(
    th1: float, th2: float, limits: tuple[tuple[float, float], tuple[float, float]]
) -> tuple[float, float]:
    """Joint angles (th1, th2) (rad) clamped to ``limits``, a robot's ``joint_limits``
    ``((th1_min, th1_max), (th2_min, th2_max))`` (rad): an angle below its range becomes the
    minimum, one above it the maximum, one within it (its ends included) stays as it is.
    The one joint clamp of the plants and the arm mover.

    A NaN angle is returned as NaN, not turned into a limit, so that the callers' checks
    of a non-finite state or command still see it.
    """
    (low1, high1), (low2, high2) = limits
    th1 = low1 if th1 < low1 else (high1 if th1 > high1 else th1)
    th2 = low2 if th2 < low2 else (high2 if th2 > high2 else th2)
    return th1, th2


@dataclass(frozen=True)
class Robot:
    """Planar differential-drive mobile manipulator with a two-link arm.

    Attributes:
        L1, L2: arm link lengths (m).
        wheel_radius: drive wheel radius r (m).
        track_width: distance between the wheels Lw (m).
        base_length, base_width: rectangular footprint, centred on the axle midpoint (m).
        base_mass: base mass (kg); base_inertia: base yaw inertia (kg m^2).
        link_masses: masses of link 1 and link 2 (kg), each concentrated at its midpoint.
        payload: payload mass at the end effector (kg).
        joint_limits: ``((th1_min, th1_max), (th2_min, th2_max))`` (rad); angles are
            clamped to them by :func:`clamp_joints`.
        joint_speed_limit: maximum |th1dot|, |th2dot| (rad/s).
        wheel_speed_limit: maximum wheel angular speed (rad/s).
        home_pose: default arm pose ``(th1, th2)`` (rad) used for start configurations;
            each angle within its ``joint_limits`` range.

    Physical fields, used by the physics plant (:class:`ddwmmr.plants.MujocoPlant`, see
    docs/physics.md) and ignored by the kinematic and thesis plants, but for the casters,
    whose support polygon the stability margin S is measured on everywhere:

    Attributes:
        caster_positions: base-frame contact points ``((x, y), ...)`` (m) of the passive,
            frictionless casters. ``None`` (default) puts one at each footprint corner
            ``(+-base_length/2, +-base_width/2)`` (see :attr:`casters`). The convex hull of
            the wheels' and casters' contact points is the support polygon, on which S is
            measured (docs/theory.md, "Tip-over stability"): with the default casters and
            the wheels within the footprint (``track_width <= base_width``) it is the
            footprint. It must hold the base centre (the axle midpoint) strictly inside,
            and each point must lie within :data:`CASTER_REACH` times the footprint's
            half-diagonal of the base centre: casters sit on the base or on short
            outriggers (twice the half-diagonal is 0.57 m for the thesis base), not metres
            away.
        wheel_mass: mass of each drive wheel (kg), part of ``base_mass`` (so the total
            mass and S are unchanged); ``2 wheel_mass < base_mass``.
        base_height: height of the base box (m); sets its roll/pitch inertia.
        arm_height: height of the arm's horizontal plane above the floor (m); the height
            of the links' and payload's masses, which matters for dynamic tipping only.
        wheel_torque_limit: peak torque of each wheel motor (N m).
        joint_torque_limits: peak torques of the shoulder and elbow motors (N m).
    """

    L1: float = 0.35
    L2: float = 0.30
    wheel_radius: float = 0.0975
    track_width: float = 0.35
    base_length: float = 0.45
    base_width: float = 0.35
    base_mass: float = 10.0
    base_inertia: float = 0.5
    link_masses: tuple[float, float] = (1.0, 1.0)
    payload: float = 1.25
    joint_limits: tuple[tuple[float, float], tuple[float, float]] = ((-_PI, _PI), (-_PI, _PI))
    joint_speed_limit: float = 2.0
    wheel_speed_limit: float = 15.0
    home_pose: tuple[float, float] = (-0.3, 0.6)
    caster_positions: tuple[tuple[float, float], ...] | None = None
    wheel_mass: float = 0.5
    base_height: float = 0.2
    arm_height: float = 0.35
    wheel_torque_limit: float = 2.0
    joint_torque_limits: tuple[float, float] = (20.0, 10.0)
    _com: ComCoefficients = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in _RANGES:
            object.__setattr__(self, name, _check_scalar(name, getattr(self, name)))
        masses = _pair("link_masses", self.link_masses, "kg")
        for i, m in enumerate(masses, start=1):
            check_range(f"link_masses[{i}]", m, *MASS_RANGE_KG, "kg")
        object.__setattr__(self, "link_masses", masses)
        limits = []
        for i, pair in enumerate(_pairs("joint_limits", self.joint_limits), start=1):
            low, high = (check_finite(f"joint_limits[{i}]", v) for v in pair)
            if not low < high:
                raise ParameterError(f"joint_limits[{i}] must satisfy min < max (got {pair})")
            limits.append((low, high))
        object.__setattr__(self, "joint_limits", tuple(limits))
        home = _pair("home_pose", self.home_pose, "rad")
        for i, (angle, (low, high)) in enumerate(zip(home, limits), start=1):
            try:
                check_range(f"home_pose[{i}]", angle, low, high, f"rad (joint_limits[{i}])")
            except ParameterError as exc:
                raise ParameterError(f"{exc}{_degrees_hint(angle)}") from None
        object.__setattr__(self, "home_pose", home)
        if not 2.0 * self.wheel_mass < self.base_mass:
            raise ParameterError(
                f"wheel_mass must be < base_mass / 2 = {self.base_mass / 2:g} kg (the wheels "
                f"are part of the base) (got {self.wheel_mass:g})"
            )
        torques = _pair("joint_torque_limits", self.joint_torque_limits, "N m")
        for i, torque in enumerate(torques, start=1):
            check_range(f"joint_torque_limits[{i}]", torque, *TORQUE_RANGE_N_M, "N m")
        object.__setattr__(self, "joint_torque_limits", torques)
        if self.caster_positions is not None:
            object.__setattr__(
                self, "caster_positions", xy_pairs("caster_positions", self.caster_positions)
            )
        self._check_magnitudes()
        object.__setattr__(
            self,
            "_com",
            stability.com_coefficients(
                self.L1,
                self.L2,
                masses[0],
                masses[1],
                self.payload,
                self.base_mass,
                self.base_length,
                self.base_width,
                self._support_edges(),
            ),
        )

    def _support_edges(self) -> stability.SupportEdges:
        """The edges of the wheels' and casters' support polygon, on which S is measured;
        :class:`ParameterError` (one line, naming ``caster_positions``) when it does not
        hold the base centre strictly inside (docs/theory.md, "Tip-over stability")."""
        points = support_loads.support_points(self)
        edges = _edges_of_points(points)
        if edges is None:
            raise ParameterError(
                "caster_positions: the base centre must lie strictly inside the support "
                "polygon of the wheels and casters, not on an edge (the stability margin S "
                "measures the centre of mass's offset from it) (got casters "
                f"{shown(self.casters, 80)}): put casters on both sides of the wheel axle "
                "(x > 0 and x < 0)"
            )
        return edges

    def _check_magnitudes(self) -> None:
        """Documented physical ranges (ddwmmr.errors) of the joint limits and casters (the
        scalar fields, link masses and torque limits are checked against theirs first):
        ``joint_limits`` of 1e300 would only overflow later."""
        for i, pair in enumerate(self.joint_limits, start=1):
            for value in pair:
                check_range(f"joint_limits[{i}]", value, -MAX_ANGLE_RAD, MAX_ANGLE_RAD, "rad")
        if self.caster_positions is not None:
            reach = CASTER_REACH * 0.5 * math.hypot(self.base_length, self.base_width)
            for i, (x, y) in enumerate(self.caster_positions, start=1):
                if not math.hypot(x, y) <= reach:
                    raise ParameterError(
                        f"caster_positions[{i}] must lie within {reach:g} m of the base centre "
                        f"({CASTER_REACH:g} x the footprint's half-diagonal) (got ({x:g}, {y:g}))"
                    )

    # -- construction -------------------------------------------------------------------
    @classmethod
    def from_toml(cls, path: str | Path) -> Robot:
        """Load a robot from a TOML file whose keys are the field names (missing = default).

        The fields are either all top-level keys or all in one ``[robot]`` table; with a
        ``[robot]`` table nothing else may be in the file (another table, ``[other]``, or
        a key outside ``[robot]`` is an error naming it), as unknown keys are: the file is
        read as :meth:`from_dict` reads a mapping, each message naming the file, and so
        are the warnings on values in a likely wrong unit (:func:`unit_doubts`).
        """
        data = load_toml(path, "robot")
        try:
            robot = cls._from_mapping(data)
        except ParameterError as exc:
            raise ParameterError(f"robot: {path}: {str(exc).removeprefix('robot: ')}") from None
        _warn_unit_doubts(robot, f"robot: {path}")
        return robot

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Robot:
        """Build a robot from a mapping of field names to values (a TOML table, a JSON
        record), missing fields taking their defaults.

        The fields are either all top-level keys or all under one ``"robot"`` key (a
        ``[robot]`` table); beside it nothing else may be in the mapping. Unknown keys and
        values of the wrong type (``L1 = "0.3"``, ``L1 = true``, a number where a pair is
        expected) are errors naming the key, each one line (:class:`ParameterError`).
        Values valid but most likely in the wrong unit (millimetres, degrees) are taken
        as given after a one-line :class:`UserWarning` each (:func:`unit_doubts`).
        """
        robot = cls._from_mapping(data)
        _warn_unit_doubts(robot, "robot")
        return robot

    @classmethod
    def _from_mapping(cls, data: dict[str, Any]) -> Robot:
        """:meth:`from_dict` without the unit warnings (the callers word them)."""
        if not isinstance(data, dict):
            raise ParameterError(f"robot: expected a table of Robot fields (got {shown(data)})")
        if "robot" in data:
            for key, value in data.items():
                if key in TOML_TABLES:
                    continue
                what = f"table [{key}]" if isinstance(value, dict | list) else f"key {shown(key)}"
                raise ParameterError(
                    f"robot: unknown {what} (Robot fields go at the top or all under one "
                    "[robot] table)"
                )
            data = data["robot"]
            if not isinstance(data, dict):
                got = "an array of tables [[robot]]" if isinstance(data, list) else shown(data)
                raise ParameterError(
                    f"robot: [robot] must be one table of Robot fields (got {got})"
                )
        known = {f.name: f for f in fields(cls) if f.init}
        unknown = sorted(set(data) - set(known), key=str)
        if unknown:
            raise ParameterError(
                f"robot: unknown parameter {shown(unknown[0])}"
                f"{did_you_mean(str(unknown[0]), known)} (known: {', '.join(sorted(known))})"
            )
        for key, value in data.items():
            _check_field_type(key, value, known[key].default)
        return cls(**data)

    def with_payload(self, payload: float) -> Robot:
        """A copy of this robot carrying ``payload`` kg at the end effector."""
        return replace(self, payload=payload)

    def in_length_unit(self, unit: float) -> Robot:
        """This robot with every length (m: the scalar lengths and ``caster_positions``)
        divided by ``unit`` (m, > 0), masses, inertias and limits kept: the robot as a
        computation measuring lengths in ``unit`` sees it (only the masses' ratios place
        the centre of mass); this robot itself for a unit of 1.0. A length that leaves
        ``LENGTH_RANGE_M`` once divided is a one-line :class:`ParameterError` naming it as
        given (m), not its quotient: the lengths too far apart for one unit. A ``unit``
        that is not a finite number > 0 is one naming ``unit``."""
        unit = check_positive("unit", unit)
        if unit == 1.0:
            return self
        lengths = {name: getattr(self, name) / unit for name in _LENGTHS}
        low, high = LENGTH_RANGE_M
        for name, scaled in lengths.items():
            if not low <= scaled <= high:
                raise ParameterError(
                    f"robot: {name} = {getattr(self, name):g} m is {scaled:g} length units of "
                    f"{unit:g} m; in that unit lengths must be in [{low:g}, {high:g}] (from "
                    f"{low * unit:g} to {high * unit:g} m): the robot's lengths are too far "
                    "apart in proportion"
                )
        casters = self.caster_positions
        if casters is not None:
            casters = tuple((x / unit, y / unit) for x, y in casters)
        return replace(self, caster_positions=casters, **lengths)

    # -- physical layout ----------------------------------------------------------------
    @property
    def casters(self) -> tuple[tuple[float, float], ...]:
        """Base-frame caster contact points (m): ``caster_positions`` or the four footprint
        corners (front-left, front-right, back-left, back-right)."""
        if self.caster_positions is not None:
            return self.caster_positions
        hl, hw = 0.5 * self.base_length, 0.5 * self.base_width
        return ((hl, hw), (hl, -hw), (-hl, hw), (-hl, -hw))

    # -- mass properties ------------------------------------------------------------------
    @property
    def total_mass(self) -> float:
        """Whole robot's mass (kg): base (wheels included), both links and the payload."""
        m1, m2 = self.link_masses
        return total_mass(self.base_mass, m1, m2, self.payload)

    @property
    def own_mass(self) -> float:
        """The robot's own mass (kg): base (wheels included) and both links, without the
        payload (what its drive and tyres are built for, not what it carries)."""
        m1, m2 = self.link_masses
        return total_mass(self.base_mass, m1, m2, 0.0)

    @property
    def base_body_mass(self) -> float:
        """Mass of the base without its two drive wheels (kg): ``base_mass - 2 wheel_mass``."""
        return self.base_mass - 2.0 * self.wheel_mass

    @property
    def yaw_inertia(self) -> YawInertia:
        """Yaw inertia about the base centre as a function of the elbow angle
        (:class:`~ddwmmr.model.mass.YawInertia`: ``robot.yaw_inertia.at(th2)``, kg m^2)."""
        return YawInertia.of(self)

    @property
    def motor_force_limit(self) -> float:
        """Largest traction force (N) each wheel's motor gives: ``wheel_torque_limit /
        wheel_radius`` (20.5 N for the default robot)."""
        return self.wheel_torque_limit / self.wheel_radius

    # -- kinematics -----------------------------------------------------------------------
    @property
    def reach(self) -> float:
        """Maximum arm reach L1 + L2 (m)."""
        return self.L1 + self.L2

    def joints_outside(self, q: npt.ArrayLike) -> str | None:
        """None if the arm joints of configuration ``q`` lie within ``joint_limits``, else
        the phrase naming the first that does not ("joint th1 = 2.5 rad is outside
        joint_limits[1] = [-1, 1] rad"), for a refusal to complete."""
        angles = _configuration(q)[3:]
        for i, (angle, (low, high)) in enumerate(zip(angles, self.joint_limits), start=1):
            if not low <= angle <= high:
                got, (lo, hi) = texts_apart(angle, low, high)
                return f"joint th{i} = {got} rad is outside joint_limits[{i}] = [{lo}, {hi}] rad"
        return None

    # Every method taking a configuration q (5 finite numbers [x, y, phi, th1, th2]) checks
    # it with _configuration: wrong shapes, strings, NaN/inf and angles beyond
    # +-MAX_CONFIGURATION_ANGLE_RAD raise ParameterError naming q. The check costs one
    # tolist() and one sum of magnitudes on the common (valid) path.
    def fk(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """End-effector pose ``[xE, yE, phiE]`` (world frame, m and rad) at configuration q."""
        return np.array(kinematics.forward_kinematics(self.L1, self.L2, _configuration(q)))

    def jacobian(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The 4x5 Jacobian: rows xE, yE, phiE, nonholonomic constraint.

        docs/theory.md, "Configuration, forward kinematics, Jacobian".
        """
        return kinematics.jacobian(self.L1, self.L2, _configuration(q))

    def augmented_jacobian(self, q: npt.ArrayLike, aux: str = "sum") -> npt.NDArray[np.float64]:
        """The 5x5 augmented Jacobian (``aux`` is ``"sum"`` or ``"shoulder"``)."""
        if not isinstance(aux, str) or aux not in kinematics.AUX_ROWS:
            raise ParameterError(
                f"aux must be one of {sorted(kinematics.AUX_ROWS)} (got {shown(aux)})"
            )
        return kinematics.augmented_jacobian(self.L1, self.L2, _configuration(q), aux)

    # -- wheels ---------------------------------------------------------------------------
    def wheel_speeds_from_u(self, v: float, w: float) -> tuple[float, float]:
        """Wheel angular speeds ``(phidot_l, phidot_r)`` (rad/s) for base speeds v (m/s), w."""
        if not (isinstance(v, float) and isinstance(w, float) and _isfinite(v + w)):
            _check_scalars(("v", v), ("w", w))  # the slow path: names the bad one
        r, lw = self.wheel_radius, self.track_width
        return (2.0 * v - lw * w) / (2.0 * r), (2.0 * v + lw * w) / (2.0 * r)

    def wheel_speeds(self, q: npt.ArrayLike, qdot: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Wheel angular speeds ``[phidot_l, phidot_r]`` (rad/s) for configuration rate qdot.

        Only the forward part ``xdot cos(phi) + ydot sin(phi)`` of the base velocity drives
        the wheels; a sideways part cannot be produced and is ignored here.
        """
        phi = _configuration(q)[2]
        (v, w, _, _), _ = kinematics.u_from_qdot(float(phi), _configuration(qdot, "qdot"))
        return np.array(self.wheel_speeds_from_u(v, w))

    def base_velocity(self, wheel_speeds: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Inverse of the wheel map: ``[v, w]`` (m/s, rad/s) from ``[phidot_l, phidot_r]``."""
        left, right = _pair("wheel_speeds", wheel_speeds, "rad/s")
        r = self.wheel_radius
        return np.array([r * (left + right) / 2.0, r * (right - left) / self.track_width])

    # -- performance metrics ------------------------------------------------------------
    def manipulability(self, q: npt.ArrayLike) -> float:
        """Normalised manipulability ``eta = |sin(th2)|`` in [0, 1]."""
        return stability.manipulability(float(_configuration(q)[4]))

    def stability(self, q: npt.ArrayLike) -> tuple[float, float, float]:
        """Tip-over stability ``(S_lon, S_lat, S)`` on the support polygon; ``S > 1`` is
        stable (capped at 10)."""
        q = _configuration(q)
        return stability.stability_terms(self._com, float(q[3]), float(q[4]))

    def stability_gradient(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Gradient of the capped stability margin S with respect to q (5,), per rad."""
        q = _configuration(q)
        _, g1, g2 = stability.stability_gradient(self._com, float(q[3]), float(q[4]))
        return np.array([0.0, 0.0, 0.0, g1, g2])

    def centre_of_mass(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Arm+payload+base centre of mass ``[x_com, y_com]`` in the base frame (m)."""
        q = _configuration(q)
        return np.array(stability.centre_of_mass(self._com, float(q[3]), float(q[4])))

    @property
    def com_coefficients(self) -> ComCoefficients:
        """Precomputed centre-of-mass coefficients (for fast inner loops)."""
        return self._com

    # -- inverse kinematics ---------------------------------------------------------------
    def base_for_end_effector(
        self, pose_e: npt.ArrayLike, th1: float, th2: float
    ) -> npt.NDArray[np.float64]:
        """The configuration with arm pose (th1, th2) that puts the end effector at ``pose_e``.

        ``pose_e = [xE, yE, phiE]``; the base heading follows from ``phiE - th1 - th2``.
        """
        xe, ye, phie = _triple("pose_e", pose_e)
        _check_scalars(("th1", th1), ("th2", th2))
        phi = phie - th1 - th2
        x = xe - self.L1 * math.cos(phi + th1) - self.L2 * math.cos(phie)
        y = ye - self.L1 * math.sin(phi + th1) - self.L2 * math.sin(phie)
        return np.array([x, y, phi, th1, th2])

    def arm_ik(self, dx: float, dy: float, elbow: int = 1) -> tuple[float, float] | None:
        """Two-link inverse kinematics in the base frame: joint angles reaching (dx, dy) m.

        ``elbow`` = +1 or -1 selects the elbow branch (sign of th2). Returns None when the
        point is out of reach.
        """
        if not (isinstance(dx, float) and isinstance(dy, float) and _isfinite(dx + dy)):
            _check_scalars(("dx", dx), ("dy", dy))
        if type(elbow) is not int or elbow not in (1, -1):
            elbow = _elbow(elbow)
        r2 = dx * dx + dy * dy
        c2 = (r2 - self.L1**2 - self.L2**2) / (2.0 * self.L1 * self.L2)
        if c2 > 1.0 + 1e-12 or c2 < -1.0 - 1e-12:
            return None
        c2 = min(1.0, max(-1.0, c2))
        th2 = math.copysign(math.acos(c2), elbow)
        th1 = math.atan2(dy, dx) - math.atan2(
            self.L2 * math.sin(th2), self.L1 + self.L2 * math.cos(th2)
        )
        return math.atan2(math.sin(th1), math.cos(th1)), th2


def long_lengths(robot: Robot) -> list[str]:
    """The length fields of ``robot`` above :data:`PLAUSIBLE_LENGTH_M`, each as it is
    shown in messages (``"L2 = 350 m"``); empty for any robot of metre-scale lengths."""
    return [
        f"{name} = {getattr(robot, name):g} m"
        for name in _LENGTHS
        if getattr(robot, name) > PLAUSIBLE_LENGTH_M
    ]


def unit_doubts(robot: Robot) -> list[str]:
    """One-line notes on the fields of ``robot`` that are valid but most likely in the
    wrong unit, each naming the fields, their values and the likely mistake: lengths above
    :data:`PLAUSIBLE_LENGTH_M` (millimetres), a wheel radius above the base length (the
    wheel and the base in different units), joint limits or home angles beyond
    :data:`PLAUSIBLE_ANGLE_RAD` in magnitude (degrees). Empty for the default robot."""
    doubts = []
    lengths = long_lengths(robot)
    if lengths:
        verb = "is" if len(lengths) == 1 else "are"
        doubts.append(
            f"{', '.join(lengths)} {verb} above {PLAUSIBLE_LENGTH_M:g} m, implausible for a "
            "mobile manipulator: lengths are in metres (given in millimetres?)"
        )
    # a wheel twice the base's length is no design, one length in cm among metres is
    if robot.base_length < robot.wheel_radius <= PLAUSIBLE_LENGTH_M:
        doubts.append(
            f"wheel_radius = {robot.wheel_radius:g} m is above base_length = "
            f"{robot.base_length:g} m (a wheel over twice as long as the base): lengths are all "
            "in metres (one given in centimetres or millimetres?)"
        )
    limits = [angle for pair in robot.joint_limits for angle in pair]
    angles = [
        f"{name} = {text} rad"
        for name, values, text in (
            ("joint_limits", limits, bracketed([bracketed(pair) for pair in robot.joint_limits])),
            ("home_pose", robot.home_pose, bracketed(robot.home_pose)),
        )
        if any(plausibly_degrees(angle) for angle in values)
    ]
    if angles:
        doubts.append(
            f"{', '.join(angles)} {'goes' if len(angles) == 1 else 'go'} beyond 2 pi rad (one "
            "turn) in magnitude: angles are in radians (given in degrees?)"
        )
    return doubts


def plausibly_degrees(angle: float) -> bool:
    """Whether a joint angle (limit or home angle) of ``angle`` rad was most likely
    written in degrees: beyond :data:`PLAUSIBLE_ANGLE_RAD` (one turn) in magnitude."""
    return abs(angle) > PLAUSIBLE_ANGLE_RAD


def _degrees_hint(angle: float) -> str:
    """What a refusal of the joint angle ``angle`` (rad) adds when it is
    :func:`plausibly_degrees`: the radians it would be in degrees. Else empty."""
    if not plausibly_degrees(angle):
        return ""
    return (
        f"; angles are in radians (given in degrees? {angle:g} deg = {math.radians(angle):.6g} rad)"
    )


def _warn_unit_doubts(robot: Robot, where: str) -> None:
    """A :class:`UserWarning` per :func:`unit_doubts` note, prefixed with ``where`` (the
    file) and naming the user's line (:func:`~ddwmmr.user_warnings.warn_user`): the robot is taken
    as given (a giant robot may be meant), so the user sees why it behaves as it does."""
    for doubt in unit_doubts(robot):
        warn_user(f"{where}: {doubt}; taken as given")


def _check_field_type(key: str, value: Any, default: Any) -> None:
    """``value`` (as read from a file) has the type of the field's ``default``.

    Numbers for number fields (not strings, not booleans), strings for string fields,
    booleans for boolean fields, and nested pairs shaped like a tuple default; fields
    without a plain default are left to ``__post_init__``.
    """
    if isinstance(default, bool):
        ok, wanted = isinstance(value, bool), "true or false"
    elif isinstance(default, int | float):
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        wanted = f"a number {_allowed(key)}" if key in _RANGES else "a number"
    elif isinstance(default, str):
        ok, wanted = isinstance(value, str), "a string"
    elif isinstance(default, tuple):
        nested = isinstance(default[0], tuple)
        ok = isinstance(value, list | tuple) and len(value) == len(default)
        if ok and nested:  # [-1, 1] for two pairs is the shape that is wrong, not -1
            ok = all(isinstance(item, list | tuple) for item in value)
        wanted = "two [min, max] pairs" if nested else "a pair of numbers"
        if ok:
            for i, (item, item_default) in enumerate(zip(value, default), start=1):
                _check_field_type(f"{key}[{i}]", item, item_default)
    else:
        return
    if not ok:
        raise ParameterError(f"robot: {key} must be {wanted} (got {shown(value)})")


def _pair(name: str, value: object, unit: str = "") -> tuple[float, float]:
    """``value`` as two finite floats; anything else raises naming ``name`` (or the entry)."""
    return _numbers(name, value, 2, "a pair of", unit)  # type: ignore[return-value]


def _triple(name: str, value: object) -> tuple[float, float, float]:
    return _numbers(name, value, 3, "3", "[xE, yE, phiE] (m, rad)")  # type: ignore[return-value]


def _numbers(name: str, value: object, size: int, count: str, unit: str) -> tuple[float, ...]:
    suffix = f" {unit}" if unit else ""
    wanted = f"{count} numbers{suffix}"
    items = list_items(name, value, wanted)  # no set: its order is undefined
    if len(items) != size:
        raise ParameterError(f"{name} must be {wanted} (got {len(items)} values)")
    return tuple(check_finite(f"{name}[{i}]", v) for i, v in enumerate(items, start=1))


def _elbow(value: Any) -> int:
    """``value`` as the int +1 or -1 (numpy's numbers and 0-d arrays too), else a one-line
    :class:`ParameterError` naming ``elbow``: a boolean is no sign."""
    number = unwrapped(value)
    numeric = isinstance(number, int | float | np.integer | np.floating)
    if numeric and not isinstance(number, bool | np.bool_) and number in (1, -1):
        return int(number)
    raise ParameterError(f"elbow must be +1 or -1 (got {shown(value)})")


def _check_scalars(*items: tuple[str, Any]) -> None:
    """Each ``(name, value)`` is a finite number: floats pass on one ``isfinite``; the rest
    (ints, strings, booleans, NaN) go through :func:`_finite`, which names the bad one."""
    for name, value in items:
        if not (isinstance(value, float) and _isfinite(value)):
            check_finite(name, value)


def _configuration(q: object, name: str = "q") -> Sequence[float]:
    """``q`` as a flat sequence of 5 finite numbers, or :class:`ParameterError` naming it;
    for a configuration (``name`` q) the angles must also be within
    +-:data:`~ddwmmr.model.kinematics.MAX_CONFIGURATION_ANGLE_RAD` rad
    (:func:`~ddwmmr.model.kinematics.check_angles`), beyond which the link headings
    ``phi + th1 + th2`` the methods form overflow.

    It runs on every call of the public methods (per control step in some loops), so the
    valid case is one ``tolist()`` and one sum of magnitudes (within the angle bound, every
    entry is finite and within it; NaN fails the comparison); only a failing sum (or an
    odd type) takes the slow path, which names the fault and clears values that are merely
    large.
    """
    values = q.tolist() if type(q) is np.ndarray else q
    if type(values) is list or type(values) is tuple:
        try:
            # the sum is finite only for real numbers (a complex one raises TypeError)
            if (
                len(values) == 5
                and _isfinite(sum(values))
                and sum(map(abs, values)) <= _MAX_Q_ANGLE
            ):
                return values
        except (TypeError, OverflowError):
            pass
    return _configuration_slow(q, name)


def _configuration_slow(q: object, name: str) -> Sequence[float]:
    wanted = f"{name} must be 5 finite numbers {_Q_ENTRIES[name]}"
    if isinstance(q, str | bytes | dict):
        raise ParameterError(f"{wanted} (got {shown(q, 60)})")
    try:
        raw = np.asarray(q)
        if raw.dtype.kind not in "iufO" or (
            raw.dtype.kind == "O"
            and not all(
                isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool)
                for v in raw.ravel().tolist()
            )
        ):
            raise TypeError
        array = raw.astype(float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"{wanted} (got {shown(q, 60)})") from None
    if array.shape != (5,):
        raise ParameterError(f"{wanted} (got shape {array.shape})")
    if not np.all(np.isfinite(array)):
        raise ParameterError(f"{wanted} (got {array.tolist()})")
    values = array.tolist()
    return kinematics.check_angles(values, name) if name == "q" else values


@functools.lru_cache(maxsize=64)
def _edges_of_points(points: tuple[tuple[float, float], ...]) -> stability.SupportEdges | None:
    """:class:`~ddwmmr.model.stability.SupportEdges` of the support points (m, base frame),
    None when they span no polygon holding the base centre farther than
    :data:`~ddwmmr.model.support_loads.ON_EDGE_TOLERANCE_M` from every edge. Cached: a
    payload sweep builds many robots on one layout."""
    try:
        polygon = support_loads.SupportPolygon.from_points(points)
    except ValueError:  # fewer than three points off a line
        return None
    if not float(np.min(-polygon.offsets)) > support_loads.ON_EDGE_TOLERANCE_M:
        return None
    return stability.SupportEdges.from_lines(polygon.normals, polygon.offsets, polygon.vertices)


def _pairs(name: str, value: object) -> tuple[tuple[float, float], ...]:
    wanted = "two (min, max) pairs"
    items = list_items(name, value, wanted)  # no set: its order is undefined
    if len(items) != 2 or any(isinstance(p, int | float) for p in items):
        raise ParameterError(f"{name} must be {wanted} (got {shown(value, 60)})")
    return tuple(_pair(f"{name}[{i}]", p, "rad") for i, p in enumerate(items, start=1))
