"""The track tool's GIF (``save_animation``) shows each recorded instant at most once: a
run shorter than ``frames`` instants gives one frame per instant, at ``fps``, instead of
the same instants repeated up to ``frames`` (which played a 0.2 s run for 5 s and
rendered every repeat)."""

from __future__ import annotations

import itertools

import matplotlib as mpl
import numpy as np
import pytest
from matplotlib.figure import Figure
from PIL import Image

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.reports import plots
from ddwmmr.reports.canvas import (
    blitted_frames,
    frame_durations_ms,
    frame_indices,
    new_figure,
    save_gif,
)
from figure_checks import SaveGifCalls, blitted_and_full


def gif_frames(path) -> tuple[int, int]:
    """(frames, total duration in ms) of a GIF file."""
    with Image.open(path) as image:
        durations = []
        for index in range(image.n_frames):
            image.seek(index)
            durations.append(image.info["duration"])
    return len(durations), sum(durations)


@pytest.mark.parametrize(("last", "frames"), [(0, 80), (1, 80), (10, 80), (79, 80), (2000, 80)])
def test_frame_indices_are_distinct_spread_and_keep_both_ends(last, frames):
    indices = frame_indices(last, frames)
    assert len(indices) == min(last + 1, frames) == len(set(indices))
    assert indices[0] == 0 and indices[-1] == last and indices == sorted(indices)
    steps = [b - a for a, b in itertools.pairwise(indices)]
    assert not steps or max(steps) - min(steps) <= 1  # evenly spread, to rounding


def test_a_short_run_is_animated_once_per_recorded_instant(tmp_path, monkeypatch):
    result = simulate(Robot(), Ellipse(), "ats", duration=0.2)  # 11 recorded instants
    saved = SaveGifCalls(monkeypatch, plots)
    path = plots.save_animation(result, tmp_path / "short.gif", frames=80, fps=15)
    rendered = [count for _, _, count in saved.calls]
    assert rendered == [11]
    count, duration_ms = gif_frames(path)
    assert count == 11
    assert duration_ms == pytest.approx(11 * 1000 / 15, abs=5)  # GIF: 10 ms units


@pytest.mark.parametrize("fps", [1, 7, 12, 15, 24, 30, 33, 100])
def test_gif_frames_keep_the_pace_in_whole_centiseconds(fps):
    """A GIF stores each frame's time in hundredths of a second: 15 fps cannot be 66.7 ms
    frames, so they alternate (70, 60, 70...) and every frame shows when it should, to
    5 ms (one per frame, cut to 60 ms, ran 15 fps at 16.7)."""
    durations = frame_durations_ms(300, fps)
    assert all(d % 10 == 0 and abs(d - 1000 / fps) < 10 for d in durations)
    elapsed = np.cumsum(durations)
    assert np.abs(elapsed - np.arange(1, 301) * 1000 / fps).max() <= 5.0


def test_a_long_run_keeps_its_frame_count(tmp_path):
    result = simulate(Robot(), Ellipse(), "ats", duration=3.0)  # 151 recorded instants
    count, _ = gif_frames(plots.save_animation(result, tmp_path / "long.gif", frames=40))
    assert count == 40


def moving_figure():
    """A figure with still parts (axes, ticks, a line, a legend) and moving ones: a growing
    line, a marker and a title naming the frame, which ``update`` returns. The moving line
    crosses no spine nor the legend (drawn over it there in a blitted frame)."""
    fig = new_figure((4.0, 3.0), dpi=60)
    ax = fig.subplots()
    ax.plot([0, 1], [-1, 1], color="0.5", label="still")
    ax.legend(loc="lower left")
    ax.set_xlim(-0.1, 1.1)
    ax.set_ylim(-1.2, 1.2)
    (line,) = ax.plot([], [], color="tab:blue")
    (dot,) = ax.plot([], [], "o", color="tab:orange")
    x = np.linspace(0, 1, 50)

    def update(frame: int):
        k = 10 * (frame + 1)
        line.set_data(x[:k], np.sin(6 * x[:k]))
        dot.set_data([x[k - 1]], [np.sin(6 * x[k - 1])])
        title = ax.set_title(f"frame {frame}: t = {0.37 * frame:.2f} s" + "!" * frame)
        return line, dot, title

    return fig, ax, update


