"""Output files reach the disk before their names do (fsync), the two single-file writers
take the same kind of writer, and a malformed trajectory digest in a run record is refused
as such."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path
from typing import BinaryIO

import pytest

from ddwmmr import outputs, provenance
from ddwmmr.cli.track import main as track
from ddwmmr.errors import ParameterError, shown
from ddwmmr.outputs import atomic, output_folder, owners
from ddwmmr.outputs.lock import lock_file
from ddwmmr.trajectories.files import package_folder

PAYLOAD = b"x,y\r\n1.0,2.0\r\n"


class _Journal:
    """Records, in order, each ``fsync`` (what the descriptor is, and its size then) and
    each ``os.replace``/``os.rename``/``os.link`` (source and destination names)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.events: list[tuple] = []
        real_fsync = os.fsync
        for name in ("replace", "rename", "link"):
            monkeypatch.setattr(os, name, self._wrap(name, getattr(os, name)))

        def fsync(fd: int) -> None:
            info = os.fstat(fd)
            kind = "folder" if stat.S_ISDIR(info.st_mode) else "file"
            self.events.append(("fsync", kind, info.st_ino, info.st_size))
            real_fsync(fd)

        monkeypatch.setattr(os, "fsync", fsync)

    def _wrap(self, name, real):
        def call(source, destination, *args, **kwargs):
            inode = os.lstat(source).st_ino
            real(source, destination, *args, **kwargs)
            self.events.append((name, inode, Path(destination)))

        return call

    def index(self, *prefix) -> int:
        return next(i for i, e in enumerate(self.events) if e[: len(prefix)] == prefix)


def test_write_atomic_syncs_the_data_before_the_rename_and_the_folder_after(tmp_path, monkeypatch):
    journal = _Journal(monkeypatch)
    path = tmp_path / "timeseries.csv"
    outputs.write_atomic(path, PAYLOAD)
    inode = path.stat().st_ino
    rename = journal.index("replace", inode)
    data = journal.index("fsync", "file", inode, len(PAYLOAD))  # all bytes in when synced
    folder = journal.index("fsync", "folder", tmp_path.stat().st_ino)
    assert data < rename < folder
    assert path.read_bytes() == PAYLOAD


def test_write_new_syncs_the_data_and_then_the_new_name(tmp_path, monkeypatch):
    (tmp_path / "a.csv").write_bytes(b"theirs")
    journal = _Journal(monkeypatch)
    written = outputs.write_new(tmp_path / "a.csv", PAYLOAD)
    assert written == tmp_path / "a-2.csv" and written.read_bytes() == PAYLOAD
    inode = written.stat().st_ino
    data = journal.index("fsync", "file", inode, len(PAYLOAD))
    link = journal.index("link", inode)
    assert data < link
    assert ("fsync", "folder", tmp_path.stat().st_ino) in [e[:3] for e in journal.events[link:]]


def test_a_committed_output_has_every_file_synced_before_it_moves_in(tmp_path, monkeypatch):
    target = tmp_path / "out"
    journal = _Journal(monkeypatch)
    with output_folder(target, "track") as staging:
        (staging / "figure.png").write_bytes(b"\x89PNG" * 10)  # as savefig writes: no fsync
        (staging / "sub").mkdir()
        (staging / "sub" / "b.csv").write_bytes(PAYLOAD)
    rename = journal.index("rename")
    synced = {e[2]: e[3] for e in journal.events[:rename] if e[:2] == ("fsync", "file")}
    for name, size in (("figure.png", 40), ("sub/b.csv", len(PAYLOAD))):
        assert synced[(target / name).stat().st_ino] == size, name
    manifest = (target / outputs.MANIFEST).stat()
    assert synced[manifest.st_ino] == manifest.st_size
    after = {e[2] for e in journal.events[rename:] if e[:2] == ("fsync", "folder")}
    assert {tmp_path.stat().st_ino, target.stat().st_ino} <= after


def test_folders_are_not_synced_on_windows(tmp_path, monkeypatch):
    opened: list[object] = []
    with monkeypatch.context() as patch:  # undone even if the call raises
        patch.setattr(os, "open", lambda *args, **kwargs: opened.append(args) or -1)
        patch.setattr(os, "name", "nt")
        atomic.sync_folder(tmp_path)
    assert opened == []


# -- one kind of writer for write_atomic and write_new -------------------------------------
def _stream(handle: BinaryIO) -> None:
    for start in range(0, len(PAYLOAD), 4):
        handle.write(PAYLOAD[start : start + 4])


