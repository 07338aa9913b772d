"""The MuJoCo model of a :class:`~ddwmmr.model.Robot`, generated in memory (MJCF).

Nothing here is a hand-kept XML file: :func:`mjcf` writes the model from the robot's fields
every time, so it cannot drift from ``Robot``. World frame: z up, floor at z = 0.

Bodies (all masses and inertias explicit, ``inertiafromgeom="false"``):

* ``base`` (free joint): the base box, ``base_length x base_width x base_height``, bottom
  :data:`BASE_CLEARANCE` above the floor. Body frame on the floor under the axle midpoint
  (the point q's ``(x, y)`` names): the free joint's translational damping (the base
  damping, rolling resistance) then acts on the floor, where a real robot's does, and
  puts no pitch moment on the base. Mass ``base_mass - 2 wheel_mass`` at the box
  centre; yaw inertia chosen so that base + wheels have ``base_inertia`` about the axle
  midpoint (docs/theory.md, "Tip-over stability"). Roll/pitch inertias are those of a
  uniform box (raised if needed to be physically consistent). The frictionless casters are
  spheres of radius :data:`CASTER_RADIUS` on this body, touching the floor at :attr:`Robot.casters`.
* ``wheel_left`` / ``wheel_right`` (hinge about the base's y axis) at ``(0, +-Lw/2)``:
  mass ``wheel_mass`` each (a disc of width :data:`WHEEL_WIDTH`); their floor contact is a
  sphere of radius ``wheel_radius`` (one contact point straight below the axle, on the
  support polygon's side edge), drawn as a cylinder; the two spheres never collide with
  each other (wider than half the track, they overlap). With ``tyre_stiffness`` (by
  default scaled to the robot, :func:`tyre_stiffness`) each wheel hangs on a vertical
  spring-damper, its rubber tyre's radial compliance in series with the floor contact
  (:data:`TYRE_DAMPING_RATIO`), preloaded so that each tyre carries :data:`TYRE_SHARE` of
  the weight at its nominal height. The wheels reach :data:`WHEEL_PRELOAD_DEPTH` below the
  casters' plane (casters mounted a hair high, as on real platforms), so they stay pressed
  on the floor wherever statics allows: six rigid supports on a plane share the load in a
  way statics leaves open, and left to the engine's regularisation a wheel can go unloaded
  while the base rests on three casters (then it spins on frictionless casters). The
  offset is the contacts' own static sink, so the tilt it adds at tipping (offset /
  half-width, 3e-4 rad) is negligible.
* ``link1`` (hinge about z at the base centre, ``arm_height`` above the floor) and
  ``link2`` (hinge at ``L1`` along link 1): uniform rods of radius :func:`link_radius`,
  mass at the midpoint as S has it
  (docs/theory.md, "Tip-over stability"). The payload is a point mass at the end effector
  (``L2`` along link 2), folded into link 2's inertial (so ``body_mass`` of link 2 is
  ``m2 + payload``). The arm never collides.
* the floor: an infinite plane with sliding friction ``friction`` (wheels grip, casters
  are frictionless through ``condim=1`` and a higher contact priority).

Actuators: velocity servos ``torque = kv (target - rate)``, clipped at the robot's motor
torques (``wheel_torque_limit``, ``joint_torque_limits``). ``kv`` is each joint's largest
reflected inertia divided by ``servo_time_constant`` (first-order response with that time
constant while the torque does not saturate).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

# mujoco ships no type hints (no py.typed): its objects are Any to mypy
import mujoco
import numpy as np

from ddwmmr.errors import ParameterError, check_positive, check_range, one_of, shown
from ddwmmr.model import Robot
from ddwmmr.model.stability import BASE_CLEARANCE_M
from ddwmmr.model.support_loads import convex_hull

if TYPE_CHECKING:
    import numpy.typing as npt

#: Radius of the caster spheres (m).
CASTER_RADIUS = 0.025
#: Height of the base box's bottom above the floor (m).
BASE_CLEARANCE = BASE_CLEARANCE_M
#: Width of each drive wheel (m): only its inertia and drawing.
WHEEL_WIDTH = 0.04
#: Depth (m) the drive wheels reach below the casters' plane (see the module docstring).
WHEEL_PRELOAD_DEPTH = 5e-5
#: Radius of the arm links (m): their axial inertia and drawing; a link shorter than
#: :data:`LINK_SLENDERNESS` times it gets a quarter of its length (:func:`link_radius`).
LINK_RADIUS = 0.02
#: Least length of a link over its radius: a rod's inertias are physical (triangle
#: inequality) down to sqrt(3); 4 keeps the links rods.
LINK_SLENDERNESS = 4.0
#: Radius of the payload sphere as drawn (m); the payload itself is a point mass.
PAYLOAD_RADIUS = 0.04
#: Engine options with the defaults chosen by measurement (docs/physics.md, "Settings").
DEFAULT_TIMESTEP = 0.002
#: Allowed range of the engine ``timestep`` (s): from 10 us (the robot's settling at reset
#: is then 50,000 engine steps, about 0.5 s of computing; at 0.1 us, about a minute) to
#: 10 ms (already unusable for tipping, docs/physics.md, "Settings").
TIMESTEP_RANGE_S = (1e-5, 0.01)
#: Most engine steps in one control step: the control step ``dt`` is at most this many
#: timesteps (20 s at the default 2 ms), so that no single ``step`` runs for minutes.
MAX_ENGINE_STEPS_PER_CONTROL_STEP = 10_000
DEFAULT_FRICTION = 1.0
DEFAULT_SERVO_TIME_CONSTANT = 0.02
DEFAULT_CONTACT_TIME_CONSTANT = 0.01
#: Allowed wheel-floor sliding friction: from PTFE or wet ice (~0.02) to soft rubber on a
#: grippy floor (~2), with room either side; outside it a wheel either never grips or
#: never slips, which no floor does.
FRICTION_RANGE = (0.01, 5.0)
#: Allowed servo time constant (s): a motor's velocity loop settles in milliseconds; 1 ms
#: is faster than any electric drive, and a servo slower than 1 s no longer follows a
#: control step's command.
SERVO_TIME_CONSTANT_RANGE_S = (1e-3, 1.0)
#: Allowed contact time constant (s), at least 2 timesteps besides: the contacts' static
#: sink grows with its square (~0.05 mm at the default 10 ms); at 50 ms it is ~1 mm, the
#: tyres' own deflection, and a softer floor is a mattress, not a floor.
CONTACT_TIME_CONSTANT_RANGE_S = (2.0 * TIMESTEP_RANGE_S[0], 0.05)
#: Allowed tyre stiffness (N/m), or 0 for rigid wheels: 1e4 N/m lets the default robot's
#: tyre sink 4-5 mm under its share of the weight (a very soft tyre); 1e8 N/m, half a
#: micrometre, is a steel wheel (stiffer than the contact itself: use 0).
TYRE_STIFFNESS_RANGE = (1e4, 1e8)
DEFAULT_CONE = "elliptic"
CONES = ("pyramidal", "elliptic")
#: Radial stiffness (N/m) of each drive wheel's tyre on the default robot: a small robot's
#: solid rubber tyre deflects about 1 mm under the ~50 N a drive wheel carries
#: (docs/physics.md, "The model, generated from Robot"). Other robots get it scaled by
#: :func:`tyre_stiffness`.
DEFAULT_TYRE_STIFFNESS = 5e4
#: Damping ratio of the tyre's radial spring (rubber's hysteresis), on the mass it carries.
TYRE_DAMPING_RATIO = 0.3
#: Share of the robot's weight each tyre carries at rest at its nominal height (the
#: casters the rest): the spring's preload.
TYRE_SHARE = 1.0 / 3.0
#: Actuator order in the model (and in ``MjData.ctrl``).
ACTUATORS = ("wheel_left", "wheel_right", "shoulder", "elbow")


@dataclass(frozen=True)
class Support:
    """One support of the base on the floor.

    Attributes:
        name: ``wheel_left``, ``wheel_right``, ``caster_front_left``, ... (or ``caster_<i>``
            for custom ``caster_positions``).
        point: nominal contact point ``(x, y)`` in the base frame (m).
        kind: ``"wheel"`` or ``"caster"``.
    """

    name: str
    point: tuple[float, float]
    kind: str


@dataclass(frozen=True)
class EngineOptions:
    """MuJoCo settings of the physics plant.

    Attributes:
        timestep: engine step (s), in :data:`TIMESTEP_RANGE_S`; the control step must be a
            whole multiple of it, at most :data:`MAX_ENGINE_STEPS_PER_CONTROL_STEP` of them.
        friction: sliding friction coefficient between the wheels and the floor, in
            :data:`FRICTION_RANGE`.
        servo_time_constant: time constant of the velocity servos (s), sets their gains;
            in :data:`SERVO_TIME_CONSTANT_RANGE_S`.
        cone: friction cone, ``"elliptic"`` (default: MuJoCo's exact Coulomb cone) or
            ``"pyramidal"`` (MuJoCo's default, four facets; a lightly loaded slipping
            wheel chatters on and off the floor under it, docs/physics.md).
        contact_time_constant: time constant of the contacts' soft constraint (s, MuJoCo's
            ``solref[0]``, critically damped): smaller is stiffer (less sinking and
            tilting under load) and needs a smaller timestep (at least 2 timesteps); in
            :data:`CONTACT_TIME_CONSTANT_RANGE_S`.
        tyre_stiffness: radial stiffness of each drive wheel's tyre (N/m, in
            :data:`TYRE_STIFFNESS_RANGE`), or 0 for a rigid wheel (the contact's own
            compliance only); None (default): :data:`DEFAULT_TYRE_STIFFNESS` scaled to the
            robot (:func:`tyre_stiffness`).

    Each option outside its range (or the cone not one of :data:`CONES`) raises a one-line
    :class:`ParameterError` naming the option and the range.
    """

    timestep: float = DEFAULT_TIMESTEP
    friction: float = DEFAULT_FRICTION
    servo_time_constant: float = DEFAULT_SERVO_TIME_CONSTANT
    cone: str = DEFAULT_CONE
    contact_time_constant: float = DEFAULT_CONTACT_TIME_CONSTANT
    tyre_stiffness: float | None = None

    def __post_init__(self) -> None:
        timestep = check_positive("timestep", self.timestep)
        check_range("timestep", timestep, *TIMESTEP_RANGE_S, "s")
        object.__setattr__(self, "timestep", timestep)
        for name, (low, high), unit in (
            ("friction", FRICTION_RANGE, ""),
            ("servo_time_constant", SERVO_TIME_CONSTANT_RANGE_S, "s"),
            ("contact_time_constant", CONTACT_TIME_CONSTANT_RANGE_S, "s"),
        ):
            object.__setattr__(self, name, check_range(name, getattr(self, name), low, high, unit))
        if self.tyre_stiffness is not None:
            object.__setattr__(self, "tyre_stiffness", _checked_stiffness(self.tyre_stiffness))
        if not one_of(self.cone, CONES):
            raise ParameterError(f"cone must be one of {', '.join(CONES)} (got {shown(self.cone)})")
        if self.contact_time_constant < 2.0 * self.timestep:
            default = (
                ", its default: set it along with the timestep"
                if self.contact_time_constant == DEFAULT_CONTACT_TIME_CONSTANT
                else ""
            )
            raise ParameterError(
                f"contact_time_constant must be >= 2 timesteps = {2 * self.timestep:g} s "
                f"(got {self.contact_time_constant:g}{default})"
            )


def _checked_stiffness(stiffness: float) -> float:
    """``tyre_stiffness`` as a float: 0 (rigid wheels) or in :data:`TYRE_STIFFNESS_RANGE`."""
    low, high = TYRE_STIFFNESS_RANGE
    if not (
        isinstance(stiffness, int | float)
        and not isinstance(stiffness, bool)
        and (stiffness == 0 or low <= stiffness <= high)
    ):
        raise ParameterError(
            f"tyre_stiffness must be 0 (rigid wheels) or in [{low:g}, {high:g}] N/m "
            f"(got {shown(stiffness)})"
        )
    return float(stiffness)


_DEFAULT_ROBOT = Robot()


def tyre_stiffness(robot: Robot, options: EngineOptions) -> float:
    """Radial stiffness (N/m) of each tyre in the model of ``robot``.

    ``options.tyre_stiffness`` if given; else :data:`DEFAULT_TYRE_STIFFNESS` times the
    robot's own mass (payload excluded: the tyre is built for the robot, not for what it
    carries) over the default robot's, times the default robot's ``track_width`` over the
    robot's. A load shift that is the same share of the weight then tilts the base on its
    tyres by the same angle on a robot of any size (the tip rule is an angle; the whole
    robot's lean, casters and contact softness included, only about: docs/physics.md
    gives the measured ratios); the tyre's natural
    frequency is then the default robot's times about ``sqrt(0.35 m / track_width)``
    (docs/physics.md, "The model, generated from Robot"). Exactly
    :data:`DEFAULT_TYRE_STIFFNESS` for the default robot at any payload; not held to
    :data:`TYRE_STIFFNESS_RANGE` (the range a user may set).
    """
    if options.tyre_stiffness is not None:
        return options.tyre_stiffness
    mass_ratio = robot.own_mass / _DEFAULT_ROBOT.own_mass
    return DEFAULT_TYRE_STIFFNESS * mass_ratio * (_DEFAULT_ROBOT.track_width / robot.track_width)


_CORNER_NAMES = ("front_left", "front_right", "back_left", "back_right")


def supports(robot: Robot) -> tuple[Support, ...]:
    """The wheels and casters with their nominal base-frame contact points."""
    half_track = 0.5 * robot.track_width
    wheels = (
        Support("wheel_left", (0.0, half_track), "wheel"),
        Support("wheel_right", (0.0, -half_track), "wheel"),
    )
    if robot.caster_positions is None:
        names = [f"caster_{corner}" for corner in _CORNER_NAMES]
    else:
        names = [f"caster_{i}" for i in range(1, len(robot.casters) + 1)]
    # cast: each caster is an (x, y) pair (Robot.casters), which tuple() keeps
    casters = tuple(
        Support(n, cast("tuple[float, float]", tuple(p)), "caster")
        for n, p in zip(names, robot.casters)
    )
    return wheels + casters


def support_polygon(robot: Robot) -> np.ndarray:
    """Convex hull (k, 2) of all support points in the base frame (m), counter-clockwise."""
    return convex_hull([s.point for s in supports(robot)])


def check_buildable(robot: Robot) -> None:
    """Raise :class:`ParameterError` for a robot MuJoCo cannot simulate (one line naming
    the field and, once, the MuJoCo plant).

    Moving bodies need mass (each arm link), the base centre must stand strictly inside the
    support polygon (else the robot has no stable rest), and ``base_inertia`` must exceed
    the wheels' share of the base yaw inertia.
    """
    for i, mass in enumerate(robot.link_masses, start=1):
        if not mass > 0.0:
            raise ParameterError(
                f"link_masses[{i}] must be > 0 for the MuJoCo plant (a moving body needs "
                f"mass) (got {mass:g})"
            )
    hull = support_polygon(robot)
    if len(hull) < 3 or min(_edge_distances(hull, (0.0, 0.0))) <= 1e-9:
        raise ParameterError(
            "caster_positions: the base centre must lie strictly inside the support polygon "
            f"of the wheels and casters for the MuJoCo plant (got casters {robot.casters})"
        )
    if not _base_body_yaw_inertia(robot) > 0.0:
        raise ParameterError(
            f"base_inertia must be > the wheels' own yaw inertia for the MuJoCo plant, "
            f"{robot.base_inertia - _base_body_yaw_inertia(robot):.4g} kg m^2 from "
            f"wheel_mass, wheel_radius and track_width (got {robot.base_inertia:g}); raise "
            "base_inertia or make the wheels lighter or smaller"
        )


def _edge_distances(hull: npt.NDArray[np.float64], point: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Signed distances (m) of ``point`` from each edge line of a CCW hull (inside > 0)."""
    start, end = hull, np.roll(hull, -1, axis=0)
    edge = end - start
    length = np.hypot(edge[:, 0], edge[:, 1])
    rel = np.asarray(point, dtype=float) - start
    return (edge[:, 0] * rel[:, 1] - edge[:, 1] * rel[:, 0]) / length