def test_blitted_frames_are_full_renders_with_the_title_of_each_frame(monkeypatch):
    """Each frame (still parts drawn once, the moving artists over them) is what a full
    render at that frame shows; the title, which changes, is drawn in each frame, not
    kept in the still background with another frame's text."""
    fig, ax, update = moving_figure()
    draws = []
    real_draw = Figure.draw
    monkeypatch.setattr(Figure, "draw", lambda *a: draws.append(1) or real_draw(*a))
    frames = [frame.copy() for frame in blitted_frames(fig, update, 5)]
    assert len(draws) == 1 and len(frames) == 5  # the still parts, once
    assert not any(artist.get_animated() for artist in update(0))  # as they were
    monkeypatch.undo()
    pairs = blitted_and_full(fig, update, 5)
    height = pairs[0][0].shape[0]
    above = slice(0, height - round(ax.bbox.y1))  # the band of the title, over the axes
    for frame, (blitted, full) in enumerate(pairs):
        assert np.array_equal(blitted[above], full[above]), frame  # its own title only
        assert np.mean(np.abs(blitted - full)) < 0.1, frame  # of 255
        assert np.mean(np.abs(blitted - full).max(axis=2) > 32) < 1e-3, frame
    first, last = pairs[0][0], pairs[-1][0]
    assert np.mean(np.abs(first[above] - last[above]).max(axis=2) > 32) > 0.01  # it changed
    assert np.mean(np.abs(first - last).max(axis=2) > 32) > 0.01  # so did the line


def test_track_gif_frames_are_the_figure_at_their_instants(tmp_path, monkeypatch):
    """Each decoded frame of ``save_animation``'s GIF is a full render of its figure at
    its instant (title with the time, trace, robot) to the palette's loss, the white
    background exactly white; the still parts are drawn once for all frames."""
    result = simulate(Robot(), Ellipse(), "ats", duration=0.4)  # 21 recorded instants
    saved = SaveGifCalls(monkeypatch, plots)
    path = plots.save_animation(result, tmp_path / "run.gif", frames=8)
    ((fig, update, count),) = saved.calls
    assert count == 8 and saved.draws == 1
    with Image.open(path) as movie:
        decoded = []
        for index in range(movie.n_frames):
            movie.seek(index)
            decoded.append(np.asarray(movie.convert("RGB"), dtype=float))
    renders = [full for _, full in blitted_and_full(fig, update, count)]
    assert len(decoded) == count
    above = slice(0, renders[0].shape[0] - round(fig.axes[0].bbox.y1))  # the title's band
    for index, frame in enumerate(decoded):
        difference = [np.mean(np.abs(frame - render)) for render in renders]
        assert difference[index] < 1.0, index  # of 255
        title = np.abs(frame[above] - renders[index][above]).max(axis=2)
        assert np.mean(title > 32) < 1e-3, index  # the title of its own instant
        assert np.argmin(difference) == index  # this instant's picture, not a neighbour's
        assert (frame[2, 2] == 255).all()  # the figure's white, not a near white


def gif_rgba(path) -> list[np.ndarray]:
    """The decoded frames of a GIF file, RGBA, int (transparent pixels: alpha 0)."""
    with Image.open(path) as movie:
        decoded = []
        for index in range(movie.n_frames):
            movie.seek(index)
            decoded.append(np.asarray(movie.convert("RGBA"), dtype=int))
    return decoded


def savefig_rgba(fig) -> np.ndarray:
    """``fig`` as a PNG of ``fig.savefig`` (the rcParams in force), decoded: RGBA, int."""
    import io

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    buffer.seek(0)
    with Image.open(buffer) as image:
        return np.asarray(image.convert("RGBA"), dtype=int)


