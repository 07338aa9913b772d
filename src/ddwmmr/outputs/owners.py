"""Who owns a staging folder, an old folder or a temporary file: the names ddwmmr gives
them carry the host, process id and start time of the run that made them
(:func:`owner_token`), so a later run can tell whether that run has ended
(:func:`_dead_owner`).
"""

from __future__ import annotations

import ctypes
import functools
import os
import re
import socket
import stat
from pathlib import Path
from typing import Any, NoReturn

from ddwmmr.errors import ParameterError, file_kind

STAGING_PREFIX = ".ddwmmr-staging-"


_OLD_PREFIX = ".ddwmmr-old-"


#: Where the files of an old folder that no manifest lists are kept (a user's files).
KEPT_PREFIX = ".ddwmmr-kept-"


#: A staging or old folder's name: prefix, owner (host, process id, start time), random.
#: A temporary file's (:func:`write_atomic`) too, with ``.tmp`` at the end of its random
#: part. An old folder's random part starts with :func:`_target_tag` of the folder it
#: replaces; that folder's name is in the note beside the old folder (:func:`_target_note`).
_OWNED_NAME = re.compile(
    r"^\.ddwmmr-(?P<kind>staging|old|tmp)-(?P<host>.+)-(?P<pid>\d+)-(?P<start>\d+)-"
    r"(?P<random>[^-]+)$"
)


_TMP_PREFIX = ".ddwmmr-tmp-"


#: The lock of an output folder, beside it (:func:`ddwmmr.outputs.lock.output_lock`).
LOCK_PREFIX = ".ddwmmr-lock-"


def _host() -> str:
    """This machine's name, reduced to letters, digits, dots and dashes (at most 64)."""
    return re.sub(r"[^A-Za-z0-9.-]", "_", socket.gethostname())[:64] or "host"


#: ``OpenProcess`` access right enough for the exit code and times (winnt.h).
_PROCESS_QUERY_LIMITED_INFORMATION = 0x1000
#: ``GetExitCodeProcess``'s code of a process still running (minwinbase.h).
_STILL_ACTIVE = 259
#: ``OpenProcess``'s error for a process id no process has (winerror.h).
_ERROR_INVALID_PARAMETER = 87


def _process_start(pid: int) -> int:
    """When process ``pid`` started, in clock ticks since boot (Linux) or in 100 ns since
    1601 (Windows' creation time), or 0 if unknown; with the process id it names one
    process, even after the id is reused."""
    if os.name == "nt":
        return _windows_process(pid)[1]
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return int(fields[19])
    except (OSError, IndexError, ValueError):
        return 0


def owner_token() -> str:
    """``host-pid-start`` of this process, put in the names of its staging folders."""
    return f"{_host()}-{os.getpid()}-{_process_start(os.getpid())}"


def temp_prefix() -> str:
    """Name prefix of this process's temporary files, carrying its :func:`owner_token`."""
    return f"{_TMP_PREFIX}{owner_token()}-"


def _dead_owner(name: str, kind: str) -> re.Match[str] | None:
    """The match of ``name`` if it is a ``kind`` (staging, old, tmp) name of a run of this
    host that has ended, else None."""
    match = _OWNED_NAME.match(name)
    if match is None or match["kind"] != kind or match["host"] != _host():
        return None
    return None if _running(int(match["pid"]), int(match["start"])) else match


def _running(pid: int, start: int) -> bool:
    """Whether the process ``pid`` that started at ``start`` (0: unknown) still runs.
    In doubt (another user's process, a platform without these checks): True."""
    if os.name == "nt":  # os.kill(pid, 0) would end the process there
        running, started = _windows_process(pid)
        return running and (not start or started in (0, start))
    if os.name != "posix":
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # it exists, another user's
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return True
    if state == "Z":
        return False  # ended, not yet reaped
    return not start or _process_start(pid) in (0, start)


def _windows_process(pid: int) -> tuple[bool, int]:
    """Windows: whether process ``pid`` runs, and its creation time (100 ns since 1601; 0
    if unknown). In doubt (no access to it): running, start unknown."""
    kernel32 = _kernel32()
    handle = kernel32.OpenProcess(_PROCESS_QUERY_LIMITED_INFORMATION, False, pid)
    if not handle:
        return (_last_error() != _ERROR_INVALID_PARAMETER, 0)
    try:
        code = ctypes.c_ulong()
        if not kernel32.GetExitCodeProcess(handle, ctypes.byref(code)):
            return (True, 0)
        # FILETIMEs (two 32-bit halves, low first) read as 64-bit integers
        times = [ctypes.c_ulonglong() for _ in range(4)]
        known = kernel32.GetProcessTimes(handle, *(ctypes.byref(t) for t in times))
        return (code.value == _STILL_ACTIVE, times[0].value if known else 0)
    finally:
        kernel32.CloseHandle(handle)