def _wheel_inertia(robot: Robot) -> tuple[float, float]:
    """Wheel (disc) inertia about its axle and about a diameter (kg m^2)."""
    m, r = robot.wheel_mass, robot.wheel_radius
    return 0.5 * m * r * r, m * (3.0 * r * r + WHEEL_WIDTH**2) / 12.0


def _base_body_yaw_inertia(robot: Robot) -> float:
    """Yaw inertia of the base body alone: ``base_inertia`` less the wheels' share."""
    _, diameter = _wheel_inertia(robot)
    wheels = 2.0 * (diameter + robot.wheel_mass * (0.5 * robot.track_width) ** 2)
    return robot.base_inertia - wheels


def _base_inertia_diagonal(robot: Robot) -> tuple[float, float, float]:
    """``(Ixx, Iyy, Izz)`` of the base body (kg m^2): box roll/pitch, given yaw.

    The box values are raised where needed so that the triangle inequalities hold (a real
    body); the yaw value is never changed.
    """
    mass = robot.base_body_mass
    length, width, height = robot.base_length, robot.base_width, robot.base_height
    ixx = mass * (width**2 + height**2) / 12.0
    iyy = mass * (length**2 + height**2) / 12.0
    izz = _base_body_yaw_inertia(robot)
    deficit = izz - ixx - iyy
    if deficit > 0.0:
        ixx, iyy = ixx + 0.5 * deficit, iyy + 0.5 * deficit
    ixx, iyy = max(ixx, iyy - izz), max(iyy, ixx - izz)
    while ixx + iyy < izz:  # the raise above, rounded down (a tiny track): up to the bound
        ixx = math.nextafter(ixx, math.inf)
    return ixx, iyy, izz


