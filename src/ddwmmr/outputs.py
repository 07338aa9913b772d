"""Output folders of the command-line tools: never lose a user's file.

Every tool (track, compare, scenarios) writes its results through :func:`output_folder`:

* the files are written into a hidden staging folder next to ``--out`` and moved into place
  only when the run succeeded; the staging folder is removed on any error, Ctrl-C or
  SIGTERM (:mod:`ddwmmr.cli.common` turns SIGTERM into an exception so this happens);
* the moves into ``--out`` hold the stop signals (:func:`_signals_deferred`): a signal
  arriving then is acted on once they are done, with the new output complete in place
  (:func:`committed_output`);
* a run killed outright (SIGKILL) cannot clean up: its staging folder, the folder of an
  earlier output it was replacing and its temporary files carry its host, process id and
  start time in their names (:func:`owner_token`), and the next run writing in the same
  folder removes those whose process is gone (:func:`remove_stale`), saying so in one
  line, after putting back every earlier output the killed run had moved aside, whichever
  ``--out`` the next run writes (:func:`_restore_killed`). Nothing is synced to disk (no
  ``fsync``): a power cut may lose the last files written;
* a folder written by a tool carries a manifest, :data:`MANIFEST`, naming the tool, the
  package version and every file written;
* an existing ``--out`` is replaced only if it is empty, or if its manifest names the same
  tool and it holds nothing but the files that manifest lists. Anything else is refused
  with one line (a :class:`ParameterError`);
* a default, time-stamped ``--out`` (``fresh``) never replaces anything: two runs started
  within the same second, or finishing together, each get their own folder (``-2``...);
* a tool that keeps a cache inside its output folder while it runs (so an interrupted run
  resumes, ``python -m ddwmmr.bounds``) writes those files in place and lists them with
  :func:`list_in_manifest`: the folder stays this tool's own between runs;
* ``force=True`` (``--force``) also writes into a folder another tool or the user made,
  and even then deletes only the files its manifest lists: a file no manifest lists always
  survives (a new file that would overwrite it is refused). An interrupt while the files
  are moved leaves the old output or the new one, each with its manifest, never a mix.

Files and folders get the user's umask like any normal file (``0644``/``0755`` for the
usual ``022``), not the ``0600``/``0700`` of temporary files.
"""

from __future__ import annotations

import contextlib
import csv
import errno
import functools
import hashlib
import io
import json
import os
import re
import shutil
import signal
import socket
import stat
import sys
import tempfile
import threading
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from ddwmmr._version import __version__
from ddwmmr.errors import ParameterError, shown

#: Name of the manifest file each tool writes into its output folder.
MANIFEST = ".ddwmmr-manifest.json"
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
#: Added to an old folder's name: the file naming the output that folder replaces.
_NOTE_SUFFIX = ".target"
#: The signals whose Python handlers wait while a commit moves files (the tools' stop
#: signals: :mod:`ddwmmr.cli.signals`, which this low layer may not import).
_DEFERRED_SIGNALS = tuple(
    getattr(signal, name)
    for name in ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT")
    if hasattr(signal, name)
)
#: Attribute set on an exception (an interrupt) that arrived once the new output was in
#: place: its value is the output folder, complete (see :func:`committed_output`).
_COMMITTED = "ddwmmr_committed_output"


# -- permissions ------------------------------------------------------------------------
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


# -- CSV text ------------------------------------------------------------------------------
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


# -- what is at the target ----------------------------------------------------------------
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


