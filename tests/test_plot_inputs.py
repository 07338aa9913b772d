"""Bad input to the documented figure functions of ddwmmr.reports.plots (docs/api.md,
"Looking at a run"): each was a Python-internal error (AttributeError on a result that is
none, IndexError for snapshots=0, TypeError from pathlib for a folder of None, OverflowError
from Pillow for fps=-1, FileNotFoundError for a missing folder, "unknown file extension"
for a GIF path without .gif); now a one-line ParameterError naming the parameter and what
it takes."""

import math

import numpy as np
import pytest

from ddwmmr import ParameterError, Robot, load_trajectory, simulate
from ddwmmr.reports.plots import (
    plot_errors,
    plot_metrics,
    plot_path,
    plot_rates,
    save_animation,
    save_run_figures,
)
from one_line import one_line


@pytest.fixture(scope="module")
def run():
    return simulate(Robot(), load_trajectory("ellipse"), "ats", duration=0.5)


@pytest.mark.parametrize("maker", [plot_path, plot_errors, plot_rates, plot_metrics])
@pytest.mark.parametrize("given", [None, "run.csv", {}, math.nan])
def test_a_result_that_is_none_is_refused_naming_result(maker, given):
    with pytest.raises(ParameterError, match=r"^result must be a SimulationResult \(got ") as info:
        maker(given)
    one_line(info)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"snapshots": 0}, r"^snapshots must be an integer >= 1 \(got 0\)"),
        ({"snapshots": None}, r"^snapshots must be an integer >= 1 \(got None\)"),
        ({"snapshots": 2.5}, r"^snapshots must be an integer >= 1 \(got 2.5\)"),
        ({"ax": 3}, r"^ax must be a Axes \(got 3\)"),
        ({"obstacles": True}, r"^obstacles must be circles, .* \(got True\)"),
        ({"obstacles": np.array(3)}, r"^obstacles must be circles, .* \(got array\(3\)\)"),
        ({"obstacles": [(1.0, 2.0)]}, r"^obstacles must be Circle\(x, y, radius\) or"),
        ({"obstacles": [(1.0, 2.0, -1.0)]}, r"^obstacle radius must be > 0"),
    ],
)
def test_plot_path_refuses_bad_options_naming_them(run, options, message):
    with pytest.raises(ParameterError, match=message) as info:
        plot_path(run, **options)
    one_line(info)


def test_more_snapshots_than_samples_draw_each_sample_once(run):
    many = plot_path(run, snapshots=10**4)
    every = plot_path(run, snapshots=len(run.timeseries["t"]))
    assert [t.get_text() for t in many.axes[0].get_legend().get_texts()] == [
        t.get_text() for t in every.axes[0].get_legend().get_texts()
    ]


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"frames": None}, r"^frames must be an integer >= 1 \(got None\)"),
        ({"frames": 0}, r"^frames must be an integer >= 1 \(got 0\)"),
        ({"fps": -1}, r"^fps must be an integer in \[1, 100\] \(got -1\)"),
        ({"fps": 1e9}, r"^fps must be an integer in \[1, 100\] \(got 1000000000\)"),
        ({"obstacles": "x" * 300}, r"^obstacles: unknown obstacle file"),
    ],
)
def test_save_animation_refuses_bad_options_naming_them(run, tmp_path, options, message):
    with pytest.raises(ParameterError, match=message) as info:
        save_animation(run, tmp_path / "a.gif", **options)
    one_line(info)
    assert not (tmp_path / "a.gif").exists()


def test_save_animation_refuses_a_path_it_cannot_write(run, tmp_path):
    for path, message in [
        (None, r"^path: a file path \(str or os.PathLike\) is needed \(got None\)"),
        (tmp_path / "a.png", r"^path must be a \.gif file \(got 'a\.png'\)"),
        (tmp_path / "missing" / "a.gif", r"^path: cannot write .*a\.gif \(No such file"),
    ]:
        with pytest.raises(ParameterError, match=message) as info:
            save_animation(run, path, frames=2)
        one_line(info)


def test_save_run_figures_needs_an_existing_folder(run, tmp_path):
    for folder, message in [
        (None, r"^folder: a file path \(str or os.PathLike\) is needed \(got None\)"),
        (tmp_path / "missing", r"^folder: .*missing is not an existing folder$"),
    ]:
        with pytest.raises(ParameterError, match=message) as info:
            save_run_figures(run, folder)
        one_line(info)
    assert [p.name for p in save_run_figures(run, tmp_path)] == [
        "path.png",
        "errors.png",
        "rates.png",
        "metrics.png",
    ]


@pytest.mark.parametrize("draw", ["path", "animation"])
def test_an_obstacle_file_is_read_once_per_figure(run, draw, tmp_path, monkeypatch):
    """An obstacle file named by the caller is read once, checked and drawn from that."""
    from ddwmmr.qp.limits import obstacles as obstacle_files

    reads = []
    original = obstacle_files.load_obstacles

    def counted(path):
        reads.append(path)
        return original(path)

    monkeypatch.setattr(obstacle_files, "load_obstacles", counted)
    if draw == "path":
        figure = plot_path(run, obstacles="ellipse_post")
        assert any(patch.get_label() == "obstacle" for patch in figure.axes[0].patches)
    else:
        save_animation(run, tmp_path / "run.gif", frames=2, obstacles="ellipse_post")
    assert len(reads) == 1
