"""``make gui-check``: open the real Tk window, drive it through real clicks, screenshot it.

Run under a display (``xvfb-run -a python -m ddwmmr.gui.check OUT_DIR``, which is what
``make gui-check`` does where ``xvfb-run`` is installed). It opens the desktop window,
clicks Run with a Tk mouse event (so the click travels Tk -> matplotlib -> widget), lets
the worker thread simulate and the Tk timers poll and play the run back, then grabs the
screen area of the window (``window_screen.png``, a real X screenshot) and saves the
figure itself (``window_figure.png``). It prints what it measured and exits 0, or 1 with
one line saying what did not happen.
"""

from __future__ import annotations

import io
import os
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ddwmmr.outputs import write_atomic

#: Give up after this long (s) without the run being simulated and played back.
TIMEOUT_S = 120.0
#: Methods and duration of the check run (two methods: the side-by-side mode).
CHECK_METHODS = ("clrrmc-ts", "qp")
CHECK_DURATION_S = 6.0
#: What the check types into the duration field (s) before it clicks Run.
TYPED_DURATION = "5.5"


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: ``python -m ddwmmr.gui.check [OUT_DIR]``."""
    argv = list(sys.argv[1:] if argv is None else argv)
    out = Path(argv[0] if argv else "runs/gui-check")
    if not os.environ.get("DISPLAY"):
        print("gui-check: no DISPLAY; run it under xvfb-run (make gui-check)", file=sys.stderr)
        return 1
    import matplotlib.pyplot as plt

    from ddwmmr.gui.app import App
    from ddwmmr.gui.layout import SPEEDS, desktop_figure
    from ddwmmr.gui.settings import Settings

    figure = desktop_figure()
    app = App(figure, Settings(methods=CHECK_METHODS, duration=CHECK_DURATION_S), interactive=True)
    app.speed_slider.set_val(SPEEDS.index(8.0))
    drive = _WindowDrive(app, figure, out)
    drive.window.after(800, drive.type_duration)
    plt.show()
    report = drive.report
    if not report["failure"] and report.get("typed") != float(TYPED_DURATION):
        report["failure"] = f"typing {TYPED_DURATION} into duration gave {report.get('typed')}"
    if report["failure"]:
        print(f"gui-check: {report['failure']}", file=sys.stderr)
        return 1
    _print_measures(app, report, out)
    return 0


class _WindowDrive:
    """Drives ``app``'s real Tk window (``figure``'s) through a chain of Tk timers: type
    :data:`TYPED_DURATION` into the duration field, click Run, watch the run be simulated
    and played back, then save the window's screenshot and its figure into ``out`` and
    close it. ``report`` collects what happened: ``draws`` (full redraws), ``typed`` (s),
    the perf_counter stamps (s) ``clicked``, ``simulated``, ``played``, the frames shown
    when the simulation ended ``frames_at_play``, ``screen`` (width px, height px,
    grey-level spread) and ``failure`` ("" when passed; "timed out" until then)."""

    def __init__(self, app: Any, figure: Any, out: Path) -> None:
        self.app, self.figure, self.out = app, figure, out
        self.canvas = canvas = figure.canvas
        self.widget = canvas.get_tk_widget()
        self.window = canvas.manager.window
        self.report: dict[str, Any] = {"draws": 0, "failure": "timed out"}
        canvas.mpl_connect("draw_event", self._count_draw)
        self.started = time.perf_counter()

    def _count_draw(self, _event: Any) -> None:
        """One more full redraw of the canvas."""
        self.report["draws"] += 1

    def click(self, ax: Any) -> None:
        """A real Tk mouse click at the centre of ``ax`` (Tk's y axis points down)."""
        x0, y0, x1, y1 = ax.get_window_extent().extents
        x, y = int((x0 + x1) / 2), int(self.canvas.figure.bbox.height - (y0 + y1) / 2)
        self.widget.event_generate("<Motion>", x=x, y=y, warp=False)
        self.widget.event_generate("<ButtonPress-1>", x=x, y=y)
        self.widget.event_generate("<ButtonRelease-1>", x=x, y=y)

    def type_duration(self) -> None:
        """Click into the duration field, replace its text key by key, press Enter; then
        Run 0.3 s later."""
        widget, window = self.widget, self.window
        # Tk drops the events sent to a canvas not mapped yet (later than 0.8 s on a loaded
        # machine): wait for it, up to TIMEOUT_S.
        if not widget.winfo_viewable() and time.perf_counter() - self.started < TIMEOUT_S:
            window.after(100, self.type_duration)
            return
        widget.focus_force()
        self.click(self.app.duration_field.ax)
        for _ in self.app.duration_field.text:
            widget.event_generate("<KeyPress>", keysym="BackSpace")
        for key in TYPED_DURATION:
            widget.event_generate("<KeyPress>", keysym="period" if key == "." else key)
        widget.event_generate("<KeyPress>", keysym="Return")
        self.report["typed"] = self.app.settings.duration
        window.after(300, self.click_run)

    def click_run(self) -> None:
        """Click Run; watch 0.2 s later."""
        self.click(self.app.transport["run"].ax)
        self.report["clicked"] = time.perf_counter()
        self.window.after(200, self.watch)

    def watch(self) -> None:
        """Every 0.1 s: stamp the end of the simulation and of the playback (then finish
        0.3 s later), or give up after TIMEOUT_S (s) since the start."""
        import matplotlib.pyplot as plt

        app, report = self.app, self.report
        now = time.perf_counter()
        if app.results is not None and "simulated" not in report:
            report["simulated"] = now
            report["frames_at_play"] = app.frames_shown
        if "simulated" in report and not app.playing:
            report["played"] = now
            self.window.after(300, self.finish)
            return
        if now - self.started > TIMEOUT_S:
            report["failure"] = f"no finished playback after {TIMEOUT_S:.0f} s ({app.message})"
            plt.close(self.figure)
            return
        self.window.after(100, self.watch)

    def finish(self) -> None:
        """Save the window's screenshot (an X grab of its screen area) and the figure as
        PNGs into ``out``, pass unless the screenshot is blank, close the window."""
        import matplotlib.pyplot as plt
        from PIL import ImageGrab, ImageStat

        window, out = self.window, self.out
        window.update()
        left, top = window.winfo_rootx(), window.winfo_rooty()
        width, height = window.winfo_width(), window.winfo_height()
        shot = ImageGrab.grab(
            bbox=(left, top, left + width, top + height), xdisplay=os.environ["DISPLAY"]
        )
        buffer = io.BytesIO()
        shot.save(buffer, format="PNG")
        write_atomic(out / "window_screen.png", buffer.getvalue())
        figure_buffer = io.BytesIO()
        self.figure.savefig(figure_buffer, format="png")
        write_atomic(out / "window_figure.png", figure_buffer.getvalue())
        spread = ImageStat.Stat(shot.convert("L")).stddev[0]  # 0 for a blank screen
        self.report["screen"] = (width, height, spread)
        self.report["failure"] = "" if spread > 5 else "the screenshot is blank"
        plt.close(self.figure)


def _print_measures(app: Any, report: Mapping[str, Any], out: Path) -> None:
    """The passed check's lines on stdout: the window's size (px), the simulation's and
    the playback's wall times (s, from the ``report``'s perf_counter stamps), the frames
    and redraws, and the two PNGs written into ``out``."""
    playback = report["played"] - report["simulated"]
    frames = app.frames_shown - report["frames_at_play"]
    width, height, _ = report["screen"]
    print(f"gui-check: window {width} x {height} px; duration typed and Run clicked via Tk")
    print(
        f"  simulated {app.results[0].summary['steps']} steps x {len(app.results)} methods in "
        f"{report['simulated'] - report['clicked']:.2f} s (worker thread)"
    )
    print(
        f"  playback of {app.view.duration:.1f} s at {app.speed:g}x: {playback:.2f} s wall, "
        f"{frames} frames ({frames / max(playback, 1e-9):.1f} per s), "
        f"{report['draws']} full redraws in all"
    )
    print(f"  wrote {out / 'window_screen.png'} and {out / 'window_figure.png'}")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