def _link2_inertial(robot: Robot) -> tuple[float, float, tuple[float, float, float]]:
    """Link 2 rod plus the payload point mass: ``(mass, com_x, (Ixx, Iyy, Izz))``."""
    m2, p, length = robot.link_masses[1], robot.payload, robot.L2
    mass = m2 + p
    com = (m2 * 0.5 * length + p * length) / mass
    transverse = m2 * length**2 / 12.0 + m2 * (0.5 * length - com) ** 2 + p * (length - com) ** 2
    axial = 0.5 * m2 * link_radius(length) ** 2
    return mass, com, (axial, transverse, transverse)


def link_radius(length: float) -> float:
    """Radius (m) of an arm link of ``length`` m: :data:`LINK_RADIUS`, or a
    :data:`LINK_SLENDERNESS`-th of the length for a short link (its inertias must satisfy
    the triangle inequality: length >= sqrt(3) radius)."""
    return min(LINK_RADIUS, length / LINK_SLENDERNESS)


def reflected_inertias(robot: Robot) -> tuple[float, float, float]:
    """The largest inertia (kg m^2) each motor moves: ``(wheel, shoulder, elbow)``.

    A wheel carries half the robot's mass at radius r (plus its own axle inertia); the
    shoulder and elbow move the stretched arm (rods plus the payload at the tip).
    """
    m1, m2 = robot.link_masses
    p, l1, l2, r = robot.payload, robot.L1, robot.L2, robot.wheel_radius
    wheel = 0.5 * robot.total_mass * r * r + _wheel_inertia(robot)[0]
    shoulder = m1 * l1**2 / 3.0 + m2 * (l2**2 / 12.0 + (l1 + 0.5 * l2) ** 2) + p * (l1 + l2) ** 2
    return wheel, shoulder, robot.yaw_inertia.elbow


