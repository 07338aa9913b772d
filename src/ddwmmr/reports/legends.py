"""Legends that never sit on the data they label.

:func:`place_legend` puts an axes' legend in the first spot (of a list of corners and
edges) that no data line, scatter point or label crosses, measured on the rendered
figure; when every spot is taken it raises the top of the y-axis until the upper spot
is free (a band above the data). :func:`legend_beside` puts it outside the axes, for
crowded panels. Use either after the data and the axis limits are set: the placement
is computed once, so it is the same on every draw and every run.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt
from matplotlib.axes import Axes
from matplotlib.collections import PathCollection
from matplotlib.legend import Legend
from matplotlib.path import Path
from matplotlib.transforms import Bbox

from ddwmmr.reports.canvas import renderer_of

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.transforms import Transform

    #: A legend spot inside the axes (matplotlib ``loc`` names).
    Spot = Literal[
        "upper right",
        "upper left",
        "lower left",
        "lower right",
        "right",
        "center left",
        "center right",
        "lower center",
        "upper center",
        "center",
        "best",
    ]

#: Spots tried in order (matplotlib ``loc`` names).
SPOTS: tuple[Spot, ...] = (
    "upper right",
    "upper left",
    "lower right",
    "lower left",
    "upper center",
    "lower center",
    "center right",
    "center left",
)
#: Gap (px) kept between a legend and the nearest data.
CLEARANCE_PX = 3.0
#: At most this many rounds of raising the y-axis top.
HEADROOM_ROUNDS = 6


def place_legend(
    ax: Axes,
    spots: Sequence[Spot] = SPOTS,
    handles: Iterable[Artist | tuple[Artist, ...]] | None = None,
    labels: Iterable[str] | None = None,
    **kwargs: Any,
) -> Legend:
    """Legend of ``ax`` where no data lies under it (see the module docstring).

    ``handles``/``labels`` and ``kwargs`` go to :meth:`Axes.legend`. Returns the legend.
    """
    kwargs.update(handles=handles, labels=labels)  # None: matplotlib's own choice
    for spot in spots:
        legend = ax.legend(loc=spot, **kwargs)
        if not covers_data(ax, legend):
            return legend
    upper: Spot = next((s for s in spots if s.startswith("upper")), "upper right")
    legend = ax.legend(loc=upper, **kwargs)
    for _ in range(HEADROOM_ROUNDS):
        if not covers_data(ax, legend):
            break
        _raise_top(ax, legend)
    return legend


def legend_beside(ax: Axes, **kwargs: Any) -> Legend:
    """Legend outside ``ax``, on its right, top-aligned (``tight_layout`` makes room)."""
    kwargs.setdefault("loc", "upper left")
    kwargs.setdefault("bbox_to_anchor", (1.02, 1.0))
    kwargs.setdefault("borderaxespad", 0.0)
    return ax.legend(**kwargs)


def covers_data(ax: Axes, legend: Legend) -> bool:
    """Whether ``legend`` (drawn where it is now) overlaps a data line, a scatter point
    or a text label of ``ax``."""
    renderer = renderer_of(ax.figure)
    ax.apply_aspect()  # an equal-aspect axes takes its final box only when drawn
    box = legend.get_window_extent(renderer).padded(CLEARANCE_PX)
    for line in ax.lines:
        if not line.get_visible():
            continue
        if line.get_linestyle() in ("None", "", " ", "none"):  # markers only: the points
            points = line.get_transform().transform(line.get_xydata())
            if box.count_contains(points):
                return True
        elif _crosses(line.get_transform(), line.get_xydata(), box):
            return True
    for collection in ax.collections:
        if isinstance(collection, PathCollection) and collection.get_visible():
            points = collection.get_offset_transform().transform(collection.get_offsets())
            if box.count_contains(points):
                return True
    return any(
        text.get_visible() and text.get_text() and box.overlaps(text.get_window_extent(renderer))
        for text in ax.texts
    )


def _crosses(transform: Transform, xy: npt.ArrayLike, box: Bbox) -> bool:
    """Whether the polyline ``xy`` (data coordinates, NaN-broken) meets ``box`` (px)."""
    xy = np.asarray(xy, dtype=float)
    if len(xy) == 0:
        return False
    display = transform.transform(xy)
    finite = np.all(np.isfinite(display), axis=1)
    if len(display) == 1:
        return bool(finite[0] and box.contains(*display[0]))
    # Runs of finite points, each one path.
    edges = np.flatnonzero(np.diff(np.r_[False, finite, False].astype(int)))
    for start, stop in zip(edges[::2], edges[1::2]):
        piece = display[start:stop]
        if len(piece) == 1:
            if box.contains(*piece[0]):
                return True
        elif Path(piece).intersects_bbox(box, filled=False):
            return True
    return False


def _raise_top(ax: Axes, legend: Legend) -> None:
    """Raise the y-axis top so that the data's top sits below the legend's bottom."""
    renderer = renderer_of(ax.figure)
    axes_box = ax.get_window_extent(renderer)
    legend_box = legend.get_window_extent(renderer)
    # Fraction of the axes height the data may use: below the legend, with a gap.
    free = (legend_box.y0 - CLEARANCE_PX * 2 - axes_box.y0) / axes_box.height
    free = float(np.clip(free, 0.2, 0.95))
    low, high = ax.get_ylim()
    if ax.get_yscale() == "log":
        low_log, high_log = np.log10(low), np.log10(high)
        ax.set_ylim(low, 10 ** (low_log + (high_log - low_log) / free))
    else:
        ax.set_ylim(low, low + (high - low) / free)
