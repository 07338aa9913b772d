"""The one simulation loop and the plant interface."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, simulate
from ddwmmr.commands import WheelForces
from ddwmmr.controllers import StepInfo
from ddwmmr.plants import (
    KinematicPlant,
    PlantDivergedError,
    ThesisPlant,
    ThesisState,
    available_plants,
    make_plant,
)
from ddwmmr.plants.base import Observation
from ddwmmr.thesis_controller import ThesisController

ROBOT = Robot()


class ConstantController:
    """Holds one input; counts its calls and remembers what the loop passed."""

    name = "constant"

    def __init__(self, u, zero_order_hold: bool = False, wants_velocity: bool = False) -> None:
        self.u = np.asarray(u, dtype=float)
        self.zero_order_hold = zero_order_hold
        self.wants_base_velocity = wants_velocity
        self.calls: list[tuple[float, tuple[float, float] | None]] = []
        self.last = StepInfo()

    def reset(self, trajectory, q0) -> None:
        self.calls.clear()

    def command(self, t, q, pose_d, velocity_d, base_velocity=None):
        self.calls.append((t, base_velocity))
        return self.u.copy()


def test_available_plants_build_by_name():
    assert {"kinematic", "thesis"} <= set(available_plants())
    assert isinstance(make_plant("kinematic", ROBOT, integrator="euler"), KinematicPlant)
    assert isinstance(make_plant("thesis", ROBOT), ThesisPlant)
    with pytest.raises(ParameterError, match="plant must be one of"):
        make_plant("nope", ROBOT)


def test_zero_order_hold_controller_is_called_once_per_sample_and_held_exactly():
    """A sampled-data controller under RK4: one call per sample, and the held (v, w)
    integrates along the exact arc x = v/w sin(w t), y = v/w (1 - cos(w t))."""
    v, w = 0.3, 0.2
    controller = ConstantController([v, w, 0.0, 0.0], zero_order_hold=True)
    trajectory = Ellipse()
    q0 = np.array([0.0, 0.0, 0.0, *ROBOT.home_pose])
    result = simulate(ROBOT, trajectory, controller, dt=0.05, duration=2.0, q0=q0)
    assert len(controller.calls) == 41  # 40 steps + the final sample
    ts = result.timeseries
    t = ts["t"]
    np.testing.assert_allclose(ts["x"], v / w * np.sin(w * t), rtol=0, atol=1e-9)
    np.testing.assert_allclose(ts["y"], v / w * (1 - np.cos(w * t)), rtol=0, atol=1e-9)
    assert result.summary["plant"] == "kinematic" and result.summary["integrator"] == "rk4"
    assert result.summary["command_interface"] == "velocity"


def test_continuous_controller_is_evaluated_at_every_rk4_stage():
    controller = ConstantController([0.1, 0.0, 0.0, 0.0])
    simulate(ROBOT, Ellipse(), controller, dt=0.1, duration=1.0)
    # 10 steps x 4 stages + the final sample; stage times include t + dt/2.
    assert len(controller.calls) == 41
    assert any(math.isclose(t, 0.05) for t, _ in controller.calls)


def test_measured_base_velocity_is_passed_when_asked():
    controller = ConstantController([0.5, 0.0, 0.0, 0.0], zero_order_hold=True, wants_velocity=True)
    simulate(ROBOT, Ellipse(), controller, dt=0.01, duration=1.0, plant="thesis")
    velocities = [bv for _, bv in controller.calls]
    assert velocities[0] == (0.0, 0.0)  # starts at rest
    # The thesis plant's velocity servo (bandwidth 10/s) reaches 0.5 m/s within ~0.5 s.
    assert velocities[-1][0] == pytest.approx(0.5, abs=5e-3)


def test_tracking_on_the_thesis_plant_through_its_velocity_servo():
    """clrrmc-ts on the force-limited base: the servo follows the slow default ellipse
    (0.3 m/s peak), so the error stays small; the plant's force columns are recorded."""
    result = simulate(ROBOT, Ellipse(), "clrrmc-ts", plant="thesis", duration=20.0)
    summary, ts = result.summary, result.timeseries
    assert summary["plant"] == "thesis" and summary["integrator"] is None
    assert summary["rms_position_error_m"] < 0.02
    assert summary["max_wheel_force_n"] <= 10.0 + 1e-12
    peak = max(np.max(np.abs(ts["force_left_n"])), np.max(np.abs(ts["force_right_n"])))
    assert peak == summary["max_wheel_force_n"] > 0.0
    kinematic = simulate(ROBOT, Ellipse(), "clrrmc-ts", duration=20.0).summary
    assert summary["rms_position_error_m"] > kinematic["rms_position_error_m"]  # the lag


