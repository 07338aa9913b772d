"""A plug-in plant's calls checked where the loop makes them: what each of ``observe()``,
``limit()`` and ``step()`` raises or returns wrongly is one line naming the plant, the
method, the step and the time, raised by a tracking run and handed to a task that ends the
run quietly (the scenario protocol); the library's own plants are not wrapped.

The tests above the ``CheckedPlant`` section go through the public loop only, so they pin
the messages and run ends whatever module does the checking."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr import simulate
from ddwmmr.errors import ParameterError, PluginError
from ddwmmr.model import Robot
from ddwmmr.plants import KinematicPlant, Observation
from ddwmmr.resolution.reference import start_configuration
from ddwmmr.sim.loop import run_loop
from ddwmmr.sim.tracking import TrackingTask
from ddwmmr.trajectories import Ellipse

ROBOT = Robot()
DT = 0.02  # the kinematic plant's default step, which simulate() uses with a plant object


class FaultyPlant:
    """Kinematic Euler steps; its ``method`` misbehaves at sample ``at``: ``"raise"`` raises
    a ValueError with a two-line message, ``"bad"`` returns NaN (observe, limit)."""

    name = "plug-faulty"
    interfaces = ("velocity",)
    extra_columns = ()

    def __init__(self, robot, method="step", at=3, misuse="raise"):
        self.robot, self.method, self.at, self.misuse = robot, method, at, misuse
        self.q, self.u, self.k = [0.0] * 5, (0.0,) * 4, 0

    def _fault(self, method):
        """True where ``method`` should return a bad value (after raising where it should)."""
        if method != self.method or self.k != self.at:
            return False
        if self.misuse == "raise":
            raise ValueError(f"{method} broke\n  at sample {self.k}")
        return True

    def reset(self, q0, dt):
        self.q, self.u, self.k = [float(a) for a in q0], (0.0,) * 4, 0

    def observe(self):
        if self._fault("observe"):
            return Observation((math.nan, *self.q[1:]), 0.0, 0.0)
        return Observation(tuple(self.q), self.u[0], self.u[1])

    def limit(self, q, u):
        if self._fault("limit"):
            return [math.nan] * 4, False
        return np.asarray(u, dtype=float), False

    def step(self, t, command, dt, policy=None):
        self._fault("step")
        if policy is not None:  # the control law at the step's midpoint
            command = policy(t + 0.5 * dt, list(self.q))
        x, y, phi, th1, th2 = self.q
        v, w, r1, r2 = self.u = tuple(float(a) for a in command)
        self.q = [x + dt * v * math.cos(phi), y + dt * v * math.sin(phi)]
        self.q += [phi + dt * w, th1 + dt * r1, th2 + dt * r2]
        self.k += 1

    def extra_values(self):
        return ()

    def summarize(self, timeseries):
        return {}


def _quiet_run(plant, controller="ats", steps=10):
    """``plant`` under a tracking task that ends a run on an error, as the scenarios' does:
    how the run ended and the (step, type, message) of each error the task was given."""
    errors = []

    class Quiet(TrackingTask):
        def controller_error(self, k, error):
            errors.append((k, type(error).__name__, str(error)))
            return True

    trajectory = Ellipse()
    if isinstance(controller, str):
        from ddwmmr.controllers import make_controller

        controller = make_controller(controller, ROBOT)
    q0 = start_configuration(ROBOT, trajectory)
    end = run_loop(plant, controller, Quiet(trajectory, plant), q0, DT, steps)
    return (end.samples, end.reason), errors


RAISED = [
    # method, sample it fails at, the end of a quiet run, the message
    ("observe", 0, 0, "plant: plug-faulty.observe() raised ValueError: 'observe broke at "
     "sample 0' at step 0, t = 0 s"),
    ("observe", 3, 3, "plant: plug-faulty.observe() raised ValueError: 'observe broke at "
     "sample 3' at step 3, t = 0.06 s"),
    ("limit", 3, 3, "plant: plug-faulty.limit() raised ValueError: 'limit broke at sample "
     "3' at step 3, t = 0.06 s"),
    ("step", 3, 4, "plant: plug-faulty.step() raised ValueError: 'step broke at sample 3' "
     "at step 3, t = 0.06 s"),
]  # fmt: skip


@pytest.mark.parametrize(("method", "at", "samples", "message"), RAISED)
def test_what_a_plug_in_plant_raises_stops_a_tracking_run_with_one_line(
    method, at, samples, message
):
    with pytest.raises(PluginError) as error:
        simulate(ROBOT, Ellipse(), "ats", plant=FaultyPlant(ROBOT, method, at), duration=0.2)
    assert str(error.value) == message
    assert isinstance(error.value.__cause__, ValueError)


@pytest.mark.parametrize(("method", "at", "samples", "message"), RAISED)
def test_what_a_plug_in_plant_raises_goes_to_the_task(method, at, samples, message):
    end, errors = _quiet_run(FaultyPlant(ROBOT, method, at))
    assert end == (samples, "plant_error")
    assert errors == [(at, "PluginError", message)]


@pytest.mark.parametrize(
    ("method", "samples", "start"),
    [
        ("observe", 3, "plant: plug-faulty.observe() must return an Observation(q, v, w) of "),
        ("limit", 3, "plant: plug-faulty.limit(q, u) must return (u, saturated) with u 4 "),
    ],
)
def test_a_bad_return_is_a_parameter_error_naming_the_plant(method, samples, start):
    plant = FaultyPlant(ROBOT, method, 3, misuse="bad")
    with pytest.raises(ParameterError) as error:
        simulate(ROBOT, Ellipse(), "ats", plant=plant, duration=0.2)
    assert str(error.value).startswith(start)
    assert "at step 3, t = 0.06 s" in str(error.value)
    end, errors = _quiet_run(FaultyPlant(ROBOT, method, 3, misuse="bad"))
    assert end == (samples, "plant_error")
    assert [(k, kind) for k, kind, _ in errors] == [(3, "ParameterError")]
    assert errors[0][2].startswith(start) and "at step 3, t = 0.06 s" in errors[0][2]


class FailsBetweenSamples:
    """A plug-in controller (RK4-style: no zero-order hold) that raises when asked for a
    command between samples, as only an integrator stage asks."""

    def reset(self, trajectory, q0):
        pass

    def command(self, t, q, pose_d, velocity_d):
        if abs(t / DT - round(t / DT)) > 1e-9:
            raise ArithmeticError("no command between samples")
        return np.zeros(4)


def test_a_controller_failing_inside_a_plug_in_plants_step_is_the_controllers_error():
    """The error reaches the loop through the plug-in plant's step, but is the
    controller's: it is not wrapped as the plant's."""
    end, errors = _quiet_run(FaultyPlant(ROBOT, method="none"), FailsBetweenSamples())
    assert end == (0, "controller_error")
    assert errors == [
        (
            0,
            "PluginError",
            "method: FailsBetweenSamples.command() raised ArithmeticError: 'no command "
            "between samples' at step 0, t = 0.01 s",
        )
    ]


# -- CheckedPlant itself --------------------------------------------------------------------
def test_a_library_plant_is_not_wrapped_and_a_plug_in_plant_is():
    from ddwmmr.plants.checked import CheckedPlant, checked_plant

    library = KinematicPlant(ROBOT)
    assert checked_plant(library, lambda k, error: True) is library
    plug_in = FaultyPlant(ROBOT)
    wrapped = checked_plant(plug_in, lambda k, error: True)
    assert isinstance(wrapped, CheckedPlant) and wrapped.plant is plug_in
    # its attributes are the plant's (the loop reads the traits through the wrapper)
    assert (wrapped.name, wrapped.interfaces, wrapped.misuse) == (
        "plug-faulty",
        ("velocity",),
        "raise",
    )
    assert checked_plant(wrapped, lambda k, error: True) is wrapped  # the library's own


def test_the_wrapper_hands_each_failure_to_the_task_and_says_where_the_run_ends():
    from ddwmmr.plants.checked import CheckedPlant, PlantFailed

    given = []
    plant = CheckedPlant(
        FaultyPlant(ROBOT, "step", 2), lambda k, error: given.append((k, error)) or True
    )
    plant.reset(np.zeros(5), 0.5)
    u = np.array([0.1, 0.0, 0.0, 0.0])
    for k in range(2):
        assert plant.observe().finite()
        applied, saturated = plant.limit(np.zeros(5), u)
        assert applied.tolist() == u.tolist() and saturated is False
        plant.step(k * 0.5, applied, 0.5)
    with pytest.raises(PlantFailed) as stop:
        plant.step(1.0, u, 0.5)
    assert stop.value.samples == 3  # the step from sample 2 failed: samples 0, 1, 2 taken
    ((k, error),) = given
    assert k == 2 and isinstance(error, PluginError)
    assert str(error) == (
        "plant: plug-faulty.step() raised ValueError: 'step broke at sample 2' at step 2, t = 1 s"
    )


def test_a_diverging_plug_in_plant_stays_diverged():
    from ddwmmr.plants import PlantDivergedError
    from ddwmmr.plants.checked import CheckedPlant

    class Diverging(FaultyPlant):
        def step(self, t, command, dt, policy=None):
            raise PlantDivergedError("state not finite")

    plant = CheckedPlant(Diverging(ROBOT), lambda k, error: pytest.fail("not the task's"))
    plant.reset(np.zeros(5), 0.02)
    with pytest.raises(PlantDivergedError, match=r"^state not finite$"):
        plant.step(0.0, np.zeros(4), 0.02)
