"""Single files written whole or not at all: :func:`write_atomic` replaces a file through
a temporary file and a rename; :func:`write_new` never replaces one, taking the first free
name (:func:`first_free`).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

from ddwmmr.errors import ParameterError
from ddwmmr.outputs.checks import check_file_target, existing_folder, unwritable_message
from ddwmmr.outputs.files import file_mode, folder_mode
from ddwmmr.outputs.owners import temp_prefix


def write_atomic(
    path: str | os.PathLike[str], data: str | bytes | Callable[[BinaryIO], None]
) -> None:
    """Write ``data`` to ``path`` through a temporary file and an atomic rename.

    ``data`` is text (written as UTF-8, a lone surrogate as its escape ``\\udcXX``),
    bytes, or a function ``data(handle)`` that writes the bytes into the temporary file's
    binary handle, piece by piece (a file too large to build in memory first: a long
    run's ``timeseries.csv``).

    ``path`` must be a non-empty ``str`` or :class:`os.PathLike`; if something exists
    there it must be a regular file, which is replaced. A folder, a device (``/dev/null``),
    a FIFO or a socket is refused with a one-line
    :class:`~ddwmmr.errors.ParameterError` naming the path before anything is created:
    the rename would put a regular file in its place (see
    :func:`check_file_target`). Missing parent folders are created, as
    ``mkdir -p`` would (the tools rely on it: the GUI's ``--snapshot figs/run.png``, the
    bench's ``--out``, the per-run sub-folders of a GUI export); a path through something
    that is not a folder is refused, and so is a folder in which nothing can be created
    (:func:`unwritable_message`: ``/proc``, a read-only mount, no permission).
    Failures of the write itself (full disk) raise :class:`OSError` naming ``path``.

    Durable: the file's bytes are synced to the disk (``fsync``) before the rename, and
    the folder's entry after it (:func:`sync_folder`), so a power cut leaves the earlier
    file or the new one under ``path``, never an empty one.

    The file gets the user's umask (``0644`` for umask 022), like any normal file, not
    the ``0600`` of the temporary file. The temporary file
    carries this process's :func:`owner_token` in its name (:func:`temp_prefix`): one a
    killed run leaves is removed by the next run (:func:`remove_stale`,
    :func:`remove_stale_temp`) and ignored by :func:`inspect`.
    """
    path = check_file_target(path)
    existing = existing_folder("path", path.parent)
    # A lone surrogate (a file name's undecodable byte, as Python reads one) has no UTF-8
    # form: it is written as its escape, \udce9, so a report quoting that path is still
    # written, as valid UTF-8.
    payload = (
        data
        if isinstance(data, bytes) or callable(data)
        else data.encode("utf-8", errors="backslashreplace")
    )
    try:
        path.parent.mkdir(parents=True, exist_ok=True, mode=folder_mode())
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=temp_prefix(), suffix=".tmp")
    except OSError as exc:  # the folder takes no new entries (/proc, read-only, no permission)
        message = unwritable_message("path", str(path.parent), path.parent, existing, exc)
        raise ParameterError(message) from exc
    try:
        with os.fdopen(fd, "wb") as handle:
            set_file_mode(handle.fileno(), tmp)
            if callable(payload):
                payload(handle)
            else:
                handle.write(payload)
            handle.flush()
            os.fsync(handle.fileno())  # the data reaches the disk before the name does
        # Once more just before the rename: a FIFO or folder made there during the write
        # would be replaced as well.
        check_file_target(path)
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        if exc.filename is not None:
            raise
        # A failed write (a full disk) names no file: name the one being written, so the
        # tools' one line says where ("error: PATH: No space left on device").
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from exc
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    sync_folder(path.parent)


def set_file_mode(fd: int, path: str | os.PathLike[str]) -> None:
    """Give the open file ``fd`` (at ``path``) :func:`file_mode`: through the descriptor
    where ``os.fchmod`` exists (POSIX), else through the path (Windows before Python 3.13,
    where the mode sets only the read-only flag)."""
    if hasattr(os, "fchmod"):
        os.fchmod(fd, file_mode())
    else:
        os.chmod(path, file_mode())


def sync_folder(folder: str | os.PathLike[str]) -> None:
    """Flush ``folder``'s entries (a rename or a new name in it) to the disk with
    ``fsync``, so that after a power cut the name points at the file written, not at an
    empty one (ext4, xfs). Skipped on Windows, which cannot open a folder for it, and
    where the file system refuses (``EINVAL`` on some network mounts): best effort."""
    if os.name == "nt":
        return
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass  # the file system does not sync folders; the files themselves are synced
    finally:
        os.close(fd)


def write_new(path: str | Path, data: str | bytes | Callable[[BinaryIO], None]) -> Path:
    """Write a new file at ``path`` or, if that name is taken, at the first free
    ``stem-2.suffix``, ``stem-3.suffix``... (:func:`first_free`); an existing file is
    never replaced, not even one another process creates at the same moment. Returns the
    path written.

    ``data`` is what :func:`write_atomic` takes: text (written as UTF-8), bytes, or a
    function ``data(handle)`` writing the bytes into a binary handle piece by piece (a
    result's ``stream_csv``). It goes to a temporary file first; that file then takes
    the free name with a hard link, which fails if the name was taken meanwhile: the next
    name is tried. Where hard links are not supported, the name is taken with an
    exclusive create, then the file is renamed onto it. Durable as :func:`write_atomic`:
    the data, then the new name, are synced to the disk."""
    path = Path(path)
    temporary = path.parent / f"{temp_prefix()}{os.urandom(4).hex()}.tmp"
    try:
        write_atomic(temporary, data)
        while True:
            candidate = first_free(path)
            try:
                os.link(temporary, candidate)
            except FileExistsError:
                continue  # taken between the look and the link: the next one
            except OSError:  # no hard links on this file system (FAT, some mounts)
                if not _take_name(candidate):
                    continue
                os.replace(temporary, candidate)
            sync_folder(candidate.parent)
            return candidate
    finally:
        temporary.unlink(missing_ok=True)


def _take_name(path: Path) -> bool:
    """Create ``path`` empty if nothing is there (exclusively); False if it was taken."""
    try:
        os.close(os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, file_mode()))
    except FileExistsError:
        return False
    return True


def first_free(path: str | Path, folder: bool = False) -> Path:
    """``path``, or ``stem-2.suffix``, ``stem-3.suffix``... (a ``folder``: ``name-2``,
    ``name-3``..., dots and all) whichever does not exist yet (a default, time-stamped
    output name: runs started within the same second get their own)."""
    path = Path(path)
    number = 1
    candidate = path
    while os.path.lexists(candidate):
        number += 1
        name = f"{path.name}-{number}" if folder else f"{path.stem}-{number}{path.suffix}"
        candidate = path.with_name(name)
    return candidate
