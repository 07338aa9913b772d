"""Inputs of ddwmmr.sim.error_dynamics that gave NaN or a TypeError: response times far
beyond any duration, and a tau given as a list of one value."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.sim import error_dynamics

RULE = "times must be at least 2 finite times (s), equally spaced, increasing, starting at 0"


@pytest.mark.parametrize("last", [1e9 * (1 + 1e-15), 1e50, 1e300])
def test_response_times_beyond_the_longest_duration_are_refused(last):
    """python-control's simulation gave [0, nan, nan] for times up to 1e50 s or more."""
    times = np.linspace(0.0, last, 3)
    for response in (error_dynamics.step_response, error_dynamics.error_response):
        with pytest.raises(ParameterError) as info:
            response(0.5, times)
        assert str(info.value) == f"{RULE} and ending by 1e+09 s (got a last time of {last:g} s)"
    with pytest.raises(ParameterError, match=r"increasing, starting at 0 and ending by 1e\+09 s"):
        error_dynamics.saturated_velocity_step(1.0, 1.0, 1.0, 1.0, 1.0, [0.0, last])


def test_response_times_up_to_the_longest_duration_are_finite():
    times = np.linspace(0.0, 1e9, 5)
    assert np.all(np.isfinite(error_dynamics.step_response(0.5, times)))


def test_a_tau_of_one_value_in_a_list_is_taken_by_every_function():
    """step_response took tau=[0.5] (as error_loops does); closed_form_step raised
    TypeError: float() argument must be ... not 'list'."""
    times = np.linspace(0.0, 3.0, 7)
    expected = error_dynamics.closed_form_step(0.5, times)
    assert np.array_equal(error_dynamics.closed_form_step([0.5], times), expected)
    assert np.array_equal(error_dynamics.closed_form_step(np.array([0.5]), times), expected)
    assert np.allclose(error_dynamics.step_response([0.5], times), expected)
    assert np.array_equal(error_dynamics.closed_form_step([np.inf], times), np.zeros(7))
    with pytest.raises(ParameterError, match=r"^tau must be one value or 1 values in s"):
        error_dynamics.closed_form_step([0.5, 0.5], times)
