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

Animations of such figures (`track --animate`, the physics animation, the window's GIF
and MP4 export) all take their frames from :func:`blitted_frames`; GIFs are encoded by
:func:`gif_bytes`.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.artist import Artist
from matplotlib.backend_bases import RendererBase
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure, FigureBase
from numpy.typing import NDArray
from PIL import Image


def new_figure(figsize: tuple[float, float], **kwargs: Any) -> Figure:
    """A figure of ``figsize`` (width, height in inches; ``kwargs``: the other
    :class:`~matplotlib.figure.Figure` arguments) on an Agg canvas of its own: the canvas a
    pyplot figure has under the Agg backend, so text is measured and PNGs are rendered
    exactly as there."""
    fig = Figure(figsize=figsize, **kwargs)
    FigureCanvasAgg(fig)
    return fig


def renderer_of(figure: FigureBase) -> RendererBase:
    """The renderer ``figure``'s text and extents are measured with: its canvas's own where
    it has one (Agg and the window's TkAgg canvas built on it), else the one matplotlib's
    ``tight_layout`` measures with (the svg, pdf and cairo canvases have no
    ``get_renderer``), so a layout can be measured in a figure on any canvas."""
    # ignore: FigureBase._get_renderer is private, outside matplotlib's stubs
    renderer: RendererBase = figure._get_renderer()  # type: ignore[attr-defined]
    return renderer


def frame_indices(last: int, frames: int) -> list[int]:
    """Up to ``frames`` distinct recorded indices from 0 to ``last``, evenly spread, both
    ends included: every index when there are no more than ``frames`` of them (a short
    run's animation shows each recorded instant once instead of repeating them)."""
    count = max(min(frames, last + 1), 1)
    return sorted({round(last * i / max(count - 1, 1)) for i in range(count)})


def blitted_frames(
    fig: Figure, update: Callable[[int], Iterable[Artist]], count: int
) -> Iterator[NDArray[np.uint8]]:
    """The ``count`` frames of an animation of ``fig`` (on an Agg canvas, as
    :func:`new_figure` makes), each a ``(height, width, 4)`` RGBA array of the canvas at
    the figure's dpi: for frame i = 0..count-1, ``update(i)`` sets the artists and returns
    the ones that move, the same ones every frame (as ``FuncAnimation``'s with
    ``blit=True``); a text that changes (a title with the time) is one of them.

    The still parts are rendered once, as they stand after ``update(count - 1)``, without
    the moving artists (marked animated meanwhile); every frame is that background with
    the moving artists drawn over it in z-order. The picture is a full render's, but where a
    moving artist crosses a still one of a higher z-order (drawn over it there). Several
    times faster than full renders, which spend most of their time on the axes' ticks.
    Each array views the canvas's buffer: it holds its frame until the next is drawn.
    """
    canvas = fig.canvas
    if count < 1:
        return
    moving = sorted(update(count - 1), key=lambda artist: artist.get_zorder())
    before = [artist.get_animated() for artist in moving]
    try:
        for artist in moving:
            artist.set_animated(True)
        canvas.draw()
        # ignore (here and below): the Agg canvas has the blitting and buffer methods the
        # base class lacks
        background = canvas.copy_from_bbox(fig.bbox)  # type: ignore[attr-defined]
        for frame in range(count):
            artists = sorted(update(frame), key=lambda artist: artist.get_zorder())
            canvas.restore_region(background)  # type: ignore[attr-defined]
            for artist in artists:
                fig.draw_artist(artist)
            yield np.asarray(canvas.buffer_rgba())  # type: ignore[attr-defined]
    finally:
        for artist, animated in zip(moving, before):
            artist.set_animated(animated)


def save_gif(
    fig: Figure,
    update: Callable[[int], Iterable[Artist]],
    count: int,
    path: Path,
    fps: int,
    advance: Callable[[], object] | None = None,
) -> Path:
    """Write ``count`` frames of ``fig`` to the GIF ``path`` at ``fps`` frames per second
    (:func:`gif_bytes`): the frames of :func:`blitted_frames` (``update(i)`` sets frame i
    and returns the artists that move), rendered at ``savefig.dpi``; ``advance()`` (if
    given) is called after each frame is drawn."""
    from matplotlib import rcParams

    dpi = rcParams["savefig.dpi"]
    figure_dpi = fig.dpi
    images = []
    try:
        if dpi != "figure":
            fig.dpi = dpi
        for rgba in blitted_frames(fig, update, count):
            images.append(Image.fromarray(rgba).convert("RGB"))  # a copy, out of the canvas
            if advance is not None:
                advance()
    finally:
        if fig.dpi != figure_dpi:
            fig.dpi = figure_dpi
    Path(path).write_bytes(gif_bytes(images, fps))
    return path


#: Colours of an animated GIF's one palette.
GIF_COLORS = 128


def gif_bytes(images: Sequence[Image.Image], fps: int) -> bytes:
    """The RGB ``images`` as a looping GIF, ``fps`` frames per second.

    One palette serves every frame: :data:`GIF_COLORS` colours of the last image (an
    animation's last frame has every trail and colour), its most common colour (the
    background) exactly, each pixel mapped to its nearest entry without dithering."""
    last = images[-1]
    palette = last.quantize(colors=GIF_COLORS, method=Image.Quantize.FASTOCTREE)
    # every pixel's colour is counted (at most one per pixel): never None
    _, common = max(last.getcolors(last.width * last.height) or [])
    background = np.asarray(common, dtype=int)
    entries = np.asarray(palette.getpalette(), dtype=int).reshape(-1, 3)
    entries[np.argmin(np.abs(entries - background).sum(axis=1))] = background
    palette.putpalette(entries.astype(np.uint8).tobytes())
    frames = [image.quantize(palette=palette, dither=Image.Dither.NONE) for image in images]
    buffer = io.BytesIO()
    frames[0].save(
        buffer,
        format="GIF",
        save_all=True,
        append_images=frames[1:],
        duration=round(1000 / fps),
        loop=0,
    )
    return buffer.getvalue()
