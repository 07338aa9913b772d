"""Reference for the benchmark: roboticstoolbox-python's holistic QP step for this robot.

What a user would otherwise pick: the reactive mobile-manipulation controller of Haviland,
Suenderhauf and Corke ("A holistic approach to reactive mobile manipulation", 2022), as
roboticstoolbox-python ships it in ``examples/holistic_mm_non_holonomic.py``, applied to
the ddwmmr robot modelled with the toolbox's own elementary transforms, the way its
``Frankie`` model describes a differential-drive base::

    base0: Rz(q0)   (yaw: w)      base1: tx(q1)   (drive: v)
    shoulder: Rz(q2) (th1)        elbow: tx(L1) Rz(q3) (th2)        ee: tx(L2)

Each step does what the example's loop does: place the base frame at ``(x, y, phi)`` with
the two base joints at 0 ("reset bases"), then build and solve the holistic QP with the
toolbox's functions (``fkine``, ``p_servo``, ``jacobe``, ``joint_velocity_damper``,
``jacobm``) and ``qpsolvers.solve_qp(..., solver="quadprog")`` (the example leaves the
solver to an old qpsolvers default; quadprog is the dense solver it used). Two adaptations
to a planar arm, both needed for the maths to mean anything: the manipulability Jacobian
uses the planar translation axes only (a 2-link arm's 6x2 Jacobian has ``det(J J') = 0``),
and ``joint_velocity_damper`` is called with keywords (its first parameter became ``q``).

Not a registered method; needs ``pip install 'ddwmmr[bench]'`` (roboticstoolbox-python).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ddwmmr.controllers.base import StepInfo
from ddwmmr.model import Robot

#: Planar translation axes (x, y) for the manipulability Jacobian.
PLANAR_AXES = [True, True, False, False, False, False]


def unavailable_reason() -> str | None:
    """Why the reference cannot run here (None when it can): the benchmark's skip reason."""
    try:
        import roboticstoolbox  # noqa: F401
    except ImportError as exc:
        return (
            f"roboticstoolbox-python is not installed ({exc.name or exc}); "
            "pip install 'ddwmmr[bench]' (-e '.[bench]' in a checkout) adds it"
        )
    return None


# Any: a roboticstoolbox Robot (an optional package without type hints)
def holistic_robot(robot: Robot) -> Any:
    """The ddwmmr robot as a roboticstoolbox ``Robot`` (joints ``yaw, drive, th1, th2``)."""
    from roboticstoolbox import ET, ETS, Link
    from roboticstoolbox import Robot as ToolboxRobot

    (low1, high1), (low2, high2) = robot.joint_limits
    yaw = Link(ETS(ET.Rz()), name="base0", parent=None, qlim=[-math.pi, math.pi])
    drive = Link(ETS(ET.tx()), name="base1", parent=yaw, qlim=[-10.0, 10.0])
    shoulder = Link(ETS(ET.Rz()), name="shoulder", parent=drive, qlim=[low1, high1])
    elbow = Link(ET.tx(robot.L1) * ET.Rz(), name="elbow", parent=shoulder, qlim=[low2, high2])
    tip = Link(ETS(ET.tx(robot.L2)), name="ee", parent=elbow)
    model = ToolboxRobot([yaw, drive, shoulder, elbow, tip], name="ddwmmr")
    v_max = robot.wheel_radius * robot.wheel_speed_limit
    w_max = 2.0 * v_max / robot.track_width
    speed = robot.joint_speed_limit
    model.qdlim = np.array([w_max, v_max, speed, speed])
    return model


def planar_pose(x: float, y: float, phi: float) -> np.ndarray:
    """Homogeneous transform (4 x 4) of a planar pose (m, m, rad)."""
    c, s = math.cos(phi), math.sin(phi)
    return np.array([[c, -s, 0.0, x], [s, c, 0.0, y], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


# r is Any: a roboticstoolbox Robot (an optional package without type hints)
def holistic_step(r: Any, Tep: np.ndarray) -> np.ndarray:
    """One step of the toolbox example's ``step_robot`` for an n-joint robot with the
    two base joints first: joint velocities ``qd`` (rad/s, m/s, rad/s, rad/s)."""
    import qpsolvers
    import roboticstoolbox as rtb

    wTe = r.fkine(r.q).A
    eTep = np.linalg.inv(wTe) @ Tep
    et = np.sum(np.abs(eTep[:3, -1]))  # spatial error
    Y = 0.01  # gain of the control minimisation
    Q = np.eye(r.n + 6)
    Q[: r.n, : r.n] *= Y
    Q[:2, :2] *= 1.0 / et
    Q[r.n :, r.n :] = (1.0 / et) * np.eye(6)  # slack
    v, _ = rtb.p_servo(wTe, Tep, 1.5)
    v[3:] *= 1.3
    Aeq = np.c_[r.jacobe(r.q), np.eye(6)]
    beq = v.reshape((6,))
    Ain = np.zeros((r.n + 6, r.n + 6))
    bin_ = np.zeros(r.n + 6)
    Ain[: r.n, : r.n], bin_[: r.n] = r.joint_velocity_damper(ps=0.1, pi=0.9, n=r.n)
    jacobm = r.jacobm(start=r.links[2], axes=PLANAR_AXES).reshape((r.n - 2,))
    c = np.concatenate((np.zeros(2), -jacobm, np.zeros(6)))
    bTe = r.fkine(r.q, include_base=False).A  # turn the base to face the end effector
    c[0] = -0.5 * math.atan2(bTe[1, -1], bTe[0, -1])
    lb = -np.r_[r.qdlim[: r.n], 10 * np.ones(6)]
    ub = np.r_[r.qdlim[: r.n], 10 * np.ones(6)]
    qd = qpsolvers.solve_qp(Q, c, Ain, bin_, Aeq, beq, lb=lb, ub=ub, solver="quadprog")
    if qd is None:
        return np.zeros(r.n)
    qd = qd[: r.n]
    return qd * (0.7 / et) if et > 0.5 else qd * 1.4


class HolisticController:
    """roboticstoolbox-python's holistic QP step as a ddwmmr controller (benchmark row).

    ``command`` servos the end effector to ``pose_d`` (the example is a pose servo: the
    desired velocity is not used) and returns ``u = (v, w, th1dot, th2dot)``.
    """

    name = "rtb-holistic"

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.model = holistic_robot(robot)
        self.last = StepInfo()

    def reset(self, trajectory: object, q0: np.ndarray) -> None:
        """Memoryless."""
        self.last = StepInfo()

    def command(
        self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray
    ) -> np.ndarray:
        """Base frame at (x, y, phi), base joints at 0, arm joints from q; one QP step."""
        x, y, phi, th1, th2 = (float(v) for v in q)
        model = self.model
        model.base = planar_pose(x, y, phi)
        model.q = np.array([0.0, 0.0, th1, th2])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            qd = holistic_step(model, planar_pose(*(float(v) for v in pose_d)))
        return np.array([qd[1], qd[0], qd[2], qd[3]])
