"""Start configurations and reference configuration trajectories.

* :func:`start_configuration` places the robot's home arm pose on the trajectory start.
* :func:`offset_configuration` moves the end effector by a small offset using the arm only;
  the offset is expressed in the end effector's frame, so whether the arm can reach it does
  not depend on which way the trajectory starts.
* :class:`ReferenceTrajectory` integrates ``q_d(t)`` from the desired task trajectory
  through the augmented task space resolution (RK4 on a fine grid, cubic Hermite lookup):
  the configuration-space reference of CLRRMC-CS (SPEC §4).
"""

from __future__ import annotations

import math

import numpy as np

from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot
from ddwmmr.resolution import kernels
from ddwmmr.trajectories.base import sampler

#: Default initial end-effector offset (m) in the end effector's start frame (x along its
#: orientation phiE, y to its left): 30 mm back and 30 mm to the right, 42.4 mm in all, so
#: closed-loop convergence shows. On the default ellipse (start heading +y) this is the
#: world offset (0.03, -0.03) m. Any start heading gives the same arm motion, which the
#: home arm pose can always make (it moves E towards the arm mount).
DEFAULT_INITIAL_OFFSET = (-0.03, -0.03)


def start_configuration(robot: Robot, trajectory) -> np.ndarray:
    """Configuration with the robot's ``home_pose`` arm whose end effector is at the start
    pose ``trajectory.pose(0)`` (position and orientation)."""
    return robot.base_for_end_effector(trajectory.pose(0.0), *robot.home_pose)


def initial_configuration(robot: Robot, trajectory, offset) -> np.ndarray:
    """A run's start: :func:`start_configuration` with the end effector moved by ``offset``
    (dx, dy) m in its frame (:func:`offset_configuration`)."""
    return offset_configuration(robot, start_configuration(robot, trajectory), offset)


def offset_configuration(robot: Robot, q: np.ndarray, offset) -> np.ndarray:
    """``q`` with the arm joints changed so the end effector moves by ``offset`` (dx, dy) m.

    The offset is in the end effector's frame at ``q``: dx along its orientation phiE, dy
    to its left. Newton iterations on the arm's 2x2 position Jacobian; the base does not
    move. An offset the arm cannot reach raises :class:`ParameterError`.
    """
    q = np.array(q, dtype=float)
    dx, dy = (float(v) for v in offset)
    x_e, y_e, phi_e = robot.fk(q)
    c, s = math.cos(phi_e), math.sin(phi_e)
    target = np.array([x_e + c * dx - s * dy, y_e + s * dx + c * dy])
    for _ in range(50):
        error = target - robot.fk(q)[:2]
        if float(np.hypot(*error)) < 1e-12:
            return q
        arm_jacobian = robot.jacobian(q)[:2, 3:5]
        if abs(np.linalg.det(arm_jacobian)) < 1e-9:
            break
        q[3:5] += np.linalg.solve(arm_jacobian, error)
    raise ParameterError(
        f"initial_offset ({dx:g}, {dy:g}) m (end-effector frame) cannot be reached with the "
        "arm alone"
    )