def read_manifest(folder: Path) -> dict | None:
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
    Temporary files ended runs left (:func:`remove_stale_temp`) are not counted."""
    entries = [
        e for e in _entries(target) if e != MANIFEST and not _is_stale_temp(PurePosixPath(e).name)
    ]
    has_manifest = os.path.lexists(target / MANIFEST)
    if not entries and not has_manifest and all(_is_stale_temp(n) for n in _names(target)):
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
    folder = _foreign_folder(target, present)
    if folder is not None:
        kind, foreign = "foreign", sorted([*foreign, folder + "/"])
    return Existing(kind, present, foreign, owner)


def _is_regular(path: Path) -> bool:
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except OSError:
        return False


def _foreign_folder(target: Path, files: list[str]) -> str | None:
    """A folder with nothing listed inside (relative name), else None: empty folders are
    foreign too, a user may have made them."""
    needed = {str(PurePosixPath(f).parent) for f in files}
    for root, dirs, _ in os.walk(target):
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


# -- checks before anything is written --------------------------------------------------
def _name_max(folder: Path) -> int:
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


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


#: File types an output path may not be, with their names for a message. Every output
#: file is moved into place by a rename, which would put a regular file where the folder,
#: device (``/dev/null``, when running as root), FIFO or socket was.
_NOT_FILES = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISSOCK, "a socket"),
)


def check_file_target(path: object, label: str = "path") -> Path:
    """``path`` as a :class:`~pathlib.Path` if an output file may be moved there by a rename.

    It must be a non-empty ``str`` or :class:`os.PathLike` without a NUL byte, and what
    exists there, if anything, a regular file (a symbolic link is judged by what it points
    to): a folder, a device, a FIFO or a socket is never replaced. Anything else raises a
    one-line :class:`ParameterError` naming ``label`` and the path; only ``os.stat`` is
    called, nothing is created.
    """
    try:
        text = os.fspath(path)  # type: ignore[arg-type]
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
    if not stat.S_ISREG(mode):
        kind = next((name for test, name in _NOT_FILES if test(mode)), "a special file")
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
    the current folder or a parent, a symbolic link (dangling too), a name too long, a
    parent that is not a writable folder. Returns the absolute path (it may not exist).
    ``probe``: also try a file in the parent (:func:`check_writable`); a caller with
    refusals of its own passes False and probes after them, so that a refused ``--out``
    leaves even the parent's modification time alone."""
    text = str(target)
    if "\0" in text:
        raise ParameterError(f"out: the {what} name contains a NUL byte")
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
    name_max = _name_max(ancestor if ancestor.is_dir() else Path("/"))
    for part in path.relative_to(ancestor).parts:
        size = len(os.fsencode(part))
        if size > name_max:
            raise ParameterError(
                f"out: the name {part[:20]}... is too long ({size} bytes, at most {name_max})"
            )
    if len(os.fsencode(str(path))) >= 4096:
        raise ParameterError("out: the path is too long (at most 4095 bytes)")
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


