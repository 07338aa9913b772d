"""Something other than a lock file at the name of an output folder's lock (a FIFO, a
folder, a link, a socket, a device) is refused in one line naming it, at once and untouched: the
lock was read as text, so a FIFO there hung the tool for ever, a link to /dev/zero filled
the memory, and a folder was taken for a killed run's lock and moved aside. The kind is
named as an output file's target names it (:func:`file_kind`). No test here touches /dev:
a device is a regular file a patched ``os.lstat`` calls one."""

import os
import signal
import socket
import stat
import sys
from pathlib import Path

import pytest

from ddwmmr.errors import ParameterError, file_kind
from ddwmmr.outputs.lock import lock_file, output_lock
from ddwmmr.outputs.owners import lock_holder, owner_token, read_lock

POSIX = pytest.mark.skipif(os.name == "nt", reason="FIFOs, sockets and links are POSIX's")


class Blocked(Exception):
    """A read that waited (not an OSError, which the lock's reader may catch)."""


@pytest.fixture
def deadline():
    """Fail instead of hanging if a read blocks (a FIFO read as a file)."""

    def expired(signum, frame):
        signal.alarm(1)  # again, should the first be caught
        raise Blocked("reading the lock blocked")

    previous = signal.signal(signal.SIGALRM, expired)
    signal.alarm(10)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def _refused(target: Path) -> str:
    with pytest.raises(ParameterError) as info, output_lock(target, str(target)):
        pass  # pragma: no cover - the lock is refused
    text = str(info.value)
    assert "\n" not in text
    return text


@POSIX
def test_a_fifo_at_the_lock_is_refused_without_waiting(tmp_path, deadline):
    target = tmp_path / "out"
    os.mkfifo(lock_file(target))
    text = _refused(target)
    assert text == (
        f"out: {lock_file(target)}, the name of the output folder's lock, is a FIFO, not a "
        "lock file a ddwmmr run wrote; remove it or choose another --out"
    )


def test_a_folder_at_the_lock_is_refused_and_left_in_place(tmp_path):
    target = tmp_path / "out"
    folder = lock_file(target)
    folder.mkdir()
    (folder / "mine.txt").write_text("keep")
    assert "is a folder, not a lock file" in _refused(target)
    assert (folder / "mine.txt").read_text() == "keep"  # was renamed to a .tmp name
    assert sorted(p.name for p in tmp_path.iterdir()) == [folder.name]


@POSIX
@pytest.mark.parametrize("to", ["file", "/nowhere"])  # not /dev/zero: read, it filled memory
def test_a_link_at_the_lock_is_refused(tmp_path, to):
    target = tmp_path / "out"
    if to == "file":
        to = tmp_path / "token"
        to.write_text(f"{owner_token().rsplit('-', 2)[0]}-0-0")  # a dead run's token
    lock_file(target).symlink_to(to)
    assert "is a symbolic link, not a lock file" in _refused(target)
    assert lock_file(target).is_symlink()


@pytest.mark.skipif(not hasattr(socket, "AF_UNIX") or sys.platform == "win32", reason="POSIX")
def test_a_socket_at_the_lock_is_refused(tmp_path):
    target = tmp_path / "out"
    server = socket.socket(socket.AF_UNIX)
    try:
        server.bind(str(lock_file(target)))
        assert "is a socket, not a lock file" in _refused(target)
    finally:
        server.close()


@pytest.mark.parametrize(
    ("kind", "name"), [(stat.S_IFCHR, "a character device"), (stat.S_IFBLK, "a block device")]
)
def test_a_device_at_the_lock_is_named_as_an_output_target_names_it(
    tmp_path, monkeypatch, kind, name
):
    target = tmp_path / "out"
    lock = lock_file(target)
    lock.write_text("")  # a regular file os.lstat says is a device: taken, not created
    real_lstat = os.lstat

    def fake_lstat(path, *args, **kwargs):
        if os.fspath(path) == str(lock):
            return os.stat_result((kind | 0o666, 0, 0, 1, 0, 0, 0, 0, 0, 0))
        return real_lstat(path, *args, **kwargs)

    monkeypatch.setattr(os, "lstat", fake_lstat)
    assert _refused(target) == (
        f"out: {lock}, the name of the output folder's lock, is {name}, not a lock file a "
        "ddwmmr run wrote; remove it or choose another --out"
    )


@pytest.mark.parametrize(
    ("mode", "name"),
    [
        (stat.S_IFREG | 0o644, None),
        (stat.S_IFDIR | 0o755, "a folder"),
        (stat.S_IFLNK | 0o777, "a symbolic link"),
        (stat.S_IFCHR | 0o666, "a character device"),
        (stat.S_IFBLK | 0o660, "a block device"),
        (stat.S_IFIFO | 0o644, "a FIFO"),
        (stat.S_IFSOCK | 0o755, "a socket"),
        (0o150000, "a special file"),  # a Solaris door: a type the list does not name
    ],
)
def test_file_kind_names_every_type_but_a_regular_file(mode, name):
    assert file_kind(mode) == name


def test_a_lock_is_read_at_most_4096_bytes(tmp_path):
    path = tmp_path / "lock"
    path.write_bytes(b"x" * 10_000 + b"\xff")
    assert read_lock(path) == "x" * 4096
    assert read_lock(tmp_path / "absent") is None
    assert lock_holder(tmp_path / "absent") is None


def test_a_regular_lock_still_locks_and_is_removed(tmp_path):
    target = tmp_path / "out"
    with output_lock(target, "out"):
        assert read_lock(lock_file(target)) == owner_token()
        busy = pytest.raises(ParameterError, match="is being written by another ddwmmr run")
        with busy, output_lock(target, "out"):
            pass  # pragma: no cover
    assert not lock_file(target).exists()


def test_an_unreadable_token_is_a_killed_runs_lock_taken_over(tmp_path):
    target = tmp_path / "out"
    lock_file(target).write_bytes(b"\xff\xfe garbage")
    with output_lock(target, "out"):
        assert read_lock(lock_file(target)) == owner_token()
    assert list(tmp_path.iterdir()) == []