def servo_gains(robot: Robot, time_constant: float) -> tuple[float, float, float]:
    """Velocity-servo gains ``(kv_wheel, kv_shoulder, kv_elbow)`` (N m s/rad): each joint's
    largest reflected inertia (:func:`reflected_inertias`) over ``time_constant``."""
    # cast: reflected_inertias gives three, so the tuple has three (mypy counts no generator)
    return cast(
        "tuple[float, float, float]",
        tuple(inertia / time_constant for inertia in reflected_inertias(robot)),
    )


def _fmt(*values: float) -> str:
    return " ".join(f"{v:.17g}" for v in values)


def _sub(parent: ET.Element, tag: str, **attributes: object) -> ET.Element:
    return ET.SubElement(parent, tag, {k: str(v) for k, v in attributes.items()})


def mjcf(robot: Robot, options: EngineOptions | None = None) -> str:
    """The MJCF text of ``robot`` (validated by :func:`check_buildable` first)."""
    options = options or EngineOptions()
    check_buildable(robot)
    r = robot.wheel_radius
    root = ET.Element("mujoco", model="ddwmmr")
    _sub(root, "compiler", angle="radian", inertiafromgeom="false")
    _sub(
        root,
        "option",
        timestep=f"{options.timestep:.17g}",
        integrator="implicitfast",
        cone=options.cone,
    )
    visual = _sub(root, "visual")  # only for MuJoCo's own renderer
    _sub(visual, "headlight", ambient="0.45 0.45 0.45", diffuse="0.5 0.5 0.5")
    default = _sub(root, "default")
    _sub(default, "geom", solref=_fmt(options.contact_time_constant, 1.0))
    world = _sub(root, "worldbody")
    _sub(
        world,
        "light",
        directional="true",
        pos="0 0 3",
        dir="0.3 0.3 -1",
        diffuse="0.5 0.5 0.5",
        castshadow="false",
    )
    _sub(
        world,
        "geom",
        name="floor",
        type="plane",
        size="0 0 0.05",
        friction=_fmt(options.friction, 0.005, 0.0001),
        condim=3,
        rgba="0.75 0.78 0.8 1",
    )
    base = _sub(world, "body", name="base", pos=_fmt(0, 0, 0))
    _sub(base, "freejoint", name="base")
    box_z = BASE_CLEARANCE + 0.5 * robot.base_height
    base_mass = robot.base_body_mass
    _sub(
        base,
        "inertial",
        pos=_fmt(0, 0, box_z),
        mass=f"{base_mass:.17g}",
        diaginertia=_fmt(*_base_inertia_diagonal(robot)),
    )
    _sub(
        base,
        "geom",
        name="base_box",
        type="box",
        pos=_fmt(0, 0, box_z),
        size=_fmt(0.5 * robot.base_length, 0.5 * robot.base_width, 0.5 * robot.base_height),
        rgba="0.45 0.5 0.6 1",
    )
    for support in supports(robot):
        if support.kind == "caster":
            _sub(
                base,
                "geom",
                name=support.name,
                type="sphere",
                size=f"{CASTER_RADIUS:.17g}",
                pos=_fmt(*support.point, CASTER_RADIUS),
                condim=1,
                priority=1,
                rgba="0.2 0.2 0.2 1",
            )
    axle, diameter = _wheel_inertia(robot)
    stiffness = tyre_stiffness(robot, options)
    for support in supports(robot):
        if support.kind != "wheel":
            continue
        wheel = _sub(
            base, "body", name=support.name, pos=_fmt(*support.point, r - WHEEL_PRELOAD_DEPTH)
        )
        if stiffness > 0.0:
            _tyre(wheel, robot, stiffness, f"tyre_{support.name.split('_')[1]}")
        _sub(wheel, "joint", name=support.name, type="hinge", axis="0 1 0")
        _sub(
            wheel,
            "inertial",
            pos="0 0 0",
            mass=f"{robot.wheel_mass:.17g}",
            diaginertia=_fmt(diameter, axle, diameter),
        )
        _sub(
            wheel,
            "geom",
            name=support.name,
            type="sphere",
            size=f"{r:.17g}",
            # MuJoCo takes the larger friction of the two geoms: set both to the floor's
            friction=_fmt(options.friction, 0.005, 0.0001),
            rgba="0 0 0 0",
        )
        _sub(
            wheel,
            "geom",
            name=f"{support.name}_tyre",
            type="cylinder",
            size=_fmt(r, 0.5 * WHEEL_WIDTH),
            zaxis="0 1 0",
            contype=0,
            conaffinity=0,
            rgba="0.1 0.1 0.1 1",
        )
    # wheel spheres wider than half the track overlap: they must touch the floor only
    _sub(_sub(root, "contact"), "exclude", body1="wheel_left", body2="wheel_right")
    _arm(base, robot)
    _actuators(root, robot, options)
    return ET.tostring(root, encoding="unicode")


