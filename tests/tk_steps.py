"""Driving the real Tk window from a script that :func:`xvfb.run_under_xvfb` runs: the
script's steps, a generator, run one after another in Tk's own event loop, as a user's
clicks and keys would, with Tk free to draw, resize and run the app's timers between
them."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any


def run_steps(window: Any, steps: Iterable[int], first_ms: int = 300) -> None:
    """Run ``steps`` in the Tk event loop of ``window`` (a figure manager's window) and
    return once every pyplot window is closed (``plt.show()``): the first step
    ``first_ms`` ms from now, each next one as many ms after the last as that step
    yielded; a step that waits for something yields a short delay until it holds. The
    last step should close the window (:func:`close`)."""
    import matplotlib.pyplot as plt

    order = iter(steps)

    def tick() -> None:
        delay = next(order, None)
        if delay is not None:
            window.after(delay, tick)

    window.after(first_ms, tick)
    plt.show()


def close(window: Any) -> None:
    """Close ``window`` as its title bar's close button does (the app's own handler:
    pyplot's other windows close with it, so ``plt.show()`` returns)."""
    window.tk.call(window.protocol("WM_DELETE_WINDOW"))
