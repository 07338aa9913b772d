"""The track tool's GIF (``save_animation``) shows each recorded instant at most once: a
run shorter than ``frames`` instants gives one frame per instant, at ``fps``, instead of
the same instants repeated up to ``frames`` (which played a 0.2 s run for 5 s and
rendered every repeat)."""

from __future__ import annotations

import itertools

import pytest
from PIL import Image

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.reports import plots
from ddwmmr.reports.canvas import frame_indices


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
    rendered = []
    real_save_gif = plots.save_gif
    monkeypatch.setattr(
        plots,
        "save_gif",
        lambda fig, update, count, *a: (
            rendered.append(count) or real_save_gif(fig, update, count, *a)
        ),
    )
    path = plots.save_animation(result, tmp_path / "short.gif", frames=80, fps=15)
    assert rendered == [11]
    count, duration_ms = gif_frames(path)
    assert count == 11
    assert duration_ms == pytest.approx(11 * 1000 / 15, abs=11 * 10)  # GIF: 10 ms units


def test_a_long_run_keeps_its_frame_count(tmp_path):
    result = simulate(Robot(), Ellipse(), "ats", duration=3.0)  # 151 recorded instants
    count, _ = gif_frames(plots.save_animation(result, tmp_path / "long.gif", frames=40))
    assert count == 40
