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
and MP4 export) all take their frames from :func:`saved_frames`: the frames of
:func:`blitted_frames` painted as ``savefig`` paints a PNG under the user's rcParams
(:func:`as_saved`); GIFs are encoded by :func:`gif_bytes` (:func:`saved_gif_bytes`,
:func:`save_gif`).
"""

from __future__ import annotations

import io
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.artist import Artist
from matplotlib.backend_bases import RendererBase
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure, FigureBase
from numpy.typing import NDArray
from PIL import Image

from ddwmmr.errors import ParameterError, as_path, check_int_at_least, shown


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


@contextmanager
def as_saved(
    fig: Figure, dpi: float | None = None, transparent: bool | None = None
) -> Iterator[Figure]:
    """``fig`` as ``fig.savefig`` renders it under the user's rcParams, restored on exit:
    at ``dpi`` (as savefig's own argument; default ``savefig.dpi``, where ``'figure'`` is
    its own), its face and edge painted in ``savefig.facecolor`` and ``savefig.edgecolor``
    (``'auto'``: its own) and, if ``transparent`` (default ``savefig.transparent``), the
    figure's and every axes' (and subfigure's) background clear, as savefig clears them.
    ``savefig.bbox`` is not applied: every frame of an animation is the whole figure (as
    matplotlib's ``Animation.save`` does)."""
    from matplotlib import rcParams
    from matplotlib.axes import Axes
    from matplotlib.figure import SubFigure
    from matplotlib.patches import Patch

    if dpi is None:
        dpi = rcParams["savefig.dpi"]
    if transparent is None:
        transparent = rcParams["savefig.transparent"]
    colors = {
        "facecolor": rcParams["savefig.facecolor"],
        "edgecolor": rcParams["savefig.edgecolor"],
    }
    backgrounds: list[Patch] = [fig.patch]
    if transparent:
        colors = {"facecolor": "none", "edgecolor": "none"}
        backgrounds += [
            found.patch for found in fig.findobj() if isinstance(found, Axes | SubFigure)
        ]
    with ExitStack() as restore:
        figure_dpi = fig.dpi
        if dpi != "figure" and dpi != figure_dpi:
            fig.dpi = dpi
            restore.callback(setattr, fig, "dpi", figure_dpi)
        for patch in backgrounds:
            for name, color in colors.items():
                if isinstance(color, str) and color == "auto":
                    continue
                own = getattr(patch, f"get_{name}")()
                getattr(patch, f"set_{name}")(color)
                restore.callback(getattr(patch, f"set_{name}"), own)
        yield fig


#: The fastest GIF animation: a GIF times its frames in hundredths of a second.
MAX_FPS = 100


def checked_gif_options(path: Any, frames: Any, fps: Any) -> tuple[Path, int, int]:
    """``(path, frames, fps)`` of an animation, checked before anything is drawn: ``path``
    a ``.gif`` file's path (a name saying another format is a slip: a GIF is written
    whatever it says), ``frames`` an integer >= 1, ``fps`` one in [1, :data:`MAX_FPS`];
    else a one-line :class:`~ddwmmr.errors.ParameterError` naming the parameter."""
    frames = check_int_at_least("frames", frames, 1)
    fps = check_int_at_least("fps", fps, 1, MAX_FPS)
    path = as_path(path, "path")
    if path.suffix.lower() != ".gif":
        raise ParameterError(f"path must be a .gif file (got {shown(path.name, 60)})")
    return path, frames, fps


def saved_frames(
    fig: Figure,
    update: Callable[[int], Iterable[Artist]],
    count: int,
    dpi: float | None = None,
    transparent: bool | None = None,
) -> Iterator[NDArray[np.uint8]]:
    """The frames of :func:`blitted_frames` (``update(i)`` sets frame i and returns the
    artists that move), each the figure as a PNG of ``fig.savefig`` shows it
    (:func:`as_saved` with ``dpi`` and ``transparent``: by default ``savefig.dpi``,
    ``savefig.facecolor``, ``savefig.edgecolor``, ``savefig.transparent``). The figure is
    its own again once the frames are exhausted (or the iterator closed)."""
    with as_saved(fig, dpi, transparent):
        yield from blitted_frames(fig, update, count)


def saved_gif_bytes(
    fig: Figure,
    update: Callable[[int], Iterable[Artist]],
    count: int,
    fps: int,
    advance: Callable[[], object] | None = None,
    dpi: float | None = None,
) -> bytes:
    """A GIF of ``count`` frames of ``fig`` at ``fps`` frames per second
    (:func:`gif_bytes`): the frames of :func:`saved_frames` (at ``dpi``, default
    ``savefig.dpi``); ``advance()`` (if given) is called after each frame is drawn. A
    transparent background (``savefig.transparent``) is transparent in the GIF, to its one
    transparent colour (:func:`gif_bytes`)."""
    images = []
    for rgba in saved_frames(fig, update, count, dpi):
        image = Image.fromarray(rgba)
        # a copy, out of the canvas; RGB where every pixel is opaque to gif_bytes, so
        # that an opaque animation's frames are held at 3 bytes a pixel, not 4
        clear = bool((rgba[..., 3] < GIF_OPAQUE).any())
        images.append(image.copy() if clear else image.convert("RGB"))
        if advance is not None:
            advance()
    return gif_bytes(images, fps)


def save_gif(
    fig: Figure,
    update: Callable[[int], Iterable[Artist]],
    count: int,
    path: Path,
    fps: int,
    advance: Callable[[], object] | None = None,
) -> Path:
    """Write ``count`` frames of ``fig`` to the GIF ``path`` at ``fps`` frames per second:
    :func:`saved_gif_bytes` (``update(i)`` sets frame i and returns the artists that
    move; each frame as a PNG of ``fig.savefig`` shows it under the user's rcParams;
    ``advance()``, if given, called after each frame is drawn)."""
    Path(path).write_bytes(saved_gif_bytes(fig, update, count, fps, advance))
    return path


#: Colours of an animated GIF's one palette.
GIF_COLORS = 128
#: The alpha (of 255) from which a pixel of an RGBA image is opaque in a GIF.
GIF_OPAQUE = 128


def gif_bytes(images: Sequence[Image.Image], fps: int) -> bytes:
    """The RGB or RGBA ``images`` as a looping GIF, ``fps`` frames per second.

    One palette serves every frame: :data:`GIF_COLORS` colours of the last image (an
    animation's last frame has every trail and colour), its most common colour (the
    background) exactly, each pixel mapped to its nearest entry without dithering.

    A GIF pixel is either opaque or transparent (one palette entry, added for it): where
    an RGBA image's alpha is below half (128), its pixel is transparent, elsewhere opaque
    in its own colour, so antialiased edges over a clear background keep their colour
    without the partial transparency of a PNG. Each frame of such a GIF replaces the one
    before (disposal 2), none shows through another. Images without a transparent pixel
    make an opaque GIF, as RGB ones."""
    clear = [
        np.asarray(image.getchannel("A")) < GIF_OPAQUE if image.mode == "RGBA" else None
        for image in images
    ]
    transparent = any(mask is not None and mask.any() for mask in clear)
    pictures = [image if image.mode == "RGB" else image.convert("RGB") for image in images]
    last = pictures[-1]
    if transparent and clear[-1] is not None and not clear[-1].all():
        # the palette and background of the last image's opaque pixels only
        last = Image.fromarray(np.asarray(last)[~clear[-1]][np.newaxis])
    palette = last.quantize(colors=GIF_COLORS - transparent, method=Image.Quantize.FASTOCTREE)
    # every pixel's colour is counted (at most one per pixel): never None
    _, common = max(last.getcolors(last.width * last.height) or [])
    background = np.asarray(common, dtype=int)
    entries = np.asarray(palette.getpalette(), dtype=int).reshape(-1, 3)
    entries[np.argmin(np.abs(entries - background).sum(axis=1))] = background
    palette.putpalette(entries.astype(np.uint8).tobytes())
    frames = [image.quantize(palette=palette, dither=Image.Dither.NONE) for image in pictures]
    options: dict[str, Any] = {}
    if transparent:
        # one more palette entry, for the clear pixels only (the quantized ones map to the
        # entries above), of a colour no other entry has: Pillow's encoder tells a frame's
        # pixels from the cleared background (disposal 2) by colour, dropping any opaque
        # pixel of the transparent entry's colour
        index = len(entries)
        used = {tuple(entry) for entry in entries.tolist()}
        unused = next(c for v in range(256) if (c := (v, 255 - v, v)) not in used)
        with_clear = np.append(entries, [unused], axis=0).astype(np.uint8).tobytes()
        for frame, mask in zip(frames, clear):
            frame.putpalette(with_clear)
            if mask is not None:
                frame.paste(index, mask=Image.fromarray(mask))
        options = {"transparency": index, "disposal": 2}
    buffer = io.BytesIO()
    frames[0].save(
        buffer,
        format="GIF",
        save_all=True,
        append_images=frames[1:],
        duration=frame_durations_ms(len(frames), fps),
        loop=0,
        **options,
    )
    return buffer.getvalue()


def frame_durations_ms(count: int, fps: float) -> list[int]:
    """How long each of ``count`` GIF frames shows (ms) for ``fps`` frames per second: a
    GIF counts in whole hundredths of a second, so frame ``i`` ends at ``i + 1`` frames'
    time rounded to one: each frame within 10 ms of ``1000 / fps`` (15 fps: 70, 60, 70
    ms...; 12 fps: 80, 90, 80 ms...), the time elapsed at every frame within 5 ms of
    the frames' count over ``fps``."""
    ends = [round(100 * (i + 1) / fps) for i in range(count)]
    return [10 * (end - start) for start, end in zip([0, *ends], ends)]
