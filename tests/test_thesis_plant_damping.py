"""The thesis plant at a small damping c1 or c2: the first-order step's closed form lost
its digits there (``1 - exp(-dt / tau)`` rounded), and a base with c1 = 1e-9 N s/m was
driven 164 m off the ellipse, the run reported as finite and not diverged."""

from __future__ import annotations

import decimal
import warnings

import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.plants.thesis import SERIES_BELOW, first_order_step


def exact(x0, u, gain, tau, dt):
    """The step's closed form in 60-digit decimal arithmetic."""
    with decimal.localcontext() as context:
        context.prec = 60
        x0, u, gain, tau, dt = (decimal.Decimal(v) for v in (x0, u, gain, tau, dt))
        x_ss, decay = gain * u, (-dt / tau).exp()
        return float(x_ss + (x0 - x_ss) * decay), float(x_ss * dt + (x0 - x_ss) * tau * (1 - decay))


@pytest.mark.parametrize(
    ("s", "rel"),
    [(1e-12, 1e-12), (1e-8, 1e-12), (0.999 * SERIES_BELOW, 1e-12), (1.001 * SERIES_BELOW, 1e-5)],
)
def test_the_step_is_exact_to_rounding_at_a_small_damping(s, rel):
    """tau = m / c, gain = 1 / c for a damping c with dt / tau = s: below SERIES_BELOW
    the series is exact to rounding; the closed form's integral was off by ~1e-16 / s^2
    of itself (1 at s = 1e-8), and above the threshold it still is (1e-6 there, kept so
    that every run at the usual dampings and steps stays as it was)."""
    mass, dt, u, x0 = 22.5, 0.02, 10.0, 0.3
    damping = s * mass / dt
    step = first_order_step(x0, u, 1.0 / damping, mass / damping, dt)
    assert step == pytest.approx(exact(x0, u, 1.0 / damping, mass / damping, dt), rel=rel)


def test_a_vanishing_damping_gives_the_undamped_step():
    """dt / tau -> 0: xdot = (gain / tau) u, x grows by u dt / m, its integral x0 dt +
    u dt^2 / (2 m)."""
    mass, dt, u, x0 = 22.5, 0.02, 10.0, 0.3
    x, integral = first_order_step(x0, u, 1e300, mass * 1e300, dt)
    assert (x, integral) == pytest.approx((x0 + u * dt / mass, x0 * dt + u * dt * dt / mass / 2))


def test_the_series_and_the_closed_form_meet_at_the_threshold():
    mass, dt, u, x0 = 22.5, 0.02, -7.0, 1.1
    below = SERIES_BELOW * (1 - 1e-9) * mass / dt
    above = SERIES_BELOW * (1 + 1e-9) * mass / dt
    x1, i1 = first_order_step(x0, u, 1.0 / below, mass / below, dt)
    x2, i2 = first_order_step(x0, u, 1.0 / above, mass / above, dt)
    assert x1 == pytest.approx(x2, rel=1e-9)
    assert i1 == pytest.approx(i2, rel=1e-5)  # the closed form's own error there: ~1e-6


def test_a_nearly_undamped_thesis_plant_tracks_as_a_lightly_damped_one():
    """c1 = 1e-9 N s/m gave an RMS error of 569 m (the base driven 164 m away), c1 = 1e-16
    one of 3e14 m, neither marked diverged; every damping from 1e-3 down now tracks with
    the same error to 1e-6 m."""
    errors = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for damping in (1e-3, 1e-9, 1e-16):
            summary = simulate(
                Robot(),
                Ellipse(),
                "clrrmc-ts",
                duration=5.0,
                plant="thesis",
                plant_options={"c1": damping, "c2": damping},
            ).summary
            assert summary["verdict"] == "tracked"
            errors.append(summary["rms_position_error_m"])
    assert errors == pytest.approx([errors[0]] * 3, abs=1e-6)
    assert errors[0] < 0.03
