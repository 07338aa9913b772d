"""A tool started as a user's terminal starts it, however the test suite was started; and
no tool a test started left running.

A process keeps a signal it was started ignoring ignored across ``exec``, and POSIX
starts an asynchronous job of a shell without job control (``( pytest ... & )``, a CI
step run in the background) with SIGINT and SIGQUIT ignored, as ``nohup`` starts one
with SIGHUP ignored. The tools rightly leave such a signal ignored
(:func:`ddwmmr.cli.common.interruptible`), so a test of what Ctrl-C, Ctrl-\\ or a closed
terminal does starts its tool with :data:`FROM_A_TERMINAL` (or, in this process, runs
under :func:`at_defaults`); a test of the inherited disposition itself sets it.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
from collections.abc import Iterable, Iterator
from typing import Any

#: The signals a terminal sends (Ctrl-C, Ctrl-\, hang-up) that this platform has.
TERMINAL_SIGNALS = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGQUIT", "SIGHUP") if hasattr(signal, name)
)


def from_a_terminal() -> None:
    """A ``preexec_fn``: in the child, before it executes the tool, each of
    :data:`TERMINAL_SIGNALS` at its default and not blocked."""
    for number in TERMINAL_SIGNALS:
        signal.signal(number, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, TERMINAL_SIGNALS)


#: ``subprocess.Popen`` keywords that start a tool with :func:`from_a_terminal` (POSIX;
#: elsewhere there is no ``preexec_fn``, nor a job start that ignores these signals).
FROM_A_TERMINAL: dict[str, Any] = {"preexec_fn": from_a_terminal} if os.name == "posix" else {}


@contextlib.contextmanager
def at_defaults() -> Iterator[None]:
    """In this process, for the block: each of :data:`TERMINAL_SIGNALS` that it was
    started ignoring at its default (SIGINT: Python's, which raises KeyboardInterrupt);
    ignored again afterwards. Nothing changes in a suite started from a terminal."""
    ignored = [n for n in TERMINAL_SIGNALS if signal.getsignal(n) is signal.SIG_IGN]
    for number in ignored:
        default = signal.default_int_handler if number == signal.SIGINT else signal.SIG_DFL
        signal.signal(number, default)
    try:
        yield
    finally:
        for number in ignored:
            signal.signal(number, signal.SIG_IGN)


def end(*processes: subprocess.Popen, workers: Iterable[int] = ()) -> None:
    """Kill each of ``processes`` (those still running), reap it and close its pipes, then
    kill each of the process ids ``workers`` still there: for a test's ``finally``, so
    that a failed check leaves no tool, nor a worker of one, running. A process started
    in a session of its own (``start_new_session``) is killed with its process group."""
    for process in processes:
        if process.poll() is None:
            with contextlib.suppress(OSError):
                if os.name == "posix" and os.getpgid(process.pid) == process.pid:
                    os.killpg(process.pid, signal.SIGKILL)
                else:
                    process.kill()
    for process in processes:
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(timeout=30)
        for stream in (process.stdin, process.stdout, process.stderr):
            if stream is not None:
                stream.close()
    for pid in workers:
        with contextlib.suppress(OSError):  # gone: as it should be
            os.kill(pid, signal.SIGKILL)
