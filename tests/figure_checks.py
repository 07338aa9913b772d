"""What every figure of the package must satisfy, measured on the rendered figure.

:func:`figure_problems` draws a matplotlib figure and lists, in words, every place where
data is hidden or cut (one check for every figure family: track, compare, scenarios,
physics, the docs scripts, the GUI):

- every point of every data line and scatter, every patch drawn in data coordinates
  (footprints, obstacles) and every text placed inside an axes lies inside that axes
  (the axes fit what is drawn), markers whole (not halved by the edge); zoom panels are
  exempt through ``cropped``;
- no legend box is crossed by a data line (segments, not only vertices, so a horizontal
  limit line under a legend counts) nor covers a scatter point or a data patch (bar,
  footprint, obstacle: its bounding box);
- no text inside an axes (annotations, labels of drawn objects) is crossed by a data line
  or overlaps another such text;
- no text of the figure (titles, axis and tick labels, legends, annotations) runs off
  the canvas.

:func:`text_collisions` checks the texts of a whole window (the simulator's: panel
widgets beside the plots): no drawn text overlaps another, lies on the frame of an axes
not its own (a label on a neighbouring text box or plot) or runs off the canvas.

Coordinates are display pixels from matplotlib's own transforms and ``get_window_extent``;
a tolerance of :data:`TOLERANCE_PX` absorbs antialiasing and line caps.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.collections import PathCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.text import Text
from matplotlib.transforms import Bbox

#: Slack (px) of the containment and overlap checks.
TOLERANCE_PX = 1.5


def figure_problems(
    fig: Figure,
    cropped: Iterable[Axes] = (),
    ignore: Callable[[Artist], bool] = lambda artist: False,
    only: Iterable[Axes] | None = None,
) -> list[str]:
    """Every violation of the rules above in ``fig`` (empty: the figure shows its data).

    Args:
        only: check the data of these axes only (default all); a window's widgets, whose
            labels sit beside their boxes on purpose, are left out this way. The texts of
            the whole figure are still checked against the canvas.
        cropped: axes that deliberately show only part of their data (zoom panels): their
            data may leave them; legends and labels must still not cover it.
        ignore: artists that are neither data nor labels (a playback cursor...).
    """
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    cropped = set(cropped)
    problems: list[str] = []
    everything: list[tuple[Bbox, list[tuple[str, np.ndarray]]]] = []  # per axes: box, data
    for ax in fig.axes if only is None else list(only):
        if not ax.get_visible():
            continue
        name = _axes_name(ax)
        polylines = data_polylines(ax, ignore)
        box = ax.get_window_extent(renderer)
        everything.append((box, [(f"{name}: {label}", xy) for label, xy in polylines]))
        if ax not in cropped:
            problems += _outside(name, box, polylines)
            problems += _markers_cut(name, ax, box, ignore)
            problems += _patches_outside(name, ax, box, ignore)
        legend = ax.get_legend()
        if legend is not None and legend.get_visible():
            extent = legend.get_window_extent(renderer)
            problems += _covered(f"{name}: legend", extent, polylines)
            problems += _patches_covered(f"{name}: legend", extent, ax, ignore)
        labels = [t for t in ax.texts if _shown(t) and not ignore(t)]
        problems += _labels(name, labels, box, polylines, renderer, ax not in cropped)
    for legend in fig.legends:
        if not legend.get_visible():
            continue
        extent = legend.get_window_extent(renderer)
        for box, polylines in everything:  # only where the data shows: inside its axes
            shared = Bbox.intersection(extent, box)
            if shared is not None:
                problems += _covered("figure legend", shared, polylines)
    problems += _off_canvas(fig, renderer)
    return problems


def assert_figure_shows_its_data(fig: Figure, **kwargs) -> None:
    """Fail with the list of :func:`figure_problems` if there is any."""
    problems = figure_problems(fig, **kwargs)
    assert not problems, "figure hides or cuts data:\n  " + "\n  ".join(problems[:20])


def drawn_texts(fig: Figure) -> list[Text]:
    """The texts a full draw of ``fig`` renders (not the hidden, empty or out-of-view
    ones, such as the tick labels matplotlib keeps beyond the axis limits)."""
    renderer = fig.canvas.get_renderer()
    seen: dict[int, Text] = {}
    draw_text = renderer.draw_text

    def record(gc, x, y, s, prop, angle, ismath=False, mtext=None):
        if mtext is not None:
            seen.setdefault(id(mtext), mtext)
        return draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)

    renderer.draw_text = record
    try:
        fig.canvas.draw()
    finally:
        del renderer.draw_text
    return list(seen.values())


def text_collisions(fig: Figure) -> list[str]:
    """Every drawn text of ``fig`` that overlaps another drawn text, lies on the frame of
    a visible axes other than its own (a field, a button, a plot), or runs off the canvas,
    in words (empty: every text stands apart)."""
    texts = drawn_texts(fig)
    renderer = fig.canvas.get_renderer()
    extents = [(text, text.get_window_extent(renderer)) for text in texts]
    frames = [ax for ax in fig.axes if ax.get_visible() and ax.get_frame_on()]
    problems = []
    for i, (text, extent) in enumerate(extents):
        name = repr(text.get_text()[:40])
        if not _contains(fig.bbox, extent):
            problems.append(f"text {name} runs off the figure")
        for other, other_extent in extents[i + 1 :]:
            if _overlap(extent, other_extent):
                problems.append(f"text {name} overlaps text {other.get_text()[:40]!r}")
        for ax in frames:
            if ax is not text.axes and _overlap(extent, ax.bbox):
                problems.append(f"text {name} lies on {_axes_name(ax)} at {ax.bbox.bounds}")
    return problems


def data_polylines(
    ax: Axes, ignore: Callable[[Artist], bool] = lambda artist: False
) -> list[tuple[str, np.ndarray]]:
    """Display coordinates (px) of every visible data line (polyline, NaN-broken) and
    scatter (points, one polyline of length 1 each) of ``ax``, with a name."""
    found = []
    for line in ax.lines:
        if not line.get_visible() or ignore(line) or not isinstance(line, Line2D):
            continue
        xy = np.column_stack(
            [
                np.asarray(line.get_xdata(orig=False), float),
                np.asarray(line.get_ydata(orig=False), float),
            ]
        )
        if len(xy) == 0:
            continue
        display = line.get_transform().transform(xy)
        if line.get_linestyle() in ("None", "", " ", "none"):  # markers only: no segments
            found += [(_artist_name(line), point[None, :]) for point in display]
        else:
            found.append((_artist_name(line), display))
    for collection in ax.collections:
        if not isinstance(collection, PathCollection) or not collection.get_visible():
            continue
        if ignore(collection):
            continue
        offsets = np.asarray(collection.get_offsets(), float)
        if len(offsets) == 0:
            continue
        display = collection.get_offset_transform().transform(offsets)
        for point in display:
            found.append((_artist_name(collection), point[None, :]))
    return found


def segments_crossing(box: Bbox, xy: np.ndarray, tolerance: float = TOLERANCE_PX) -> int:
    """How many segments of the polyline ``xy`` (display px; NaN breaks it) meet ``box``
    shrunk by ``tolerance``; a single point counts when it lies inside."""
    x0, y0 = box.x0 + tolerance, box.y0 + tolerance
    x1, y1 = box.x1 - tolerance, box.y1 - tolerance
    if x1 <= x0 or y1 <= y0:
        return 0
    xy = np.asarray(xy, float)
    if len(xy) == 1:
        x, y = xy[0]
        return int(x0 < x < x1 and y0 < y < y1)
    p, q = xy[:-1], xy[1:]
    keep = np.all(np.isfinite(p), axis=1) & np.all(np.isfinite(q), axis=1)
    p, q = p[keep], q[keep]
    # Liang-Barsky clipping of every segment at once.
    d = q - p
    low, high = np.zeros(len(p)), np.ones(len(p))
    inside = np.ones(len(p), bool)
    for along, start, lo, hi in ((d[:, 0], p[:, 0], x0, x1), (d[:, 1], p[:, 1], y0, y1)):
        for num, den in ((start - lo, -along), (hi - start, along)):
            parallel = den == 0
            inside &= ~(parallel & (num < 0))
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = num / den
            entering = (den < 0) & ~parallel
            leaving = (den > 0) & ~parallel
            low = np.where(entering, np.maximum(low, ratio), low)
            high = np.where(leaving, np.minimum(high, ratio), high)
    return int(np.sum(inside & (low < high)))


# -- the individual checks --------------------------------------------------------------


def _outside(name: str, box: Bbox, polylines: list[tuple[str, np.ndarray]]) -> list[str]:
    grown = box.expanded(1.0, 1.0).padded(TOLERANCE_PX)
    problems = []
    for label, xy in polylines:
        finite = xy[np.all(np.isfinite(xy), axis=1)]
        out = ~(
            (finite[:, 0] >= grown.x0)
            & (finite[:, 0] <= grown.x1)
            & (finite[:, 1] >= grown.y0)
            & (finite[:, 1] <= grown.y1)
        )
        if np.any(out):
            problems.append(f"{name}: {label} has {int(out.sum())} points outside the axes")
    return problems


def _markers_cut(name: str, ax: Axes, box: Bbox, ignore: Callable[[Artist], bool]) -> list[str]:
    """Markers (of lines and scatters) whole inside the axes, not halved by its edge."""
    scale = ax.figure.dpi / 72.0
    problems = []
    found: list[tuple[Artist, np.ndarray, np.ndarray]] = []  # artist, centres, radii (px)
    for line in ax.lines:
        if not line.get_visible() or ignore(line) or line.get_marker() in (None, "", "None", " "):
            continue
        xy = np.column_stack(
            [
                np.asarray(line.get_xdata(orig=False), float),
                np.asarray(line.get_ydata(orig=False), float),
            ]
        )
        centres = line.get_transform().transform(xy) if len(xy) else np.empty((0, 2))
        found.append((line, centres, np.full(len(centres), 0.5 * line.get_markersize() * scale)))
    for collection in ax.collections:
        if not isinstance(collection, PathCollection) or not collection.get_visible():
            continue
        if ignore(collection) or len(collection.get_offsets()) == 0:
            continue
        centres = collection.get_offset_transform().transform(collection.get_offsets())
        sizes = np.resize(np.asarray(collection.get_sizes(), float), len(centres))
        found.append((collection, centres, 0.5 * np.sqrt(sizes) * scale))
    for artist, centres, radii in found:
        keep = np.all(np.isfinite(centres), axis=1)
        centres, radii = centres[keep], radii[keep] - TOLERANCE_PX
        cut = (
            (centres[:, 0] - radii < box.x0)
            | (centres[:, 0] + radii > box.x1)
            | (centres[:, 1] - radii < box.y0)
            | (centres[:, 1] + radii > box.y1)
        )
        if np.any(cut):
            problems.append(f"{name}: {_artist_name(artist)} has {int(cut.sum())} markers cut")
    return problems


def _patches_outside(name: str, ax: Axes, box: Bbox, ignore: Callable[[Artist], bool]) -> list[str]:
    """Patches drawn in data coordinates (robot footprints, obstacles) inside the axes."""
    problems = []
    grown = box.padded(TOLERANCE_PX)
    for patch in ax.patches:
        if not isinstance(patch, Patch) or not patch.get_visible() or ignore(patch):
            continue
        if patch.get_transform().contains_branch(ax.transAxes):
            continue  # placed in axes coordinates: a frame, not data
        extent = patch.get_window_extent()
        if extent.width == 0 and extent.height == 0:
            continue
        if not (grown.x0 <= extent.x0 and extent.x1 <= grown.x1 and grown.y0 <= extent.y0) or not (
            extent.y1 <= grown.y1
        ):
            problems.append(f"{name}: patch {_artist_name(patch)} is cut by the axes")
    return problems


def _patches_covered(what: str, box: Bbox, ax: Axes, ignore: Callable[[Artist], bool]) -> list[str]:
    """Data patches (bars, footprints, obstacles) that ``box`` overlaps."""
    problems = []
    for patch in ax.patches:
        if not patch.get_visible() or ignore(patch):
            continue
        if patch.get_transform().contains_branch(ax.transAxes):
            continue
        if _overlap(box, patch.get_window_extent()):
            problems.append(f"{what} covers patch {_artist_name(patch)}")
    return problems


def _covered(what: str, box: Bbox, polylines: list[tuple[str, np.ndarray]]) -> list[str]:
    problems = []
    for label, xy in polylines:
        hits = segments_crossing(box, xy)
        if hits:
            problems.append(f"{what} covers {label} ({hits} segments)")
    return problems


def _labels(
    name: str,
    labels: list[Text],
    box: Bbox,
    polylines: list[tuple[str, np.ndarray]],
    renderer,
    must_be_inside: bool,
) -> list[str]:
    problems = []
    extents = [(t.get_text(), t.get_window_extent(renderer)) for t in labels]
    for i, (text, extent) in enumerate(extents):
        label = f"{name}: label {text!r}"
        if must_be_inside and not _contains(box, extent):
            problems.append(f"{label} leaves the axes")
        problems += _covered(label, extent, polylines)
        for other, other_extent in extents[i + 1 :]:
            if _overlap(extent, other_extent):
                problems.append(f"{label} overlaps label {other!r}")
    return problems


def _off_canvas(fig: Figure, renderer) -> list[str]:
    """Titles, axis and tick labels, legends and texts of the figure inside the canvas."""
    canvas = fig.bbox
    problems = []
    for ax in fig.axes:
        if ax.get_visible() and not _contains(canvas, ax.get_tightbbox(renderer)):
            problems.append(f"{_axes_name(ax)}: labels, ticks or legend run off the figure")
    for text in fig.texts:
        if _shown(text) and not _contains(canvas, text.get_window_extent(renderer)):
            problems.append(f"text {text.get_text()[:40]!r} runs off the figure")
    for legend in fig.legends:
        if legend.get_visible() and not _contains(canvas, legend.get_window_extent(renderer)):
            problems.append("figure legend runs off the figure")
    return problems


# -- small helpers ----------------------------------------------------------------------


def _shown(text: Text) -> bool:
    return text.get_visible() and bool(text.get_text().strip())


def _contains(outer: Bbox, inner: Bbox) -> bool:
    return (
        outer.x0 - TOLERANCE_PX <= inner.x0
        and inner.x1 <= outer.x1 + TOLERANCE_PX
        and outer.y0 - TOLERANCE_PX <= inner.y0
        and inner.y1 <= outer.y1 + TOLERANCE_PX
    )


def _overlap(a: Bbox, b: Bbox) -> bool:
    return (
        min(a.x1, b.x1) - max(a.x0, b.x0) > TOLERANCE_PX
        and min(a.y1, b.y1) - max(a.y0, b.y0) > TOLERANCE_PX
    )


def _axes_name(ax: Axes) -> str:
    title = ax.get_title() or ax.get_ylabel().replace("\n", " ") or "axes"
    return f"[{title[:40]}]"


def _artist_name(artist: Artist) -> str:
    label = str(artist.get_label())
    return (
        f"{type(artist).__name__} {label!r}" if not label.startswith("_") else type(artist).__name__
    )


def blitted_and_full(fig: Figure, update, count: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each frame of :func:`ddwmmr.reports.canvas.blitted_frames` (``fig``, ``update``,
    ``count``) beside a full render of ``fig`` after the same ``update(i)``: RGB, float."""
    from ddwmmr.reports.canvas import blitted_frames

    blitted = [frame[..., :3].astype(float) for frame in blitted_frames(fig, update, count)]
    full = []
    for frame in range(count):
        update(frame)
        fig.canvas.draw()
        full.append(np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(float))
    return list(zip(blitted, full))