def _tyre(wheel: ET.Element, robot: Robot, stiffness: float, name: str) -> None:
    """The tyre's radial compliance: a vertical slide joint between the base and the
    wheel, a spring of ``stiffness`` (N/m) preloaded to carry :data:`TYRE_SHARE` of the
    weight at the wheel's nominal height, damped at :data:`TYRE_DAMPING_RATIO` of the
    mass that share is."""
    mass = robot.total_mass
    preload = TYRE_SHARE * mass * 9.81
    damping = 2.0 * TYRE_DAMPING_RATIO * math.sqrt(stiffness * TYRE_SHARE * mass)
    _sub(
        wheel,
        "joint",
        name=name,
        type="slide",
        axis="0 0 1",
        stiffness=f"{stiffness:.17g}",
        damping=f"{damping:.17g}",
        springref=f"{-preload / stiffness:.17g}",
    )


def _arm(base: ET.Element, robot: Robot) -> None:
    (low1, high1), (low2, high2) = robot.joint_limits
    m1 = robot.link_masses[0]
    link1 = _sub(base, "body", name="link1", pos=_fmt(0, 0, robot.arm_height))
    _sub(link1, "joint", name="shoulder", type="hinge", axis="0 0 1", range=_fmt(low1, high1))
    _sub(
        link1,
        "inertial",
        pos=_fmt(0.5 * robot.L1, 0, 0),
        mass=f"{m1:.17g}",
        diaginertia=_fmt(
            0.5 * m1 * link_radius(robot.L1) ** 2, m1 * robot.L1**2 / 12, m1 * robot.L1**2 / 12
        ),
    )
    _link_geom(link1, "link1", robot.L1)
    link2 = _sub(link1, "body", name="link2", pos=_fmt(robot.L1, 0, 0))
    _sub(link2, "joint", name="elbow", type="hinge", axis="0 0 1", range=_fmt(low2, high2))
    mass, com, inertia = _link2_inertial(robot)
    _sub(link2, "inertial", pos=_fmt(com, 0, 0), mass=f"{mass:.17g}", diaginertia=_fmt(*inertia))
    _link_geom(link2, "link2", robot.L2)
    _sub(
        link2,
        "geom",
        name="payload",
        type="sphere",
        size=f"{PAYLOAD_RADIUS:.17g}",
        pos=_fmt(robot.L2, 0, 0),
        contype=0,
        conaffinity=0,
        rgba="0.85 0.35 0.1 1",
    )
    _sub(link2, "site", name="end_effector", pos=_fmt(robot.L2, 0, 0))


