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
    """Closed loop ``v / v_d`` of the velocity-tracking loop (kg, N s/m, 1/s), linear."""
    plant = control.tf([1.0], [mass, damping])
    gain = bandwidth * mass
    return control.minreal((damping + gain) * control.feedback(plant, gain), verbose=False)


def velocity_loop_summary(mass: float, damping: float, bandwidth: float) -> dict[str, float]:
    """Pole (1/s), time constant and 95 % settling time (s) of :func:`velocity_loop`."""
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
    force clipped to ``+-force_limit`` (N): a python-control nonlinear I/O system."""

    def update(t, x, u, params):
        force = damping * u[0] + bandwidth * mass * (u[0] - x[0])
        force = min(force_limit, max(-force_limit, force))
        return [(force - damping * x[0]) / mass]

    system = control.nlsys(update, None, inputs=1, outputs=1, states=1, name="velocity_loop")
    times = np.asarray(times, dtype=float)
    response = control.input_output_response(
        system, times, np.full_like(times, step), X0=[0.0], solve_ivp_kwargs={"max_step": 0.005}
    )
    return np.asarray(response.outputs, dtype=float).ravel()