@functools.cache
def _kernel32() -> Any:
    """Windows' kernel32, with the functions :func:`_windows_process` calls typed (a
    process handle is pointer-sized)."""
    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)  # type: ignore[attr-defined]
    kernel32.OpenProcess.restype = ctypes.c_void_p
    kernel32.OpenProcess.argtypes = (ctypes.c_ulong, ctypes.c_int, ctypes.c_ulong)
    kernel32.GetExitCodeProcess.argtypes = (ctypes.c_void_p, ctypes.c_void_p)
    kernel32.GetProcessTimes.argtypes = (ctypes.c_void_p, *[ctypes.c_void_p] * 4)
    kernel32.CloseHandle.argtypes = (ctypes.c_void_p,)
    return kernel32


def _last_error() -> int:
    """Windows: the error code of the last kernel32 call of this thread."""
    # ignore: typeshed declares get_last_error on Windows only, where this is called
    code: int = ctypes.get_last_error()  # type: ignore[attr-defined]
    return code


def _is_stale_temp(name: str) -> bool:
    """Whether ``name`` is a temporary file's name (:func:`temp_prefix`) of an ended run."""
    return name.endswith(".tmp") and _dead_owner(name, "tmp") is not None


#: Most bytes of a lock file read: its token is a host name, a process id and a time.
_LOCK_BYTES = 4096


def read_lock(path: Path) -> str | None:
    """The text of the output lock ``path`` (its first :data:`_LOCK_BYTES` bytes, a byte
    that is not UTF-8 as U+FFFD; ``""`` if it cannot be read), None if nothing is there.

    Anything at ``path`` that is not a regular file raises a one-line
    :class:`ParameterError` naming it: reading a FIFO would wait for ever and ``/dev/zero``
    would fill the memory, and a folder is no run's lock, to be moved aside as a killed
    run's. The file is opened without following a link and without waiting (a FIFO
    swapped in after the check)."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return None
    except OSError:
        return ""
    if not stat.S_ISREG(mode):
        _not_a_lock(path, mode)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        return None
    except OSError:
        return ""
    with os.fdopen(fd, "rb") as handle:
        mode = os.fstat(handle.fileno()).st_mode
        if not stat.S_ISREG(mode):
            _not_a_lock(path, mode)
        try:
            data = handle.read(_LOCK_BYTES)
        except OSError:
            return ""
    return data.decode("utf-8", errors="replace")


def _not_a_lock(path: Path, mode: int) -> NoReturn:
    """Refuse ``path`` (its ``st_mode`` is ``mode``): something other than a regular file
    stands at the lock's name, and reading it could block (a FIFO), never end (a device)
    or take a folder for a dead run's lock."""
    kind = file_kind(mode)
    raise ParameterError(
        f"out: {path}, the name of the output folder's lock, is {kind}, not a lock file a "
        "ddwmmr run wrote; remove it or choose another --out"
    )


def lock_holder(path: Path) -> tuple[str, int, int] | None:
    """``(host, pid, start)`` of the run holding the lock ``path`` (its text is that run's
    :func:`owner_token`; an unreadable or cut-short one: this host, pid 0, which
    :func:`dead_lock` counts as ended), or None if there is no lock. Something there that
    is not a regular file is refused (:func:`read_lock`)."""
    token = read_lock(path)
    if token is None:
        return None
    rest, _, start = token.rpartition("-")
    host, _, pid = rest.rpartition("-")
    if not (host and pid.isdigit() and start.isdigit()):
        return (_host(), 0, 0)
    return (host, int(pid), int(start))


def dead_lock(holder: tuple[str, int, int]) -> bool:
    """Whether the lock ``holder`` (:func:`lock_holder`) is of a run of this host that has
    ended (a lock of another host's run is never taken for dead)."""
    host, pid, start = holder
    return host == _host() and (pid == 0 or not _running(pid, start))


def ended_leftover(path: Path) -> bool:
    """Whether ``path`` is a staging folder (a real folder, not a link) or an output lock
    (a regular file) that a run of this host left and that run has ended: never a user's
    file, and removed by the next run writing beside it."""
    try:
        mode = os.lstat(path).st_mode
    except OSError:
        return False
    if stat.S_ISDIR(mode):
        return _dead_owner(path.name, "staging") is not None
    if not (stat.S_ISREG(mode) and path.name.startswith(LOCK_PREFIX)):
        return False
    holder = lock_holder(path)
    return holder is not None and dead_lock(holder)
