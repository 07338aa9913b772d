"""The support-loads figure's floor legend reads right at every robot size."""

from ddwmmr.reports.physics_plots import _newtons


def test_the_floor_legend_keeps_a_small_robots_floor_visible():
    assert _newtons(12.99825) == "13.0"  # the default robot's figure, as before
    assert _newtons(0.0016249) == "0.00162"  # a twentieth robot's: not "0.0"
    assert _newtons(0.1) == "0.1"
