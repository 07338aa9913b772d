"""Legend placement over data drawn as points: marker-only lines and scatter points."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from ddwmmr.reports.legends import covers_data, place_legend

#: Points in the upper-right corner of the unit square, where the first spot's legend sits.
CORNER = np.array([[0.9, 0.9], [0.95, 0.85], [0.85, 0.95], [0.92, 0.93]])


def _draw(ax, kind: str) -> None:
    if kind == "markers":
        ax.plot(CORNER[:, 0], CORNER[:, 1], "o", label="points")
    else:
        ax.scatter(CORNER[:, 0], CORNER[:, 1], label="points")
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.0, 1.0)


@pytest.mark.parametrize("kind", ["markers", "scatter"])
def test_a_legend_on_points_covers_them_and_place_legend_moves_it(kind):
    fig, ax = plt.subplots(figsize=(4, 3))
    try:
        _draw(ax, kind)
        on_points = ax.legend(loc="upper right")
        assert covers_data(ax, on_points)
        off_points = ax.legend(loc="lower left")
        assert not covers_data(ax, off_points)
        legend = place_legend(ax)
        box, frame = legend.get_window_extent(), ax.get_window_extent()
        # "upper left", the first spot off the points: in the axes' upper-left quarter
        assert box.x1 < frame.x0 + 0.5 * frame.width
        assert box.y0 > frame.y0 + 0.5 * frame.height
        assert not covers_data(ax, legend)
        assert ax.get_ylim() == (0.0, 1.0)  # a free spot: no headroom added
    finally:
        plt.close(fig)
