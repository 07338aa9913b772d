"""python-control error loops: closed form, and the simulated closed loop follows them."""

from __future__ import annotations

import math
import warnings

import control
import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.sim.error_dynamics import (
    closed_form_step,
    error_loop,
    error_loops,
    error_response,
    loop_summary,
    step_response,
)

TAUS = (0.2, 0.5, 1.0, 2.0)


@pytest.mark.parametrize("tau", TAUS)
def test_loop_is_first_order_with_pole_at_minus_one_over_tau(tau: float) -> None:
    loop = error_loop(tau)
    np.testing.assert_allclose(control.poles(loop), [-1.0 / tau], rtol=1e-12)
    assert float(np.real(control.dcgain(loop))) == pytest.approx(1.0, abs=1e-12)
    num, den = loop.num[0][0], loop.den[0][0]
    np.testing.assert_allclose(num / den[0], [1.0 / tau], rtol=1e-12)
    np.testing.assert_allclose(den / den[0], [1.0, 1.0 / tau], rtol=1e-12)


@pytest.mark.parametrize("tau", TAUS)
def test_step_response_matches_closed_form(tau: float) -> None:
    times = np.linspace(0.0, 6.0 * tau, 601)
    np.testing.assert_allclose(step_response(tau, times), closed_form_step(tau, times), atol=1e-9)
    at_tau = step_response(tau, [0.0, tau])[1]
    assert at_tau == pytest.approx(1.0 - math.exp(-1.0), abs=1e-9)
    np.testing.assert_allclose(
        error_response(tau, times), np.exp(-times / tau), atol=1e-9, rtol=0.0
    )


def test_summary_and_channels() -> None:
    summary = loop_summary(0.5)
    assert summary["pole_1_s"] == pytest.approx(-2.0)
    assert summary["t95_s"] == pytest.approx(0.5 * math.log(20.0))
    loops = error_loops("clrrmc-ts", [0.5, 1.0, math.inf])
    assert list(loops) == ["xE", "yE", "phiE"]
    assert control.poles(loops["yE"])[0] == pytest.approx(-1.0)
    final = step_response(math.inf, [0.0, 1.0])
    np.testing.assert_allclose(final, 0.0)  # feedback off: the error never decays
    assert list(error_loops("clrrmc-cs", 0.3)) == ["x", "y", "phi", "th1", "th2"]
    with pytest.raises(ValueError):
        error_loops("pi", 0.5)


def test_feedback_off_gives_zeros_without_simulating_a_static_system(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # tau = inf makes the loop the static gain 0; python-control 0.10.2 simulates a static
    # system by assigning ndarray.shape, deprecated from NumPy 2.5 (Python 3.12+ installs
    # it), so the answer must not come from control.step_response.
    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("control.step_response called for the static loop")

    monkeypatch.setattr(control, "step_response", refuse)
    times = np.linspace(0.0, 2.0, 5)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        response = step_response(math.inf, times)
        remaining = error_response(math.inf, times)
    assert response.shape == (5,)
    assert response.dtype == np.float64
    np.testing.assert_array_equal(response, np.zeros(5))
    np.testing.assert_array_equal(remaining, np.ones(5))  # the error never decays


@pytest.mark.parametrize("tau", (0.2, 0.5, 1.0))
def test_simulated_position_error_decays_like_the_loop(tau: float) -> None:
    """clrrmc-ts on the ellipse, RK4, dt = 0.02 s: e(t)/e(0) = exp(-t/tau).

    Measured relative deviation at t = tau: 8e-7 (tau 0.2), 1e-8 (0.5), 1e-9 (1.0). The
    bound is 1e-3; it holds while no speed limit saturates (see docs/theory.md).
    """
    result = simulate(Robot(), Ellipse(), "clrrmc-ts", tau=tau, duration=3.0 * tau)
    ts = result.timeseries
    assert result.summary["saturated_steps"] == 0
    times, error = ts["t"], ts["position_error_m"]
    ratio = error / error[0]
    at_tau = int(np.argmin(np.abs(times - tau)))
    assert times[at_tau] == pytest.approx(tau)
    assert ratio[at_tau] == pytest.approx(math.exp(-1.0), rel=1e-3)
    np.testing.assert_allclose(ratio, error_response(tau, times), atol=1e-3)


# -- the thesis plant's velocity-tracking loop -----------------------------------------------


@pytest.mark.parametrize("bandwidth", (2.0, 10.0))
def test_velocity_loop_is_first_order_with_the_feed_forward_making_it_exact(bandwidth):
    from ddwmmr.sim.error_dynamics import velocity_loop, velocity_loop_summary

    mass, damping = 15.0, 15.0
    loop = velocity_loop(mass, damping, bandwidth)
    pole = -(damping / mass + bandwidth)
    np.testing.assert_allclose(control.poles(loop), [pole], rtol=1e-12)
    assert float(np.real(control.dcgain(loop))) == pytest.approx(1.0, abs=1e-12)
    times = np.linspace(0.0, 1.0, 201)
    response = np.asarray(control.step_response(loop, times).outputs).ravel()
    np.testing.assert_allclose(response, 1.0 - np.exp(pole * times), atol=1e-9)
    assert velocity_loop_summary(mass, damping, bandwidth)["tau_s"] == pytest.approx(-1 / pole)


def test_saturated_velocity_step_matches_the_thesis_plant_under_the_scenario_loop():
    """The nonlinear python-control model of the loop and the real plant driven by the
    thesis plant's VelocityServo agree; small steps follow the linear loop."""
    from ddwmmr.plants.thesis import ThesisPlant, ThesisState
    from ddwmmr.plants.thesis import VelocityServo as VelocityLoop
    from ddwmmr.sim.error_dynamics import saturated_velocity_step, velocity_loop

    robot = Robot().with_payload(3.0)
    plant = ThesisPlant(robot)
    loop = VelocityLoop(plant)
    dt, steps = 0.001, 2000
    times = np.arange(steps + 1) * dt
    for step in (0.05, 1.0):
        state = ThesisState(0.0, 0.0, 0.0, 0.0, 1.5)
        speeds = [0.0]
        for _ in range(steps):
            left, right = loop.forces(state, step, 0.0)
            plant.advance(state, left, right, (0.0, 1.5), dt)
            speeds.append(state.v)
        model = saturated_velocity_step(plant.mass, plant.c1, 10.0, 20.0, step, times)
        np.testing.assert_allclose(model, speeds, atol=2e-3 * step + 1e-4)
    small = saturated_velocity_step(plant.mass, plant.c1, 10.0, 20.0, 0.05, times)
    linear = 0.05 * np.asarray(
        control.step_response(velocity_loop(15.0, 15.0, 10.0), times).outputs
    )
    np.testing.assert_allclose(small, linear.ravel(), atol=1e-5)
    large = saturated_velocity_step(plant.mass, plant.c1, 10.0, 20.0, 1.0, times)
    assert large[200] < 0.5 * (1.0 - math.exp(-11.0 * 0.2))  # force-limited: slower
