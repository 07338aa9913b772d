"""Permissions and CSV text of output files.

A new output file or folder gets the user's umask like any normal file (:func:`file_mode`,
:func:`folder_mode`: ``0644``/``0755`` for the usual ``022``); a CSV file is written in one
dialect (:func:`csv_text`), keeping the line ending of the file it replaces
(:func:`line_ending`).
"""

from __future__ import annotations

import contextlib
import csv
import io
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from ddwmmr._version import __version__


def umask() -> int:
    """The process umask: from ``/proc/self/status`` on Linux (no race with other
    threads), else by setting and restoring it (``os.umask`` can only be read so)."""
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def file_mode() -> int:
    """Mode of a new output file under the user's umask (``0o644`` for umask 022)."""
    return 0o666 & ~umask()


def folder_mode() -> int:
    """Mode of a new output folder under the user's umask (``0o755`` for umask 022)."""
    return 0o777 & ~umask()


def package_version() -> str:
    """The installed ddwmmr version."""
    return __version__


def line_ending(path: str | Path, default: str = "\n") -> str:
    """The line ending of the CSV file at ``path``: ``"\\r\\n"`` if it has one, else
    ``default`` (also when the file is absent). A file rewritten with it keeps its bytes
    where its rows are unchanged."""
    try:
        return "\r\n" if b"\r\n" in Path(path).read_bytes() else default
    except FileNotFoundError:
        return default


def csv_text(
    header: Sequence[str], rows: Iterable[Mapping[str, object]], ending: str = "\n"
) -> str:
    """CSV text of ``rows`` (each a mapping from the names of ``header``) under
    ``header``, in :class:`csv.DictWriter`'s dialect with ``ending`` ending every line;
    write it with :func:`write_atomic`. A row with a name ``header``
    lacks raises :class:`ValueError`; a missing name is written empty."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(header), lineterminator=ending)
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()
