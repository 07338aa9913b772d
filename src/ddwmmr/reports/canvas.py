"""Figures of the report writers' own, not pyplot's.

A :class:`~matplotlib.figure.Figure` made here belongs to no pyplot figure manager, so
drawing or saving it never chooses, switches or needs the user's matplotlib backend (their
``plt.show()`` keeps working after ``import ddwmmr``), opens no window and may be drawn in a
worker thread. It is not shown by ``plt.show()``: save it (``fig.savefig``) or, in
Jupyter once the inline backend is active (``%matplotlib inline``, or after a pyplot
figure), display it (a cell's value, ``IPython.display.display(fig)``). To show a run's figures in a
window, the plotting functions of :mod:`ddwmmr.reports.plots` draw into pyplot's instead:
``plot_path(result, ax=ax)``, ``plot_errors(result, fig=plt.figure())`` (likewise
``plot_rates``, ``plot_metrics``), then ``plt.show()``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def new_figure(figsize: tuple[float, float], **kwargs: Any) -> Figure:
    """A figure of ``figsize`` (width, height in inches; ``kwargs``: the other
    :class:`~matplotlib.figure.Figure` arguments) on an Agg canvas of its own: the canvas a
    pyplot figure has under the Agg backend, so text is measured and PNGs are rendered
    exactly as there."""
    fig = Figure(figsize=figsize, **kwargs)
    FigureCanvasAgg(fig)
    return fig


def frame_indices(last: int, frames: int) -> list[int]:
    """Up to ``frames`` distinct recorded indices from 0 to ``last``, evenly spread, both
    ends included: every index when there are no more than ``frames`` of them (a short
    run's animation shows each recorded instant once instead of repeating them)."""
    count = max(min(frames, last + 1), 1)
    return sorted({round(last * i / max(count - 1, 1)) for i in range(count)})


def save_gif(
    fig: Figure,
    update: Callable[[int], object],
    count: int,
    path: Path,
    fps: int,
    advance: Callable[[], object] | None = None,
) -> Path:
    """Write ``count`` frames of ``fig`` to the GIF ``path`` at ``fps`` frames per second:
    for each frame i = 0..count-1, ``update(i)`` sets the artists, the figure is rendered
    once at ``savefig.dpi`` and ``advance()`` (if given) is called.

    The file is byte for byte what ``FuncAnimation(fig, update, frames=count).save(path,
    writer=PillowWriter(fps=fps))`` writes, in half the time: that renders every frame twice
    (a redraw after the update, then the grab), and rendering is nearly all of the time.
    """
    from matplotlib import rcParams
    from matplotlib.animation import PillowWriter

    dpi = rcParams["savefig.dpi"]
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, str(path), fig.dpi if dpi == "figure" else dpi):
        for frame in range(count):
            update(frame)
            writer.grab_frame()
            if advance is not None:
                advance()
    return path
