"""The physics animation checks its options before it draws, as save_animation does: fps
0 raised ZeroDivisionError after every frame was drawn, and fps above 100 wrote frames a
GIF cannot time (0 ms)."""

from __future__ import annotations

import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.reports.physics_plots import save_physics_animation


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"fps": 0}, "fps must be"),
        ({"fps": 101}, "fps must be"),
        ({"frames": 0}, "frames must be"),
        ({"after_tip_s": -1.0}, "after_tip_s must be >= 0"),
        ({"after_tip_s": float("nan")}, "after_tip_s"),
        ({"name": "tipping.png"}, "path must be a .gif file (got 'tipping.png')"),
    ],
)
def test_bad_options_are_refused_before_anything_is_drawn(tmp_path, options, message):
    path = tmp_path / options.pop("name", "tipping.gif")
    # no run is needed: the options are refused first
    with pytest.raises(ParameterError, match=message.replace("(", r"\(").replace(")", r"\)")):
        save_physics_animation(None, [], 1.0, path, **options)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []
