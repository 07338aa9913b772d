"""Limits said at their edge: a run of exactly MAX_STEPS steps whose duration / dt is
off by round-off, the heaviest payload of a small robot (below a gram), and errors.png of a
near-constant error."""

from __future__ import annotations

import math
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest

from ddwmmr import Robot, load_trajectory
from ddwmmr.errors import MAX_STEPS, ParameterError, check_step_count
from ddwmmr.model.stability import max_payload
from ddwmmr.reports.plots import plot_errors
from ddwmmr.sim.simulate import simulate, tipping_message
from scaled_robots import TWENTIETH

# -- the step cap ----------------------------------------------------------------------


def test_a_run_of_exactly_max_steps_passes_despite_round_off():
    quotient = 600.0 / 0.0006
    assert quotient > MAX_STEPS  # the float quotient is one ulp above the cap
    assert check_step_count(600.0, 0.0006) == MAX_STEPS
    assert check_step_count(1000.0, 0.001) == MAX_STEPS


@pytest.mark.parametrize(("duration", "dt"), [(600.0, 0.0005999), (1000000.001, 1.0)])
def test_a_real_excess_is_still_refused(duration, dt):
    with pytest.raises(ParameterError, match=r"duration / dt must be <= 1000000"):
        check_step_count(duration, dt)


# -- the heaviest payload of a small robot ---------------------------------------------

#: The default robot a twentieth as long (masses by the cube): it holds under a gram.
TINY = TWENTIETH


def _s(robot: Robot, payload: float) -> float:
    return robot.with_payload(payload).stability(np.zeros(5))[2]


def test_a_limit_below_a_gram_is_named_to_four_digits():
    limit = max_payload(TINY, 0.0, 0.0)
    assert limit == pytest.approx(0.0005955, abs=1e-10)  # was rounded down to 0 kg
    assert _s(TINY, limit) > 1.0  # a bound the user may type back
    assert _s(TINY, limit + 1e-7) <= 1.0  # the next four-digit payload tips
    message = tipping_message(TINY.with_payload(0.0007), np.zeros(5), start="--offset")
    assert "holds at most 0.0005955 kg" in message


def test_limits_of_a_kilogram_and_more_stay_in_grams():
    limit = max_payload(Robot(), 0.0, 0.0)
    assert limit == pytest.approx(4.764, abs=1e-12)
    assert limit == math.floor(limit * 1e3) / 1e3


# -- errors.png of a near-constant error -----------------------------------------------


def _labels(ax) -> list[str]:
    low, high = ax.get_ylim()
    ticks = list(ax.yaxis.get_major_ticks()) + list(ax.yaxis.get_minor_ticks())
    return [
        t.label1.get_text()
        for t in ticks
        if low <= t.get_loc() <= high and t.label1.get_visible() and t.label1.get_text()
    ]


def test_a_constant_error_has_readable_axes():
    run = simulate(None, load_trajectory("ellipse"), "ats")
    error = run.timeseries["position_error_m"]
    assert error.max() < 1.000001 * error.min()  # the near-constant case
    fig = plot_errors(run)
    fig.canvas.draw()
    position, orientation = fig.axes
    low, high = position.get_ylim()
    assert (low, high) == pytest.approx((1e-2, 1e-1), rel=1e-12)  # whole decades around it
    assert len(_labels(position)) >= 2
    assert len(set(_labels(position))) == len(_labels(position))  # no tick reads alike
    assert orientation.yaxis.get_offset_text().get_text() == ""
    low, high = orientation.get_ylim()
    assert high - low == pytest.approx(0.01 * 0.0260735, rel=1e-4)
    labels = _labels(orientation)
    assert len(labels) >= 3 and len(set(labels)) == len(labels)
    assert all(float(text.replace("\N{MINUS SIGN}", "-")) < -0.0259 for text in labels)
    plt.close(fig)


def test_varying_errors_keep_matplotlibs_limits():
    t = np.linspace(0.0, 10.0, 201)
    series = {
        "t": t,
        "position_error_m": 0.03 * np.exp(0.22 * t),  # a factor of 9: under a decade
        "orientation_error_rad": -0.026 + 0.002 * np.sin(t),  # 8 % of its level
    }
    fig = plot_errors(SimpleNamespace(timeseries=series, summary={}))
    plain, (a, b) = plt.subplots(2, 1)
    a.semilogy(t, series["position_error_m"])
    b.plot(t, series["orientation_error_rad"])
    assert fig.axes[0].get_ylim() == pytest.approx(a.get_ylim(), rel=1e-12)
    assert fig.axes[1].get_ylim() == pytest.approx(b.get_ylim(), rel=1e-12)
    plt.close(fig)
    plt.close(plain)
