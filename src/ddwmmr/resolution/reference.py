"""Start configurations and reference configuration trajectories.

* :func:`start_configuration` places the robot's home arm pose on the trajectory start.
* :func:`offset_configuration` moves the end effector by a small offset using the arm only;
  the offset is expressed in the end effector's frame, so whether the arm can reach it does
  not depend on which way the trajectory starts. :func:`default_offset` is a robot's
  default one, :data:`DEFAULT_INITIAL_OFFSET` in its length unit.
* :class:`ReferenceTrajectory` integrates ``q_d(t)`` from the desired task trajectory
  through the augmented task space resolution (RK4 on a fine grid, cubic Hermite lookup):
  the configuration-space reference of CLRRMC-CS (docs/theory.md, "Methods").
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ddwmmr.errors import ParameterError, round_significant
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import base_motion, principal_angle
from ddwmmr.resolution import kernels
from ddwmmr.trajectories.base import sampler

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt

#: Default initial end-effector offset of the default robot (m; of any robot in its length
#: unit, :func:`default_offset`) in the end effector's start frame (x along its orientation
#: phiE, y to its left): 30 mm back and 30 mm to the right, 42.4 mm in all, so closed-loop
#: convergence shows. On the default ellipse (start heading +y) this is the world offset
#: (0.03, -0.03) m. Any start heading gives the same arm motion, which the home arm pose
#: can always make (it moves E towards the arm mount).
DEFAULT_INITIAL_OFFSET = (-0.03, -0.03)


def default_offset(robot: Robot) -> tuple[float, float]:
    """The robot's default initial end-effector offset (dx, dy) in m, in the end effector's
    start frame: :data:`DEFAULT_INITIAL_OFFSET` times the robot's length unit
    (:func:`kernels.length_unit`), so a robot scaled by s starts s times as far off as the
    default robot, on whose steps it then runs; exactly :data:`DEFAULT_INITIAL_OFFSET` for
    the default robot."""
    unit = kernels.length_unit(robot.L1)
    dx, dy = DEFAULT_INITIAL_OFFSET
    return (dx * unit, dy * unit)


#: Position error (m) at which :func:`offset_configuration` accepts the arm's pose, near
#: the origin.
OFFSET_TOLERANCE_M = 1e-12
#: The same as a share of the target's largest coordinate |x|, |y| (m), whose float
#: spacing bounds the error computable there: 1e-14 is 45 to 90 spacings, where 1e-12 m
#: alone is less than one spacing beyond 8192 m (documented coordinates reach 1e6 m).
#: Below 100 m the absolute 1e-12 m is the larger and governs.
OFFSET_RELATIVE_TOLERANCE = 1e-14


def start_configuration(robot: Robot, trajectory: Any) -> np.ndarray:
    """Configuration with the robot's ``home_pose`` arm whose end effector is at the start
    pose ``trajectory.pose(0)`` (position and orientation).

    The start orientation is taken in (-pi, pi] (:func:`principal_angle`, the identity for
    one already there): whole turns are the same pose, and a heading of 1e5 rad would
    leave the base heading too few significant digits to place the end effector to 1e-12 m.
    """
    x_e, y_e, phi_e = (float(v) for v in trajectory.pose(0.0))
    return robot.base_for_end_effector((x_e, y_e, principal_angle(phi_e)), *robot.home_pose)


def initial_configuration(
    robot: Robot,
    trajectory: Any,
    offset: Sequence[float] | npt.NDArray[np.float64],
    *,
    name: str = "initial_offset",
) -> np.ndarray:
    """A run's start: :func:`start_configuration` with the end effector moved by ``offset``
    (dx, dy) m in its frame (:func:`offset_configuration`, whose refusal names the offset
    ``name``)."""
    return offset_configuration(robot, start_configuration(robot, trajectory), offset, name=name)


def offset_configuration(
    robot: Robot,
    q: np.ndarray,
    offset: Sequence[float] | npt.NDArray[np.float64],
    *,
    name: str = "initial_offset",
) -> np.ndarray:
    """``q`` with the arm joints changed so the end effector moves by ``offset`` (dx, dy) m.

    The offset is in the end effector's frame at ``q``: dx along its orientation phiE, dy
    to its left. Newton iterations on the arm's 2x2 position Jacobian; the base does not
    move. The end effector is placed to within :data:`OFFSET_TOLERANCE_M` or
    :data:`OFFSET_RELATIVE_TOLERANCE` times the target's largest world coordinate (m),
    whichever is larger (float spacing grows with the coordinates). Newton may land a
    joint whole turns away from its limits (th1 = -24.2 rad for an offset of 0.25 m):
    such a joint is turned back by whole turns into its ``joint_limits`` where that fits
    (the same arm pose). An offset the arm cannot reach raises a one-line
    :class:`ParameterError` naming it ``name`` (as the caller's user gives it: the API's
    ``initial_offset``, the command line's ``--offset``) and the largest offset along the
    same direction that it reaches, rounded down (:func:`reachable_offset`).
    """
    q = np.array(q, dtype=float)
    dx, dy = (float(v) for v in offset)
    # beyond the arm's span no pose reaches it (and 1e308 m would overflow the target)
    placed = _placed(robot, q, (dx, dy)) if max(abs(dx), abs(dy)) <= _span(robot) else None
    if placed is not None:
        return placed
    fit_x, fit_y = reachable_offset(robot, q, (dx, dy))
    raise ParameterError(
        f"{name} ({dx:g}, {dy:g}) m (end-effector frame) cannot be reached with the arm "
        f"alone; along that direction it reaches ({fit_x:g}, {fit_y:g}) m"
    )


def _placed(robot: Robot, start: np.ndarray, offset: tuple[float, float]) -> np.ndarray | None:
    """:func:`offset_configuration`'s result, or None for an offset out of the arm's reach.

    Newton iterations from ``start``; where they fail (an iterate near a singular arm pose,
    or bouncing near the edge of the reach) or converge on the other elbow branch, the
    closed-form pose on the start's branch (:func:`_placed_in_closed_form`) is taken
    instead, so neighbouring offsets start on one branch."""
    q = start.copy()
    dx, dy = offset
    x_e, y_e, phi_e = robot.fk(q)
    c, s = math.cos(phi_e), math.sin(phi_e)
    target = np.array([x_e + c * dx - s * dy, y_e + s * dx + c * dy])
    tolerance = _offset_tolerance(target)
    for _ in range(50):
        error = target - robot.fk(q)[:2]
        if float(np.hypot(*error)) < tolerance:
            if _elbow_branch(q[4]) != _elbow_branch(start[4]):
                break
            return _turned_into_limits(robot, q)
        arm_jacobian = robot.jacobian(q)[:2, 3:5]
        if abs(np.linalg.det(arm_jacobian)) < 1e-9:
            break
        q[3:5] += np.linalg.solve(arm_jacobian, error)
    return _placed_in_closed_form(robot, start, target, tolerance)


def _placed_in_closed_form(
    robot: Robot, start: np.ndarray, target: np.ndarray, tolerance: float
) -> np.ndarray | None:
    """``start`` with the arm joints of :meth:`Robot.arm_ik` (on the start pose's elbow
    branch) that put the end effector at the world ``target`` (m) to within ``tolerance``
    (m), turned into the joint limits where that fits; None if it is out of reach."""
    x, y, phi = (float(v) for v in start[:3])
    c, s = math.cos(phi), math.sin(phi)
    dx, dy = float(target[0]) - x, float(target[1]) - y
    solution = robot.arm_ik(c * dx + s * dy, -s * dx + c * dy, _elbow_branch(start[4]))
    if solution is None:
        return None
    q = start.copy()
    q[3:5] = solution
    if not float(np.hypot(*(target - robot.fk(q)[:2]))) < tolerance:
        return None
    return _turned_into_limits(robot, q)


def _elbow_branch(th2: float) -> int:
    """The elbow branch of the elbow angle ``th2`` (rad, any wrap): +1 where ``sin th2 >=
    0``, else -1 (:meth:`Robot.arm_ik`'s ``elbow``)."""
    return 1 if math.sin(float(th2)) >= 0.0 else -1


#: Points along the offset's direction :func:`reachable_offset` tries before it bisects
#: (so it finds the first point the arm cannot reach, not a later boundary of its annulus).
REACH_SCAN_POINTS = 32


def reachable_offset(
    robot: Robot, q: np.ndarray, offset: tuple[float, float]
) -> tuple[float, float]:
    """The largest multiple ``k offset`` (0 <= k <= 1; dx, dy in m, end-effector frame at
    ``q``) up to which the arm places the end effector within its joint limits, rounded
    down to two significant digits of its larger component: a value to suggest in place
    of an offset it cannot reach. ``(0, 0)`` if none but the start is reached. The search
    goes no further than the arm's span (:func:`_span`), which no offset passes: an
    absurd offset (1e300 m) gets the same answer as one just out of reach."""

    def fits(k: float) -> bool:
        placed = _placed(robot, q, (k * offset[0], k * offset[1]))
        return placed is not None and robot.joints_outside(placed) is None

    larger = max(abs(offset[0]), abs(offset[1]))
    span = _span(robot)
    top = min(1.0, span / larger) if larger > span else 1.0
    low, high = 0.0, top
    for k in np.linspace(0.0, top, REACH_SCAN_POINTS + 1)[1:]:
        if not fits(float(k)):
            high = float(k)
            break
        low = float(k)
    else:
        if top == 1.0:
            return offset
    for _ in range(40 if high > low else 0):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if fits(middle) else (low, middle)
    if low * larger <= 0.0:
        return (0.0, 0.0)
    k = round_significant(low * larger, 2, math.floor) / larger
    return (k * offset[0], k * offset[1])


def _span(robot: Robot) -> float:
    """The arm's span ``2 (L1 + L2)`` (m): the farthest the arm alone moves the end
    effector, from one side of its reach to the other."""
    return 2.0 * (robot.L1 + robot.L2)


def _offset_tolerance(target: np.ndarray) -> float:
    """Accepted end-effector position error (m) for a world ``target`` (x, y) in m."""
    scale = float(np.max(np.abs(target)))
    return max(OFFSET_TOLERANCE_M, OFFSET_RELATIVE_TOLERANCE * scale)


def _turned_into_limits(robot: Robot, q: np.ndarray) -> np.ndarray:
    """``q`` with each arm joint outside its ``joint_limits`` moved by the whole turns
    that bring it inside, where some do (else left for the start check to refuse); a
    joint inside is kept to the bit."""
    for index, (low, high) in zip((3, 4), robot.joint_limits):
        angle = q[index]
        if low <= angle <= high:
            continue
        turned = angle - 2.0 * math.pi * round((angle - 0.5 * (low + high)) / (2.0 * math.pi))
        if low <= turned <= high:
            q[index] = turned
    return q


#: Most RK4 steps one lookup integrates past the end of the reference. A lookup further
#: ahead integrates the distance in this many equal steps instead (each longer than
#: ``step``), so its cost does not grow with the distance. A simulation looks up at least
#: once per control step ``dt`` (the RK4 plant every half step), so this happens only for
#: a ``dt`` of more than 256 reference steps (2.56 s at the default step), and then the
#: reference is still integrated 256 times finer than the loop moves the robot.
MAX_LOOKUP_STEPS = 256


class _Piece:
    """Consecutive reference segments on one uniform grid.

    Segment ``k`` spans ``origin + k step .. origin + (k + 1) step`` (s). The first
    ``dropped`` segments were discarded; ``coefficients`` and ``damped`` hold segments
    ``dropped, dropped + 1, ...``.
    """

    __slots__ = ("coefficients", "damped", "dropped", "origin", "step")

    def __init__(self, origin: float, step: float) -> None:
        self.origin = origin
        self.step = step
        self.dropped = 0
        self.coefficients: list[tuple[tuple[float, float, float, float], ...]] = []
        self.damped: list[bool] = []

    @property
    def count(self) -> int:
        """Segments integrated on this grid, dropped ones included."""
        return self.dropped + len(self.coefficients)

    @property
    def end(self) -> float:
        """Time (s) of the piece's last node."""
        return self.origin + self.count * self.step

    def index(self, t: float) -> int:
        """Segment holding time t (s); the first or the last one for a t outside."""
        return max(0, min(int((t - self.origin) / self.step), self.count - 1))

    def drop_before(self, index: int) -> None:
        """Discard the segments before ``index``."""
        surplus = index - self.dropped
        if surplus > 0:
            del self.coefficients[:surplus]
            del self.damped[:surplus]
            self.dropped = index


class ReferenceTrajectory:
    """Reference configurations ``q_d(t)`` and rates ``qdot_d(t)`` for a task trajectory.

    Integrated with classical RK4 at step ``step`` (s) through the augmented task space
    resolution with auxiliary row ``aux`` (damped as in :func:`kernels.ats` with
    ``threshold`` and ``damping``; None: the robot's own, :func:`kernels.damping_options`):
    up front to ``horizon`` (s; every step of it, the caller bounds it), then lazily when
    a lookup goes past the end. Lookups are cubic Hermite (fourth-order accurate, like the
    integrator).

    The time a lookup takes and the memory kept do not grow with t. A lookup more than
    :data:`MAX_LOOKUP_STEPS` steps past the end integrates that distance in
    :data:`MAX_LOOKUP_STEPS` longer steps, and the integration goes on at ``step`` from
    there. Only the segments from the previous lookup on are kept; a lookup before them
    (time going backwards, which no simulation loop does) integrates afresh from t = 0,
    giving the numbers of a new reference.

    Attributes:
        singular_nodes: number of rate evaluations (nodes and RK4 stages) that were damped.
        last_damped: whether the segment of the last lookup was integrated with damping at
            any of its rate evaluations (how ``clrrmc-cs`` reports singular steps).
    """

    def __init__(
        self,
        robot: Robot,
        trajectory: Any,
        q_start: np.ndarray,
        aux: str = "shoulder",
        step: float = 0.01,
        threshold: float | None = None,
        damping: float | None = None,
        horizon: float | None = None,
    ) -> None:
        self.robot = robot
        self.trajectory = trajectory
        self.aux = aux
        self.step = float(step)
        self.threshold, self.damping = kernels.damping_options(robot.L1, threshold, damping)
        self.horizon = None if horizon is None else float(horizon)
        self.singular_nodes = 0
        self.last_damped = False
        self._L1, self._L2 = robot.L1, robot.L2
        q0 = [float(v) for v in q_start]
        rate, damped = self._rate(q0, trajectory.velocity(0.0).tolist())
        self._start_node = (q0, rate, damped)
        self._restart()

    def _restart(self) -> None:
        """Back to the start node, integrated up to ``horizon``."""
        self._pieces = [_Piece(0.0, self.step)]
        #: The last node: configuration, rate, whether that rate was damped.
        self._node = self._start_node
        self._end = -1.0  # queries up to this time need no extension
        self._window_start = -math.inf  # lookups before this time need a restart
        self._last_lookup = 0.0
        if self.horizon is not None:
            piece = self._pieces[0]
            # cast: with no limit _fine_end always returns an index
            self._integrate(piece, cast(int, self._fine_end(piece, self.horizon, None)))
            self._end = piece.origin + (piece.count - 1) * piece.step

    def _rate(self, q: list[float], velocity: list[float]) -> tuple[list[float], bool]:
        """Configuration rate at q for the desired end-effector ``velocity`` (3 floats)."""
        xd, yd, pd = velocity
        phi = q[2]
        (v, w, t1, t2), singular = kernels.ats(
            self._L1, self._L2, phi, q[3], q[4], xd, yd, pd, self.aux, self.threshold, self.damping
        )
        self.singular_nodes += singular
        return list(base_motion(phi, v, w, t1, t2)), singular

    def _stage_velocities(
        self, piece: _Piece, first: int, last: int
    ) -> list[tuple[list[float], list[float]]]:
        """Desired velocities at ``origin + k h + h/2`` and ``origin + k h + h`` for the
        piece's steps k = first..last-1: in one vectorised call when the trajectory has
        ``sample`` (same numbers)."""
        origin, h = piece.origin, piece.step
        sample = sampler(self.trajectory)
        if sample is None:
            velocity = self.trajectory.velocity
            return [
                (velocity(origin + k * h + h / 2).tolist(), velocity(origin + k * h + h).tolist())
                for k in range(first, last)
            ]
        start = origin + np.arange(first, last) * h
        _, rates = sample(np.concatenate([start + h / 2, start + h]))
        rows = rates.tolist()
        count = last - first
        return list(zip(rows[:count], rows[count:]))

    @staticmethod
    def _fine_end(piece: _Piece, t: float, limit: int | None) -> int | None:
        """Node index up to which ``piece`` must be integrated for a lookup at t: the first
        node at or after ``t + step``, if within ``limit`` steps of its end, else None."""
        origin, h, first = piece.origin, piece.step, piece.count
        target = t + h
        if limit is not None and (target - origin) / h - first > limit + 2:
            return None
        last = max(first, int((target - origin) / h) - 2)
        while origin + last * h < target:  # the exact rule, from just below it
            last += 1
        return last if limit is None or last - first <= limit else None

    def _extend_to(self, t: float) -> None:
        """Integrate up to a lookup at t beyond ``_end``."""
        self._drop_before_last_lookup()
        piece = self._pieces[-1]
        if piece.step != self.step:  # after a long stride, on at ``step`` from its end
            piece = _Piece(piece.end, self.step)
        last = self._fine_end(piece, t, MAX_LOOKUP_STEPS)
        if last is None:
            start = self._pieces[-1].end
            piece = _Piece(start, (t - start) / MAX_LOOKUP_STEPS)
            last, end = MAX_LOOKUP_STEPS, t
        else:
            end = piece.origin + (last - 1) * piece.step
        if piece is not self._pieces[-1]:
            self._pieces.append(piece)
        self._integrate(piece, last)
        self._end = end

    def _drop_before_last_lookup(self) -> None:
        """Discard the segments before the one of the last lookup."""
        piece = self._piece_at(self._last_lookup)
        while self._pieces[0] is not piece:
            del self._pieces[0]
        piece.drop_before(piece.index(self._last_lookup))
        if len(self._pieces) > 1 or piece.dropped or piece.origin > 0.0:
            self._window_start = piece.origin + piece.dropped * piece.step

    def _integrate(self, piece: _Piece, last: int) -> None:
        """RK4 steps on the piece's grid from its last node to node ``last``."""
        h = piece.step
        rate, half, sixth = self._rate, h / 2, h / 6
        q, k1, damped = self._node
        coefficients, segment_damped = piece.coefficients, piece.damped
        for middle, end in self._stage_velocities(piece, piece.count, last):
            k2, d2 = rate([a + half * b for a, b in zip(q, k1)], middle)
            k3, d3 = rate([a + half * b for a, b in zip(q, k2)], middle)
            k4, d4 = rate([a + h * b for a, b in zip(q, k3)], end)
            q_next = [
                a + sixth * (b1 + 2 * b2 + 2 * b3 + b4)
                for a, b1, b2, b3, b4 in zip(q, k1, k2, k3, k4)
            ]
            rate_next, d_next = rate(q_next, end)
            segment_damped.append(damped or d2 or d3 or d4 or d_next)
            coefficients.append(self._cubic(h, q, q_next, k1, rate_next))
            q, k1, damped = q_next, rate_next, d_next
        self._node = (q, k1, damped)

    @staticmethod
    def _cubic(
        h: float, q0: list[float], q1: list[float], rate0: list[float], rate1: list[float]
    ) -> tuple[tuple[float, float, float, float], ...]:
        """Cubic coefficients ``(c0, c1, c2, c3)`` per coordinate of the segment of length
        ``h`` (s) from node ``(q0, rate0)`` to node ``(q1, rate1)`` (in s = 0..1).

        Computed once per segment while integrating, so a lookup is a polynomial evaluation.
        """
        return tuple(
            [
                (a, h * da, 3.0 * (b - a) - h * (2.0 * da + db), 2.0 * (a - b) + h * (da + db))
                for a, b, da, db in zip(q0, q1, rate0, rate1)
            ]
        )

    def _piece_at(self, t: float) -> _Piece:
        """The kept piece whose grid holds time t (s)."""
        pieces = self._pieces
        for piece in reversed(pieces):
            if t >= piece.origin:
                return piece
        return pieces[0]

    def __call__(self, t: float) -> tuple[list[float], list[float]]:
        """``(q_d, qdot_d)`` at time t >= 0 (s), as lists of 5 floats."""
        if t > self._end:
            self._extend_to(t)
        piece = self._piece_at(t)
        i = piece.index(t)
        if t < self._window_start or i < piece.dropped:
            self._restart()
            if t > self._end:
                self._extend_to(t)
            piece = self._piece_at(t)
            i = piece.index(t)
        self._last_lookup = t
        self.last_damped = piece.damped[i - piece.dropped]
        h = piece.step
        s = (t - piece.origin) / h - i
        position, rate = [], []
        for c0, c1, c2, c3 in piece.coefficients[i - piece.dropped]:
            position.append(c0 + s * (c1 + s * (c2 + s * c3)))
            rate.append((c1 + s * (2.0 * c2 + 3.0 * s * c3)) / h)
        return position, rate
