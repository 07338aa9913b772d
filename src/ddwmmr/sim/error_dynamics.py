"""First-order error loops of the closed-loop methods, built with python-control.

With the plant following the command exactly, every feedback channel of ``clrrmc-ts``
(end-effector xE, yE, phiE) and ``clrrmc-cs`` (each configuration coordinate) is an
integrator ``1/s`` (the rate command integrates into the pose) in unity negative feedback
through the gain ``K = 1/tau`` (1/s)::

    r --(+)--> K --> 1/s --+--> y          T(s) = K / (s + K)
        (-)                |
         +-----------------+

The step response ``1 - exp(-t/tau)`` is how the measured pose approaches a step in the
desired pose; the tracking error ``e = r - y`` of an initial offset decays as
``exp(-t/tau)`` (``e_dot + K e = 0``; docs/theory.md, "Error dynamics and python-control").

Bad input (a ``tau`` that is no time constant, a ``method`` without error loops, ``times``
that are not what a function asks for, a negative mass) is a one-line
:class:`~ddwmmr.errors.ParameterError` naming the parameter and the allowed range.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

# python-control ships no type hints (no py.typed): its objects are Any to mypy
import control
import numpy as np

from ddwmmr.errors import (
    DURATION_RANGE_S,
    ParameterError,
    check_bool,
    check_finite,
    check_nonnegative,
    check_positive,
    shown,
)
from ddwmmr.gains import MIN_TAU, check_gain, gains_from_tau
from ddwmmr.trajectories.base import check_times

if TYPE_CHECKING:
    import numpy.typing as npt

#: Feedback channels of each closed-loop method, in the order of its ``tau`` values.
CHANNELS = {
    "clrrmc-ts": ("xE", "yE", "phiE"),
    "clrrmc-cs": ("x", "y", "phi", "th1", "th2"),
}


def error_loop(tau: float) -> control.TransferFunction:
    """Closed loop ``K/(s + K)`` of one channel with time constant ``tau`` (s).

    Built as the unity negative feedback of ``K * (1/s)``; ``tau = inf`` (feedback off)
    gives the zero transfer function.
    """
    (gain,) = gains_from_tau(tau, 1)
    integrator = control.tf([1.0], [1.0, 0.0])
    return control.feedback(gain * integrator, 1)


def error_loops(method: str, tau: float | Sequence[float]) -> dict[str, control.TransferFunction]:
    """One :func:`error_loop` per feedback channel of ``method`` (see :data:`CHANNELS`).

    ``tau`` is one time constant (s) for every channel or one per channel
    (:data:`ddwmmr.gains.TAU_RANGE`); ``method`` one of :data:`CHANNELS`.
    """
    if not isinstance(method, str) or method not in CHANNELS:
        raise ParameterError(f"method must be one of {', '.join(CHANNELS)} (got {shown(method)})")
    names = CHANNELS[method]
    gains = gains_from_tau(tau, len(names))
    taus = [np.inf if k == 0.0 else 1.0 / k for k in gains]
    return {name: error_loop(t) for name, t in zip(names, taus)}


def step_response(tau: float, times: Sequence[float] | np.ndarray) -> np.ndarray:
    """Unit step response of :func:`error_loop` at ``times`` (s), computed by python-control.

    ``times``: at least 2 finite times, equally spaced, increasing and starting at 0 (the
    step), as python-control simulates them (:func:`check_response_times`). ``tau = inf``
    (feedback off) gives zeros at every time.
    """
    times = check_response_times(times, spaced=True)
    (gain,) = gains_from_tau(tau, 1)
    if gain == 0.0:
        # The loop is the static gain 0. python-control 0.10.2 simulates a static system by
        # assigning ndarray.shape, deprecated from NumPy 2.5 (the NumPy that Python 3.12+
        # installs), so the answer is given here rather than through it.
        return np.zeros(times.size)
    response = control.step_response(error_loop(tau), times)
    return np.asarray(response.outputs, dtype=float)


def error_response(tau: float, times: Sequence[float] | np.ndarray) -> np.ndarray:
    """Remaining fraction of an initial error at ``times`` (s): ``1 - step response``
    (``tau`` and ``times`` as in :func:`step_response`)."""
    return 1.0 - step_response(tau, times)


def closed_form_step(tau: float, times: Sequence[float] | np.ndarray) -> np.ndarray:
    """Analytic step response ``1 - exp(-t/tau)`` (dimensionless) at ``times`` (s): one
    time or a 1-D sequence, each finite and >= 0 (the step is at t = 0), in any order;
    ``tau`` as in :func:`error_loop` (``inf``: no feedback, 0 throughout)."""
    gains_from_tau(tau, 1)  # checks tau: a time constant, or inf (one, or a list of one)
    checked = check_times(times)
    if np.any(checked < 0.0):
        raise ParameterError(
            f"times must be >= 0 s (the step is at t = 0) (got {float(np.min(checked)):g})"
        )
    (value,) = np.asarray(tau, dtype=float).reshape(-1)
    return 1.0 - np.exp(-np.asarray(times, dtype=float) / float(value))


def check_response_times(times: Sequence[float] | np.ndarray, spaced: bool) -> np.ndarray:
    """``times`` (s) of a simulated response as a 1-D float array: at least 2 finite
    times, strictly increasing, starting at 0 (the step) and ending by the longest
    duration, :data:`~ddwmmr.errors.DURATION_RANGE_S` (1e9 s); with ``spaced``, equally spaced
    as python-control's linear simulation needs them (its test: every step within
    ``numpy.allclose`` of the mean step). Anything else is a one-line
    :class:`~ddwmmr.errors.ParameterError` naming ``times``; ``spaced`` must be True or
    False (else one naming ``spaced``)."""
    spaced = check_bool("spaced", spaced)
    array = check_times(times)
    wanted = "equally spaced, increasing" if spaced else "increasing"
    last = DURATION_RANGE_S[1]
    rule = (
        f"times must be at least 2 finite times (s), {wanted}, starting at 0 and ending by "
        f"{last:g} s"
    )
    if array.size < 2:
        raise ParameterError(f"{rule} (got {array.size} time{'' if array.size == 1 else 's'})")
    if array[0] != 0.0:
        raise ParameterError(f"{rule} (got a first time of {array[0]:g} s)")
    if array[-1] > last:  # python-control's simulation gave NaN from about 1e50 s
        raise ParameterError(f"{rule} (got a last time of {array[-1]:g} s)")
    steps = np.diff(array)
    if not np.all(steps > 0.0):
        index = int(np.argmin(steps > 0.0)) + 1  # times[index + 1] (from 1) goes back
        raise ParameterError(
            f"{rule} (got times[{index}] = {array[index - 1]:g} s then times[{index + 1}] = "
            f"{array[index]:g} s)"
        )
    if spaced and not np.allclose(steps, (array[-1] - array[0]) / (array.size - 1)):
        raise ParameterError(f"{rule} (got steps from {np.min(steps):g} s to {np.max(steps):g} s)")
    return array


def loop_summary(tau: float) -> dict[str, float]:
    """Pole (1/s), DC gain, and the 63 % / 95 % / 99 % settling times (s) of one channel;
    ``tau`` (s) as in :func:`error_loop` but finite (``inf`` is no loop: no pole)."""
    (gain,) = gains_from_tau(tau, 1)
    if gain == 0.0:
        raise ParameterError(
            f"tau must be a finite time constant for a loop summary, >= {MIN_TAU:g} s (inf "
            "is no feedback: no pole to summarise) (got inf)"
        )
    loop = error_loop(tau)
    (pole,) = np.real(control.poles(loop))
    return {
        "tau_s": float(tau),
        "pole_1_s": float(pole),
        "dc_gain": float(np.real(control.dcgain(loop))),
        "t63_s": float(tau),
        "t95_s": float(tau * np.log(20.0)),
        "t99_s": float(tau * np.log(100.0)),
    }


# -- the thesis plant's velocity-tracking loop (qp on the thesis plant, mpc fallback) ---------
#
# Translation (rotation is the same with I, c2 and the torque): the base obeys
# ``m vdot + c v = F`` and the loop commands ``F = c v_d + k m (v_d - v)`` (damping
# feed-forward plus a proportional term of bandwidth k, 1/s), so
#
#     V(s) / V_d(s) = (c + k m) / (m s + c + k m)
#
# a first-order loop with its pole at -(c/m + k): the feed-forward makes the steady state
# exact, k sets the speed. Large steps saturate the wheel forces (|F| <= 2 F_max), and the
# response is then the plant's own open-loop acceleration.


def velocity_loop(mass: float, damping: float, bandwidth: float) -> control.TransferFunction:
    """Closed loop ``v / v_d`` of the velocity-tracking loop (kg, N s/m, 1/s), linear.

    ``mass`` (kg) finite and > 0, ``damping`` (N s/m) finite and >= 0, ``bandwidth``
    (1/s) a gain in [0, :data:`ddwmmr.gains.MAX_GAIN`] (:func:`check_velocity_loop`).
    """
    check_velocity_loop(mass, damping, bandwidth)
    plant = control.tf([1.0], [mass, damping])
    gain = bandwidth * mass
    return control.minreal((damping + gain) * control.feedback(plant, gain), verbose=False)


def velocity_loop_summary(mass: float, damping: float, bandwidth: float) -> dict[str, float]:
    """Pole (1/s), time constant and 95 % settling time (s) of :func:`velocity_loop`
    (its arguments, with ``damping`` or ``bandwidth`` > 0: else there is no pole)."""
    check_velocity_loop(mass, damping, bandwidth)
    if float(damping) == 0.0 and float(bandwidth) == 0.0:
        raise ParameterError(
            "bandwidth must be > 0 1/s when damping is 0 (no force, no loop to summarise) (got 0)"
        )
    loop = velocity_loop(mass, damping, bandwidth)
    (pole,) = np.real(control.poles(loop))
    return {
        "pole_1_s": float(pole),
        "tau_s": float(-1.0 / pole),
        "t95_s": float(-np.log(20.0) / pole),
        "dc_gain": float(np.real(control.dcgain(loop))),
    }


def saturated_velocity_step(
    mass: float,
    damping: float,
    bandwidth: float,
    force_limit: float,
    step: float,
    times: Sequence[float] | np.ndarray,
) -> np.ndarray:
    """Speed (m/s) after a step of the command from rest to ``step`` (m/s), with the total
    force clipped to ``+-force_limit`` (N): a python-control nonlinear I/O system.

    ``mass``, ``damping``, ``bandwidth`` as in :func:`velocity_loop`; ``force_limit``
    (N) finite and > 0, ``step`` finite; ``times`` (s) as :func:`check_response_times`
    with ``spaced=False`` (the step at t = 0).
    """
    check_velocity_loop(mass, damping, bandwidth)
    check_positive("force_limit", force_limit)
    check_finite("step", step)
    times = check_response_times(times, spaced=False)

    def update(
        t: float, x: npt.NDArray[np.float64], u: npt.NDArray[np.float64], params: object
    ) -> list[float]:
        force = damping * u[0] + bandwidth * mass * (u[0] - x[0])
        force = min(force_limit, max(-force_limit, force))
        return [(force - damping * x[0]) / mass]

    system = control.nlsys(update, None, inputs=1, outputs=1, states=1, name="velocity_loop")
    response = control.input_output_response(
        system, times, np.full_like(times, step), X0=[0.0], solve_ivp_kwargs={"max_step": 0.005}
    )
    return np.asarray(response.outputs, dtype=float).ravel()


def check_velocity_loop(mass: float, damping: float, bandwidth: float) -> None:
    """The arguments of :func:`velocity_loop`: ``mass`` (kg) finite and > 0, ``damping``
    (N s/m) finite and >= 0, ``bandwidth`` (1/s) a gain in [0, 1e4]
    (:func:`ddwmmr.gains.check_gain`); else a one-line
    :class:`~ddwmmr.errors.ParameterError` naming the argument."""
    check_positive("mass", mass)
    check_nonnegative("damping", damping)
    check_gain("bandwidth", bandwidth, zero=True)
