"""An interrupt a solver in C swallowed is raised when the solve returns."""

import contextlib
import signal

import numpy as np
import pytest

from ddwmmr import interrupts
from ddwmmr.bounds import diffdrive
from ddwmmr.cli import common
from ddwmmr.cli.common import Terminated, interruptible
from terminal_signals import at_defaults


@pytest.fixture(autouse=True)
def nothing_pending():
    """No interrupt a test recorded outlives it (the next solve would raise it); SIGINT
    at Python's default, as in a tool run from a terminal, whatever the suite's start."""
    with at_defaults():
        yield
    interrupts.clear()


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


def test_the_tools_handler_records_what_it_raises(monkeypatch):
    # the handler stops the tool's workers (and silences their loggers): not this process's
    monkeypatch.setattr(common, "stop_workers", lambda: None)
    with pytest.raises(Terminated), interruptible():
        signal.raise_signal(signal.SIGTERM)
    # the handler recorded it too, and the context it left by the stop dropped it
    interrupts.raise_pending()
    with interruptible():
        with contextlib.suppress(KeyboardInterrupt):  # as a solver in C would
            signal.raise_signal(signal.SIGINT)
        with pytest.raises(KeyboardInterrupt):  # what a solver would have swallowed
            interrupts.raise_pending()


def test_a_run_stops_at_the_next_step_after_a_swallowed_interrupt():
    """An interrupt recorded during a step (as one the mpc's QP solver swallowed would be)
    stops the run at the start of the next step."""
    from ddwmmr import Robot, simulate
    from ddwmmr.trajectories import Ellipse

    steps = []

    def progress(k, total):
        steps.append(k)
        if k == 3:
            interrupts.record(KeyboardInterrupt())

    with pytest.raises(KeyboardInterrupt):
        simulate(Robot(), Ellipse(), "ats", duration=1.0, progress=progress)
    assert steps == [1, 2, 3]
