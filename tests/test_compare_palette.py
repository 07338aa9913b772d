"""compare's method colours have one home, :mod:`ddwmmr.reports.palette`, next to the path
and snapshot colours: matplotlib's default cycle (tab10) in the order the methods are
listed, the colours compare's figures have always had."""

from __future__ import annotations

import pytest
from matplotlib import colormaps
from matplotlib.colors import to_rgb

from ddwmmr import Ellipse
from ddwmmr.reports import compare_plots, palette
from ddwmmr.reports.compare import CompareConfig
from ddwmmr.reports.compare.report import _Context


def test_methods_take_the_tab10_colours_in_order_and_wrap_after_ten():
    labels = [f"m{i}" for i in range(12)]
    colours = palette.method_colors(labels)
    tab10 = colormaps["tab10"].colors
    for i, label in enumerate(labels):
        assert to_rgb(colours[label]) == pytest.approx(tab10[i % 10], abs=1e-12)
    assert colours["m10"] == colours["m0"] and colours["m11"] == colours["m1"]


def test_the_report_colours_its_methods_from_the_palette_only():
    assert not hasattr(compare_plots, "method_colors")  # one home: the palette
    config = CompareConfig(
        methods=("qp", "ats"), trajectories={"ellipse": Ellipse()}, study_methods=("ats", "pi")
    )
    context = _Context(config, None, {}, None, None)
    assert context.colors == {"qp": "C0", "ats": "C1", "pi": "C2"}
