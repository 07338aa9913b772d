"""An interrupt a solver in C swallowed is raised when the solve returns."""

import contextlib
import signal

import numpy as np
import pytest

from ddwmmr import interrupts
from ddwmmr.bounds import diffdrive
from ddwmmr.cli.common import Terminated, interruptible


def test_a_recorded_interrupt_is_raised_once_and_clear_drops_it():
    interrupts.raise_pending()  # nothing recorded: nothing raised
    interrupts.record(Terminated(signal.SIGTERM))
    with pytest.raises(Terminated):
        interrupts.raise_pending()
    interrupts.raise_pending()  # once
    interrupts.record(KeyboardInterrupt())
    interrupts.clear()
    interrupts.raise_pending()


def test_the_minimum_time_solve_raises_an_interrupt_that_came_during_it():
    """IPOPT turns what a signal handler raises mid-solve into a warning and carries on
    (python -m ddwmmr.bounds under `timeout` ran to the end): the solve's caller gets the
    interrupt as soon as the solve returns."""
    goal = (1.0, 0.5, 0.0)
    wheels = {"wheel_radius": 0.0975, "half_track": 0.175, "wheel_speed": 15.0}
    interrupts.record(KeyboardInterrupt())
    with pytest.raises(KeyboardInterrupt):
        diffdrive.ocp_time((0.0, 0.0, 0.0), goal, **wheels)
    assert np.isfinite(diffdrive.ocp_time((0.0, 0.0, 0.0), goal, **wheels))  # raised once


def test_the_tools_handler_records_what_it_raises():
    with interruptible(), pytest.raises(Terminated):
        signal.raise_signal(signal.SIGTERM)
    # the handler recorded it too, and leaving the context dropped it
    interrupts.raise_pending()
    with interruptible():
        with contextlib.suppress(KeyboardInterrupt):  # as a solver in C would
            signal.raise_signal(signal.SIGINT)
        with pytest.raises(KeyboardInterrupt):  # what a solver would have swallowed
            interrupts.raise_pending()
