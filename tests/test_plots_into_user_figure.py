"""plot_errors, plot_rates and plot_metrics draw into a figure the caller passes as ``fig``,
plot_path into an axes passed as ``ax``.

By default they draw on a figure of their own that pyplot does not know, so ``plt.show()``
does not show it; ``fig=plt.figure()`` is how a script looks at them in a window. These
tests check that the passed figure is the one drawn into (and stays pyplot's), that it holds
the same panels and lines as the default, that the default is as before, and that a figure
that cannot be drawn into is refused in one line naming ``fig``; and that plot_path's legend
stays on the caller's figure whatever its layout."""

from __future__ import annotations

import io
import warnings

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.backends.backend_svg import FigureCanvasSVG
from matplotlib.figure import Figure
from matplotlib.layout_engine import ConstrainedLayoutEngine

from ddwmmr import ParameterError, Robot, load_trajectory, simulate
from ddwmmr.reports.canvas import new_figure
from ddwmmr.reports.legends import place_legend
from ddwmmr.reports.plots import plot_errors, plot_metrics, plot_path, plot_rates
from one_line import one_line

MAKERS = {"errors": plot_errors, "rates": plot_rates, "metrics": plot_metrics}
#: Size (inches) of each maker's own figure.
DEFAULT_SIZES = {"errors": (7.0, 5.0), "rates": (8.6, 6.4), "metrics": (7.0, 5.0)}


@pytest.fixture(scope="module")
def run():
    """Two seconds of ats on the ellipse: 100 samples, enough for every panel's lines."""
    return simulate(Robot(), load_trajectory("ellipse"), "ats", duration=2.0)


@pytest.fixture
def pyplot_figures():
    """pyplot's figures made during a test, closed afterwards."""
    before = set(plt.get_fignums())
    yield
    for number in set(plt.get_fignums()) - before:
        plt.close(number)


def drawn(fig: Figure) -> list[dict]:
    """What each axes of ``fig`` shows: title, labels, scale and every line (data, colour,
    style, label), in the axes' order."""
    return [
        {
            "title": ax.get_title(),
            "xlabel": ax.get_xlabel(),
            "ylabel": ax.get_ylabel(),
            "yscale": ax.get_yscale(),
            "lines": [
                (
                    line.get_xydata().tolist(),
                    line.get_color(),
                    line.get_linestyle(),
                    line.get_label(),
                )
                for line in ax.get_lines()
            ],
            "legend": []
            if ax.get_legend() is None
            else [text.get_text() for text in ax.get_legend().get_texts()],
        }
        for ax in fig.axes
    ]


def png(fig: Figure) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, metadata={"Software": None})
    return buffer.getvalue()


@pytest.mark.parametrize("name", MAKERS)
def test_a_pyplot_figure_passed_in_is_drawn_into_and_shown_by_pyplot(run, name, pyplot_figures):
    fig = plt.figure()
    returned = MAKERS[name](run, fig=fig)
    assert returned is fig
    assert fig.number in plt.get_fignums()  # plt.show() shows it
    assert tuple(fig.get_size_inches()) == (6.4, 4.8)  # the caller's size is kept
    assert drawn(fig) == drawn(MAKERS[name](run))
    assert len(fig.axes) == {"errors": 2, "rates": 3, "metrics": 2}[name]
    assert len(drawn(fig)[0]["lines"]) >= 1


@pytest.mark.parametrize("name", MAKERS)
def test_the_default_figure_is_its_own_and_a_same_sized_one_passed_in_renders_the_same(
    run, name, pyplot_figures
):
    before = plt.get_fignums()
    default = MAKERS[name](run)
    assert plt.get_fignums() == before  # not pyplot's: the backend stays the user's
    assert default.canvas.manager is None
    assert tuple(default.get_size_inches()) == DEFAULT_SIZES[name]
    passed = MAKERS[name](run, fig=new_figure(DEFAULT_SIZES[name]))
    assert png(passed) == png(default)


@pytest.mark.parametrize("name", MAKERS)
def test_a_constrained_figure_keeps_its_layout_engine_without_a_warning(run, name):
    fig = Figure(layout="constrained")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        MAKERS[name](run, fig=fig)
    assert isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine)


def test_metrics_into_a_figure_on_a_canvas_without_a_renderer_keep_that_canvas(run):
    """The svg, pdf and cairo backends' canvases cannot be asked for a renderer, which the
    metrics figure's legend placement measures on; the figure keeps its canvas."""
    fig = Figure(figsize=(7, 5))
    canvas = FigureCanvasSVG(fig)
    plot_metrics(run, fig=fig)
    assert fig.canvas is canvas
    buffer = io.StringIO()
    fig.savefig(buffer, format="svg")
    assert "performance metrics" in buffer.getvalue()
    assert drawn(fig) == drawn(plot_metrics(run))