def test_integrator_is_only_for_the_kinematic_plant():
    with pytest.raises(ParameterError, match="only the kinematic plant takes an integrator"):
        simulate(ROBOT, Ellipse(), "ats", plant="thesis", integrator="euler", duration=1.0)


def test_force_controller_needs_a_plant_that_takes_forces():
    controller = ThesisController(ROBOT)
    with pytest.raises(ParameterError, match="does not accept force commands"):
        simulate(ROBOT, Ellipse(), controller, duration=1.0)


def test_thesis_plant_interface_step_equals_the_model_step():
    """Plant.step with WheelForces is exactly ThesisPlant.advance on a ThesisState."""
    q0 = np.array([0.2, -0.1, 0.3, -0.7, 1.5])
    plant = ThesisPlant(ROBOT)
    plant.reset(q0, 0.01)
    reference = ThesisState(*q0.tolist())
    for k in range(50):
        forces = WheelForces(8.0, 6.0 + 0.1 * k, -0.6, 1.4)
        plant.step(k * 0.01, forces, 0.01)
        plant.advance(reference, 8.0, 6.0 + 0.1 * k, (-0.6, 1.4), 0.01)
    obs = plant.observe()
    np.testing.assert_array_equal(obs.q, np.array(reference.q))
    assert (obs.v, obs.w) == (reference.v, reference.w)
    assert plant.extra_values() == (8.0, 10.0)  # the right force clipped at 10 N


class ExplodingPlant(KinematicPlant):
    """A kinematic plant whose state blows up at the sixth step."""

    name = "exploding"

    def step(self, t, command, dt, policy=None) -> None:
        if t >= 5 * dt - 1e-12:
            raise PlantDivergedError(f"exploded at t = {t + dt:g} s")
        super().step(t, command, dt, policy)


def test_a_diverging_plant_stops_the_run_and_keeps_the_record():
    plant = ExplodingPlant(ROBOT, "euler")
    result = simulate(ROBOT, Ellipse(), "ats", plant=plant, dt=0.1, duration=2.0)
    assert result.summary["diverged_at_step"] == 6
    assert "exploded" in result.summary["diverged"]
    assert len(result.timeseries["t"]) == 6  # samples 0..5 were recorded
    assert np.all(np.isfinite(result.timeseries["x"]))


def test_kinematic_plant_observation_is_a_copy():
    plant = KinematicPlant(ROBOT)
    plant.reset(np.zeros(5), 0.1)
    obs = plant.observe()
    assert isinstance(obs, Observation)
    obs.q[0] = 99.0
    assert plant.observe().q[0] == 0.0


def test_observation_gives_the_configuration_as_floats_and_as_an_array():
    """A plant may measure q as floats or as an array; both views hold the same numbers,
    the array is built once, on first use, and changing it leaves the floats alone."""
    values = (0.5, -1.25, 0.3, -0.7, 1.5)
    from_floats = Observation(values, 0.2, -0.1)
    assert from_floats.values is values
    q = from_floats.q
    assert isinstance(q, np.ndarray) and q.dtype == np.float64
    assert q.tolist() == list(values) and from_floats.q is q
    from_array = Observation(np.array(values), 0.2, -0.1)
    assert from_array.values == values
    assert all(type(value) is float for value in from_array.values)
    q[0] = 99.0
    assert from_floats.values[0] == 0.5
    assert (from_floats.v, from_floats.w) == (0.2, -0.1)


