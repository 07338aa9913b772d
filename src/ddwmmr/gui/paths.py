"""Where the app writes: the ``--snapshot`` file and the export folder, checked up front.

Both are checked before anything is built or simulated, so a path that cannot be written
fails in one line (a :class:`ParameterError`, status 2) instead of after the run:

* ``--snapshot PATH``: :func:`ddwmmr.outputs.check_output_path` (no symbolic link, not the
  current folder, names not too long, the nearest existing folder writable), an image
  suffix matplotlib writes, and never an existing file unless ``--force`` or an earlier
  snapshot wrote it: a snapshot in a format with metadata (:data:`MARKED_FORMATS`) carries
  :data:`SNAPSHOT_MARK` (:func:`snapshot_metadata`), so a rerun may replace its own file
  (:func:`written_by_snapshot`) and no other; a folder or a special file is refused even
  with ``--force``;
* the export folder: a folder, or a path where one can be made.

"Writable" is tried, not inferred from the permission bits, and refused in the wording of
every tool (:func:`ddwmmr.outputs.check_writable`).
"""

from __future__ import annotations

import os
from pathlib import Path

from ddwmmr.errors import ParameterError, file_kind, printable_line, shown
from ddwmmr.outputs import (
    check_name_lengths,
    check_output_path,
    check_writable,
    nearest_existing,
)

#: Suffixes (formats) ``--snapshot`` may have: what matplotlib writes by itself or through
#: Pillow (pgf needs LaTeX; raw/rgba are headerless pixel dumps, not image files).
SNAPSHOT_FORMATS = (
    "png",
    "svg",
    "svgz",
    "pdf",
    "eps",
    "ps",
    "jpg",
    "jpeg",
    "tif",
    "tiff",
    "webp",
    "gif",
)


#: What a snapshot writes into its file's metadata, and looks for before replacing a file
#: (no parentheses: PDF strings would escape them).
SNAPSHOT_MARK = "ddwmmr simulator snapshot: python -m ddwmmr.gui --snapshot"
#: Formats whose metadata matplotlib writes as plain text, with the key holding the mark
#: and how such a file starts (or, for SVG, what its first KiB holds).
MARKED_FORMATS = {
    "png": ("Software", b"\x89PNG\r\n\x1a\n"),
    "pdf": ("Creator", b"%PDF"),
    "svg": ("Creator", b"<svg"),
    "eps": ("Creator", b"%!PS"),
    "ps": ("Creator", b"%!PS"),
}
#: Largest file read to look for the mark (a snapshot is far smaller).
MARK_SCAN_BYTES = 64 * 1024 * 1024


def snapshot_metadata(fmt: str) -> dict[str, str] | None:
    """The ``metadata`` of ``savefig`` for a snapshot in format ``fmt`` (None: the format
    has none, and its file cannot be recognised later)."""
    if fmt not in MARKED_FORMATS:
        return None
    return {MARKED_FORMATS[fmt][0]: SNAPSHOT_MARK}


def written_by_snapshot(path: Path, fmt: str) -> bool:
    """Whether the file at ``path`` is a ``fmt`` file an earlier snapshot wrote (it has
    the format's signature and :data:`SNAPSHOT_MARK` in its metadata)."""
    if fmt not in MARKED_FORMATS:
        return False
    signature = MARKED_FORMATS[fmt][1]
    try:
        with open(path, "rb") as file:
            data = file.read(MARK_SCAN_BYTES)
    except OSError:
        return False
    head = data[:1024] if fmt == "svg" else data[: len(signature)]
    found = signature in head if fmt == "svg" else head == signature
    return found and SNAPSHOT_MARK.encode() in data


def snapshot_format(text: str) -> str:
    """The image format of ``--snapshot`` ``text``, from its suffix (one of
    :data:`SNAPSHOT_FORMATS`, any case)."""
    suffix = Path(text).suffix.lower().lstrip(".")
    if suffix not in SNAPSHOT_FORMATS:
        got = f"got .{suffix}" if suffix else "no suffix"
        raise ParameterError(
            f"snapshot: {text} must end in an image suffix: .{', .'.join(SNAPSHOT_FORMATS)} ({got})"
        )
    return suffix


def check_snapshot_path(text: str, force: bool = False) -> Path:
    """The absolute ``--snapshot`` path, checked before the run (see the module doc)."""
    if not text:
        raise ParameterError("snapshot: the file name is empty; give e.g. --snapshot gui.png")
    try:
        path = check_output_path(text, "file", probe=False)
    except ParameterError as exc:  # its messages name --out; this option is --snapshot
        raise ParameterError(f"snapshot: {str(exc).removeprefix('out: ')}") from None
    if path.is_dir():
        raise ParameterError(f"snapshot: {text} is a folder; give a file name such as gui.png")
    snapshot_format(text)
    check_existing_snapshot(path, text, force)
    check_writable("snapshot", path.parent)
    return path


def check_existing_snapshot(path: Path, text: str, force: bool) -> None:
    """Refuse an existing ``path`` unless ``force`` or an earlier snapshot wrote it
    (:func:`written_by_snapshot`); a special file (FIFO, device...) always. Called before
    the run and again just before the file is written."""
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise ParameterError(f"snapshot: cannot check {text} ({exc.strerror})") from None
    kind = file_kind(info.st_mode)
    if kind is not None:
        raise ParameterError(f"snapshot: {text} exists and is not a regular file ({kind})")
    fmt = snapshot_format(text)
    if force or written_by_snapshot(path, fmt):
        return
    why = (
        "no snapshot wrote it"
        if fmt in MARKED_FORMATS
        else f"a .{fmt} file cannot show that a snapshot wrote it: .{', .'.join(MARKED_FORMATS)}"
        " can"
    )
    raise ParameterError(
        f"snapshot: {text} exists and {why}; choose another file, or add --force to replace it"
    )


def check_export_root(text: str) -> Path:
    """The export folder ``text`` if it is a folder or can be made (one-line error)."""
    text = text.strip()
    if not text:
        raise ParameterError("export folder must not be empty")
    if "\0" in text:
        raise ParameterError("export: the folder name contains a NUL byte")
    if not printable_line(text):
        raise ParameterError(
            f"export: the folder name must be one line of printable characters (got {shown(text)})"
        )
    path = Path(os.path.abspath(text))
    if os.path.lexists(path) and not path.is_dir():
        raise ParameterError(f"export: {text} exists and is not a folder")
    check_name_lengths("export", path, nearest_existing(path))
    check_writable("export", path, text)
    return path