# -- atomic files ------------------------------------------------------------------------
def write_atomic(path: str | os.PathLike[str], data: str | bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and an atomic rename.

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
    Failures of the write itself (full disk) raise :class:`OSError`.

    The file gets the user's umask (``0644`` for umask 022), like any normal file, not
    the ``0600`` of the temporary file; text is written as UTF-8. The temporary file
    carries this process's :func:`owner_token` in its name (:func:`temp_prefix`): one a
    killed run leaves is removed by the next run (:func:`remove_stale`,
    :func:`remove_stale_temp`) and ignored by :func:`inspect`.
    """
    path = check_file_target(path)
    existing = existing_folder("path", path.parent)
    payload = data if isinstance(data, bytes) else data.encode("utf-8")
    try:
        path.parent.mkdir(parents=True, exist_ok=True, mode=folder_mode())
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=temp_prefix(), suffix=".tmp")
    except OSError as exc:  # the folder takes no new entries (/proc, read-only, no permission)
        message = unwritable_message("path", str(path.parent), path.parent, existing, exc)
        raise ParameterError(message) from exc
    try:
        with os.fdopen(fd, "wb") as handle:
            os.fchmod(handle.fileno(), file_mode())
            handle.write(payload)
        # Once more just before the rename: a FIFO or folder made there during the write
        # would be replaced as well.
        check_file_target(path)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_new(path: str | Path, data: str | bytes | Callable[[Path], None]) -> Path:
    """Write a new file at ``path`` or, if that name is taken, at the first free
    ``stem-2.suffix``, ``stem-3.suffix``... (:func:`first_free`); an existing file is
    never replaced, not even one another process creates at the same moment. Returns the
    path written.

    ``data`` (text, written as UTF-8, or bytes) goes to a temporary file first, or
    ``data(temporary_path)`` writes it there (e.g. a result's ``write_csv``). That file
    then takes the free name with a hard link, which fails if the name was taken
    meanwhile: the next name is tried. Where hard links are not supported, the name is
    taken with an exclusive create, then the file is renamed onto it."""
    path = Path(path)
    temporary = path.parent / f"{temp_prefix()}{os.urandom(4).hex()}.tmp"
    try:
        if callable(data):
            data(temporary)
        else:
            write_atomic(temporary, data)
        while True:
            candidate = first_free(path)
            try:
                os.link(temporary, candidate)
                return candidate
            except FileExistsError:
                continue  # taken between the look and the link: the next one
            except OSError:  # no hard links on this file system (FAT, some mounts)
                if _take_name(candidate):
                    os.replace(temporary, candidate)
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


# -- who owns a staging folder ---------------------------------------------------------
def _host() -> str:
    """This machine's name, reduced to letters, digits, dots and dashes (at most 64)."""
    return re.sub(r"[^A-Za-z0-9.-]", "_", socket.gethostname())[:64] or "host"


def _process_start(pid: int) -> int:
    """When process ``pid`` started, in clock ticks since boot (Linux), or 0 if unknown;
    with the process id it names one process, even after the id is reused."""
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


def _target_tag(target: Path) -> str:
    """A short digest of ``target``'s name, put in the name of the old folder replacing it."""
    return hashlib.sha256(os.fsencode(target.name)).hexdigest()[:8]


def _target_note(old: Path) -> Path:
    """The file beside the old folder ``old`` that holds the name of the output it replaces
    (bytes, as the file system has it). It is written before the first file moves and
    removed once the new output is complete: while it is there, the replace is unfinished."""
    return old.with_name(old.name + _NOTE_SUFFIX)


def _noted_target(old: Path) -> Path | None:
    """The output the old folder ``old`` was made to replace, from its note: a name in the
    same folder whose :func:`_target_tag` starts ``old``'s random part. None without a
    valid note."""
    match = _OWNED_NAME.match(old.name)
    note = _target_note(old)
    if match is None or not _is_regular(note):
        return None
    try:
        name = os.fsdecode(note.read_bytes())
    except OSError:
        return None
    if not name or "/" in name or "\0" in name or name in (".", ".."):
        return None
    target = old.parent / name
    return target if match["random"].startswith(_target_tag(target)) else None


def _drop_note(old: Path) -> None:
    with contextlib.suppress(OSError):
        _target_note(old).unlink(missing_ok=True)


def _remove_stale_notes(folder: Path) -> None:
    """Remove the notes (:func:`_target_note`) of ended runs whose old folder is gone."""
    for name in _names(folder):
        base = name.removesuffix(_NOTE_SUFFIX)
        if base != name and _dead_owner(base, "old") and not os.path.lexists(folder / base):
            _unlink_regular(folder / name)


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
    if os.name != "posix":
        return True  # os.kill(pid, 0) would end the process on Windows
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


def stale_folders(folder: Path) -> list[Path]:
    """Staging and old folders in ``folder`` left by runs on this host that have ended."""
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return []
    found = []
    for name in names:
        match = _OWNED_NAME.match(name)
        path = folder / name
        if match is None or match["kind"] == "tmp" or os.path.islink(path) or not path.is_dir():
            continue
        if _dead_owner(name, match["kind"]) is not None:
            found.append(path)
    return found


def remove_stale(folder: Path) -> list[Path]:
    """Remove :func:`stale_folders` of ``folder`` and say so in one line on stderr.

    First, every earlier output a killed run was replacing in ``folder`` (whichever its
    name) and left absent or with listed files missing is put back from that run's old
    folder (:func:`_restore_killed`), said in one line each. Then a staging folder, which
    holds only an unfinished run's files, goes whole. An old folder holds an earlier
    output being replaced: only the files its manifest lists (and the manifest) go, as the
    replace would have done; anything else in it is kept. An old folder whose output is
    still absent is never emptied. Returns the folders removed. Temporary files of ended
    runs (:func:`temp_prefix`) in ``folder`` go too."""
    _restore_killed(folder)
    removed, kept = [], []
    for path in stale_folders(folder):
        if path.name.startswith(STAGING_PREFIX):
            shutil.rmtree(path, ignore_errors=True)
        elif _output_missing(path):
            continue  # its output could not be put back: it is kept (_restore_killed)
        else:
            manifest = read_manifest(path)
            for name in [*(manifest["files"] if manifest else []), MANIFEST]:
                with contextlib.suppress(OSError):
                    _unlink_regular(path / name)
            _prune_empty(path)
        if os.path.lexists(path):
            kept.append(_set_aside(path))  # a user's files: kept, under a name never swept
        else:
            removed.append(path)
    _remove_stale_notes(folder)
    if removed or kept:
        count = len(removed)
        line = f"note: removed {count} folder{'s' * (count != 1)} left in {folder} by runs "
        line += f"that were killed{_listed(removed)}"
        if kept:
            line += f"; kept files no manifest lists in {_listed(kept).strip(' ()')}"
        _say(line)
    remove_stale_temp(folder)
    return removed


def _is_stale_temp(name: str) -> bool:
    """Whether ``name`` is a temporary file's name (:func:`temp_prefix`) of an ended run."""
    return name.endswith(".tmp") and _dead_owner(name, "tmp") is not None


def remove_stale_temp(folder: Path, recursive: bool = False) -> list[Path]:
    """Remove the temporary files ended runs left in ``folder`` (and, ``recursive``, below
    it) and say so in one line on stderr; returns them. Only regular files whose names
    carry the owner of a run of this host that has ended are touched."""
    removed = []
    for root, _, files in os.walk(folder) if recursive else [(folder, [], _names(folder))]:
        for name in files:
            path = Path(root) / name
            if _is_stale_temp(name) and _is_regular(path):
                with contextlib.suppress(OSError):
                    path.unlink()
                    removed.append(path)
    if removed:
        count = len(removed)
        _say(
            f"note: removed {count} temporary file{'s' * (count != 1)} left in {folder} "
            f"by runs that were killed{_listed(removed)}"
        )
    return removed


def _names(folder: Path) -> list[str]:
    try:
        return os.listdir(folder)
    except OSError:
        return []


def _restore_killed(folder: Path) -> None:
    """Put back the earlier outputs killed runs were replacing in ``folder``: each old
    folder of an ended run names its output in its note (:func:`_noted_target`). An
    output that is absent (killed between the two renames of :func:`_swap`) gets back
    the newest such old folder holding every file its manifest lists; one whose manifest
    lists files it lacks (killed during :func:`_merge`) gets back the earlier files from
    the newest old folder that, with the output, still holds them all. An absent output
    with no such old folder keeps its old folders, set aside (:func:`_set_aside`). Says
    what it did in one line each."""
    olds: dict[Path, list[Path]] = {}
    for old in stale_folders(folder):
        target = _noted_target(old)
        if target is not None and read_manifest(old) is not None:
            olds.setdefault(target, []).append(old)
    for target, found in sorted(olds.items()):
        _put_back(target, sorted(found, key=_note_age))


def _put_back(target: Path, olds: list[Path]) -> None:
    """Put back ``target``'s earlier output from the first usable of ``olds`` (old folders
    of ended runs made for it, newest first); see :func:`_restore_killed`."""
    for old in olds:
        try:
            restored = _restore_from(old, target)
        except OSError:
            continue  # left as it is: remove_stale keeps what no manifest lists
        if restored:
            _drop_note(old)
            _say(f"note: put back the earlier output of {target} that a killed run was replacing")
            return
    if os.path.lexists(target):
        return
    for old in olds:  # nothing whole to put back: keep every part of it
        aside = _set_aside(old)
        if aside != old:
            _drop_note(old)
            _say(f"warning: kept the incomplete earlier output of {target} in {aside}")


def _restore_from(old: Path, target: Path) -> bool:
    """Put ``target``'s earlier output back from ``old`` if ``target`` needs it and ``old``
    (with ``target``) holds every file of it; whether it did."""
    manifest = read_manifest(old)
    if manifest is None:
        return False
    files = manifest["files"]
    if not os.path.lexists(target):
        if not all(_is_regular(old / name) for name in files):
            return False
        os.rename(old, target)  # the whole earlier folder, as _swap moved it
        return True
    if os.path.islink(target) or not target.is_dir() or not _incomplete(target):
        return False
    if not all(_is_regular(old / name) or _is_regular(target / name) for name in files):
        return False
    _merge_back(old, target, manifest)
    return True


def _note_age(old: Path) -> tuple[int, str]:
    """Sort key of old folders, newest first: when their notes were written."""
    try:
        return (-os.lstat(_target_note(old)).st_mtime_ns, old.name)
    except OSError:
        return (0, old.name)


def _output_missing(old: Path) -> bool:
    """Whether ``old`` is an old folder holding an earlier output (a manifest) whose
    folder (:func:`_noted_target`) is absent."""
    target = _noted_target(old)
    missing = target is not None and not os.path.lexists(target)
    return missing and read_manifest(old) is not None


def _incomplete(folder: Path) -> bool:
    """Whether ``folder``'s manifest is missing or lists a file ``folder`` lacks."""
    manifest = read_manifest(folder)
    return manifest is None or not all(_is_regular(folder / f) for f in manifest["files"])


def _merge_back(old: Path, target: Path, manifest: dict) -> None:
    """Undo a :func:`_merge` killed midway: remove the new files it had moved into
    ``target`` (listed by ``target``'s manifest, not by the earlier ``manifest``), move
    the earlier files back from ``old``, then the earlier manifest."""
    current = read_manifest(target)
    earlier = set(manifest["files"])
    for name in sorted(set(current["files"] if current else []) - earlier):
        _unlink_regular(target / name)
        _prune_up((target / name).parent, target)
    for name in sorted(earlier):
        if _is_regular(old / name):
            _move(old / name, target / name, [], [])
    os.replace(old / MANIFEST, target / MANIFEST)
    _prune_empty(old)


def _set_aside(path: Path) -> Path:
    """Rename ``path`` (an old folder holding files no manifest lists) to a free
    ``.ddwmmr-kept-*`` name, which carries no owner; returns where it went (``path`` if
    the rename failed)."""
    with contextlib.suppress(OSError):
        aside = Path(tempfile.mkdtemp(prefix=KEPT_PREFIX, dir=path.parent))
        aside.rmdir()
        os.rename(path, aside)
        return aside
    return path


def _listed(paths: list[Path]) -> str:
    """`` (a, b, ...)``: the first two names of ``paths``, or nothing."""
    if not paths:
        return ""
    return " (" + ", ".join(p.name for p in paths[:2]) + (", ...)" if len(paths) > 2 else ")")


def _say(line: str) -> None:
    with contextlib.suppress(OSError):
        print(line, file=sys.stderr)


# -- the staging folder -------------------------------------------------------------------
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


class OutputFolder:
    """What :func:`output_folder` returns: a context manager whose ``with`` block gets the
    staging folder, and whose :attr:`path` is where the files went once it has run."""

    def __init__(self, target: str | Path, tool: str, force: bool, fresh: bool) -> None:
        self._text = str(target)
        self.tool, self.force, self.fresh = tool, force, fresh
        #: Absolute path of the output folder (after a ``fresh`` commit, the numbered
        #: sibling the files went to if the target had appeared meanwhile).
        #: The name a ``fresh`` commit numbers from (``target``, ``target-2``...): always
        #: the unnumbered default, so runs racing for it never make ``target-2-2``.
        self._base = Path(target)
        if fresh:  # a default name: only where it goes must be writable, nothing replaced
            self.path = check_output_path(first_free(target, folder=True))
        else:
            self.path = check_output_folder(target, tool, force)
        self._staging: Path | None = None
        self._created: list[Path] = []
        self._entered = False

    def __enter__(self) -> Path:
        if self._entered:
            raise RuntimeError("an OutputFolder is used for one with-block only")
        self._entered = True
        remove_stale(self.path.parent)
        prefix = f"{STAGING_PREFIX}{owner_token()}-"
        for attempt in range(2):
            self._created = _make_parents(self.path.parent)
            try:
                staging = Path(tempfile.mkdtemp(prefix=prefix, dir=self.path.parent))
                break
            except FileNotFoundError:
                # another run removed the empty parent it had made: make it again, once
                if attempt == 1:
                    raise ParameterError(
                        f"out: cannot write in {self.path.parent} (it keeps disappearing)"
                    ) from None
            except OSError as exc:
                remove_created(self._created)
                raise ParameterError(
                    f"out: cannot write in {self.path.parent} ({exc.strerror})"
                ) from None
        self._staging = staging
        try:
            os.chmod(staging, folder_mode())
        except BaseException:
            self._discard()
            raise
        return staging

    def __exit__(self, exc_type, exc, traceback) -> bool:
        if exc_type is not None:
            self._discard()
            return False  # the block's exception goes on
        done: list[Path] = []
        try:
            with _signals_deferred():
                target = self._base if self.fresh else self.path
                _commit(self._staging, target, self.tool, self.force, self._text, done, self.fresh)
        except BaseException as error:
            if done:  # the new output is in place: it stays, and the exception says so
                self.path, self._staging = done[0], None
                setattr(error, _COMMITTED, done[0])
                raise
            self._discard()
            if isinstance(error, OSError) and not isinstance(error, ParameterError):
                raise OSError(
                    error.errno,
                    f"out: cannot move the results into {self._text} ({error.strerror})",
                ) from error
            raise
        self.path = done[0]
        return False

    def _discard(self) -> None:
        if self._staging is not None:
            shutil.rmtree(self._staging, ignore_errors=True)
            self._staging = None
        remove_created(self._created)


def output_folder(
    target: str | Path, tool: str, force: bool = False, fresh: bool = False
) -> OutputFolder:
    """A context manager yielding a staging folder whose files replace or join ``target``
    if the block succeeds.

    On success a manifest listing every staged file is added and the files are moved into
    ``target`` (see the module docstring for when an existing folder may be replaced). On
    any exception (Ctrl-C and SIGTERM included) the staging folder, and any parent folder
    created for it, is removed and nothing else is touched. ``fresh`` (a default,
    time-stamped name the user did not choose): an existing folder is never replaced, not
    even an earlier run of the same tool; if ``target`` appeared during the run, the files
    go to the first free ``target-2``, ``target-3``... (the returned object's ``path``).
    """
    return OutputFolder(target, tool, force, fresh)


def committed_output(error: BaseException) -> Path | None:
    """The output folder an interrupt arrived too late to stop: the run's new output was
    already complete in it (the stop came while the replaced one was being deleted).
    None for any other exception."""
    return getattr(error, _COMMITTED, None)


@contextlib.contextmanager
def _signals_deferred() -> Iterator[None]:
    """Hold the stop signals (:data:`_DEFERRED_SIGNALS`) whose handlers are Python code
    (the tools' :func:`ddwmmr.cli.common.interruptible`, Python's Ctrl-C) while the block
    moves files: an output is never left half moved by a signal. Afterwards every handler
    is put back, even if a signal cut the setup short, and each different signal that came
    is raised again, in the order they came (:func:`signal.raise_signal`), so its handler
    runs as it would have, after those of the earlier ones; a handler that raises does not
    keep the later ones from coming. Outside the main thread (where handlers cannot be
    set) nothing is held."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    swapped: list[tuple[int, Callable[..., object]]] = []
    try:
        for number in _DEFERRED_SIGNALS:
            handler = signal.getsignal(number)
            if callable(handler):
                swapped.append((number, handler))  # first: a swap cut short is undone too
                signal.signal(number, lambda signum, frame: held.append(signum))
        yield
    finally:
        try:
            _run_all([functools.partial(signal.signal, n, h) for n, h in swapped])
        finally:
            _run_all([functools.partial(signal.raise_signal, n) for n in dict.fromkeys(held)])


def _run_all(calls: Sequence[Callable[[], object]]) -> None:
    """Make every call of ``calls`` in order, even the ones after a call that raises (that
    exception goes on once the later calls are made)."""
    if calls:
        try:
            calls[0]()
        finally:
            _run_all(calls[1:])


def _make_parents(folder: Path) -> list[Path]:
    """Create missing parent folders; return those this call made (deepest last) so a
    failure can undo them. A folder another run makes meanwhile is used, not recorded."""
    made: list[Path] = []
    for candidate in missing_folders(folder):
        try:
            candidate.mkdir(mode=folder_mode())
        except FileExistsError:
            if candidate.is_dir():
                continue  # made by another run at the same moment: theirs, use it
            remove_created(made)
            raise ParameterError(f"out: {candidate} exists and is not a folder") from None
        except OSError as exc:
            remove_created(made)
            raise ParameterError(f"out: cannot create {candidate} ({exc.strerror})") from None
        made.append(candidate)
    return made


def remove_created(created: list[Path]) -> None:
    """Remove the folders :func:`missing_folders` listed (outermost first) where they are
    empty again, innermost first."""
    for folder in reversed(created):
        with contextlib.suppress(OSError):
            folder.rmdir()


def _commit(
    staging: Path,
    target: Path,
    tool: str,
    force: bool,
    text: str,
    done: list[Path],
    fresh: bool = False,
) -> None:
    """Move the staged files into ``target`` (or, ``fresh``, a free sibling). The folder
    they went to is appended to ``done`` as soon as the new output is complete there,
    before the replaced one is deleted: an exception after that finds it in ``done``."""
    files = _entries(staging)
    manifest = {"tool": tool, "version": package_version(), "files": files}
    _write_manifest(staging, manifest)
    if fresh:
        _commit_fresh(staging, target, done)
        return
    if not os.path.lexists(target):
        os.rename(staging, target)
        done.append(target)
        return
    if os.path.islink(target) or not target.is_dir():
        raise ParameterError(f"out: {text} changed during the run and is not a folder any more")
    remove_stale_temp(target, recursive=True)
    existing = inspect(target, tool)
    if existing.kind in ("empty", "own"):
        _swap(staging, target, existing, done)
    elif force:
        _merge(staging, target, files, existing, text, done)
    else:
        raise ParameterError(_refusal(text, tool, existing))


def _commit_fresh(staging: Path, target: Path, done: list[Path]) -> None:
    """Rename ``staging`` to the first of ``target``, ``target-2``... that nobody holds:
    each candidate is taken with an exclusive ``mkdir`` (so two runs finishing together
    cannot take the same one), then the staging folder replaces that empty folder; see
    :func:`_commit` for ``done``."""
    while True:
        candidate = first_free(target, folder=True)
        try:
            os.mkdir(candidate, folder_mode())
        except FileExistsError:
            continue  # taken between the look and the mkdir: the next one
        except BaseException:  # Ctrl-C just after the mkdir: do not leave it behind
            with contextlib.suppress(OSError):
                candidate.rmdir()
            raise
        try:
            os.rename(staging, candidate)  # onto our own empty folder
        except BaseException:
            if not os.path.lexists(staging):  # the rename was made: the output is there
                done.append(candidate)
                raise
            with contextlib.suppress(OSError):
                candidate.rmdir()
            raise
        done.append(candidate)
        return


def list_in_manifest(folder: str | Path, tool: str, names: Sequence[str]) -> None:
    """Add ``names`` (relative, posix) to the manifest of ``folder``, a folder of ``tool``
    (made here if absent; an empty folder gets a new manifest). Refuses (one-line
    :class:`ParameterError`) a folder that is not this tool's own."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True, mode=folder_mode())
    remove_stale_temp(folder, recursive=True)  # a killed write of an earlier run
    existing = inspect(folder, tool)
    fresh = [n for n in names if n not in existing.listed]
    other_tool = existing.tool is not None and existing.tool != tool
    parents = {str(PurePosixPath(n).parent) + "/" for n in fresh}
    strangers = set(existing.foreign) - set(fresh) - parents
    if other_tool or (existing.kind == "foreign" and strangers):
        raise ParameterError(_refusal(str(folder), tool, existing))
    if not all(_safe_relative(n) for n in names):
        raise ParameterError(f"out: unsafe file names for {folder}: {list(names)}")
    files = sorted({*existing.listed, *names})
    manifest = {"tool": tool, "version": package_version(), "files": files}
    write_atomic(folder / MANIFEST, json.dumps(manifest, indent=2) + "\n")


def _write_manifest(folder: Path, manifest: dict) -> None:
    path = folder / MANIFEST
    path.write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
    os.chmod(path, file_mode())


def _old_folder(target: Path) -> Path:
    """A new old folder for the output ``target`` replaces, owned by this process and
    tagged with ``target``'s name, and its note naming ``target`` (:func:`_target_note`):
    any later run writing beside it puts the output back after a kill
    (:func:`_restore_killed`)."""
    prefix = f"{_OLD_PREFIX}{owner_token()}-{_target_tag(target)}"
    old = Path(tempfile.mkdtemp(prefix=prefix, dir=target.parent))
    try:
        _write_note(_target_note(old), os.fsencode(target.name))
    except BaseException:
        with contextlib.suppress(OSError):
            old.rmdir()
        _drop_note(old)  # an interrupt just after its rename
        raise
    return old


def _write_note(note: Path, data: bytes) -> None:
    """Create ``note`` (a new name: exclusively) holding ``data``. No rename: the commit's
    renames are all moves of output files. A note cut short by a kill is refused by
    :func:`_noted_target` (its name does not match the old folder's tag), and nothing had
    moved yet then."""
    fd = os.open(note, os.O_CREAT | os.O_EXCL | os.O_WRONLY, file_mode())
    with os.fdopen(fd, "wb") as handle:
        handle.write(data)


def _replaced(old: Path, target: Path, listed: list[str], done: list[Path]) -> None:
    """The new output is complete in ``target``: record it in ``done``, drop ``old``'s note
    (the replace is over) and delete the replaced output in ``old``."""
    done.append(target)
    _drop_note(old)
    _discard_old(old, target, listed)


def _swap(staging: Path, target: Path, existing: Existing, done: list[Path]) -> None:
    """Replace ``target`` (empty, or only this tool's listed files) by ``staging``; see
    :func:`_commit` for ``done``.

    Each rename is recorded before it is made (:func:`_move`), so an exception arriving
    just after one is undone too: ``target`` is the old folder again, or, once the
    staging folder is in its place, the new one (the old one is then deleted)."""
    old = _old_folder(target)
    moves: list[tuple[Path, Path]] = []
    try:
        old.rmdir()  # only its name was wanted
        _move(target, old, moves, [])
        _move(staging, target, moves, [])
    except BaseException:
        if len(moves) == 2 and not os.path.lexists(staging):  # the new one is in place
            _replaced(old, target, existing.listed, done)
        else:
            _undo(moves, [])  # put the old folder back before reporting the error
            with contextlib.suppress(OSError):
                old.rmdir()  # still there if the interrupt came before the first rename
            _drop_note(old)
        raise
    _replaced(old, target, existing.listed, done)


def _merge(
    staging: Path, target: Path, files: list[str], existing: Existing, text: str, done: list[Path]
) -> None:
    """``--force``: replace the listed files of ``target`` by the staged ``files``, keeping
    every file no manifest lists; see :func:`_commit` for ``done``.

    The old listed files go first into an old folder (with a copy of their manifest, so a
    run killed outright is cleaned up as :func:`remove_stale` cleans after :func:`_swap`),
    then the new manifest and the new files move in; the output is the new one once the
    last file is in. An exception before that (Ctrl-C, SIGTERM, a full disk) moves
    everything back, so ``target`` holds the old output again with its own manifest."""
    listed = set(existing.listed)
    clashes = [f for f in files if os.path.lexists(target / f) and f not in listed]
    if MANIFEST in existing.foreign:  # an unreadable manifest is not ours to overwrite
        clashes.append(MANIFEST)
    if clashes:
        raise ParameterError(_clash(text, clashes[0]))
    old = _old_folder(target)
    had_manifest = os.path.lexists(target / MANIFEST)
    moves: list[tuple[Path, Path]] = []
    made: list[Path] = []
    try:
        if had_manifest:
            shutil.copyfile(target / MANIFEST, old / MANIFEST)
        for name in existing.listed:
            _move(target / name, old / name, moves, [])
        _move(staging / MANIFEST, target / MANIFEST, moves, made)
        for name in files:
            _move(staging / name, target / name, moves, made)
    except BaseException:
        _undo(moves, made)
        if had_manifest and not os.path.lexists(target / MANIFEST):
            os.replace(old / MANIFEST, target / MANIFEST)
        shutil.rmtree(old, ignore_errors=True)
        _drop_note(old)
        raise
    _replaced(old, target, existing.listed, done)
    shutil.rmtree(staging, ignore_errors=True)
    for name in existing.listed:  # folders the old output alone had
        _prune_up((target / name).parent, target)


def _move(source: Path, destination: Path, moves: list, made: list[Path]) -> None:
    """Rename ``source`` to ``destination``, its missing parent folders made (and added to
    ``made``). The move is added to ``moves`` before it is done, so that an interrupt
    arriving just after the rename is undone too (:func:`_undo` checks what happened)."""
    for folder in missing_folders(destination.parent):
        made.append(folder)
        folder.mkdir(mode=folder_mode())
    moves.append((source, destination))
    os.replace(source, destination)


def _undo(moves: list[tuple[Path, Path]], made: list[Path]) -> None:
    """Reverse the renames :func:`_move` recorded that did happen, last first, then remove
    the folders it made (where empty again)."""
    for source, destination in reversed(moves):
        if os.path.lexists(destination) and not os.path.lexists(source):
            os.replace(destination, source)
    remove_created(made)


def _discard_old(old: Path, target: Path, listed: list[str]) -> None:
    """Delete the replaced output in ``old`` (its listed files and manifest); anything else
    found there is kept, set aside under a name no run sweeps, and said."""
    for name in [*listed, MANIFEST]:
        _unlink_regular(old / name)
    _prune_empty(old)
    if old.exists():  # something appeared meanwhile: keep it, say where
        _say(f"warning: kept unexpected files of the old {target} in {_set_aside(old)}")


def _prune_up(folder: Path, top: Path) -> None:
    """Remove ``folder`` and its parents below ``top`` while they are empty."""
    while folder != top and top in folder.parents:
        try:
            folder.rmdir()
        except OSError:
            return
        folder = folder.parent


def _unlink_regular(path: Path) -> None:
    if _is_regular(path):
        path.unlink()


def _prune_empty(folder: Path) -> None:
    """Remove ``folder`` and its sub-folders bottom-up where they are empty."""
    for root, _, _ in sorted(os.walk(folder), key=lambda w: -len(w[0])):
        with contextlib.suppress(OSError):
            os.rmdir(root)
