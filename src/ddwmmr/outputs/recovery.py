"""Cleaning up after runs that were killed outright (SIGKILL): their staging folders,
the old folders of the outputs they were replacing and their temporary files are removed
(:func:`remove_stale`, :func:`remove_stale_temp`), after every earlier output such a run
had moved aside is put back (:func:`_restore_killed`), from the note beside its old folder
(:func:`_target_note`). Also the moves and removals of files the commit shares
(:func:`_move`, :func:`_prune_empty`...).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import sys
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ddwmmr.outputs.checks import MANIFEST, _is_regular, _names, missing_folders, read_manifest
from ddwmmr.outputs.files import folder_mode
from ddwmmr.outputs.owners import (
    _OWNED_NAME,
    KEPT_PREFIX,
    LOCK_PREFIX,
    STAGING_PREFIX,
    _dead_owner,
    _is_stale_temp,
    dead_lock,
    lock_holder,
    temp_prefix,
)

if TYPE_CHECKING:
    from collections.abc import Iterable

#: Added to an old folder's name: the file naming the output that folder replaces.
_NOTE_SUFFIX = ".target"


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


def _remove_stale_locks(folder: Path) -> None:
    """Remove the output locks (:data:`LOCK_PREFIX`) in ``folder`` of runs that have ended
    (:func:`dead_lock`): a run killed outright cannot remove its own."""
    for name in _names(folder):
        path = folder / name
        if name.startswith(LOCK_PREFIX) and _is_regular(path):
            holder = lock_holder(path)
            if holder is not None and dead_lock(holder):
                drop_stale_lock(path, holder)


def drop_stale_lock(path: Path, holder: tuple[str, int, int]) -> None:
    """Remove the lock ``path`` of the ended run ``holder``, unless another run has taken
    it over meanwhile (that lock is put back). The lock is first renamed to a name of this run's
    own, so two runs taking over the same stale lock cannot remove each other's new one."""
    aside = path.with_name(f"{temp_prefix()}{os.urandom(4).hex()}.tmp")
    try:
        os.rename(path, aside)
    except FileNotFoundError:
        return  # another run removed it
    if lock_holder(aside) != holder:
        with contextlib.suppress(OSError):
            os.link(aside, path)  # a live run's lock, moved by mistake: put it back
    aside.unlink(missing_ok=True)


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
    _remove_stale_locks(folder)
    if removed or kept:
        count = len(removed)
        line = f"note: removed {count} folder{'s' * (count != 1)} left in {folder} by runs "
        line += f"that were killed{_listed(removed)}"
        if kept:
            line += f"; kept files no manifest lists in {_listed(kept).strip(' ()')}"
        _say(line)
    remove_stale_temp(folder)
    return removed


def remove_stale_temp(folder: Path, recursive: bool = False) -> list[Path]:
    """Remove the temporary files ended runs left in ``folder`` (and, ``recursive``, below
    it) and say so in one line on stderr; returns them. Only regular files whose names
    carry the owner of a run of this host that has ended are touched."""
    removed = []
    walk: Iterable[tuple[str | Path, list[str], list[str]]] = (
        os.walk(folder) if recursive else [(folder, [], _names(folder))]
    )
    for root, _, files in walk:
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


def _merge_back(old: Path, target: Path, manifest: dict[str, Any]) -> None:
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


def _move(
    source: Path, destination: Path, moves: list[tuple[Path, Path]], made: list[Path]
) -> None:
    """Rename ``source`` to ``destination``, its missing parent folders made (and added to
    ``made``). The move is added to ``moves`` before it is done, so that an interrupt
    arriving just after the rename is undone too (:func:`_undo` checks what happened)."""
    for folder in missing_folders(destination.parent):
        made.append(folder)
        folder.mkdir(mode=folder_mode())
    moves.append((source, destination))
    os.replace(source, destination)


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
