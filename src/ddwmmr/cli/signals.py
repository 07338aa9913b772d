"""How a command-line tool ends on a signal, and the guard that gives a starting tool that
ending before its imports are done.

A tool stopped by SIGINT (Ctrl-C) or one of :data:`STOP_SIGNALS` says one line on stderr
(:func:`stop_line`) and exits with 128 + the signal number, the shell convention. While
the tool runs, :func:`ddwmmr.cli.common.run_main` does this after stopping the workers
and unwinding the stack; before (the imports of numpy, CasADi, matplotlib... take a few
tenths of a second) and after it (the process's exit: its ``atexit`` functions, the
workers' end), the guard of :func:`guard_start` does it at once.

Standard library only: the package imports this module while a tool starts
(:mod:`ddwmmr`), before anything heavy.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from pathlib import Path

#: Exit statuses after SIGINT (Ctrl-C) and SIGTERM: 128 + the signal number.
EXIT_INTERRUPTED = 128 + signal.SIGINT
EXIT_TERMINATED = 128 + signal.SIGTERM
#: Signals that stop a tool as SIGTERM does (those this platform has): a closed terminal
#: (SIGHUP) and Ctrl-\ (SIGQUIT) would otherwise end it without a word, or with a core
#: dump, and leave its workers and staging folder behind; so would Ctrl-Break (SIGBREAK,
#: Windows).
STOP_SIGNALS = tuple(
    getattr(signal, name)
    for name in ("SIGTERM", "SIGHUP", "SIGQUIT", "SIGBREAK")
    if hasattr(signal, name)
)


def stop_line(signum: int, complete: Path | None = None) -> str:
    """The line a tool says when signal ``signum`` stops it; ``complete``: the output
    folder the run had already finished writing when the signal came (it is kept)."""
    what = "unfinished output removed"
    if complete is not None:
        what = f"the output in {complete} is complete"
    if signum == signal.SIGINT:
        return f"interrupted (Ctrl-C): stopped; {what}"
    return f"terminated ({signal.Signals(signum).name}): stopped; {what}"


def say(line: str) -> None:
    """Print ``line`` on stderr in one write; a closed or missing stderr (or one a signal
    handler interrupted in the middle of a write) is not an error of its own."""
    with contextlib.suppress(OSError, ValueError, RuntimeError, AttributeError):
        # one write: print() writes the text and the newline separately, and two worker
        # processes warning at once could then share a line
        sys.stderr.write(line + "\n")
        sys.stderr.flush()


#: The output folders the tool's run completed, in order (a list
#: :func:`~ddwmmr.cli.common.run_main` fills, :func:`report_outputs`).
_completed: list[Path] = []


def report_outputs(completed: list[Path]) -> None:
    """From now on, the guard's line says the last folder in ``completed`` (a list the
    caller fills as the run completes each output) is complete, not removed."""
    global _completed
    _completed = completed


def guard_start() -> None:
    """From now on, SIGINT and :data:`STOP_SIGNALS` end this process at once with the tool's
    line and status (signals the process was started ignoring, e.g. under ``nohup``, stay
    ignored).

    For a tool's start only: nothing is running that would need stopping, and an
    exception raised in the middle of an import could surface as another error (numpy
    turns one raised while its C extensions load into an ImportError). The tool's
    :func:`~ddwmmr.cli.common.run_main` replaces the guard while the tool runs and puts
    it back when it returns. Call it from the main thread."""
    for number in (signal.SIGINT, *STOP_SIGNALS):
        if signal.getsignal(number) is not signal.SIG_IGN:
            signal.signal(number, _stop_at_once)


def _stop_at_once(signum: int, frame: object) -> None:
    with contextlib.suppress(OSError, ValueError, RuntimeError):
        sys.stdout.flush()  # what the tool printed before (os._exit does not flush)
    say(stop_line(signum, _completed[-1] if _completed else None))
    os._exit(128 + signum)
