"""The desktop window's Support loads button opens the panels in a window of their own:
pyplot's backend is still the window's TkAgg when they are drawn (the reports modules,
imported on the way, leave it alone); on an Agg figure they could not be shown (a warning,
no window). Runs the real Tk window under ``xvfb-run``; skipped where it is not installed
(CI). Closing the simulator closes the support window too, so the program ends (the run
returns)."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

from xvfb import NEEDS_XVFB, run_under_xvfb

pytestmark = NEEDS_XVFB

SCRIPT = textwrap.dedent(
    """
    import sys
    import matplotlib.pyplot as plt
    from ddwmmr.gui.app import App
    from ddwmmr.gui.layout import desktop_figure
    from ddwmmr.gui.settings import Settings
    from tk_steps import close, run_steps

    figure = desktop_figure()
    settings = Settings(methods=("qp", None), plant="mujoco", duration=0.2)
    app = App(figure, settings, interactive=True)
    app.export_field.submit(sys.argv[1])
    window = figure.canvas.manager.window

    def steps():
        app.run()
        while app.worker is not None:
            yield 100
        app.export_support_loads()
        yield 500
        others = [plt.figure(n) for n in plt.get_fignums() if plt.figure(n) is not figure]
        print("message:", app.message)
        print("windows:", [type(f.canvas).__name__ for f in others])
        close(window)  # closes the support window too

    run_steps(window, steps(), 500)
    """
)


def test_support_loads_opens_a_tk_window_of_its_own(tmp_path: Path) -> None:
    script = tmp_path / "support_loads.py"
    script.write_text(SCRIPT)
    done = run_under_xvfb([sys.executable, str(script), str(tmp_path / "export")])
    assert done.returncode == 0, done.stderr
    assert "message: wrote " in done.stdout and "support_loads.png" in done.stdout
    assert "windows: ['FigureCanvasTkAgg']" in done.stdout, done.stdout + done.stderr
    assert "non-interactive" not in done.stderr
