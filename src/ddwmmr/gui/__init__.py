"""Interactive simulator: ``python -m ddwmmr.gui`` (matplotlib widgets, Tk on a desktop; its
command line is :mod:`ddwmmr.cli.gui`).

One window with a control panel (trajectory and its geometry, methods A and B with their
own options, plant, payload, integrator, dt), run/pause/step/reset, a time slider and a
speed control, the robot view with live plots, and export (CSV/JSON, PNG, GIF/MP4). It
runs the same engine as the command-line tools (:func:`ddwmmr.simulate` with controllers
from :func:`ddwmmr.make_controller`). See docs/gui.md.

Off-screen use (tests, documentation)::

    from matplotlib.figure import Figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from ddwmmr.gui import App, Settings

    figure = Figure(figsize=(16, 10)); FigureCanvasAgg(figure)
    app = App(figure, Settings(methods=("ats", None)))
    app.run(); app.wait()              # simulate in the worker thread, take the result
    app.show_index(app.view.last_index)
"""

from ddwmmr.gui.app import App
from ddwmmr.gui.settings import Settings

__all__ = ["App", "Settings"]
