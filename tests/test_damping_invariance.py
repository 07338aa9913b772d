"""The singularity damping does not depend on the robot's size (docs/theory.md section 4,
"Other robots").

A robot scaled by s in every length, on a trajectory scaled by s, is the default robot seen
in another length unit: it must be damped on the same steps and track with s times the
default robot's errors. Measured in metres, the smallest singular values of the resolution's
matrices (they mix m/s and rad/s) and the isotropic damping do not scale by one factor: the
10x robot's pseudoinverse was damped on every step of a run, far from cos th1 = 0.
"""

import functools
import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from ddwmmr import Ellipse, Robot, make_controller, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.resolution import kernels
from scaled_robots import scaled_robot
from test_damping_scale import ats_band

DEFAULT = Robot()
#: The default ellipse with a constant orientation: every method below passes near the
#: singularity on part of it (aux = sum), so the damped steps are a real pattern.
TASK = Ellipse(orientation="constant")
METHODS = [
    ("pi", {}),
    ("ap", {}),
    ("ats", {"aux": "sum"}),
    ("clrrmc-ts", {"aux": "sum"}),
    ("clrrmc-cs", {"aux": "sum"}),
]
#: Damped rows of the default robot on TASK (of 2001), which pin the pattern compared.
DEFAULT_DAMPED = {"pi": 913, "ap": 1101, "ats": 687, "clrrmc-ts": 501, "clrrmc-cs": 1314}


def run(factor: float, method: str, options: dict):
    task = replace(TASK, a=TASK.a * factor, b=TASK.b * factor)
    offset = (-0.03 * factor, -0.03 * factor)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a 0.05x robot's lengths look like unit mistakes
        return simulate(scaled_robot(factor), task, method, initial_offset=offset, **options)


@functools.cache
def default_run(method: str) -> tuple[np.ndarray, float]:
    """The default robot's run of ``method`` (its METHODS options): its damped steps
    (read only) and RMS position error (m), computed once per module and compared with
    every scale."""
    reference = run(1.0, method, dict(METHODS)[method])
    damped = np.asarray(reference.timeseries["singular"], dtype=bool)
    damped.setflags(write=False)
    return damped, reference.summary["rms_position_error_m"]


@pytest.mark.parametrize("factor", [0.05, 10.0])
@pytest.mark.parametrize(("method", "options"), METHODS)
def test_a_scaled_robot_is_damped_on_the_default_robots_steps(method, options, factor):
    (damped, rms), other = default_run(method), run(factor, method, options)
    assert damped.sum() == DEFAULT_DAMPED[method]
    assert np.array_equal(np.asarray(other.timeseries["singular"], dtype=bool), damped)
    assert other.summary["rms_position_error_m"] == pytest.approx(factor * rms, rel=1e-9)


@pytest.mark.parametrize("factor", [0.05, 10.0])
def test_the_kernels_give_the_default_robots_command_in_the_scaled_unit(factor):
    """Scaled lengths and linear rates: the same damping flag, v times the factor, the same
    angular rates, on states inside and outside the damping band."""
    rng = np.random.default_rng(138)
    L1, L2 = DEFAULT.L1, DEFAULT.L2
    for _ in range(300):
        phi, th2 = rng.uniform(-math.pi, math.pi, 2)
        th1 = math.acos(rng.uniform(-0.4, 0.4)) * rng.choice([-1.0, 1.0])
        xd, yd, pd = rng.normal(size=3)
        for kernel, extra in (
            (kernels.pseudoinverse, {}),
            (kernels.ats, {"aux": "sum"}),
            (kernels.ats, {"aux": "shoulder"}),
        ):
            u, flag = kernel(L1, L2, phi, th1, th2, xd, yd, pd, **extra)
            us, flag_s = kernel(
                L1 * factor, L2 * factor, phi, th1, th2, xd * factor, yd * factor, pd, **extra
            )
            assert flag_s == flag
            expected = (u[0] * factor, *u[1:])
            assert us == pytest.approx(expected, rel=1e-9, abs=1e-12 * max(factor, 1.0))


def test_the_large_robot_of_the_probe_is_damped_only_where_the_default_one_is():
    """10x robot on the 10x ellipse for 5 s: the pseudoinverse was damped on 250 of 250
    steps (|cos th1| >= 0.9 throughout); the default robot on the default ellipse on none."""
    large = scaled_robot(10.0)
    summary = simulate(large, Ellipse(a=20.0, b=15.0), "pi", duration=5.0).summary
    assert summary["steps"] == 250
    assert summary["singular_steps"] == 0


@pytest.mark.parametrize("factor", [1e-6 / DEFAULT.L2, 0.2, 5.0])
def test_the_defaults_and_a_given_value_mean_the_same_band_on_every_size(factor):
    robot = replace(DEFAULT, L1=DEFAULT.L1 * factor, L2=DEFAULT.L2 * factor)
    controller = make_controller("ats", robot)
    assert (controller.threshold, controller.damping) == (0.05, 0.05)
    assert ats_band(robot) == pytest.approx(0.1512, abs=5e-4)
    # sigma_min(M) < 0.2 in the robot's unit: |cos th1| < 0.595 on every size
    assert ats_band(robot, singularity_threshold=0.2) == pytest.approx(
        ats_band(DEFAULT, singularity_threshold=0.2), abs=1e-9
    )
    assert ats_band(DEFAULT, singularity_threshold=0.2) == pytest.approx(0.5945, abs=1e-3)


@pytest.mark.parametrize("L1", [0.0, -0.35, math.nan, math.inf, 1e-310, 1e-7, 2e3])
def test_a_first_link_that_is_no_length_is_refused_by_the_kernels(L1):
    """Outside the robot's length range (1e-310 m made L2 / unit overflow to a NaN command)."""
    with pytest.raises(
        ParameterError, match=r"^L1 must be (a finite number )?in \[1e-06, 1000\] m \(got "
    ):
        kernels.pseudoinverse(L1, 0.3, 0.0, 0.1, 0.2, 0.1, 0.0, 0.0)
    with pytest.raises(
        ParameterError, match=r"^L1 must be (a finite number )?in \[1e-06, 1000\] m"
    ):
        kernels.ats(L1, 0.3, 0.0, 0.1, 0.2, 0.1, 0.0, 0.0)
    with pytest.raises(
        ParameterError, match=r"^L1 must be (a finite number )?in \[1e-06, 1000\] m"
    ):
        kernels.damping_options(L1)
