"""One run at a time per output folder: a run writing ``--out`` holds a lock file beside
it (:func:`output_lock`), so two runs started together on the same ``--out`` never leave
a folder whose files come from both; the second is refused in one line. A lock a killed
run left (its process is gone) is taken over.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

from ddwmmr.errors import ParameterError
from ddwmmr.outputs.atomic import set_file_mode
from ddwmmr.outputs.files import file_mode
from ddwmmr.outputs.owners import (
    LOCK_PREFIX,
    _host,
    dead_lock,
    lock_holder,
    owner_token,
    read_lock,
    temp_prefix,
)
from ddwmmr.outputs.recovery import _target_tag, drop_stale_lock


def lock_file(target: Path) -> Path:
    """The lock of the output folder ``target``: ``.ddwmmr-lock-<tag>`` beside it (not
    inside: the commit renames the folder itself, and an absent ``target`` stays absent
    until the results move in). Its text is the holder's :func:`owner_token`. Every
    spelling of the same folder gets the same lock (:func:`_lock_tag`)."""
    return target.with_name(f"{LOCK_PREFIX}{_lock_tag(target)}")


def _lock_tag(target: Path) -> str:
    """:func:`_target_tag` of ``target``'s name, case-folded where the parent's file system
    ignores case (:func:`_case_insensitive`), so that ``Results`` and ``results`` share a
    lock there. The name alone is enough: the lock is made in the parent folder itself, so
    every path reaching that folder (a symbolic link, ``..``, another case, a bind mount)
    finds the same file, where a key from the spelled or resolved parent path would not
    (a resolved path differs between two mounts of one folder)."""
    name = target.name.casefold() if _case_insensitive(target.parent) else target.name
    return _target_tag(target.with_name(name))


def _case_insensitive(folder: Path) -> bool:
    """Whether names in ``folder`` are looked up ignoring case: a temporary file is made
    there and looked up with its letters' case swapped (a mount of another file system,
    FAT or a Windows share, differs from the system's default). If the file cannot be
    made: True on Windows and macOS, whose usual file systems ignore case."""
    try:
        fd, probe = tempfile.mkstemp(dir=folder, prefix=temp_prefix(), suffix=".tmp")
    except OSError:
        return os.name == "nt" or sys.platform == "darwin"
    os.close(fd)
    try:
        return os.path.lexists(os.path.join(folder, os.path.basename(probe).swapcase()))
    finally:
        with contextlib.suppress(OSError):
            os.unlink(probe)


@contextlib.contextmanager
def output_lock(target: Path, text: str) -> Iterator[None]:
    """Hold the lock of ``target`` (shown as ``text``) for the block; a one-line
    :class:`ParameterError` if another live run holds it: ``out: DIR is being written by
    another ddwmmr run (pid N)``. The lock is removed when the block ends, however it
    ends; one whose holder has ended (same host) is taken over. One of another host's run
    (a shared folder, or this host renamed since) is never taken over: the refusal names
    the lock file, for the user to delete once that run has ended."""
    path = lock_file(target)
    token = owner_token()
    _take(path, text, token)
    try:
        yield
    finally:
        with contextlib.suppress(OSError, ParameterError):
            if read_lock(path) == token:
                path.unlink()


def _take(path: Path, text: str, token: str) -> None:
    """Create the lock ``path`` holding ``token``, taking over one of an ended run."""
    for _ in range(3):
        if _create(path, token):
            return
        holder = lock_holder(path)
        if holder is None:
            continue  # removed meanwhile: try again
        if dead_lock(holder):
            drop_stale_lock(path, holder)  # a killed run's: take it over
            continue
        host, pid, _ = holder
        if host == _host():
            raise ParameterError(f"out: {text} is being written by another ddwmmr run (pid {pid})")
        raise ParameterError(
            f"out: {text} is being written by another ddwmmr run (pid {pid} on {host}); "
            f"if that run has ended, delete {path}"
        )
    raise ParameterError(
        f"out: {text} is being written by another ddwmmr run; if it has ended, delete {path}"
    )


def _create(path: Path, token: str) -> bool:
    """Make the lock whole or not at all: the token is written to a temporary file that
    then takes the name with a hard link (fails if the name exists); where hard links are
    not supported, an exclusive create. False if the lock exists."""
    fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=temp_prefix(), suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            set_file_mode(handle.fileno(), temporary)
            handle.write(token)
        try:
            os.link(temporary, path)
        except FileExistsError:
            return False
        except OSError:  # no hard links on this file system (FAT, some mounts)
            return _create_exclusive(path, token)
        return True
    finally:
        Path(temporary).unlink(missing_ok=True)


def _create_exclusive(path: Path, token: str) -> bool:
    """Create ``path`` holding ``token`` with an exclusive create; False if it exists."""
    try:
        fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, file_mode())
    except FileExistsError:
        return False
    with os.fdopen(fd, "w", encoding="utf-8") as handle:
        handle.write(token)
    return True