class ReferenceTrajectory:
    """Reference configurations ``q_d(t)`` and rates ``qdot_d(t)`` for a task trajectory.

    Integrated with classical RK4 at step ``step`` (s) through the augmented task space
    resolution with auxiliary row ``aux`` (damped as in :func:`kernels.ats` with
    ``threshold`` and ``damping``); extended lazily when queried past its end. Lookups are
    cubic Hermite (fourth-order accurate, like the integrator).

    Attributes:
        singular_nodes: number of rate evaluations (nodes and RK4 stages) that were damped.
        last_damped: whether the segment of the last lookup was integrated with damping at
            any of its rate evaluations (how ``clrrmc-cs`` reports singular steps).
    """

    def __init__(
        self,
        robot: Robot,
        trajectory,
        q_start: np.ndarray,
        aux: str = "shoulder",
        step: float = 0.01,
        threshold: float = kernels.SINGULARITY_THRESHOLD,
        damping: float = kernels.MAX_DAMPING,
    ) -> None:
        self.robot = robot
        self.trajectory = trajectory
        self.aux = aux
        self.step = float(step)
        self.threshold = float(threshold)
        self.damping = float(damping)
        self.singular_nodes = 0
        self.last_damped = False
        self._L1, self._L2 = robot.L1, robot.L2
        q0 = [float(v) for v in q_start]
        self._q = [q0]
        rate, damped = self._rate(q0, trajectory.velocity(0.0).tolist())
        self._qdot = [rate]
        self._node_damped = [damped]
        #: Per segment: was any rate evaluation that defines it damped?
        self._segment_damped: list[bool] = []
        #: Cubic coefficients of each segment, appended as the reference is integrated.
        self._coefficients: list[tuple[tuple[float, ...], ...]] = []
        self._end = -1.0  # queries up to this time need no extension

    def _rate(self, q: list[float], velocity: list[float]) -> tuple[list[float], bool]:
        """Configuration rate at q for the desired end-effector ``velocity`` (3 floats)."""
        xd, yd, pd = velocity
        phi = q[2]
        (v, w, t1, t2), singular = kernels.ats(
            self._L1, self._L2, phi, q[3], q[4], xd, yd, pd, self.aux, self.threshold, self.damping
        )
        self.singular_nodes += singular
        return [v * math.cos(phi), v * math.sin(phi), w, t1, t2], singular

    def _stage_velocities(self, first: int, last: int) -> list[tuple[list[float], list[float]]]:
        """Desired velocities at ``k h + h/2`` and ``k h + h`` for steps k = first..last-1:
        in one vectorised call when the trajectory has ``sample`` (same numbers)."""
        h = self.step
        sample = sampler(self.trajectory)
        if sample is None:
            velocity = self.trajectory.velocity
            return [
                (velocity(k * h + h / 2).tolist(), velocity(k * h + h).tolist())
                for k in range(first, last)
            ]
        start = np.arange(first, last) * h
        _, rates = sample(np.concatenate([start + h / 2, start + h]))
        rows = rates.tolist()
        count = last - first
        return list(zip(rows[:count], rows[count:]))

    def _extend_to(self, t: float) -> None:
        h = self.step
        first = len(self._q) - 1
        last = first
        while last * h < t + h:  # the steps the loop below takes
            last += 1
        rate, half, sixth = self._rate, h / 2, h / 6
        q, k1, damped = self._q[-1], self._qdot[-1], self._node_damped[-1]
        for middle, end in self._stage_velocities(first, last):
            k2, d2 = rate([a + half * b for a, b in zip(q, k1)], middle)
            k3, d3 = rate([a + half * b for a, b in zip(q, k2)], middle)
            k4, d4 = rate([a + h * b for a, b in zip(q, k3)], end)
            q_next = [
                a + sixth * (b1 + 2 * b2 + 2 * b3 + b4)
                for a, b1, b2, b3, b4 in zip(q, k1, k2, k3, k4)
            ]
            rate_next, d_next = rate(q_next, end)
            self._segment_damped.append(damped or d2 or d3 or d4 or d_next)
            self._coefficients.append(self._cubic(q, q_next, k1, rate_next))
            self._q.append(q_next)
            self._qdot.append(rate_next)
            self._node_damped.append(d_next)
            q, k1, damped = q_next, rate_next, d_next

    def _cubic(
        self, q0: list[float], q1: list[float], rate0: list[float], rate1: list[float]
    ) -> tuple[tuple[float, float, float, float], ...]:
        """Cubic coefficients ``(c0, c1, c2, c3)`` per coordinate of the segment from node
        ``(q0, rate0)`` to node ``(q1, rate1)`` (in s = 0..1).

        Computed once per segment while integrating, so a lookup is a polynomial evaluation.
        """
        h = self.step
        return tuple(
            [
                (a, h * da, 3.0 * (b - a) - h * (2.0 * da + db), 2.0 * (a - b) + h * (da + db))
                for a, b, da, db in zip(q0, q1, rate0, rate1)
            ]
        )

    def __call__(self, t: float) -> tuple[list[float], list[float]]:
        """``(q_d, qdot_d)`` at time t >= 0 (s), as lists of 5 floats."""
        if t > self._end:
            self._extend_to(t)
            self._end = (len(self._q) - 2) * self.step
        h = self.step
        i = min(int(t / h), len(self._q) - 2)
        self.last_damped = self._segment_damped[i]
        s = t / h - i
        position, rate = [], []
        for c0, c1, c2, c3 in self._coefficients[i]:
            position.append(c0 + s * (c1 + s * (c2 + s * c3)))
            rate.append((c1 + s * (2.0 * c2 + 3.0 * s * c3)) / h)
        return position, rate