@pytest.mark.parametrize("name", MAKERS)
def test_a_figure_with_axes_is_refused_in_one_line_and_left_as_it_was(run, name):
    fig = new_figure((7, 5))
    ax = fig.subplots()
    ax.plot([0.0, 1.0], [2.0, 3.0])
    with pytest.raises(ParameterError) as info:
        MAKERS[name](run, fig=fig)
    assert one_line(info) == (
        "fig: must be an empty Figure (it holds 1 axes); "
        "pass a new one, e.g. plt.figure(), or call fig.clear() first"
    )
    assert fig.axes == [ax] and len(ax.get_lines()) == 1
    np.testing.assert_array_equal(ax.get_lines()[0].get_xydata(), [[0.0, 2.0], [1.0, 3.0]])


@pytest.mark.parametrize("name", MAKERS)
@pytest.mark.parametrize(
    ("fig", "kind"), [("errors.png", "str"), (None, None), (Figure().subfigures(1, 1), "SubFigure")]
)
def test_what_is_not_a_figure_is_refused_in_one_line(run, name, fig, kind):
    if fig is None:  # an Axes: plot_path's argument, not this one's
        fig, kind = new_figure((7, 5)).subplots(), "Axes"
    with pytest.raises(ParameterError) as info:
        MAKERS[name](run, fig=fig)
    assert one_line(info) == f"fig: must be a matplotlib Figure, e.g. plt.figure() (got {kind})"


@pytest.mark.parametrize("name", MAKERS)
@pytest.mark.parametrize(("size", "shown"), [((0.0, 5.0), "0 x 5"), ((7.0, 0.0), "7 x 0")])
def test_a_figure_of_zero_width_or_height_is_refused_in_one_line(run, name, size, shown):
    """No panel fits in it (matplotlib's layout would fail with a singular matrix)."""
    fig = new_figure(size)
    with pytest.raises(ParameterError) as info:
        MAKERS[name](run, fig=fig)
    assert one_line(info) == (
        f"fig: must have a positive width and height (it is {shown} inches); "
        "pass e.g. plt.figure(figsize=(7, 5))"
    )
    assert fig.axes == []


@pytest.mark.parametrize("name", MAKERS)
def test_fig_is_keyword_only(run, name):
    with pytest.raises(TypeError):
        MAKERS[name](run, Figure())


@pytest.fixture(scope="module")
def wide_run():
    """Ten seconds of ats on the ellipse: a path wider than tall, so that its equal-aspect
    axes fill the figure's width and a legend beside them needs room made."""
    return simulate(Robot(), load_trajectory("ellipse"), "ats", duration=10.0)


def _path_figure(run, layout: str | None) -> tuple[Figure, object]:
    """plot_path drawn into the one axes of a 6.4 x 4.8 inch Agg figure of ``layout``."""
    fig = Figure(layout=layout)
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    plot_path(run, ax=ax)
    fig.canvas.draw()
    return fig, ax


@pytest.mark.parametrize("layout", [None, "constrained"])
def test_a_path_legend_drawn_into_a_callers_axes_sits_beside_it_within_the_figure(wide_run, layout):
    fig, ax = _path_figure(wide_run, layout)
    legend = ax.get_legend().get_window_extent()
    assert legend.x0 >= ax.bbox.x1  # beside the axes, off the data
    assert fig.bbox.x0 <= legend.x0 and legend.x1 <= fig.bbox.x1  # not cut off
    assert fig.bbox.y0 <= legend.y0 and legend.y1 <= fig.bbox.y1
    assert tuple(fig.get_size_inches()) == (6.4, 4.8)  # the caller's size is kept
    if layout == "constrained":  # the caller's engine is kept
        assert isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine)


@pytest.mark.parametrize("layout", [None, "constrained"])
def test_a_path_drawn_into_axes_in_a_subfigure_returns_that_subfigure(wide_run, layout):
    """Axes in a SubFigure: plot_path failed laying it out (a SubFigure has neither
    tight_layout nor a size); its hint said Figure while it handed back the SubFigure.
    Now the whole figure is laid out and the SubFigure, the figure ``ax`` is on, returned."""
    fig = Figure(layout=layout)
    FigureCanvasAgg(fig)
    left, _ = fig.subfigures(1, 2)
    ax = left.subplots()
    assert plot_path(wide_run, ax=ax) is left
    fig.canvas.draw()
    legend = ax.get_legend().get_window_extent()
    assert legend.x0 >= ax.bbox.x1  # beside the axes, off the data
    assert fig.bbox.x0 <= legend.x0 and legend.x1 <= fig.bbox.x1  # on the figure
    assert tuple(fig.get_size_inches()) == (6.4, 4.8)


def test_place_legend_takes_the_labels_of_handles_given_alone():
    fig = Figure()
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    (line,) = ax.plot([0.0, 1.0], [0.0, 1.0], label="a line")
    legend = place_legend(ax, handles=[line])
    assert [t.get_text() for t in legend.get_texts()] == ["a line"]