class SavedFigures:
    """Every figure saved while installed (``Figure.savefig`` patched through pytest's
    ``monkeypatch``): its name and :func:`figure_problems`, checked just before it is
    written. Scripts that save by themselves (the docs figure scripts) are checked this
    way without changing them, and so is every frame of an animation
    (:func:`ddwmmr.reports.canvas.blitted_frames` patched: checked after its update)."""

    def __init__(self, monkeypatch, **check) -> None:
        from ddwmmr.reports import canvas

        self.problems: dict[str, list[str]] = {}
        original = Figure.savefig
        original_frames = canvas.blitted_frames
        saved = self

        def blitted_frames(fig: Figure, update, count: int):
            def checked(frame: int):
                artists = update(frame)
                saved.problems[f"frame#{len(saved.problems)}"] = figure_problems(fig, **check)
                return artists

            return original_frames(fig, checked, count)

        monkeypatch.setattr(canvas, "blitted_frames", blitted_frames)

        def savefig(fig: Figure, fname, *args, **kwargs):
            name = fname.name if isinstance(fname, Path) else str(fname)
            name = name if isinstance(fname, (str, Path)) else "frame"  # a buffer
            key = name if name not in saved.problems else f"{name}#{len(saved.problems)}"
            saved.problems[key] = figure_problems(fig, **check)
            return original(fig, fname, *args, **kwargs)

        monkeypatch.setattr(Figure, "savefig", savefig)

    def failing(self) -> dict[str, list[str]]:
        """The saved figures with problems (name -> the first five)."""
        return {name: found[:5] for name, found in self.problems.items() if found}


class SaveGifCalls:
    """Each call of ``module.save_gif`` while installed (patched through pytest's
    ``monkeypatch``), recorded then made by the real one: :attr:`calls` holds its
    ``(fig, update, count)``, :attr:`draws` counts the full renders (``Figure.draw``) made
    during the calls."""

    def __init__(self, monkeypatch, module) -> None:
        self.calls: list[tuple[Figure, Callable, int]] = []
        self.draws = 0
        real_save_gif = module.save_gif
        real_draw = Figure.draw
        recorded = self

        def draw(*args):
            recorded.draws += 1
            return real_draw(*args)

        def save_gif(fig: Figure, update, count: int, *args):
            recorded.calls.append((fig, update, count))
            with monkeypatch.context() as during:
                during.setattr(Figure, "draw", draw)
                return real_save_gif(fig, update, count, *args)

        monkeypatch.setattr(module, "save_gif", save_gif)
