"""The staging folder of a run (:func:`output_folder`, :class:`OutputFolder`) and its
commit: the staged files replace or join ``--out`` with the stop signals held
(:func:`_signals_deferred`), and an interrupt that came once the new output was in place
says so (:func:`committed_output`). Also the manifest of a folder a tool writes in place
(:func:`list_in_manifest`).
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path, PurePosixPath
from typing import TYPE_CHECKING, Any

from ddwmmr.errors import ParameterError
from ddwmmr.outputs.atomic import first_free, sync_folder, write_atomic
from ddwmmr.outputs.checks import (
    MANIFEST,
    Existing,
    _clash,
    _entries,
    _refusal,
    _safe_relative,
    check_output_folder,
    check_output_path,
    inspect,
    missing_folders,
)
from ddwmmr.outputs.files import file_mode, folder_mode, package_version
from ddwmmr.outputs.lock import output_lock
from ddwmmr.outputs.owners import _OLD_PREFIX, STAGING_PREFIX, owner_token
from ddwmmr.outputs.recovery import (
    _drop_note,
    _move,
    _prune_empty,
    _prune_up,
    _say,
    _set_aside,
    _target_note,
    _target_tag,
    _unlink_regular,
    remove_stale,
    remove_stale_temp,
)

if TYPE_CHECKING:
    from types import TracebackType

#: The signals whose Python handlers wait while a commit moves files (the tools' stop
#: signals: :mod:`ddwmmr.cli.signals`, which this low layer may not import; SIGBREAK is
#: Windows' Ctrl-Break).
_DEFERRED_SIGNALS = tuple(
    getattr(signal, name)
    for name in ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT", "SIGBREAK")
    if hasattr(signal, name)
)


#: Attribute set on an exception (an interrupt) that arrived once the new output was in
#: place: its value is the output folder, complete (see :func:`committed_output`).
_COMMITTED = "ddwmmr_committed_output"
#: The lists :func:`recording_commits` hands out, innermost last: each commit appends the
#: output folder it completed to every one.
_recorders: list[list[Path]] = []


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
        self._lock = contextlib.ExitStack()

    def __enter__(self) -> Path:
        if self._entered:
            raise RuntimeError("an OutputFolder is used for one with-block only")
        self._entered = True
        remove_stale(self.path.parent)
        staging = self._make_staging()  # and the missing parents, where the lock goes
        if not self.fresh:  # a fresh output never replaces one: nothing to lock out
            try:
                self._lock.enter_context(output_lock(self.path, self._text))
            except BaseException:
                self._discard()
                raise
        return staging

    def _make_staging(self) -> Path:
        """Create the staging folder (and any missing parent of ``--out``)."""
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

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> bool:
        try:
            return self._finish(exc_type)
        finally:
            self._lock.close()  # released however the commit ends

    def _finish(self, exc_type: type[BaseException] | None) -> bool:
        """Commit the staged files (no ``exc_type``) or discard them."""
        if exc_type is not None:
            self._discard()
            return False  # the block's exception goes on
        staging = self._staging
        if staging is None:  # only a with-block that was not entered reaches this
            raise RuntimeError("an OutputFolder commits only the with-block it entered")
        done: list[Path] = []
        try:
            with _signals_deferred():
                target = self._base if self.fresh else self.path
                _commit(staging, target, self.tool, self.force, self._text, done, self.fresh)
        except BaseException as error:
            if done:  # the new output is in place: it stays, and the exception says so
                self.path, self._staging = done[0], None
                _completed(done[0])
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
        _completed(self.path)  # before the sync: a stop during it finds the output in place
        _sync_output(self.path)
        return False

    def _discard(self) -> None:
        if self._staging is not None:
            shutil.rmtree(self._staging, ignore_errors=True)
            self._staging = None
        self._lock.close()  # first: the parents made for the output go only if empty
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
def recording_commits(committed: list[Path]) -> Iterator[list[Path]]:
    """Append to ``committed`` (and yield it) the output folder of every commit made in
    the block, as soon as its new output is complete in place: a stop that comes after
    a tool's commit, while it prints its summary or stops its workers, finds its output
    there (:func:`ddwmmr.cli.common.run_main` then says that output is complete)."""
    _recorders.append(committed)
    try:
        yield committed
    finally:
        # by identity: another block's list may be equal to this one
        _recorders[:] = [other for other in _recorders if other is not committed]


def _completed(folder: Path) -> None:
    """Tell every :func:`recording_commits` block that ``folder`` holds its new output."""
    for committed in _recorders:
        committed.append(folder)


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
    _sync_files(staging)
    if fresh:
        _commit_fresh(staging, target, done)
        return
    if not os.path.lexists(target):
        os.rename(staging, target)
        done.append(target)
        return
    if os.path.islink(target) or not target.is_dir():
        raise ParameterError(f"out: {text} changed during the run and is not a folder any more")
    _sweep(target)
    existing = inspect(target, tool)
    if existing.kind in ("empty", "own"):
        _swap(staging, target, existing, done)
    elif force:
        _merge(staging, target, files, existing, text, done)
    else:
        raise ParameterError(_refusal(text, tool, existing))


def _sweep(folder: Path) -> None:
    """Remove what ended runs left in the output ``folder`` itself, which :func:`inspect`
    does not count as the user's: the staging folders and locks of runs writing into it
    (:func:`remove_stale`, which also puts back an earlier output they were replacing),
    and temporary files at any depth."""
    remove_stale(folder)
    remove_stale_temp(folder, recursive=True)


def _commit_fresh(staging: Path, target: Path, done: list[Path]) -> None:
    """Rename ``staging`` to the first of ``target``, ``target-2``... that nobody holds:
    each candidate is taken with an exclusive ``mkdir`` (so two runs finishing together
    cannot take the same one), then the staging folder replaces that empty folder; see
    :func:`_commit` for ``done``. On Windows, whose rename never replaces anything (and so
    is exclusive itself), the staging folder is renamed to the candidate directly."""
    if os.name == "nt":
        _rename_to_free(staging, target, done)
        return
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


def _rename_to_free(staging: Path, target: Path, done: list[Path]) -> None:
    """Rename ``staging`` to the first free of ``target``, ``target-2``... where a rename
    refuses an existing destination (Windows): a candidate taken meanwhile fails the
    rename, and the next one is tried; see :func:`_commit` for ``done``."""
    while True:
        candidate = first_free(target, folder=True)
        try:
            os.rename(staging, candidate)
        except FileExistsError:
            continue  # taken between the look and the rename: the next one
        except BaseException:
            if not os.path.lexists(staging):  # the rename was made: the output is there
                done.append(candidate)
            raise
        done.append(candidate)
        return


def list_in_manifest(folder: str | Path, tool: str, names: Sequence[str]) -> None:
    """Add ``names`` (relative, posix) to the manifest of ``folder``, a folder of ``tool``
    (made here if absent; an empty folder gets a new manifest). Refuses (one-line
    :class:`ParameterError`) a folder that is not this tool's own."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True, mode=folder_mode())
    _sweep(folder)  # what runs killed while writing here left
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


def _sync_files(folder: Path) -> None:
    """Sync every regular file below ``folder`` to the disk (``fsync``): whatever wrote
    it (``savefig`` too), its bytes are on the disk before the commit's renames make it
    the output, so a power cut never leaves an empty file under an output name."""
    # Windows syncs only a file opened for writing (FlushFileBuffers needs write access);
    # POSIX syncs any, and read-only keeps a file the umask made read-only syncable.
    flags = os.O_RDWR if os.name == "nt" else os.O_RDONLY
    for root, _, files in os.walk(folder):
        for name in files:
            path = Path(root) / name
            if os.path.islink(path):
                continue
            fd = os.open(path, flags)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)


def _sync_output(folder: Path) -> None:
    """Sync the entries of the committed output ``folder``, of every folder below it and
    of its parent (:func:`sync_folder`): the renames that made it the output reach the
    disk."""
    for root, _, _ in os.walk(folder):
        sync_folder(root)
    sync_folder(folder.parent)


def _write_manifest(folder: Path, manifest: dict[str, Any]) -> None:
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