def test_gif_frames_take_the_savefig_colours(tmp_path):
    """A GIF's frames are painted as savefig paints a PNG of the figure: the figure's face
    and edge in ``savefig.facecolor`` and ``savefig.edgecolor``; the figure keeps its own
    colours afterwards."""
    fig, _, update = moving_figure()
    fig.patch.set_linewidth(6)  # an edge to paint
    colours = {"savefig.facecolor": "black", "savefig.edgecolor": "red"}
    with mpl.rc_context(colours):
        save_gif(fig, update, 5, tmp_path / "dark.gif", 5)
        update(4)
        png = savefig_rgba(fig)
    frames = gif_rgba(tmp_path / "dark.gif")
    assert len(frames) == 5 and frames[-1].shape == png.shape
    middle = png.shape[0] // 2
    for picture in (png, frames[-1]):
        assert (picture[middle, 1] == [255, 0, 0, 255]).all()  # the edge
        assert (picture[middle, 8] == [0, 0, 0, 255]).all()  # the face, beside the axes
    assert np.mean(np.abs(frames[-1] - png)) < 1.0  # the whole picture, to the palette
    assert fig.get_facecolor() == (1, 1, 1, 1) and fig.get_edgecolor() == (1, 1, 1, 1)
    with mpl.rc_context({"savefig.facecolor": "auto"}):
        assert (savefig_rgba(fig)[middle, 8] == 255).all()  # white again


def test_a_transparent_savefig_makes_a_transparent_gif(tmp_path):
    """Under ``savefig.transparent``, each frame is transparent where a PNG of the figure
    at that frame is less than half opaque (the figure's and the axes' backgrounds), and
    shows its colours elsewhere; no frame shows through the next. The figure's and the
    axes' backgrounds are theirs again afterwards."""
    fig, ax, update = moving_figure()
    with mpl.rc_context({"savefig.transparent": True}):
        save_gif(fig, update, 5, tmp_path / "clear.gif", 5)
        pngs = []
        for frame in range(5):
            update(frame)
            pngs.append(savefig_rgba(fig))
    frames = gif_rgba(tmp_path / "clear.gif")
    assert len(frames) == 5
    for index, (decoded, png) in enumerate(zip(frames, pngs)):
        opaque = png[..., 3] >= 128
        assert 0.01 < np.mean(opaque) < 0.2, index  # the lines and texts only
        assert set(np.unique(decoded[..., 3])) == {0, 255}, index
        mismatched = (decoded[..., 3] == 255) != opaque
        assert np.mean(mismatched) < 1e-3, index  # where the moving line crosses still ones
        both = opaque & (decoded[..., 3] == 255)
        assert np.mean(np.abs(decoded[both][:, :3] - png[both][:, :3])) < 3.0, index
    assert fig.get_facecolor() == (1, 1, 1, 1) and ax.get_facecolor() == (1, 1, 1, 1)


def test_an_opaque_animation_is_held_at_three_bytes_a_pixel(tmp_path, monkeypatch):
    """save_gif keeps an opaque frame as RGB until it is encoded (held as RGBA, a 300
    frame track GIF peaked at 795 MB, not 472 MB), a frame with clear pixels as RGBA."""
    from ddwmmr.reports import canvas

    modes: list[str] = []
    real_gif_bytes = canvas.gif_bytes

    def gif_bytes(images, fps):
        modes.extend(image.mode for image in images)
        return real_gif_bytes(images, fps)

    monkeypatch.setattr(canvas, "gif_bytes", gif_bytes)
    fig, _, update = moving_figure()
    save_gif(fig, update, 3, tmp_path / "opaque.gif", 5)
    with mpl.rc_context({"savefig.transparent": True}):
        save_gif(fig, update, 3, tmp_path / "clear.gif", 5)
    assert modes == ["RGB"] * 3 + ["RGBA"] * 3
