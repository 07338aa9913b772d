"""The real Tk window follows its size: resized to a 1366 x 768 laptop's screen, then a
1920 x 1080 one and back (``wm geometry``, as a window manager does when the user drags
or maximises), it takes the resolution and the text scale of each size, its texts stand
apart at each, and a drag of many steps is laid out once. Runs under ``xvfb-run``;
skipped where it is not installed (CI)."""

from __future__ import annotations

import json
import sys
import textwrap
from pathlib import Path

import pytest

from xvfb import NEEDS_XVFB, run_under_xvfb

pytestmark = NEEDS_XVFB

#: Window sizes (px, toolbar included) the script sets in turn; 0 x 0: as opened.
SIZES = [(0, 0), (1366, 768), (1920, 1080), (1366, 768)]

SCRIPT = textwrap.dedent(
    """
    import json
    import sys
    import time

    from figure_checks import text_collisions
    from tk_steps import close, run_steps

    from ddwmmr.gui.app import App
    from ddwmmr.gui.layout import desktop_figure
    from ddwmmr.gui.settings import Settings

    sizes = json.loads(sys.argv[1])
    figure = desktop_figure()
    app = App(figure, Settings(methods=("clrrmc-ts", "qp"), duration=1.0), interactive=True)
    window, canvas = figure.canvas.manager.window, figure.canvas.get_tk_widget()
    relayouts, resized, fitted = [], [0.0], [0.0]
    figure.canvas.mpl_connect("resize_event", lambda _: resized.append(time.perf_counter()))
    if hasattr(app, "fit_canvas"):
        relayout, fit_canvas = app.relayout, app.fit_canvas
        app.relayout = lambda *args: (relayouts.append(1), relayout(*args))
        app.fit_canvas = lambda: (fitted.append(time.perf_counter()), fit_canvas())[1]

    def settled(since):
        # a resize came since ``since``, none for 0.5 s, and the app fitted the canvas
        # after it (an app that does not follow its size: none for 2 s)
        now, last = time.perf_counter(), resized[-1]
        if last <= since or now - last < 0.5:
            return False
        return fitted[-1] > last if hasattr(app, "fit_canvas") else now - last > 2.0

    def steps():
        while not canvas.winfo_viewable():
            yield 100
        app.run()
        while app.results is None:
            yield 100
        app.show_index(app.view.last_index)
        app.pause()
        for width, height in sizes:
            since = time.perf_counter() if width else 0.0
            if width:
                window.geometry(f"{width}x{height}")
            yield 300
            while not settled(since):
                yield 200
            label = app.dt_field.box.label
            print("size", json.dumps({
                "window": [window.winfo_width(), window.winfo_height()],
                "dpi": figure.dpi,
                "scale": app.text_scale,
                "panel_px": label.get_fontsize() * figure.dpi / 72,
                "collisions": text_collisions(figure),
            }), flush=True)
        before, since, events = len(relayouts), time.perf_counter(), len(resized)
        for step in range(1, 9):  # a drag: one resize after another, no pause
            window.geometry(f"{1366 + 60 * step}x{768 + 35 * step}")
            window.update_idletasks()
        while not settled(since):
            yield 200
        drag = {"resizes": len(resized) - events, "relayouts": len(relayouts) - before}
        print("drag", json.dumps(drag), flush=True)
        close(window)

    run_steps(window, steps(), 300)
    """
)


def test_the_window_follows_its_size(tmp_path: Path) -> None:
    script = tmp_path / "resize.py"
    script.write_text(SCRIPT)
    done = run_under_xvfb([sys.executable, str(script), json.dumps(SIZES)])
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    sizes = [json.loads(line.split(" ", 1)[1]) for line in lines if line.startswith("size ")]
    assert [tuple(size["window"]) for size in sizes[1:]] == SIZES[1:], done.stdout
    opened, laptop, desktop, laptop_again = sizes
    assert len(sizes) == len(SIZES), done.stdout
    for size in sizes:
        assert size["collisions"] == [], size
    # The 1920 x 1080 screen's window as it opened (90.72 px per inch, text scale 1); a
    # canvas of 1366 x 718 px takes 81 px per inch (the panel font 9 px), a larger
    # text scale; one of 1920 x 1030 px 103 px per inch. Before, every size kept 90.72.
    assert opened["dpi"] == pytest.approx(90.72) and opened["scale"] == 1.0
    assert laptop["dpi"] == pytest.approx(81.0) and laptop["scale"] > 1.1
    assert laptop["panel_px"] == pytest.approx(9.0)
    assert desktop["dpi"] == pytest.approx(103.0) and desktop["scale"] == 1.0
    assert desktop["panel_px"] > opened["panel_px"] > laptop["panel_px"]
    assert laptop_again == laptop
    drag = json.loads(next(line for line in lines if line.startswith("drag ")).split(" ", 1)[1])
    assert drag["resizes"] >= 8 and drag["relayouts"] == 1, done.stdout
