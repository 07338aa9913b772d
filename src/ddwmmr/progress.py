"""Progress on stderr for long runs: a ``tqdm`` bar on a terminal, short lines elsewhere.

* On a terminal, :class:`ProgressBar` draws a tqdm bar (rate, elapsed time, ETA at the
  average rate of the whole phase so far, as :func:`eta`: a rate that drifts during a run
  moves it slowly, where tqdm's default, the rate of the last few seconds, swings with
  every fast or slow stretch). A terminal that reports no size (0 columns: a
  pseudo-terminal nobody sized, e.g. under ``script``) gets a bar
  :data:`FALLBACK_COLUMNS` wide.
* When stderr is not a terminal (``make demo | tee``, CI logs), a bar would print control
  characters, so a :class:`ProgressBar` prints one short line when it finishes (and one
  every :data:`LOG_INTERVAL_S` of a long phase, with the time left at the rate so far:
  ``scenarios: 40/100 after 177 s, ETA 4 min 26 s``), e.g. ``compare: runs 120/120 done
  in 41.3 s``.
* :func:`phase` marks a long step without a known count (report writing, GIF encoding):
  a line when it starts on a terminal, one every :data:`LOG_INTERVAL_S` while it lasts
  (``track: writing timeseries.csv: still running after 30 s``), and one line with its
  duration when it ends (elsewhere only for phases of :data:`QUIET_PHASE_S` or more).

``enabled=False`` (the tools' ``--no-progress``) silences everything.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from collections.abc import Iterator
from typing import TextIO

from tqdm import tqdm  # tqdm ships no hints

#: Seconds between the progress lines of a long phase when stderr is not a terminal.
LOG_INTERVAL_S = 30.0
#: Phases shorter than this (s) print nothing when stderr is not a terminal.
QUIET_PHASE_S = 1.0
#: Width (characters) and height (lines) of the bar on a terminal that reports a size of
#: 0: tqdm would size the bar to it and print nothing at all.
FALLBACK_COLUMNS = 80
FALLBACK_LINES = 24


def eta(elapsed: float, done: int, total: int) -> float:
    """Seconds left when ``done`` of ``total`` items took ``elapsed`` seconds, at the rate
    so far (what tqdm's bar shows on a terminal)."""
    return elapsed * (total - done) / done if done else float("inf")


def _duration(seconds: float) -> str:
    """``42 s``, ``3 min 05 s``, ``1 h 02 min``: a duration as a person reads it."""
    if seconds != seconds or seconds == float("inf"):
        return "unknown"
    whole = round(seconds)
    if whole < 60:
        return f"{whole} s"
    minutes, secs = divmod(whole, 60)
    if minutes < 60:
        return f"{minutes} min {secs:02d} s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes:02d} min"


def _is_terminal(stream: TextIO) -> bool:
    return bool(getattr(stream, "isatty", lambda: False)())


def _unsized(stream: TextIO) -> bool:
    """Whether ``stream`` is a terminal reporting 0 columns or 0 lines (a size nobody
    set); False when the size cannot be asked (tqdm then takes its own default)."""
    try:
        size = os.get_terminal_size(stream.fileno())
    except (AttributeError, OSError, ValueError):
        return False
    return size.columns <= 0 or size.lines <= 0


def _bar_size(stream: TextIO) -> dict[str, object]:
    """tqdm's size options: follow the terminal's width, or a fixed size if it has none."""
    if _unsized(stream):
        return {"ncols": FALLBACK_COLUMNS, "nrows": FALLBACK_LINES, "dynamic_ncols": False}
    return {"dynamic_ncols": True}


class _Bar(tqdm):  # type: ignore[misc]  # tqdm is Any to mypy (no hints)
    """tqdm's bar without tqdm's monitor thread, which would be alive while the tools'
    process pools fork their workers (a forked child gets copies of the locks other
    threads hold, locked for good; Python 3.12+ warns).

    The monitor redraws a bar that has not been redrawn for ``maxinterval`` (10 s)
    because tqdm skips the clock until ``miniters`` updates have come, a count it raises
    to the most updates seen between two redraws: after a slowdown a bar would freeze.
    Our bars set ``miniters=1`` (every update looks at the clock and redraws once
    ``mininterval`` has passed), so the monitor has nothing to do."""

    monitor_interval = 0  # a class attribute: tqdm reads it before __init__


class ProgressBar:
    """Progress of ``total`` items: ``with ProgressBar(total, "runs") as bar: bar.advance()``.

    Args:
        total: number of items (steps, runs, scenarios).
        label: what is counted, printed in front (``"track: steps"``).
        enabled: False prints nothing.
        stream: where to write (default stderr).
        unit: name of one item in the bar (``"step"``, ``"run"``).
    """

    def __init__(
        self,
        total: int,
        label: str = "",
        enabled: bool = True,
        stream: TextIO | None = None,
        unit: str = "it",
    ) -> None:
        self.total = max(int(total), 1)
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.done = 0
        self._start = time.perf_counter()
        self._last_line = self._start
        self._bar: tqdm | None = None
        if enabled and _is_terminal(self.stream):
            self._bar = _Bar(
                total=self.total,
                desc=label,
                unit=unit,
                file=self.stream,
                mininterval=0.2,
                miniters=1,  # look at the clock at every update: no monitor thread needed
                smoothing=0.0,  # the ETA at the average rate so far (see the module doc)
                leave=True,
                **_bar_size(self.stream),
            )

    def advance(self, count: int = 1) -> None:
        """Record ``count`` finished items."""
        count = min(count, self.total - self.done)
        self.done += count
        if self._bar is not None:
            self._bar.update(count)
        elif self.enabled and self.done < self.total:
            now = time.perf_counter()
            if now - self._last_line >= LOG_INTERVAL_S:
                self._last_line = now
                elapsed = now - self._start
                self._line(
                    f"{self.done}/{self.total} after {elapsed:.0f} s, "
                    f"ETA {_duration(eta(elapsed, self.done, self.total))}"
                )

    def _line(self, text: str) -> None:
        self.stream.write(f"{self.label}: {text}\n" if self.label else f"{text}\n")
        self.stream.flush()

    def close(self) -> None:
        """Finish the bar (terminal) or print the one-line summary (elsewhere)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self.enabled and self.done:
            elapsed = time.perf_counter() - self._start
            self._line(f"{self.done}/{self.total} done in {elapsed:.1f} s")
            self.enabled = False  # print the summary once

    def __enter__(self) -> ProgressBar:
        return self

    def __exit__(self, *exc: object) -> None:
        if exc[0] is not None and self._bar is None:
            self.enabled = False  # interrupted: the error line says what happened
        self.close()


@contextlib.contextmanager
def phase(label: str, enabled: bool = True, stream: TextIO | None = None) -> Iterator[None]:
    """Report a long step without a count: ``with phase("compare: writing report"): ...``."""
    stream = stream if stream is not None else sys.stderr
    if not enabled:
        yield
        return
    terminal = _is_terminal(stream)
    if terminal:
        stream.write(f"{label} ...\n")
        stream.flush()
    start = time.perf_counter()
    with _heartbeat(label, stream, start):
        yield
    elapsed = time.perf_counter() - start
    if terminal or elapsed >= QUIET_PHASE_S:
        stream.write(f"{label}: done in {elapsed:.1f} s\n")
        stream.flush()


@contextlib.contextmanager
def _heartbeat(label: str, stream: TextIO, start: float) -> Iterator[None]:
    """While the body runs, a line every :data:`LOG_INTERVAL_S` saying that ``label`` is
    still running and for how long since ``start`` (a :func:`time.perf_counter` time),
    from a background thread (:class:`_Heartbeat`): a phase has no count to advance, and
    its work (writing a file, encoding a GIF) must not have to call back."""
    beat = _Heartbeat(label, stream, start)
    beat.start()
    _BEATING.add(beat)
    try:
        yield
    finally:
        _BEATING.discard(beat)
        beat.stop()


class _Heartbeat:
    """The thread of a phase's "still running" lines, which can stop and start again
    without changing when its lines are due (multiples of :data:`LOG_INTERVAL_S` after
    ``start``): it stops around every fork of this process (a process pool's workers
    started in a phase), because a forked child gets copies of the locks other threads
    hold, locked for good (the stream's, while a line is being written)."""

    def __init__(self, label: str, stream: TextIO, start: float) -> None:
        self.label = label
        self.stream = stream
        self.start_time = start
        self._due = start + LOG_INTERVAL_S  # perf_counter time of the next line
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        """Start the thread (again)."""
        self._stop = threading.Event()
        self._thread = threading.Thread(
            target=self._beat, args=(self._stop,), name=f"progress: {self.label}", daemon=True
        )
        self._thread.start()

    def stop(self) -> None:
        """Stop the thread and wait until it has (a line being written is finished)."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join()
        self._thread = None

    def _beat(self, stop: threading.Event) -> None:
        while not stop.wait(self._due - time.perf_counter()):
            now = time.perf_counter()
            self.stream.write(
                f"{self.label}: still running after {_duration(now - self.start_time)}\n"
            )
            self.stream.flush()
            # the next multiple of the interval, but not at once after a line that a stop
            # (a fork) held back
            self._due = max(self._due + LOG_INTERVAL_S, now + LOG_INTERVAL_S / 2)


#: The heartbeats running now (phases may nest, or run in several threads).
_BEATING: set[_Heartbeat] = set()


def _pause_heartbeats() -> None:
    for beat in list(_BEATING):
        beat.stop()


def _resume_heartbeats() -> None:
    for beat in list(_BEATING):
        beat.start()


if hasattr(os, "register_at_fork"):  # no fork on Windows
    os.register_at_fork(
        before=_pause_heartbeats,
        after_in_parent=_resume_heartbeats,
        after_in_child=_BEATING.clear,  # the child has no such thread and runs no phase
    )
