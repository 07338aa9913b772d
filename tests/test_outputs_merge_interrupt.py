"""A Ctrl-C while ``--force`` merges a run into a folder holding a user's file: at every
rename, whether it arrives just before or just after it, the folder holds either the old
output or the new one, its manifest listing exactly the files there, and nothing is left
next to it."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from ddwmmr.outputs import MANIFEST, commit, output_folder

OLD = {"a.txt": "old a\n", "sub/b.txt": "old b\n", "gone.txt": "old gone\n"}
NEW = {"a.txt": "new a\n", "sub/c.txt": "new c\n", "fresh/deep/d.txt": "new d\n"}
USER = {"notes.txt": "mine\n"}


def _write(target: Path, files: dict[str, str], force: bool = False) -> None:
    with output_folder(target, "track", force=force) as staging:
        for name, text in files.items():
            (staging / name).parent.mkdir(parents=True, exist_ok=True)
            (staging / name).write_text(text)


def _state(target: Path) -> dict[str, str]:
    """Every file below ``target`` but the manifest, with its text."""
    return {
        p.relative_to(target).as_posix(): p.read_text()
        for p in sorted(target.rglob("*"))
        if p.is_file() and p.name != MANIFEST
    }


def _interrupt_at(monkeypatch, move: int, after: bool) -> list[int]:
    """Make rename number ``move`` (from 1) of the merge raise KeyboardInterrupt, before or
    ``after`` renaming; returns the count of renames seen, updated as they come."""
    seen = [0]
    real_merge, real_replace, real_rename = commit._merge, os.replace, os.rename

    def flaky(real):
        def rename(source, destination, *args, **kwargs):
            seen[0] += 1
            if seen[0] == move and not after:
                raise KeyboardInterrupt
            result = real(source, destination, *args, **kwargs)
            if seen[0] == move:
                raise KeyboardInterrupt
            return result

        return rename

    def merge(*args, **kwargs):
        monkeypatch.setattr(os, "replace", flaky(real_replace))
        monkeypatch.setattr(os, "rename", flaky(real_rename))
        try:
            return real_merge(*args, **kwargs)
        finally:
            monkeypatch.setattr(os, "replace", real_replace)
            monkeypatch.setattr(os, "rename", real_rename)

    monkeypatch.setattr(commit, "_merge", merge)
    return seen


@pytest.mark.parametrize("after", [False, True], ids=["before", "after"])
def test_an_interrupt_at_any_rename_leaves_the_old_output_or_the_new(tmp_path, monkeypatch, after):
    outcomes = []
    for move in range(1, 30):
        target = tmp_path / f"out{move}"
        _write(target, OLD)
        for name, text in USER.items():
            (target / name).write_text(text)
        seen = _interrupt_at(monkeypatch, move, after)
        try:
            _write(target, NEW, force=True)
            interrupted = False
        except KeyboardInterrupt:
            interrupted = True
        monkeypatch.undo()
        state = _state(target)
        expected = {**(OLD if state.get("a.txt") == OLD["a.txt"] else NEW), **USER}
        assert state == expected, f"rename {move} ({'after' if after else 'before'})"
        listed = json.loads((target / MANIFEST).read_text())["files"]
        assert sorted(listed) == sorted(set(state) - set(USER))
        assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
        assert not (target / "fresh").exists() or state == {**NEW, **USER}
        outcomes.append("old" if state.get("gone.txt") else "new")
        if not interrupted:
            assert seen[0] < move and outcomes[-1] == "new"
            break
    # 3 old files out, the manifest and 3 new files in: 7 renames, each one interrupted
    assert len(outcomes) == 8
    assert outcomes[:7] == ["old"] * 7 and outcomes[7] == "new"
