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
``exp(-t/tau)`` (SPEC §4: ``e_dot + K e = 0``).
"""

from __future__ import annotations

from collections.abc import Sequence

import control
import numpy as np

from ddwmmr.gains import gains_from_tau

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

    ``tau`` is one time constant (s) for every channel or one per channel.
    """
    if method not in CHANNELS:
        raise ValueError(f"method must be one of {', '.join(CHANNELS)} (got {method!r})")
    names = CHANNELS[method]
    gains = gains_from_tau(tau, len(names))
    taus = [np.inf if k == 0.0 else 1.0 / k for k in gains]
    return {name: error_loop(t) for name, t in zip(names, taus)}


def step_response(tau: float, times: Sequence[float] | np.ndarray) -> np.ndarray:
    """Unit step response of :func:`error_loop` at ``times`` (s), computed by python-control.

    ``times`` must be increasing and start at 0.
    """
    times = np.asarray(times, dtype=float)
    response = control.step_response(error_loop(tau), times)
    return np.asarray(response.outputs, dtype=float)


def error_response(tau: float, times: Sequence[float] | np.ndarray) -> np.ndarray:
    """Remaining fraction of an initial error at ``times`` (s): ``1 - step response``."""
    return 1.0 - step_response(tau, times)


def closed_form_step(tau: float, times: Sequence[float] | np.ndarray) -> np.ndarray:
    """Analytic step response ``1 - exp(-t/tau)`` (dimensionless)."""
    return 1.0 - np.exp(-np.asarray(times, dtype=float) / float(tau))


def loop_summary(tau: float) -> dict[str, float]:
    """Pole (1/s), DC gain, and the 63 % / 95 % / 99 % settling times (s) of one channel."""
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
