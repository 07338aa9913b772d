"""What is at an output path, and the checks made before anything is written there.

:func:`inspect` classifies an existing ``--out`` folder (:class:`Existing`) by its manifest
(:data:`MANIFEST`); :func:`check_output_folder`, :func:`check_output_file`,
:func:`check_output_path`, :func:`check_file_target` and :func:`check_writable` refuse, with
one-line :class:`~ddwmmr.errors.ParameterError`, a path that may not or cannot be written.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import stat
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any

from ddwmmr.errors import ParameterError, file_kind, printable_line, shown
from ddwmmr.outputs.owners import _is_stale_temp, ended_leftover, temp_prefix

#: Name of the manifest file each tool writes into its output folder.
MANIFEST = ".ddwmmr-manifest.json"


@dataclass
class Existing:
    """What ``--out`` currently is.

    ``kind``: ``absent``, ``empty``, ``own`` (this tool's manifest lists every file),
    ``foreign`` (files no manifest of this tool lists). ``listed``: files a valid manifest
    lists (any tool); ``foreign``: the other files; ``tool``: the manifest's tool.
    """

    kind: str
    listed: list[str] = field(default_factory=list)
    foreign: list[str] = field(default_factory=list)
    tool: str | None = None


def _safe_relative(name: object) -> bool:
    """A manifest entry that stays inside its folder (no absolute path, no ``..``)."""
    if not isinstance(name, str) or not name or "\\" in name or "\0" in name:
        return False
    path = PurePosixPath(name)
    return not path.is_absolute() and all(part not in ("", ".", "..") for part in path.parts)


def read_manifest(folder: Path) -> dict[str, Any] | None:
    """The folder's manifest if it is a valid one (tool and safe file names), else None."""
    path = folder / MANIFEST
    try:
        if not stat.S_ISREG(os.lstat(path).st_mode):
            return None
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or not isinstance(data.get("tool"), str):
        return None
    files = data.get("files")
    if not isinstance(files, list) or not all(_safe_relative(f) for f in files):
        return None
    return data


def _entries(folder: Path) -> list[str]:
    """Every file (not folder) below ``folder``, relative, posix style, sorted."""
    found = []
    for root, dirs, files in os.walk(folder, followlinks=False):
        base = Path(root).relative_to(folder)
        # A symlink to a folder is listed by os.walk in dirs: count it as an entry.
        for name in [*files, *(d for d in dirs if (Path(root) / d).is_symlink())]:
            found.append((base / name).as_posix())
    return sorted(found)


def inspect(target: Path, tool: str) -> Existing:
    """Classify an existing folder (see :class:`Existing`); ``target`` must be a folder.
    What ended runs left is not counted: temporary files (:func:`remove_stale_temp`) and,
    directly in ``target``, staging folders and locks (:func:`ended_leftover`) of runs
    writing there, which the commit removes (:func:`remove_stale`)."""
    left = {n for n in _names(target) if ended_leftover(target / n)}
    entries = [
        e
        for e in _entries(target)
        if e != MANIFEST
        and not _is_stale_temp(PurePosixPath(e).name)
        and PurePosixPath(e).parts[0] not in left
    ]
    has_manifest = os.path.lexists(target / MANIFEST)
    others = [n for n in _names(target) if n not in left and not _is_stale_temp(n)]
    if not entries and not has_manifest and not others:
        return Existing("empty")
    manifest = read_manifest(target)
    listed = set(manifest["files"]) if manifest else set()
    regular = {e for e in entries if _is_regular(target / e)}
    foreign = sorted(e for e in entries if e not in listed or e not in regular)
    if has_manifest and manifest is None:
        foreign = sorted([*foreign, MANIFEST])  # not ours to overwrite: unreadable
    present = sorted(e for e in entries if e in listed and e in regular)
    owner = manifest["tool"] if manifest else None
    kind = "own" if manifest and owner == tool and not foreign else "foreign"
    folder = _foreign_folder(target, present, left)
    if folder is not None:
        kind, foreign = "foreign", sorted([*foreign, folder + "/"])
    return Existing(kind, present, foreign, owner)


def _is_regular(path: Path) -> bool:
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except OSError:
        return False


def _foreign_folder(target: Path, files: list[str], skipped: set[str]) -> str | None:
    """A folder with nothing listed inside (relative name), else None: empty folders are
    foreign too, a user may have made them. ``skipped``: names in ``target`` not looked at."""
    needed = {str(PurePosixPath(f).parent) for f in files}
    for root, dirs, _ in os.walk(target):
        if root == os.fspath(target):
            dirs[:] = [d for d in dirs if d not in skipped]
        for name in dirs:
            rel = (Path(root) / name).relative_to(target).as_posix()
            if not any(n == rel or n.startswith(rel + "/") for n in needed):
                return rel
    return None


def _check_replaceable(path: Path, text: str, existing: Existing) -> None:
    """Refuse, before the run, an existing output whose files cannot be replaced: the
    folder itself and every folder holding a listed file must be writable."""
    folders = {path, *((path / name).parent for name in existing.listed)}
    for folder in sorted(folders):
        if not os.access(folder, os.W_OK | os.X_OK):
            shown = text if folder == path else f"{text}/{folder.relative_to(path)}"
            raise ParameterError(f"out: cannot replace files in {shown} (permission denied)")


def _name_max(folder: Path) -> int:
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


#: The longest path (bytes) a system call takes, less one: Linux's PATH_MAX is 4096.
MAX_PATH_BYTES = 4095


def check_name_lengths(label: str, path: Path, ancestor: Path) -> None:
    """Refuse (one line, ``label:``) a ``path`` whose names below its existing
    ``ancestor`` (those yet to be made) are longer than the file system there takes
    (``PC_NAME_MAX``, else 255 bytes), or which is longer than :data:`MAX_PATH_BYTES`:
    writing it would fail only later, mid-run or mid-export."""
    name_max = _name_max(ancestor if ancestor.is_dir() else Path("/"))
    for part in path.relative_to(ancestor).parts:
        size = len(os.fsencode(part))
        if size > name_max:
            raise ParameterError(
                f"{label}: the name {part[:20]}... is too long ({size} bytes, at most {name_max})"
            )
    if len(os.fsencode(str(path))) > MAX_PATH_BYTES:
        raise ParameterError(f"{label}: the path is too long (at most {MAX_PATH_BYTES} bytes)")


def nearest_existing(path: Path) -> Path:
    """``path`` if it exists (a dangling link counts), else its nearest existing ancestor."""
    for candidate in [path, *path.parents]:
        if os.path.lexists(candidate):
            return candidate
    return Path(path.anchor or "/")  # pragma: no cover - the root always exists


def missing_folders(folder: Path) -> list[Path]:
    """The folders above and including ``folder`` that do not exist yet, outermost first."""
    missing = []
    for candidate in [folder, *folder.parents]:
        if os.path.lexists(candidate):
            break
        missing.append(candidate)
    return list(reversed(missing))


def existing_folder(label: str, folder: Path) -> Path:
    """The nearest existing folder at or above ``folder`` (where the missing ones would be
    created from); a one-line :class:`ParameterError` if what exists there is not a folder
    (a file, a dangling symbolic link)."""
    existing = nearest_existing(folder)
    if not existing.is_dir():
        raise ParameterError(f"{label}: {existing} is not a folder")
    return existing


def check_file_target(path: object, label: str = "path") -> Path:
    """``path`` as a :class:`~pathlib.Path` if an output file may be moved there by a rename.

    It must be a non-empty ``str`` or :class:`os.PathLike` without a NUL byte, and what
    exists there, if anything, a regular file (a symbolic link is judged by what it points
    to): a folder, a device, a FIFO or a socket is never replaced. Anything else raises a
    one-line :class:`ParameterError` naming ``label`` and the path; only ``os.stat`` is
    called, nothing is created.
    """
    try:
        # ignore: path may be any object; os.fspath's TypeError is the check
        text = os.fspath(path)  # type: ignore[call-overload]
    except TypeError:
        text = None
    if not isinstance(text, str) or not text:
        raise ParameterError(
            f"{label} must be a file name, a non-empty str or os.PathLike (got {shown(path)})"
        )
    if "\0" in text:
        raise ParameterError(f"{label}: the file name contains a NUL byte ({shown(text)})")
    try:
        mode = os.stat(text).st_mode
    except OSError:
        return Path(text)  # absent, or not reachable: creating the file reports why
    # Every output file is moved into place by a rename, which would put a regular file
    # where the folder, device (``/dev/null``, when running as root), FIFO or socket was.
    kind = file_kind(mode)
    if kind is not None:
        raise ParameterError(
            f"{label}: {text} exists and is not a regular file ({kind}); give a file name"
        )
    return Path(text)


def check_writable(label: str, folder: Path, name: str | None = None) -> None:
    """Raise a one-line :class:`ParameterError` unless files can be created in ``folder``
    (or, if it does not exist yet, in the nearest existing folder above it). Tried, not
    inferred from permission bits: a file is created there and removed at once, which
    catches what ``os.access`` does not show (root on ``/proc``, a read-only mount).
    ``name``: ``folder`` as the user wrote it, for the message (default: ``folder``).
    The :class:`OSError` of the failed try is the error's ``__cause__``."""
    existing = existing_folder(label, folder)
    try:
        fd, probe = tempfile.mkstemp(dir=existing, prefix=temp_prefix(), suffix=".tmp")
    except OSError as exc:
        shown_name = str(folder) if name is None else name
        raise ParameterError(unwritable_message(label, shown_name, folder, existing, exc)) from exc
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)


