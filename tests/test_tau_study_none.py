"""The tau study's figure when no run converged (every convergence time NaN): drawn,
with a note in the convergence panel, without a warning."""

import math
import warnings

import numpy as np
from matplotlib.text import Text

from ddwmmr.reports import compare_plots, palette

TAUS = (0.1, 0.3, 1.0, 3.0)


def _curves(methods):
    t = np.linspace(0.0, 0.2, 11)
    return {m: {tau: (t, 0.04 * np.exp(-t / tau)) for tau in TAUS} for m in methods}


def test_no_run_converged_is_drawn_with_a_note(tmp_path) -> None:
    methods = ["clrrmc-ts", "clrrmc-cs"]
    convergence = {m: dict.fromkeys(TAUS, math.nan) for m in methods}
    colors = palette.method_colors(methods)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = compare_plots.plot_tau_study(_curves(methods), convergence, -np.log(0.05), colors)
        panel = fig.axes[1]
        notes = [t.get_text() for t in panel.findobj(Text)]
        low, high = panel.get_xlim()
        path = compare_plots.save(fig, tmp_path / "study_tau.png")
    assert any("no run converged" in note for note in notes)
    assert 0.0 < low < min(TAUS) and high > max(TAUS)
    assert path.stat().st_size > 10_000


def test_a_converged_run_gets_no_note() -> None:
    methods = ["clrrmc-ts"]
    convergence = {"clrrmc-ts": {0.1: 0.3, 0.3: math.nan, 1.0: math.nan, 3.0: math.nan}}
    colors = palette.method_colors(methods)
    fig = compare_plots.plot_tau_study(_curves(methods), convergence, -np.log(0.05), colors)
    notes = [t.get_text() for t in fig.axes[1].findobj(Text)]
    assert not any("no run converged" in note for note in notes)
