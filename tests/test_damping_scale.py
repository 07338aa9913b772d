"""The damping defaults follow the robot's size (docs/theory.md section 4, "Other robots").

A fixed smallest-singular-value threshold damps a short arm almost everywhere: the
singular values of the resolution's matrices shrink with the first link. The defaults are
the robot's own, so that damping starts at the same |cos th1| on every robot; the default
robot keeps 0.05 and 0.05 exactly, and a value given is used as it is.
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


def test_the_scale_follows_the_first_links_singular_slope():
    # L1 / sqrt(1 + L1^2) relative to the default robot's: 0.2114 at 0.2x, 2.628 at 5x.
    small, large = make_controller("pi", scaled(0.2)), make_controller("pi", scaled(5.0))
    assert small.threshold == pytest.approx(0.05 * 0.211379, rel=1e-5)
    assert large.threshold == pytest.approx(0.05 * 2.62825, rel=1e-5)
    assert (small.damping, large.damping) == (small.threshold, large.threshold)


def test_a_given_value_is_used_as_it_is():
    controller = make_controller("pi", scaled(0.2), singularity_threshold=0.05)
    assert (controller.threshold, controller.damping) == pytest.approx(
        (0.05, 0.05 * 0.211379), rel=1e-5
    )
    controller = make_controller("clrrmc-cs", scaled(5.0), damping=0.2)
    assert (controller.threshold, controller.damping) == pytest.approx(
        (0.05 * 2.62825, 0.2), rel=1e-5
    )
    # explicit 0.05 reproduces the fixed threshold: the small robot's band is 0.715 again
    assert ats_band(scaled(0.2), singularity_threshold=0.05) == pytest.approx(0.7153, abs=1e-3)


def test_a_micrometre_arm_gets_defaults_inside_the_allowed_range():
    controller = make_controller("ats", replace(DEFAULT, L1=1e-6, L2=1e-6))
    assert (controller.threshold, controller.damping) == (1e-6, 1e-6)


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
