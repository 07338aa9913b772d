"""Open-loop redundancy resolution controllers: ``pi``, ``ats``, ``ap``.

They feed the desired end-effector velocity forward through an inverse of the Jacobian and
ignore the pose error, so an initial offset is kept (and integration errors accumulate).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

import numpy as np

from ddwmmr.controllers.base import StepInfo, register_controller
from ddwmmr.controllers.inputs import check_command, check_inputs, check_start
from ddwmmr.errors import ParameterError, shown
from ddwmmr.gains import check_gain
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import AUX_ROWS, whole_turns
from ddwmmr.resolution import kernels

if TYPE_CHECKING:
    import numpy.typing as npt

#: An input ``(v, w, th1dot, th2dot)`` as floats (m/s, rad/s, rad/s, rad/s).
Input = tuple[float, float, float, float]


class ResolvedRate(ABC):
    """Shared by the resolved-rate methods (these and ``clrrmc-ts``): robot lengths,
    singularity handling, last step info, and ``command`` as the validated ``law``.

    ``singularity_threshold`` is the smallest singular value below which the inverse is
    damped and ``damping`` the damping factor at the singularity (see
    :mod:`ddwmmr.resolution.kernels`: with ``damping >= singularity_threshold`` the command
    is bounded by a documented constant times the desired speed at every state). None, the
    default, is the robot's own value (:func:`~ddwmmr.resolution.kernels.damping_options`:
    0.05 and 0.05, in the robot's length unit on every robot).
    """

    name = "base"

    def __init__(
        self,
        robot: Robot,
        singularity_threshold: float | None = None,
        damping: float | None = None,
    ) -> None:
        self.robot = robot
        self.L1, self.L2 = robot.L1, robot.L2
        self.threshold, self.damping = kernels.damping_options(
            robot.L1, singularity_threshold, damping
        )
        self.last = StepInfo()

    def reset(self, trajectory: object, q0: np.ndarray) -> None:
        """Nothing to prepare: these methods are memoryless (the feedback, if any, uses
        the measured configuration). ``q0``, the start ``[x, y, phi, th1, th2]`` (m, rad),
        must be 5 finite numbers (:func:`~ddwmmr.controllers.inputs.check_start`)."""
        check_start(q0)
        self.last = StepInfo()

    def command(
        self, t: float, q: npt.ArrayLike, pose_d: npt.ArrayLike, velocity_d: npt.ArrayLike
    ) -> np.ndarray:
        """Input ``u = (v, w, th1dot, th2dot)`` (m/s, rad/s, rad/s, rad/s) for the desired
        end-effector velocity (world frame, m/s, rad/s); the arguments are validated."""
        t, q, pose_d, velocity_d = check_inputs(t, q, pose_d, velocity_d)
        u, singular = self.law(t, q, pose_d, velocity_d)
        check_command(u, q, pose_d)
        self.last = StepInfo(singular=singular)
        return np.array(u)

    @abstractmethod
    def law(
        self, t: float, q: list[float], pose_d: list[float], velocity_d: list[float]
    ) -> tuple[Input, bool]:
        """The control law on lists of floats: ``(u, singular)``, no validation, no state
        change (the integrator evaluates it at its stages; see :mod:`ddwmmr.sim.loop`)."""


def check_aux(aux: str) -> str:
    """Validate the auxiliary constraint name of the augmented task space (one of
    :data:`~ddwmmr.model.kinematics.AUX_ROWS`; anything else, a list too, is a
    :class:`ParameterError`)."""
    if not isinstance(aux, str) or aux not in AUX_ROWS:
        raise ParameterError(f"aux must be one of {', '.join(AUX_ROWS)} (got {shown(aux)})")
    return aux


@register_controller("pi")
class PseudoinverseController(ResolvedRate):
    """RR-PI: pseudoinverse resolution qdot = J^# Xd_dot (open loop)."""

    def law(
        self, t: float, q: list[float], pose_d: list[float], velocity_d: list[float]
    ) -> tuple[Input, bool]:
        """Minimum-norm input for the desired end-effector velocity (m/s, rad/s)."""
        _, _, phi, th1, th2 = q
        xd, yd, pd = velocity_d
        return kernels.pseudoinverse(
            self.L1, self.L2, phi, th1, th2, xd, yd, pd, self.threshold, self.damping
        )


@register_controller("ats")
class AugmentedTaskSpaceController(ResolvedRate):
    """RR-ATS: augmented task space, one auxiliary row (aux = sum | shoulder), open loop."""

    def __init__(self, robot: Robot, aux: str = "shoulder", **kwargs: float | None) -> None:
        super().__init__(robot, **kwargs)
        self.aux = check_aux(aux)

    def law(
        self, t: float, q: list[float], pose_d: list[float], velocity_d: list[float]
    ) -> tuple[Input, bool]:
        """Input solving the square augmented system for the desired velocity."""
        _, _, phi, th1, th2 = q
        xd, yd, pd = velocity_d
        return kernels.ats(
            self.L1, self.L2, phi, th1, th2, xd, yd, pd, self.aux, self.threshold, self.damping
        )


@register_controller("ap")
class ArtificialPotentialController(ResolvedRate):
    """RR-AP: pseudoinverse plus null-space descent of V = K1 th1^2 + K2 th2^2 + K3 phi^2."""

    def __init__(
        self,
        robot: Robot,
        K1: float = 1.0,
        K2: float = 0.25,
        K3: float = 0.66,
        **kwargs: float | None,
    ) -> None:
        super().__init__(robot, **kwargs)
        self.K1 = check_gain("K1", K1, zero=True)
        self.K2 = check_gain("K2", K2, zero=True)
        self.K3 = check_gain("K3", K3, zero=True)
        self._turns = (0.0, 0.0)

    def reset(self, trajectory: object, q0: np.ndarray) -> None:
        """Count phi and th1 of the potential from the start's own turn: the whole turns
        in ``q0``'s phi and th1 (beyond (-pi, pi]) are subtracted for the run, so a start
        given whole turns apart is the same physical pose and gives the same run (a start
        within (-pi, pi] subtracts nothing)."""
        super().reset(trajectory, q0)
        self._turns = (whole_turns(float(q0[2])), whole_turns(float(q0[3])))

    def law(
        self, t: float, q: list[float], pose_d: list[float], velocity_d: list[float]
    ) -> tuple[Input, bool]:
        """Pseudoinverse input plus the projected potential descent (K2 has no effect: th2
        cannot move without moving the end effector, so it is not in the null space)."""
        _, _, phi, th1, th2 = q
        xd, yd, pd = velocity_d
        (v, w, t1, t2), singular = kernels.pseudoinverse(
            self.L1, self.L2, phi, th1, th2, xd, yd, pd, self.threshold, self.damping
        )
        phi_turns, th1_turns = self._turns
        k = kernels.null_space_rate(
            phi, th1, 2.0 * self.K3 * (phi - phi_turns), 2.0 * self.K1 * (th1 - th1_turns)
        )
        return (v, w + k, t1 - k, t2), singular