def _link_geom(body: ET.Element, name: str, length: float) -> None:
    _sub(
        body,
        "geom",
        name=name,
        type="capsule",
        fromto=_fmt(0, 0, 0, length, 0, 0),
        size=f"{link_radius(length):.17g}",
        contype=0,
        conaffinity=0,
        rgba="0.95 0.6 0.1 1",
    )


def _actuators(root: ET.Element, robot: Robot, options: EngineOptions) -> None:
    kv_wheel, kv_shoulder, kv_elbow = servo_gains(robot, options.servo_time_constant)
    actuator = _sub(root, "actuator")
    limits = (
        robot.wheel_torque_limit,
        robot.wheel_torque_limit,
        *robot.joint_torque_limits,
    )
    for name, kv, limit in zip(ACTUATORS, (kv_wheel, kv_wheel, kv_shoulder, kv_elbow), limits):
        _sub(
            actuator,
            "velocity",
            name=name,
            joint=name,
            kv=f"{kv:.17g}",
            forcelimited="true",
            forcerange=_fmt(-limit, limit),
        )


def build_model(robot: Robot, options: EngineOptions | None = None) -> mujoco.MjModel:
    """Compile :func:`mjcf` into a ``mujoco.MjModel``.

    Raises :class:`ParameterError` (one line) for a robot MuJoCo cannot build.
    """
    text = mjcf(robot, options)
    try:
        return mujoco.MjModel.from_xml_string(text)
    except ValueError as exc:  # MuJoCo's compiler error: report its first line
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else "unknown error"
        raise ParameterError(f"robot: MuJoCo cannot build the model ({first})") from None


def total_mass(model: mujoco.MjModel) -> float:
    """Sum of all body masses of a compiled model (kg)."""
    return float(np.sum(model.body_mass))


__all__ = [
    "ACTUATORS",
    "BASE_CLEARANCE",
    "CASTER_RADIUS",
    "DEFAULT_TIMESTEP",
    "EngineOptions",
    "Support",
    "build_model",
    "check_buildable",
    "convex_hull",
    "link_radius",
    "mjcf",
    "reflected_inertias",
    "servo_gains",
    "support_polygon",
    "supports",
    "tyre_stiffness",
]
