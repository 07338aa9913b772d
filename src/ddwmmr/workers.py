"""Worker process pools whose workers die with the process that started them.

A pool's workers wait on a pipe for work. If their parent is killed outright (SIGKILL, a
crash, an out-of-memory kill), nothing tells them to stop, and they would stay, orphaned,
until the machine restarts. Every worker of :func:`process_pool` therefore runs
:func:`die_with_parent` first:

* on Linux the kernel sends it SIGKILL when its parent exits (``prctl(PR_SET_PDEATHSIG)``),
  even while it is busy in C code (not for a worker of the ``forkserver`` start method,
  whose parent is the fork server);
* on every platform a daemon thread waits on the parent's sentinel
  (:func:`multiprocessing.parent_process`, closed by the operating system when the parent
  ends) and ends the worker at once.

Workers only compute and return results: they write no files, so ending them can leave
nothing half-written.

A worker also shows warnings the way the process that started the pool does when that
process's display (``warnings.showwarning``) says how (:func:`worker_display`): the tools
show the library's warnings as one line each, and a worker that was not forked (the
``spawn`` and ``forkserver`` start methods) starts with Python's own display. A display
that keeps the lines it has shown (:data:`SHOWN`) hands them on, so that a worker does not
repeat a warning its parent has shown (one that every run gives, such as a plant's warning
about the robot, is said once per command when the parent says it before the pool starts).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import multiprocessing
import multiprocessing.connection
import os
import signal
import sys
import threading
import warnings
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from multiprocessing.context import BaseContext

#: ``prctl`` option that asks for a signal when the parent exits (linux/prctl.h).
PR_SET_PDEATHSIG = 1
#: Exit status of a worker that outlived its parent (the parent is gone: nobody reads it).
EXIT_ORPHANED = 1
#: Most workers a process pool may have on Windows (``WaitForMultipleObjects`` waits on at
#: most 64 handles; :class:`~concurrent.futures.ProcessPoolExecutor` keeps 3 for itself).
WINDOWS_MAX_WORKERS = 61


#: Attribute of a warnings display (``warnings.showwarning``) naming the module-level
#: function (picklable: a spawned worker imports it) that installs the same display in the
#: process that calls it.
IN_WORKERS = "in_workers"
#: Attribute of a warnings display: the set of the lines (str) it has shown, which it does
#: not show again; a worker's display starts with its parent's (:func:`worker_display`).
SHOWN = "shown"


def process_pool(jobs: int, mp_context: BaseContext | None = None) -> ProcessPoolExecutor:
    """A pool of ``jobs`` worker processes that end when this process ends, however, and
    show warnings as this process does (:func:`worker_display`).

    ``mp_context``: the :mod:`multiprocessing` context that starts the workers (default:
    the platform's start method). On Windows at most :data:`WINDOWS_MAX_WORKERS` workers
    start, however many ``jobs`` asks for: the results do not depend on the count.
    """
    if sys.platform == "win32":
        jobs = min(jobs, WINDOWS_MAX_WORKERS)
    return ProcessPoolExecutor(
        max_workers=jobs,
        mp_context=mp_context,
        initializer=start_worker,
        initargs=(os.getpid(), worker_display()),
    )


def worker_display() -> Callable[[], None] | None:
    """The function that installs this process's warnings display in a worker: the
    ``in_workers`` attribute (:data:`IN_WORKERS`) of ``warnings.showwarning``, which for a
    display that keeps its shown lines (:data:`SHOWN`) also hands on those shown so far;
    None for Python's display, or one that does not say how to reproduce it. Picklable,
    for a worker that is not forked."""
    install = getattr(warnings.showwarning, IN_WORKERS, None)
    shown = getattr(warnings.showwarning, SHOWN, None)
    if install is None or shown is None:
        return install
    return functools.partial(_install_display, install, frozenset(shown))


def _install_display(install: Callable[[], None], shown: frozenset[str]) -> None:
    """``install()``, then count the parent's ``shown`` lines as shown by the display it
    installed (:data:`SHOWN`): a forked worker's display, a copy of its parent's, holds
    them already; a worker started otherwise begins without them."""
    install()
    getattr(warnings.showwarning, SHOWN, set[str]()).update(shown)


def start_worker(parent_pid: int, display: Callable[[], None] | None) -> None:
    """A pool worker's first step: :func:`die_with_parent`, then ``display()`` (a
    :func:`worker_display` of the parent), if any."""
    die_with_parent(parent_pid)
    if display is not None:
        display()


def die_with_parent(parent_pid: int) -> None:
    """End this process when the process ``parent_pid`` that started it ends.

    Runs first in every worker (a pool initializer). If the parent has already gone by
    then, the worker ends here. A worker that a fork server made (the ``forkserver``
    start method) is that server's child, not ``parent_pid``'s: the kernel's signal would
    follow the server, so only the watchdog thread watches the parent.
    """
    if os.getppid() == parent_pid:  # the parent's own child (fork, spawn)
        _ask_kernel_for_death_signal()
        if os.getppid() != parent_pid:  # gone before the request above took effect
            os._exit(EXIT_ORPHANED)
    parent = multiprocessing.parent_process()
    if parent is not None and parent.sentinel is not None:
        watchdog = threading.Thread(
            target=_exit_when_ready, args=(parent.sentinel,), name="ddwmmr-parent-watchdog"
        )
        watchdog.daemon = True
        watchdog.start()


def _ask_kernel_for_death_signal() -> bool:
    """Linux: SIGKILL this process when its parent exits. False where unavailable."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        done: bool = libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
        return done
    except (OSError, AttributeError):  # no libc or no prctl: the watchdog still runs
        return False


def _exit_when_ready(sentinel: int) -> None:
    """Block until the parent's sentinel is ready (the parent ended), then exit."""
    multiprocessing.connection.wait([sentinel])
    os._exit(EXIT_ORPHANED)
