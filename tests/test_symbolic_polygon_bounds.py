"""symbolic.stability_bounds is the rectangle's box only: None on any other polygon."""

import pytest

from ddwmmr import Robot
from ddwmmr.model import symbolic as sym


def test_the_box_is_the_rectangles_only():
    assert sym.stability_bounds(Robot(), 1.25) == pytest.approx((0.225 / 1.25, 0.175 / 1.25))
    diamond = Robot(caster_positions=((0.225, 0.0), (-0.225, 0.0)))
    assert sym.stability_bounds(diamond, 1.25) is None  # the footprint's box is not S there
    assert len(sym.stability_edges(diamond, 1.25)) == 4
