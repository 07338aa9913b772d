"""The damping follows the robot's size (docs/theory.md section 4, "Other robots").

Measured in metres, a fixed smallest-singular-value threshold damps a short arm almost
everywhere: the singular values of the resolution's matrices shrink with the first link.
The kernels measure lengths in the robot's own unit, so damping starts at the same
|cos th1| on every robot; the default robot keeps 0.05 and 0.05 exactly
(tests/test_damping_invariance.py: the damped steps of scaled robots, step by step).
"""

import math
from dataclasses import replace

import pytest

from ddwmmr import Ellipse, Robot, make_controller, simulate

DEFAULT = Robot()
#: Where ats starts damping on the default robot: sigma_min(M) = 0.05 (docs/theory.md).
ATS_BAND = 0.1512


def scaled(factor: float) -> Robot:
    """The default robot with both links ``factor`` times as long."""
    return replace(DEFAULT, L1=DEFAULT.L1 * factor, L2=DEFAULT.L2 * factor)


def ats_band(robot: Robot, **options) -> float:
    """Largest |cos th1| at which the ats controller of ``robot`` damps (bisection on the
    singular flag, th2 = 0.5 rad, heading 0, unit speed along x)."""
    controller = make_controller("ats", robot, **options)
    inside, outside = 0.0, 1.0
    for _ in range(40):
        middle = 0.5 * (inside + outside)
        q = [0.0, 0.0, 0.0, math.acos(middle), 0.5]
        _, singular = controller.law(0.0, q, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
        inside, outside = (middle, outside) if singular else (inside, middle)
    return inside


def test_default_robot_keeps_the_documented_constants_exactly():
    for method in ("pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs"):
        controller = make_controller(method, DEFAULT)
        assert (controller.threshold, controller.damping) == (0.05, 0.05)


@pytest.mark.parametrize("factor", [0.2, 0.5, 2.0, 5.0])
def test_ats_starts_damping_at_the_default_robots_band_on_any_size(factor):
    # With a fixed 0.05 the band was |cos th1| < 0.715 at 0.2x and < 0.058 at 5x.
    assert ats_band(scaled(factor)) == pytest.approx(ATS_BAND, abs=5e-4)
    assert ats_band(DEFAULT) == pytest.approx(ATS_BAND, abs=5e-4)


@pytest.mark.parametrize("method", ["ats", "clrrmc-cs"])
def test_a_small_robot_tracks_as_the_default_one_scaled(method):
    """0.2x robot on the 0.2x ellipse (aux = sum, start offset scaled): no damped step and
    0.2 times the default robot's RMS error (with 0.05: 40% resp. 35% of the steps damped
    and 1.27x resp. 5.1x the relative error)."""
    reference = simulate(DEFAULT, Ellipse(), method, aux="sum").summary
    summary = simulate(
        scaled(0.2), Ellipse(a=0.4, b=0.3), method, aux="sum", initial_offset=(-0.006, -0.006)
    ).summary
    assert reference["singular_steps"] == 0
    assert summary["singular_steps"] == 0
    assert summary["rms_position_error_m"] == pytest.approx(
        0.2 * reference["rms_position_error_m"], rel=1e-3
    )
