"""Run a simulation job in a background thread, with progress, pause and cancel.

The window stays responsive while :func:`ddwmmr.simulate` runs: the job runs in a daemon
thread and reports through the simulation's ``progress`` callback, which is also where it
pauses (waits) and where a cancel takes effect (raises :class:`RunCancelled`). The app
polls :attr:`Worker.state` and :attr:`Worker.fraction` from its own thread; only the main
thread touches matplotlib.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from ddwmmr.errors import ParameterError, PluginError
from ddwmmr.gui.widgets import message_line

#: A job: called with a progress callback ``progress(part, step, steps)``; returns a value.
Job = Callable[[Callable[[int, int, int], None]], Any]


class RunCancelled(Exception):
    """Raised inside the job's progress callback after :meth:`Worker.cancel`."""


class Worker:
    """One job in one background thread.

    Attributes:
        parts: how many sub-runs the job reports (slots A and B), for the progress fraction.
        result: the job's return value once :attr:`state` is ``"done"``.
        error: one-line message once :attr:`state` is ``"failed"``.
        bad_input: the failure was a :class:`ParameterError` (bad settings, not a crash).
    """

    def __init__(self, job: Job, parts: int = 1) -> None:
        self.job = job
        self.parts = max(int(parts), 1)
        self.result: Any = None
        self.error = ""
        self.bad_input = False
        self._fraction = 0.0
        self._state = "ready"
        self._lock = threading.Lock()
        self._resume = threading.Event()
        self._resume.set()
        self._cancelled = False
        self._thread = threading.Thread(target=self._run, name="ddwmmr-gui-run", daemon=True)

    # -- control (main thread) ------------------------------------------------------------
    def start(self) -> None:
        """Start the job (once)."""
        with self._lock:
            if self._state == "ready":
                self._state = "paused" if not self._resume.is_set() else "running"
        self._thread.start()

    def pause(self) -> None:
        """Hold the job at its next progress report."""
        self._resume.clear()
        with self._lock:
            if self._state == "running":
                self._state = "paused"

    def resume(self) -> None:
        """Let a paused job continue."""
        with self._lock:
            if self._state == "paused":
                self._state = "running"
        self._resume.set()

    def cancel(self) -> None:
        """Stop the job at its next progress report (its result is dropped)."""
        self._cancelled = True
        self._resume.set()

    def join(self, timeout: float | None = None) -> None:
        """Wait for the thread to end (if it was started)."""
        if self._thread.is_alive() or self._thread.ident is not None:
            self._thread.join(timeout)

    # -- status (any thread) --------------------------------------------------------------
    @property
    def state(self) -> str:
        """``ready``, ``running``, ``paused``, ``done``, ``failed`` or ``cancelled``."""
        with self._lock:
            return self._state

    @property
    def fraction(self) -> float:
        """Share of the job's steps done, in [0, 1]."""
        with self._lock:
            return self._fraction

    @property
    def finished(self) -> bool:
        """True once the job ended (done, failed or cancelled)."""
        return self.state in ("done", "failed", "cancelled")

    # -- the thread ---------------------------------------------------------------------
    def _progress(self, part: int, step: int, steps: int) -> None:
        with self._lock:
            self._fraction = min((part + step / max(steps, 1)) / self.parts, 1.0)
        if not self._resume.is_set():
            self._resume.wait()
        if self._cancelled:
            raise RunCancelled

    def _run(self) -> None:
        try:
            if self._cancelled:
                raise RunCancelled
            value = self.job(self._progress)
        except RunCancelled:
            self._finish("cancelled")
        except ParameterError as exc:
            self.bad_input = True
            self._finish("failed", error=str(exc))  # one line: ParameterError escapes
        except PluginError as exc:  # a user's controller raised: the line says so
            self._finish("failed", error=f"run failed: {exc}")
        except Exception as exc:  # the window shows it; the app must not die
            self._finish("failed", error=f"run failed: {type(exc).__name__}: {exc}")
        else:
            self._finish("done", result=value)

    def _finish(self, state: str, result: Any = None, error: str = "") -> None:
        with self._lock:
            self.result, self.error = result, message_line(error.splitlines()[0]) if error else ""
            if state == "done":
                self._fraction = 1.0
            self._state = state
