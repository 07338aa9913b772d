"""Figures of the report writers' own, not pyplot's.

A :class:`~matplotlib.figure.Figure` made here belongs to no pyplot figure manager, so
drawing or saving it never chooses, switches or needs the user's matplotlib backend (their
``plt.show()`` keeps working after ``import ddwmmr``), opens no window and may be drawn in a
worker thread. It is not shown by ``plt.show()``: save it (``fig.savefig``) or display it
(a Jupyter cell's value, ``IPython.display.display(fig)``).
"""

from __future__ import annotations

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
