"""A feedback gain too large for the control step warns before the run: the sampled loop of
``e' = -K e`` is stable only for K dt below 2 (a held command, Euler) or 2.785 (RK4 with
the control law at its stages)."""

import math
import warnings

import numpy as np
import pytest

from ddwmmr import Robot, simulate
from ddwmmr.controllers.base import available_methods, make_controller
from ddwmmr.gains import GAIN_STEP_MARGIN, STABLE_GAIN_STEP
from ddwmmr.plants import available_plants, make_plant
from ddwmmr.plants.kinematic import INTEGRATORS, KinematicPlant
from ddwmmr.sim.simulate import default_step, warn_gain_step
from ddwmmr.trajectories import Ellipse, available_trajectories, load_trajectory


def _warnings(method, dt, integrator=None, **options):
    """The UserWarnings of a short ``method`` run on the ellipse at step ``dt`` (s)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulate(None, Ellipse(), method, dt=dt, duration=2 * dt, integrator=integrator, **options)
    return [str(w.message) for w in caught if issubclass(w.category, UserWarning)]


def test_clrrmc_ts_at_two_seconds_with_rk4_warns_naming_tau_dt_the_limit_and_the_cure():
    (message,) = _warnings("clrrmc-ts", 2.0)
    assert message.startswith("tau = 0.5 s with dt = 2 s: K dt = 4 (K = 1/tau) is beyond 2.785")
    assert "the stability limit of RK4 with the control law at its stages: the tracking " in (
        message
    )
    # 0.65 * 2.7853 / 2 = 0.9052 s (rounded down); 2 / (0.65 * 2.7853) = 1.1047 s (up)
    assert message.endswith("use dt below 0.905 s or tau above 1.11 s")


def test_below_the_limit_the_warning_gives_the_share_reached():
    (message,) = _warnings("qp", 1.0)  # K dt = 2: the qp does not track the ellipse there
    assert "K dt = 2 (K = 1/tau) is 0.72 of 2.785" in message
    assert "the robot's runs fail from about 0.65 of it" in message
    assert _warnings("qp", 0.9) == []  # K dt = 1.8 < 0.65 * 2.785 = 1.81: it tracks


def test_euler_at_1_1_s_warns_but_rk4_at_0_9_s_does_not():
    (message,) = _warnings("clrrmc-ts", 1.1, "euler")
    assert "K dt = 2.2" in message and "beyond 2, the stability limit of a command held" in message
    assert message.endswith("use dt below 0.65 s or tau above 0.847 s")
    assert _warnings("clrrmc-ts", 0.9) == []  # K dt = 1.8 < 0.65 * 2.785 = 1.81


def test_clrrmc_cs_names_its_shortest_tau_and_a_switched_off_channel_counts_nothing():
    (message,) = _warnings("clrrmc-cs", 1.0, "euler", tau=(0.5, 1.0, 1.0, math.inf, 1.0))
    assert message.startswith("tau = 0.5 s (the shortest) with dt = 1 s: K dt = 2 ")
    assert _warnings("clrrmc-cs", 1.0, "euler", tau=(math.inf, 1.0, 1.0, 1.0, 1.0)) == []


def _amplification(integrator: str, x: float) -> float:
    """e(dt) / e(0) of one kinematic-plant step of th1' = -K th1, K dt = ``x``: the plant's
    own integrator with the law as its policy."""
    plant = KinematicPlant(Robot(), integrator)
    gain, dt, error = 1.0, x, 1e-3  # slow enough for the 2 rad/s joint limit

    def law(t, q):
        return (0.0, 0.0, -gain * q[3], 0.0)

    q = np.array([0.0, 0.0, 0.0, error, 0.0])
    new, _, _ = plant.integrate(0.0, q, dt, law)
    return float(new[3]) / error


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_the_limits_are_where_the_plants_integrator_stops_shrinking_the_error(integrator):
    scheme = "rk4" if integrator == "rk4" else "hold"
    limit = STABLE_GAIN_STEP[scheme]
    assert abs(_amplification(integrator, limit)) == pytest.approx(1.0, abs=1e-12)
    assert abs(_amplification(integrator, 0.999 * limit)) < 1.0
    assert abs(_amplification(integrator, 1.001 * limit)) > 1.0
    # the RK4 polynomial 1 - x + x^2/2 - x^3/6 + x^4/24 = 1 at its one positive root
    roots = np.roots([1.0 / 24.0, -1.0 / 6.0, 0.5, -1.0])
    positive = [r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0.0]
    assert STABLE_GAIN_STEP["rk4"] == pytest.approx(positive[0], rel=1e-14)
    assert GAIN_STEP_MARGIN == 0.65


def test_no_default_run_of_any_method_trajectory_or_plant_warns():
    robot = Robot()
    for method in available_methods():
        controller = make_controller(method, robot)
        for plant_name in available_plants():
            plant = make_plant(plant_name, robot)
            for name in available_trajectories():
                dt = default_step(load_trajectory(name), plant_name, robot)
                with warnings.catch_warnings():
                    warnings.simplefilter("error")
                    warn_gain_step(controller, plant, dt)
    # the default K dt: 2 1/s times 0.02 s, far inside either limit
    assert make_controller("clrrmc-ts", robot).feedback_gains == (2.0, 2.0, 2.0)
    assert default_step(Ellipse(), "kinematic", robot) == 0.02


def test_the_qp_tracking_gain_is_checked_too():
    """The qp's tracking task is an e' = -K e loop evaluated at RK4's stages as well."""
    qp = make_controller("qp", Robot())
    assert qp.feedback_gains == (2.0, 2.0, 2.0)
    assert make_controller("qp", Robot(), track_orientation=False).feedback_gains[2] == 0.0
