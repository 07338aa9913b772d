"""Closed-loop resolved-rate motion control: ``clrrmc-cs`` and ``clrrmc-ts``.

Gains are given as time constants ``tau`` (s): ``K = 1/tau``. The error dynamics are then
``e_dot + K e = 0``, i.e. each error decays as ``exp(-t / tau)`` while the plant follows the
command (see ``ddwmmr.sim.error_dynamics.error_loop`` for the python-control model).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ddwmmr.controllers.base import StepInfo, register_controller
from ddwmmr.controllers.inputs import check_command, check_inputs, check_start
from ddwmmr.controllers.resolved_rate import Input, ResolvedRate, check_aux
from ddwmmr.errors import MAX_STEPS, ParameterError, check_range, check_step_count
from ddwmmr.gains import gains_from_tau
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import check_angles, principal_angle, refuse_angles, wrap_angle
from ddwmmr.resolution import kernels
from ddwmmr.resolution.reference import ReferenceTrajectory, start_configuration
from ddwmmr.trajectories.base import require_trajectory

if TYPE_CHECKING:
    import numpy.typing as npt

#: Default time constant (s) of every closed-loop channel.
DEFAULT_TAU = 0.5
#: Range of the reference's integration step (s): finer than 0.1 ms buys nothing (the
#: reference is RK4), coarser than 1 s does not resolve any trajectory of the library.
MIN_REFERENCE_STEP, MAX_REFERENCE_STEP = 1e-4, 1.0


@register_controller("clrrmc-ts")
class TaskSpaceController(ResolvedRate):
    """CLRRMC-TS: qdot = J_aug^-1 [Xd_dot + K (Xd - X)], feedback on xE, yE, phiE.

    The orientation error ``phiE_d - phiE`` is wrapped to [-pi, pi) (one turn of the end
    effector is no error), so a desired heading given wrapped or unwrapped gives the same
    run. ``tau`` is one time constant (s) or three (x, y, phi); ``inf`` switches a channel
    off (the slides' K3 = 0 is ``tau = (0.5, 0.5, inf)``).
    """

    def __init__(
        self,
        robot: Robot,
        tau: float | Sequence[float] = DEFAULT_TAU,
        aux: str = "shoulder",
        singularity_threshold: float | None = None,
        damping: float | None = None,
    ) -> None:
        self.kx, self.ky, self.kphi = gains_from_tau(tau, 3)
        self.aux = check_aux(aux)
        super().__init__(robot, singularity_threshold, damping)

    @property
    def feedback_gains(self) -> tuple[float, float, float]:
        """The gains K (1/s) of the xE, yE, phiE error loops ``e' = -K e`` (0: off); the
        run checks them against its control step (:func:`ddwmmr.gains.gain_step_warning`)."""
        return self.kx, self.ky, self.kphi

    def law(
        self, t: float, q: list[float], pose_d: list[float], velocity_d: list[float]
    ) -> tuple[Input, bool]:
        """Input for the desired velocity plus the pose-error correction (see
        :meth:`ResolvedRate.law`)."""
        x, y, phi, th1, th2 = q
        L1, L2 = self.L1, self.L2
        a1 = phi + th1
        a12 = a1 + th2
        try:
            xe = x + L1 * math.cos(a1) + L2 * math.cos(a12)
            ye = y + L1 * math.sin(a1) + L2 * math.sin(a12)
        except ValueError:  # a sum overflowed: angles out of range (kernels.ats checks them)
            refuse_angles(phi, th1, th2)
        px, py, pphi = pose_d
        vx, vy, vphi = velocity_d
        return kernels.ats(
            L1,
            L2,
            phi,
            th1,
            th2,
            vx + self.kx * (px - xe),
            vy + self.ky * (py - ye),
            vphi + self.kphi * wrap_angle(pphi - a12),
            self.aux,
            self.threshold,
            self.damping,
        )


@register_controller("clrrmc-cs")
class ConfigurationSpaceController:
    """CLRRMC-CS: qdot = qdot_d + K (q_d - q) around an ATS reference q_d(t).

    A step counts as singular (``last.singular``) when the reference segment it looks up
    was integrated with damping (the reference passed near cos th1 = 0 there). The errors
    of phi, th1 and th2 are taken in (-pi, pi] (:func:`principal_angle`): a configuration
    whole turns away from the reference is no error. ``singularity_threshold`` and
    ``damping`` damp the reference as in :class:`ResolvedRate` (None: the robot's own).
    """

    def __init__(
        self,
        robot: Robot,
        tau: float | Sequence[float] = DEFAULT_TAU,
        aux: str = "shoulder",
        reference_step: float = 0.01,
        singularity_threshold: float | None = None,
        damping: float | None = None,
    ) -> None:
        self.robot = robot
        self.gains = gains_from_tau(tau, 5)
        self.aux = check_aux(aux)
        self.reference_step = check_range(
            "reference_step", reference_step, MIN_REFERENCE_STEP, MAX_REFERENCE_STEP, "s"
        )
        self.threshold, self.damping = kernels.damping_options(
            robot.L1, singularity_threshold, damping
        )
        self.reference: ReferenceTrajectory | None = None
        self.last = StepInfo()

    @property
    def feedback_gains(self) -> tuple[float, ...]:
        """The gains K (1/s) of the x, y, phi, th1, th2 error loops ``e' = -K e`` (0: off);
        the run checks them against its control step (:func:`ddwmmr.gains.gain_step_warning`)."""
        return self.gains

    def reset(self, trajectory: object, q0: np.ndarray) -> None:
        """Build the reference q_d(t) from :func:`start_configuration` of ``trajectory``.

        The reference starts at the home arm pose placed on the trajectory start, which is
        also where :func:`ddwmmr.simulate` starts before applying its initial offset.
        ``q0`` (5 finite numbers, m and rad) is checked but not used.
        """
        require_trajectory(trajectory)
        check_start(q0)
        period = getattr(trajectory, "duration", 0.0)
        self._check_reference_steps(period)
        self.reference = ReferenceTrajectory(
            self.robot,
            trajectory,
            start_configuration(self.robot, trajectory),
            self.aux,
            self.reference_step,
            self.threshold,
            self.damping,
            horizon=period,  # one period up front
        )
        self.last = StepInfo()

    def _check_reference_steps(self, period: float) -> None:
        """At most :data:`~ddwmmr.errors.MAX_STEPS` reference steps over ``period`` (s),
        with the round-off slack of a run's step cap (:func:`~ddwmmr.errors.check_step_count`:
        a period and step read from decimal text may land a few ulps past the cap); else a
        one-line :class:`ParameterError` naming ``reference_step``."""
        step = self.reference_step
        if not period > step:  # at most one step: within the cap
            return
        try:
            check_step_count(period, step)
        except ParameterError:
            raise ParameterError(
                f"reference_step: {period:g} s / {step:g} s is more than "
                f"{MAX_STEPS} reference steps; use a larger reference_step"
            ) from None

    def command(
        self, t: float, q: npt.ArrayLike, pose_d: npt.ArrayLike, velocity_d: npt.ArrayLike
    ) -> np.ndarray:
        """Reference rate plus configuration-error feedback, projected on the inputs.

        The sideways part of the commanded base velocity cannot be produced; it is reported
        in ``last.nonholonomic_residual`` (m/s).
        """
        t, q, pose_d, velocity_d = check_inputs(t, q, pose_d, velocity_d)
        check_angles(q)
        u, residual, damped = self._input(t, q)
        check_command(u, q, pose_d)
        self.last = StepInfo(singular=damped, nonholonomic_residual=residual)
        return np.array(u)

    def law(
        self, t: float, q: list[float], pose_d: list[float], velocity_d: list[float]
    ) -> tuple[Input, bool]:
        """The control law on lists of floats: ``(u, singular)``, no validation (the
        integrator evaluates it at its stages; see :mod:`ddwmmr.sim.loop`)."""
        u, _, damped = self._input(t, q)
        return u, damped

    def _input(self, t: float, q: list[float]) -> tuple[Input, float, bool]:
        """``(u, residual, damped)``: the reference rate plus configuration feedback,
        projected on the inputs, its sideways base part (m/s) that the drive cannot
        produce, and whether the reference segment looked up was integrated with damping."""
        reference = self.reference
        if reference is None:
            raise RuntimeError("clrrmc-cs needs reset(trajectory, q0) before command()")
        q_ref, qdot_ref = reference(t)
        error = [r - a for r, a in zip(q_ref, q)]
        # whole turns of phi, th1 or th2 are no error: a start given one turn apart is the
        # same physical pose (and the same run)
        error[2:] = [principal_angle(e) for e in error[2:]]
        qdot = [d + k * e for d, k, e in zip(qdot_ref, self.gains, error)]
        c, s = math.cos(q[2]), math.sin(q[2])
        u = (qdot[0] * c + qdot[1] * s, qdot[2], qdot[3], qdot[4])
        return u, -qdot[0] * s + qdot[1] * c, reference.last_damped