class FloatStateController(ConstantController):
    """Takes q as a tuple of floats (the loop's float_state contract)."""

    float_state = True

    def __init__(self, u) -> None:
        super().__init__(u, zero_order_hold=True, wants_velocity=True)
        self.states: list[object] = []

    def command(self, t, q, pose_d, velocity_d, base_velocity=None):
        self.states.append(q)
        return super().command(t, q, pose_d, velocity_d, base_velocity)


@pytest.mark.parametrize("plant", ["kinematic", "thesis"])
def test_the_loop_passes_floats_to_controllers_that_take_them(plant):
    """float_state = True: every call gets the measured q as a tuple of 5 floats, the same
    numbers a plain controller gets as an array."""
    u = [0.2, 0.1, 0.3, -0.2]
    floats = FloatStateController(u)
    plain = ConstantController(u, zero_order_hold=True)
    plain.states = []
    plain_command = plain.command

    def remember(t, q, pose_d, velocity_d, base_velocity=None):
        plain.states.append(q.copy())
        return plain_command(t, q, pose_d, velocity_d, base_velocity)

    plain.command = remember
    for controller in (floats, plain):
        simulate(ROBOT, Ellipse(), controller, dt=0.05, duration=1.0, plant=plant)
    assert len(floats.states) == len(plain.states) == 21
    for got, want in zip(floats.states, plain.states):
        assert type(got) is tuple and all(type(value) is float for value in got)
        assert isinstance(want, np.ndarray)
        assert list(got) == want.tolist()
    assert floats.states[-1] != floats.states[0]  # the robot moved


def test_the_loop_tells_sampled_data_controllers_its_step():
    """simulate(..., dt=0.01) on a trajectory of 0.02 s resolution: the mpc plans with the
    0.01 s the loop holds its commands (its joint targets are th + rate dt), the qp looks
    ahead 0.01 s; an explicit dt option still wins."""
    from ddwmmr import Robot, simulate
    from ddwmmr.controllers import make_controller
    from ddwmmr.trajectories import Ellipse

    robot = Robot()
    for method in ("mpc", "qp"):
        controller = make_controller(method, robot)
        simulate(robot, Ellipse(), controller, dt=0.01, duration=0.05)
        step = controller.dt if method == "mpc" else controller.ctx.dt
        assert step == 0.01, method
        fixed = make_controller(method, robot, dt=0.03)
        simulate(robot, Ellipse(), fixed, dt=0.01, duration=0.05)
        assert (fixed.dt if method == "mpc" else fixed.ctx.dt) == 0.03, method


def test_an_undeclared_interface_attribute_is_warned_about_at_run_loops_caller():
    """The deprecation warning of an ``interface`` attribute outside the declared
    ``interfaces`` names the line that called ``run_loop``, not the loop's own code."""
    import warnings

    from ddwmmr.resolution.reference import start_configuration
    from ddwmmr.sim.loop import run_loop
    from ddwmmr.sim.tracking import TrackingTask

    class Pusher(ConstantController):
        interface, interfaces = "force", ("velocity",)

        def command(self, t, q, pose_d, velocity_d, base_velocity=None):
            return WheelForces(0.0, 0.0, 0.0, 0.0)

    trajectory, plant = Ellipse(), ThesisPlant(ROBOT)
    task = TrackingTask(trajectory, plant)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        end = run_loop(
            plant, Pusher([0.0] * 4), task, start_configuration(ROBOT, trajectory), 0.02, 2
        )
    assert end.reason == "steps"
    assert [(w.category, w.filename) for w in caught] == [(FutureWarning, __file__)]