def test_write_new_and_write_atomic_take_the_same_streaming_writer(tmp_path):
    outputs.write_atomic(tmp_path / "atomic.csv", _stream)
    written = outputs.write_new(tmp_path / "new.csv", _stream)
    assert written == tmp_path / "new.csv"
    assert written.read_bytes() == (tmp_path / "atomic.csv").read_bytes() == PAYLOAD
    assert sorted(p.name for p in tmp_path.iterdir()) == ["atomic.csv", "new.csv"]


# -- a malformed trajectory digest in a run record -------------------------------------------
@pytest.mark.parametrize("digest", [None, 7, "0" * 63, "g" * 64, "A" * 64])
def test_a_malformed_recorded_digest_is_refused_as_such(digest):
    shipped = package_folder() / "figure8.csv"  # there and unchanged: only the digest is bad
    record = {"name": "figure8", "file": str(shipped), "sha256": digest, "type": "samples"}
    with pytest.raises(ParameterError) as caught:
        provenance.read_trajectory_record(record)
    assert str(caught.value) == (
        f"trajectory.sha256 must be a string of 64 hex digits (0-9, a-f) (got {shown(digest)})"
    )


def test_rerun_of_a_record_with_a_null_digest_names_the_key(tmp_path, capsys):
    first = tmp_path / "first"
    args = ["--method", "ats", "--traj", "figure8", "--duration", "0.2", "--no-plots"]
    assert track([*args, "--no-progress", "--out", str(first)]) == 0
    summary = json.loads((first / "summary.json").read_text())
    assert summary["run"]["trajectory"]["type"] == "samples"
    summary["run"]["trajectory"]["sha256"] = None
    damaged = tmp_path / "damaged.json"
    damaged.write_text(json.dumps(summary))
    capsys.readouterr()
    assert track(["--rerun", str(damaged), "--out", str(tmp_path / "again")]) == 2
    assert capsys.readouterr().err == (
        f"error: rerun: {damaged}: trajectory.sha256 must be a string of 64 hex digits "
        "(0-9, a-f) (got None)\n"
    )
    assert not (tmp_path / "again").exists()


# -- two runs writing the same --out at once ---------------------------------------------------
def _staged(target: Path, who: str, force: bool = True):
    folder = output_folder(target, "track", force=force)
    staging = folder.__enter__()
    for name in ("path.png", "summary.json", "timeseries.csv"):
        (staging / name).write_text(f"{who}\n")
    return folder


def test_a_second_run_on_the_same_out_is_refused_while_the_first_writes(tmp_path):
    target = tmp_path / "out"
    target.mkdir()
    (target / "mine.txt").write_text("user\n")  # --force merges the runs' files in
    first = _staged(target, "A")
    with pytest.raises(ParameterError) as caught:
        _staged(target, "B")
    assert str(caught.value) == (
        f"out: {target} is being written by another ddwmmr run (pid {os.getpid()})"
    )
    first.__exit__(None, None, None)
    texts = {p.name: p.read_text() for p in target.iterdir() if p.name != outputs.MANIFEST}
    assert texts == {
        "mine.txt": "user\n",
        "path.png": "A\n",
        "summary.json": "A\n",
        "timeseries.csv": "A\n",
    }
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no lock, no staging left
    _staged(target, "B").__exit__(None, None, None)  # once the first is done: the next one
    assert (target / "path.png").read_text() == "B\n"


def _token(pid: int) -> str:
    return f"{owners._host()}-{pid}-{owners._process_start(pid)}"


def test_the_cli_refuses_an_out_a_live_run_writes_and_takes_over_a_dead_ones(tmp_path, capsys):
    out = tmp_path / "run"
    lock = lock_file(out)
    args = ["--method", "ats", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        lock.write_text(_token(live.pid))
        assert track([*args, "--no-progress", "--out", str(out)]) == 2
        assert capsys.readouterr().err == (
            f"error: out: {out} is being written by another ddwmmr run (pid {live.pid})\n"
        )
        assert not out.exists() and lock.read_text() == _token(live.pid)
    finally:
        live.kill()
        live.wait()
    lock.write_text(f"{owners._host()}-{live.pid}-1")  # that run was killed: its lock stays
    assert track([*args, "--no-progress", "--out", str(out)]) == 0
    assert (out / "summary.json").is_file() and not lock.exists()
