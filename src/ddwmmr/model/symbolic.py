"""The robot model as CasADi expressions: kinematics, stability, manipulability, dynamics.

One home for every symbolic formula the optimisation-based code needs (the MPC, the
minimum-time study). The numeric twins are :mod:`ddwmmr.model.kinematics`,
:mod:`ddwmmr.model.stability`, :mod:`ddwmmr.model.support_loads` and
:class:`ddwmmr.plants.thesis.ThesisPlant`; the tests
check values and derivatives against them.

Frames and units (docs/theory.md, "Model"): configuration ``q = [x, y, phi, th1, th2]``
(world frame; m, m, rad, rad, rad), inputs ``u = [v, w, th1dot, th2dot]`` (m/s, rad/s,
rad/s, rad/s).

* **Kinematic model** ``qdot = G(q) u`` (:func:`kinematic_rhs`): the nonholonomic row holds
  by construction.
* **Force-level model of the thesis plant** (:class:`ThesisDynamics`; docs/thesis.md,
  "What is simulated"): state ``x = [q, v, w]`` (7), inputs ``[F_left, F_right, th1dot,
  th2dot]`` (N, N, rad/s, rad/s)::

      m vdot + c1 v = F_left + F_right
      I(th2) wdot + c2 w = (F_right - F_left) b

  with the whole robot's mass ``m``, its pose-dependent yaw inertia ``I(th2)`` (links as
  uniform rods, payload a point mass at the end effector) and the wheels' lever about the
  base centre ``b = track_width / 2``. The arm joints follow rate
  commands: the plant's servo reaches a target ``th + rate dt`` in one step whenever
  ``|rate| <= joint_speed``.

Functions accept CasADi ``SX``/``MX`` (or numbers, returning ``DM``) so that one definition
serves graph construction and evaluation.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import casadi as ca

from ddwmmr.errors import check_nonnegative, check_positive
from ddwmmr.model import Robot, stability
from ddwmmr.model.support_loads import EdgeLoadModel
from ddwmmr.model.thesis_base import robot_constants

#: Sizes: configuration, velocity inputs, force-model state and inputs.
NQ, NU = 5, 4
NX_FORCE, NU_FORCE = 7, 4

Symbolic = Any  # ca.SX | ca.MX | ca.DM


def input_matrix(q: Symbolic) -> Symbolic:
    """The 5x4 matrix ``G(q)`` of ``qdot = G(q) u`` (depends on the heading only)."""
    phi = q[2]
    zero, one = 0.0, 1.0
    return ca.vertcat(
        ca.horzcat(ca.cos(phi), zero, zero, zero),
        ca.horzcat(ca.sin(phi), zero, zero, zero),
        ca.horzcat(zero, one, zero, zero),
        ca.horzcat(zero, zero, one, zero),
        ca.horzcat(zero, zero, zero, one),
    )


def kinematic_rhs(q: Symbolic, u: Symbolic) -> Symbolic:
    """Configuration rate ``qdot = G(q) u`` (5,)."""
    phi = q[2]
    return ca.vertcat(u[0] * ca.cos(phi), u[0] * ca.sin(phi), u[1], u[2], u[3])


def forward_kinematics(robot: Robot, q: Symbolic) -> Symbolic:
    """End-effector pose ``[xE, yE, phiE]`` (world frame, m and rad)."""
    a1 = q[2] + q[3]
    a12 = a1 + q[4]
    return ca.vertcat(
        q[0] + robot.L1 * ca.cos(a1) + robot.L2 * ca.cos(a12),
        q[1] + robot.L1 * ca.sin(a1) + robot.L2 * ca.sin(a12),
        a12,
    )


def centre_of_mass(robot: Robot, q: Symbolic) -> Symbolic:
    """Arm+payload+base centre of mass ``[x_com, y_com]`` in the base frame (m)."""
    k = robot.com_coefficients
    th1, th12 = q[3], q[3] + q[4]
    return ca.vertcat(
        k.A * ca.cos(th1) + k.B * ca.cos(th12), k.A * ca.sin(th1) + k.B * ca.sin(th12)
    )


def stability_terms(robot: Robot, q: Symbolic) -> Symbolic:
    """The exact, uncapped terms ``[S_lon, S_lat]`` of the stability margin on the
    robot's support polygon (:mod:`ddwmmr.model.stability`): on the rectangle ``[(length/2)
    /|x_com|, (width/2)/|y_com|]``, on another polygon each term's least ``d_e / (n_e .
    c)`` over its edges.

    Infinite where the corresponding moment vanishes; the numeric model caps at 10.
    """
    k = robot.com_coefficients
    com = centre_of_mass(robot, q)
    if k.edges is None:
        return ca.vertcat(k.half_length / ca.fabs(com[0]), k.half_width / ca.fabs(com[1]))
    terms = []
    for edges in (k.edges.lon, k.edges.lat):
        term = ca.inf
        for n_x, n_y, d in edges:
            reach = n_x * com[0] + n_y * com[1]
            term = ca.fmin(term, ca.if_else(reach > 0.0, d / reach, ca.inf))
        terms.append(term)
    return ca.vertcat(*terms)


def stability_bounds(robot: Robot, stability_min: float) -> tuple[float, float] | None:
    """Bounds ``(x_max, y_max)`` (m) with ``S >= stability_min  <=>  |x_com| <= x_max and
    |y_com| <= y_max`` on the rectangle; None on any other support polygon (then
    :func:`stability_edges` holds the condition: the footprint's box is not S there).

    ``S_lon = hl/|x_com| >= S_min`` holds exactly when ``|x_com| <= hl/S_min`` (both sides
    are positive), and likewise for the lateral term. Constraining the centre of mass
    (:func:`centre_of_mass`) to this box is therefore the exact nonlinear condition
    ``S >= S_min`` in a smooth form (no division, no kink of ``min`` or ``|.|``).
    """
    s_min = check_positive("stability_min", stability_min)
    k = robot.com_coefficients
    if k.edges is not None:
        return None
    return k.half_length / s_min, k.half_width / s_min


def stability_edges(
    robot: Robot, stability_min: float
) -> tuple[tuple[float, float, float, int], ...] | None:
    """``S >= stability_min`` on a support polygon other than the rectangle as one linear
    row per edge: ``(n_x, n_y, bound, term)`` with ``n_x x_com + n_y y_com <= bound`` (m),
    ``term`` 0 for an edge of ``S_lon``, 1 of ``S_lat``. None on the rectangle, whose rows
    are :func:`stability_bounds`'s box.

    ``d_e / (n_e . c) >= S_min`` holds exactly when ``n_e . c <= d_e / S_min`` (``d_e >
    0``; an edge with ``n_e . c <= 0`` meets both), so the rows are the exact nonlinear
    condition, as the box is on the rectangle.
    """
    s_min = check_positive("stability_min", stability_min)
    edges = robot.com_coefficients.edges
    if edges is None:
        return None
    return tuple(
        (n_x, n_y, d / s_min, term)
        for term, group in enumerate((edges.lon, edges.lat))
        for n_x, n_y, d in group
    )


def zero_moment_point(
    robot: Robot,
    q: Symbolic,
    rates: Symbolic,
    v: Symbolic,
    w: Symbolic,
    v_dot: Symbolic,
    w_dot: Symbolic,
    accelerations: Symbolic = (0.0, 0.0),
) -> Symbolic:
    """Zero moment point ``[x, y]`` in the base frame (m): the formula of
    :func:`ddwmmr.model.stability.zero_moment_point` built symbolically (joint rates
    ``rates`` rad/s and ``accelerations`` rad/s^2, base speeds v, w and their rates)."""
    point = stability.zero_moment_point(
        robot.com_coefficients,
        stability.inertial_terms(robot),
        q[3],
        q[4],
        rates[0],
        rates[1],
        v,
        w,
        v_dot,
        w_dot,
        accelerations[0],
        accelerations[1],
        cos=ca.cos,
        sin=ca.sin,
    )
    return ca.vertcat(*point)


def edge_loads(
    robot: Robot,
    q: Symbolic,
    rates: Symbolic,
    accelerations: Symbolic,
    base_acceleration: Symbolic,
    w: Symbolic,
    w_dot: Symbolic,
) -> Symbolic:
    """Normal loads (N) on the edges of the support polygon, one per edge: the formula of
    :meth:`ddwmmr.model.support_loads.EdgeLoadModel.loads` built symbolically (joint
    rates rad/s and accelerations rad/s^2, the axle midpoint's acceleration ``(a_x, a_y)``
    m/s^2 in the base frame, the yaw rate and its rate)."""
    model = EdgeLoadModel.from_robot(robot)
    loads = model.loads(
        q[3],
        q[4],
        (rates[0], rates[1]),
        (accelerations[0], accelerations[1]),
        (base_acceleration[0], base_acceleration[1]),
        w,
        w_dot,
        cos=ca.cos,
        sin=ca.sin,
    )
    return ca.vertcat(*loads)


def manipulability(q: Symbolic) -> Symbolic:
    """Normalised manipulability ``eta = |sin th2|`` in [0, 1] (thesis 4.1.1)."""
    return ca.fabs(ca.sin(q[4]))


def manipulability_squared(q: Symbolic) -> Symbolic:
    """``eta^2 = sin^2 th2``: the same maximisers as eta, smooth everywhere."""
    return ca.sin(q[4]) ** 2


def wheel_speeds(robot: Robot, v: Symbolic, w: Symbolic) -> Symbolic:
    """Wheel angular speeds ``[phidot_l, phidot_r]`` (rad/s) for base speeds v, w."""
    r, lw = robot.wheel_radius, robot.track_width
    return ca.vertcat((2.0 * v - lw * w) / (2.0 * r), (2.0 * v + lw * w) / (2.0 * r))


def rk4_step(
    rhs: Callable[[Symbolic, Symbolic], Symbolic], x: Symbolic, u: Symbolic, h: float | Symbolic
) -> Symbolic:
    """One classical Runge-Kutta step of ``xdot = rhs(x, u)`` with u held over h (s)."""
    k1 = rhs(x, u)
    k2 = rhs(x + 0.5 * h * k1, u)
    k3 = rhs(x + 0.5 * h * k2, u)
    k4 = rhs(x + h * k3, u)
    return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def _trig(value: Symbolic) -> tuple[Callable[[Symbolic], Symbolic], Callable[[Symbolic], Symbolic]]:
    """``(cos, sin)`` for a value: ``math``'s for a plain number (float out), CasADi's for
    a symbol."""
    return (math.cos, math.sin) if isinstance(value, int | float) else (ca.cos, ca.sin)


@dataclass(frozen=True)
class ThesisDynamics:
    """Parameters and equations of the thesis plant's force-level model.

    The model: docs/thesis.md, "What is simulated".

    Build it with :meth:`from_robot`; the defaults are the thesis plant's constants for
    the robot (:func:`~ddwmmr.model.thesis_base.robot_constants`; for the thesis robot
    c1 = 15 N s/m, c2 = 4 N m s/rad, 10 N per wheel, 2 rad/s).

    Attributes:
        mass: whole robot (base + links + payload) (kg).
        c1: translational damping (N s/m); c2: rotational damping (N m s/rad).
        force_limit: per-wheel force limit (N); joint_speed: arm servo speed (rad/s).
        half_width: lever arm b of the wheel forces about the base centre (m; the thesis
            plant's ``track_width / 2``, the wheels are that far either side).
        inertia_fixed, inertia_cos: yaw inertia ``I(th2) = inertia_fixed + inertia_cos
            cos(th2)`` about the base centre (kg m^2).
        shoulder_fixed, elbow_fixed: the arm's angular momentum about the base centre from
            its own motion is ``H = a th1dot + b (th1dot + th2dot)``, ``a = shoulder_fixed +
            k cos th2``, ``b = elbow_fixed + k cos th2``, ``k = inertia_cos / 2`` (kg m^2);
            the thesis plant's arm has no such reaction, a physical one does
            (:meth:`arm_yaw_reaction`).
    """

    mass: float
    c1: float
    c2: float
    force_limit: float
    joint_speed: float
    half_width: float
    inertia_fixed: float
    inertia_cos: float
    shoulder_fixed: float = 0.0
    elbow_fixed: float = 0.0

    @classmethod
    def from_robot(
        cls,
        robot: Robot,
        c1: float | None = None,
        c2: float | None = None,
        force_limit: float | None = None,
        joint_speed: float | None = None,
        half_width: float | None = None,
    ) -> ThesisDynamics:
        """The model of ``ThesisPlant(robot, c1, c2, force_limit, joint_speed)``: c1
        (N s/m), c2 (N m s/rad) and force_limit (N per wheel) each None: the robot's own,
        as the plant's (:func:`~ddwmmr.model.thesis_base.robot_constants`: 15, 4 and 10
        for the thesis robot); ``joint_speed`` rad/s, None: the robot's
        ``joint_speed_limit``, as the plant's; ``half_width`` (m) is the wheels' lever
        about the base centre, by default the thesis plant's ``robot.track_width / 2``."""
        own = robot_constants(robot)
        c1 = own["c1"] if c1 is None else c1
        c2 = own["c2"] if c2 is None else c2
        force_limit = own["force_limit"] if force_limit is None else force_limit
        inertia = robot.yaw_inertia  # the collected form I(th2) = fixed + cos * cos th2
        return cls(
            mass=robot.total_mass,
            c1=check_nonnegative("c1", c1),  # 0: an undamped base (the physics plant)
            c2=check_nonnegative("c2", c2),
            force_limit=check_positive("force_limit", force_limit),
            joint_speed=check_positive(
                "joint_speed", robot.joint_speed_limit if joint_speed is None else joint_speed
            ),
            half_width=(
                0.5 * robot.track_width
                if half_width is None
                else check_positive("half_width", half_width)
            ),
            inertia_fixed=inertia.fixed,
            inertia_cos=inertia.cos,
            shoulder_fixed=inertia.shoulder,
            elbow_fixed=inertia.elbow,
        )

    # -- numbers ------------------------------------------------------------------------
    def inertia(self, th2: Symbolic) -> Symbolic:
        """Yaw inertia ``I(th2)`` (kg m^2); numbers in, float out."""
        return self.inertia_fixed + self.inertia_cos * _trig(th2)[0](th2)

    @property
    def top_speed(self) -> float:
        """Steady forward speed under the full force of both wheels, ``2 F / c1`` (m/s;
        infinite without damping)."""
        return 2.0 * self.force_limit / self.c1 if self.c1 > 0.0 else math.inf

    @property
    def top_yaw_rate(self) -> float:
        """Steady yaw rate under the full opposite forces, ``2 F b / c2`` (rad/s;
        infinite without damping)."""
        torque = 2.0 * self.force_limit * self.half_width
        return torque / self.c2 if self.c2 > 0.0 else math.inf

    # -- equations ----------------------------------------------------------------------
    def rhs(self, x: Symbolic, u: Symbolic) -> Symbolic:
        """State rate of ``x = [x, y, phi, th1, th2, v, w]`` under
        ``u = [F_left, F_right, th1dot, th2dot]`` (7,)."""
        phi, th2, v, w = x[2], x[4], x[5], x[6]
        f_left, f_right = u[0], u[1]
        return ca.vertcat(
            v * ca.cos(phi),
            v * ca.sin(phi),
            w,
            u[2],
            u[3],
            (f_left + f_right - self.c1 * v) / self.mass,
            ((f_right - f_left) * self.half_width - self.c2 * w) / self.inertia(th2),
        )

    def arm_momentum(self, th2: Symbolic, rates: Symbolic) -> Symbolic:
        """The arm's angular momentum ``H`` about the base centre from its own motion
        (kg m^2/s) at joint rates ``rates`` (rad/s)."""
        a, b = self._arm_levers(_trig(th2)[0](th2))
        return a * rates[0] + b * (rates[0] + rates[1])

    def arm_yaw_reaction(
        self, th2: Symbolic, w: Symbolic, rates: Symbolic, accelerations: Symbolic
    ) -> Symbolic:
        """Yaw acceleration (rad/s^2) the arm's own motion adds to the base's: the total
        angular momentum ``I(th2) w + H`` about the base centre changes only by the
        wheels' torque and the damping, so ``I wdot`` loses ``dI/dt w + dH/dt``. Joint
        rates (rad/s) and accelerations (rad/s^2), yaw rate w (rad/s)."""
        cos, sin = _trig(th2)
        a, b = self._arm_levers(cos(th2))
        # d(cos th2)/dt times k: the rate of a and b, half the rate of I
        k_rate = -0.5 * self.inertia_cos * sin(th2) * rates[1]
        rate12 = rates[0] + rates[1]
        change = (
            2.0 * k_rate * w  # dI/dt w
            + a * accelerations[0]
            + b * (accelerations[0] + accelerations[1])
            + k_rate * (rates[0] + rate12)  # da/dt th1dot + db/dt th12dot
        )
        return -change / self.inertia(th2)

    def _arm_levers(self, cos2: Symbolic) -> tuple[Symbolic, Symbolic]:
        """``(a, b)`` of :meth:`arm_momentum` at ``cos th2`` (kg m^2)."""
        k = 0.5 * self.inertia_cos
        return self.shoulder_fixed + k * cos2, self.elbow_fixed + k * cos2

    def velocity_envelope(self, fraction: float = 0.8) -> dict[str, float]:
        """What a velocity command can ask of this base, as ``fraction`` of the physics.

        Top speeds where the full force balances damping and accelerations from rest with
        the largest yaw inertia (arm stretched); the same numbers as
        :meth:`ddwmmr.plants.thesis.ThesisPlant.velocity_envelope` (tested), keyed like the
        ``qp`` controller's options.
        """
        total = 2.0 * self.force_limit
        torque = total * self.half_width
        stretched = self.inertia(0.0)
        envelope = {
            "max_acceleration": fraction * total / self.mass,
            "max_yaw_acceleration": fraction * torque / stretched,
        }
        # without damping nothing caps the speeds but the wheel-speed limit
        if self.c1 > 0.0:
            envelope["max_base_speed"] = fraction * total / self.c1
        if self.c2 > 0.0:
            envelope["max_yaw_rate"] = fraction * torque / self.c2
        return envelope

    def velocity_tracking_forces(
        self,
        v: float,
        w: float,
        v_d: float,
        w_d: float,
        th2: float,
        bandwidth: float = 10.0,
    ) -> tuple[float, float]:
        """Left/right wheel forces (N) making the base follow a velocity command.

        Damping feed-forward plus a proportional term of bandwidth ``bandwidth`` (1/s):
        ``F = c1 v_d + k m (v_d - v)``, ``T = c2 w_d + k I (w_d - w)``; mixed with rotation
        priority within the force limit (the velocity loop the ``qp`` controller uses on
        this plant). Speeds in m/s and rad/s, th2 in rad.
        """
        total_limit = 2.0 * self.force_limit
        f_t = self.c1 * v_d + bandwidth * self.mass * (v_d - v)
        torque = self.c2 * w_d + bandwidth * self.inertia(float(th2)) * (w_d - w)
        f_r = min(total_limit, max(-total_limit, torque / self.half_width))
        room = total_limit - abs(f_r)
        f_t = min(room, max(-room, f_t))
        return 0.5 * f_t - 0.5 * f_r, 0.5 * f_t + 0.5 * f_r


def casadi_functions(
    robot: Robot, dynamics: ThesisDynamics | None = None
) -> dict[str, ca.Function]:
    """The expressions above as CasADi functions of q (and u / x), for evaluation and tests.

    Keys: ``fk`` (q -> 3), ``com`` (q -> 2), ``stability`` (q -> [S_lon, S_lat]), ``eta``
    (q -> 1), ``kinematic`` ((q, u) -> qdot), and with ``dynamics`` ``thesis``
    ((x, u) -> xdot).
    """
    q = ca.SX.sym("q", NQ)
    u = ca.SX.sym("u", NU)
    functions = {
        "fk": ca.Function("fk", [q], [forward_kinematics(robot, q)]),
        "com": ca.Function("com", [q], [centre_of_mass(robot, q)]),
        "stability": ca.Function("stability", [q], [stability_terms(robot, q)]),
        "eta": ca.Function("eta", [q], [manipulability(q)]),
        "kinematic": ca.Function("kinematic", [q, u], [kinematic_rhs(q, u)]),
    }
    if dynamics is not None:
        x = ca.SX.sym("x", NX_FORCE)
        f = ca.SX.sym("f", NU_FORCE)
        functions["thesis"] = ca.Function("thesis", [x, f], [dynamics.rhs(x, f)])
    return functions