def unwritable_message(label: str, name: str, folder: Path, existing: Path, error: OSError) -> str:
    """Why nothing can be created in ``folder`` (shown as ``name``): ``existing``, the
    folder itself or the nearest one above it that exists, takes no new entries. The
    operating system's reason (``error``) is added unless it is "No such file or
    directory", which a file system that takes no new entries (``/proc``) gives although
    ``existing`` is there."""
    reason = ""
    if error.errno != errno.ENOENT and error.strerror:
        reason = f" ({error.strerror})"
    refusal = f"{existing} takes no new files or folders{reason}; choose a folder elsewhere"
    if Path(os.path.abspath(existing)) == Path(os.path.abspath(folder)):
        return f"{label}: cannot write in {name}: {refusal}"
    return f"{label}: cannot make the folder {name}: {refusal}"


def check_output_path(target: str | Path, what: str = "folder", probe: bool = True) -> Path:
    """Refuse (one-line :class:`ParameterError`) an ``--out`` path that cannot be written:
    the current folder or a parent, a symbolic link (dangling too), a name too long or
    holding a control character (a line break would split the tool's last line, ``wrote
    <path>``), a parent that is not a writable folder. Returns the absolute path (it may not exist).
    ``probe``: also try a file in the parent (:func:`check_writable`); a caller with
    refusals of its own passes False and probes after them, so that a refused ``--out``
    leaves even the parent's modification time alone."""
    text = str(target)
    if "\0" in text:
        raise ParameterError(f"out: the {what} name contains a NUL byte")
    if not printable_line(text, undecodable=True):  # a line break would split "wrote <path>"
        raise ParameterError(
            f"out: the {what} name holds a control character (a line break, a tab, an "
            f"escape) (got {shown(text, 60)}); give one without"
        )
    path = Path(os.path.abspath(text or "."))
    cwd = Path.cwd()
    real = Path(os.path.realpath(path))
    if cwd in (path, real) or path in cwd.parents or real in cwd.parents:
        raise ParameterError(
            f"out: {text or '.'} is the current folder or one of its parents; give a new {what}"
        )
    if os.path.islink(path):
        raise ParameterError(
            f"out: {text} is a symbolic link (to {os.readlink(path)}); give a real {what}"
        )
    ancestor = nearest_existing(path.parent)
    check_name_lengths("out", path, ancestor)
    if os.path.islink(ancestor) and not ancestor.exists():
        raise ParameterError(f"out: {ancestor} is a dangling symbolic link")
    if not ancestor.is_dir():
        raise ParameterError(f"out: {ancestor} is not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise ParameterError(f"out: cannot write in {ancestor} (permission denied)")
    if probe:
        check_writable("out", path.parent)  # what os.access does not show (root on /proc)
    return path


def check_output_folder(
    target: str | Path, tool: str, force: bool = False, writes: Sequence[str] = ()
) -> Path:
    """Refuse (one-line :class:`ParameterError`) an ``--out`` that may not be written.

    Returns the absolute target path. Called before any simulation, so bad output paths
    fail fast; :func:`output_folder` checks again just before it moves files into place.
    ``writes``: the names (relative, posix) of the files the run will write; with
    ``force``, a file or folder no manifest lists under one of them is refused here, before
    the run, rather than after it (the check after the run stays as the last guard).
    """
    path = check_output_path(target, probe=False)
    if os.path.lexists(path):
        _check_existing_folder(path, str(target), tool, force, writes)
    check_writable("out", path.parent)
    return path


def _check_existing_folder(
    path: Path, text: str, tool: str, force: bool, writes: Sequence[str]
) -> None:
    """The refusals of :func:`check_output_folder` for an ``--out`` that exists."""
    if not path.is_dir():
        raise ParameterError(f"out: {text} exists and is not a folder; choose another --out")
    existing = inspect(path, tool)
    if existing.kind == "foreign" and not force:
        raise ParameterError(_refusal(text, tool, existing))
    names = set(writes)
    clash = next((f for f in existing.foreign if f.rstrip("/") in names), None)
    if clash is not None:
        raise ParameterError(_clash(text, clash))
    _check_replaceable(path, text, existing)


def _clash(text: str, name: str) -> str:
    return (
        f"out: {text}/{name} is not a file a ddwmmr manifest lists and would be "
        "overwritten; move it or choose another --out"
    )


def check_output_file(
    target: str | Path, tool: str, is_ours: Callable[[Path], bool], force: bool = False
) -> Path:
    """:func:`check_output_path` for a single output file: an existing file is replaced
    only if ``is_ours(path)`` says this tool wrote it (or with ``force``); a folder, a
    device, a FIFO or a socket never (:func:`check_file_target`), and that is said before
    anything that would suggest ``--force``."""
    text = str(target)
    path = check_output_path(target, "file", probe=False)
    if path.is_dir():
        raise ParameterError(f"out: {text} is a folder; give a file name")
    check_file_target(text, "out")
    if path.exists() and not force and not is_ours(path):
        raise ParameterError(
            f"out: {text} exists and is not a {tool} report (use --force to replace it)"
        )
    check_writable("out", path.parent)
    return path


def _refusal(text: str, tool: str, existing: Existing) -> str:
    return (
        f"out: {text} {foreign_contents(tool, existing)}; choose another --out, or add "
        "--force (deletes only files a ddwmmr manifest lists)"
    )


def foreign_contents(tool: str, existing: Existing) -> str:
    """What makes the folder ``existing`` describes no output of ``tool``, as a predicate
    ("was written by ddwmmr scenarios, not bounds", "holds files no ... run wrote (...)")."""
    if existing.tool is not None and existing.tool != tool:
        return f"was written by ddwmmr {existing.tool}, not {tool}"
    sample = ", ".join(existing.foreign[:2]) + (", ..." if len(existing.foreign) > 2 else "")
    return f"holds files no ddwmmr {tool} run wrote ({sample})"


def _names(folder: Path) -> list[str]:
    try:
        return os.listdir(folder)
    except OSError:
        return []
