"""An output commit interrupted, failed or killed at any rename never loses an output.

The interrupts are injected at the N-th rename of the commit (``os.rename`` and
``os.replace`` counted together), before or after it is made; a kill is a child process
that ends itself with SIGKILL there.
"""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import BinaryIO

import pytest

from ddwmmr import outputs
from ddwmmr.outputs import MANIFEST, checks, commit, output_folder, owners, recovery
from ddwmmr.outputs.lock import lock_file


def _write_run(target: Path, text: str, force: bool = False, names=("a.csv",)) -> None:
    with output_folder(target, "track", force=force) as staging:
        for name in names:
            (staging / name).write_text(text)


def _leftovers(folder: Path) -> list[str]:
    return sorted(n for n in os.listdir(folder) if n.startswith(".ddwmmr-"))


def _renames_fail(monkeypatch, at: int, after: bool, error: BaseException) -> None:
    """Raise ``error`` at the ``at``-th call of os.rename/os.replace from now on."""
    calls = [0]

    def wrap(real):
        def call(*args, **kwargs):
            calls[0] += 1
            if calls[0] == at and not after:
                raise error
            result = real(*args, **kwargs)
            if calls[0] == at and after:
                raise error
            return result

        return call

    monkeypatch.setattr(os, "rename", wrap(os.rename))
    monkeypatch.setattr(os, "replace", wrap(os.replace))


@pytest.mark.parametrize("after", [False, True])
@pytest.mark.parametrize("at", [1, 2])
def test_an_interrupt_at_either_rename_of_a_replace_keeps_an_output(
    tmp_path, monkeypatch, at, after
):
    target = tmp_path / "out"
    _write_run(target, "old\n")
    folder = output_folder(target, "track")
    staging = folder.__enter__()
    (staging / "a.csv").write_text("new\n")
    _renames_fail(monkeypatch, at, after, KeyboardInterrupt())
    with pytest.raises(KeyboardInterrupt) as caught:
        folder.__exit__(None, None, None)
    monkeypatch.undo()
    committed = at == 2 and after  # the staging folder was already in place
    assert (target / "a.csv").read_text() == ("new\n" if committed else "old\n")
    assert json.loads((target / MANIFEST).read_text())["files"] == ["a.csv"]
    assert outputs.committed_output(caught.value) == (target if committed else None)
    assert _leftovers(tmp_path) == []


def test_a_signal_during_the_commit_waits_until_the_output_is_in(tmp_path, monkeypatch):
    target = tmp_path / "out"
    _write_run(target, "old\n")
    folder = output_folder(target, "track")
    staging = folder.__enter__()
    (staging / "a.csv").write_text("new\n")
    real = os.replace

    def signalled(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)  # Python's handler would raise at once
        return real(*args, **kwargs)

    monkeypatch.setattr(os, "replace", signalled)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt) as caught:
            folder.__exit__(None, None, None)
    finally:
        signal.signal(signal.SIGINT, previous)
    monkeypatch.undo()
    assert outputs.committed_output(caught.value) == target
    assert (target / "a.csv").read_text() == "new\n"
    assert _leftovers(tmp_path) == []


def test_an_interrupt_while_the_old_output_is_deleted_says_the_new_one_is_in(tmp_path, monkeypatch):
    target = tmp_path / "out"
    _write_run(target, "old\n")
    real = commit._discard_old

    def interrupted(*args):
        real(*args)
        raise KeyboardInterrupt

    monkeypatch.setattr(commit, "_discard_old", interrupted)
    with pytest.raises(KeyboardInterrupt) as caught:
        _write_run(target, "new\n")
    assert outputs.committed_output(caught.value) == target
    assert (target / "a.csv").read_text() == "new\n"


def _dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_temporary_files_carry_their_owner_and_dead_ones_are_swept(tmp_path, monkeypatch):
    names = []
    real = os.replace
    monkeypatch.setattr(os, "replace", lambda a, b: names.append(Path(a).name) or real(a, b))
    outputs.write_atomic(tmp_path / "x.txt", "x")
    monkeypatch.undo()
    match = owners._OWNED_NAME.match(names[0])
    assert match["kind"] == "tmp" and int(match["pid"]) == os.getpid()

    dead = f".ddwmmr-tmp-{owners._host()}-{_dead_pid()}-1-abcd1234.tmp"
    target = tmp_path / "bd"
    (target / "cache").mkdir(parents=True)
    (target / "cache" / "c.json").write_text("{}")
    (target / "cache" / dead).write_bytes(b"\0" * 1000)
    outputs.list_in_manifest(target, "bounds", ["cache/c.json"])
    assert not (target / "cache" / dead).exists()
    (target / "cache" / dead).write_bytes(b"\0")  # a resumed run finds one again
    assert outputs.inspect(target, "bounds").kind == "own"
    outputs.check_output_folder(target, "bounds")
    (tmp_path / dead).write_bytes(b"\0")
    assert outputs.remove_stale(tmp_path) == []
    assert not (tmp_path / dead).exists()


KILLER = textwrap.dedent(
    """
    import os, signal, sys
    from pathlib import Path
    from ddwmmr.outputs import output_folder
    target, force, at = Path(sys.argv[1]), sys.argv[2] == "1", int(sys.argv[3])
    calls = [0]
    def wrap(real):
        def call(*args, **kwargs):
            calls[0] += 1
            if calls[0] == at:
                os.kill(os.getpid(), signal.SIGKILL)
            return real(*args, **kwargs)
        return call
    with output_folder(target, "track", force=force) as staging:
        for name in ("a.csv", "b.csv"):
            (staging / name).write_text("new\\n")
        os.rename, os.replace = wrap(os.rename), wrap(os.replace)
    """
)


@pytest.mark.parametrize(("force", "at"), [(False, 2), (True, 2), (True, 3), (True, 4)])
def test_the_output_a_killed_run_was_replacing_is_put_back(tmp_path, capsys, force, at):
    target = tmp_path / "out"
    _write_run(target, "old\n")
    if force:
        (target / "mine.txt").write_text("mine\n")
    child = subprocess.run([sys.executable, "-c", KILLER, str(target), str(int(force)), str(at)])
    assert child.returncode == -signal.SIGKILL
    with output_folder(target, "track", force=force) as staging:
        assert (target / "a.csv").read_text() == "old\n"
        assert not (target / "b.csv").exists()
        assert json.loads((target / MANIFEST).read_text())["files"] == ["a.csv"]
        assert "put back the earlier output" in capsys.readouterr().err
        ours = (".ddwmmr-staging-" + outputs.owner_token(), lock_file(target).name)
        assert [n for n in _leftovers(tmp_path) if not n.startswith(ours)] == []
        (staging / "a.csv").write_text("newer\n")
    assert (target / "a.csv").read_text() == "newer\n"
    assert (target / "mine.txt").exists() == force


def test_a_failed_commit_names_the_output_not_the_staging_folder(tmp_path, monkeypatch):
    target = tmp_path / "out"
    error = PermissionError(errno.EPERM, "Operation not permitted", "staging")
    with pytest.raises(OSError) as caught, output_folder(target, "track") as staging:
        (staging / "a.csv").write_text("new\n")
        _renames_fail(monkeypatch, 1, False, error)
    monkeypatch.undo()
    assert caught.value.strerror == (
        f"out: cannot move the results into {target} (Operation not permitted)"
    )
    assert caught.value.filename is None
    assert _leftovers(tmp_path) == [] and not target.exists()


def test_write_new_never_replaces_a_file_made_meanwhile(tmp_path):
    wanted = tmp_path / "timeseries.csv"

    def racing_write(handle: BinaryIO) -> None:
        wanted.write_text("theirs\n")  # another app takes the name during our write
        handle.write(b"ours\n")

    written = outputs.write_new(wanted, racing_write)
    assert written == tmp_path / "timeseries-2.csv"
    assert wanted.read_text() == "theirs\n" and written.read_text() == "ours\n"
    assert _leftovers(tmp_path) == []


class _RacingResult:
    """A result whose CSV write sees another app take ``timeseries.csv`` meanwhile."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder

    def stream_csv(self, handle: BinaryIO) -> None:
        (self.folder / "timeseries.csv").write_text("theirs\n")
        handle.write(b"ours\n")

    def summary_text(self, **extra) -> str:
        return "{}\n"


def test_two_gui_exports_at_once_keep_each_others_files(tmp_path):
    from ddwmmr.gui import export

    first, second = export.run_folder(tmp_path, "run"), export.run_folder(tmp_path, "run")
    assert (first, second) == (tmp_path / "run", tmp_path / "run-2")
    assert first.is_dir() and second.is_dir()
    written = export.write_run_data(first, [_RacingResult(first)], ["A"])
    assert written == [first / "timeseries-2.csv", first / "summary.json"]
    assert (first / "timeseries.csv").read_text() == "theirs\n"
    assert (first / "timeseries-2.csv").read_text() == "ours\n"
    assert _leftovers(first) == []


@pytest.mark.parametrize("fresh", [False, True])
@pytest.mark.parametrize(("force", "at"), [(False, 2), (True, 2), (True, 3), (True, 4)])
def test_any_next_run_beside_it_puts_back_the_output_a_killed_run_was_replacing(
    tmp_path, capsys, force, at, fresh
):
    target = tmp_path / "mine"
    _write_run(target, "old\n")
    if force:
        (target / "mine.txt").write_text("mine\n")
    child = subprocess.run([sys.executable, "-c", KILLER, str(target), str(int(force)), str(at)])
    assert child.returncode == -signal.SIGKILL
    capsys.readouterr()
    # The next run writes another --out in the same folder (plain `track` into runs/).
    with output_folder(tmp_path / "other", "track", fresh=fresh) as staging:
        (staging / "a.csv").write_text("x\n")
    assert (target / "a.csv").read_text() == "old\n"
    assert not (target / "b.csv").exists()
    assert json.loads((target / MANIFEST).read_text())["files"] == ["a.csv"]
    assert (target / "mine.txt").exists() == force
    assert f"put back the earlier output of {target}" in capsys.readouterr().err
    assert _leftovers(tmp_path) == []


def _dead_old(
    parent: Path, target: str, files: dict[str, str], random: str, noted_at: int | None
) -> Path:
    """An old folder of an ended run made to replace ``parent/target``: its manifest lists
    ``files``, those whose text is not None are there; ``noted_at``: the time (ns) of its
    note naming ``target``, None for no note (a replace that had finished)."""
    tag = recovery._target_tag(parent / target)
    old = parent / f".ddwmmr-old-{owners._host()}-{_dead_pid()}-1-{tag}{random}"
    old.mkdir()
    for name, text in files.items():
        if text is not None:
            (old / name).write_text(text)
    manifest = {"tool": "track", "version": "0", "files": sorted(files)}
    (old / MANIFEST).write_text(json.dumps(manifest))
    if noted_at is not None:
        note = old.with_name(old.name + ".target")
        note.write_bytes(os.fsencode(target))
        os.utime(note, ns=(noted_at, noted_at))
    return old


def test_the_newest_complete_old_folder_is_put_back(tmp_path, capsys):
    # Sorted by name the older one, partly deleted, would come first.
    _dead_old(tmp_path, "mine", {"a.csv": "older\n", "b.csv": None}, "aaaa", 10**18)
    _dead_old(tmp_path, "mine", {"a.csv": "newer\n", "b.csv": "newer\n"}, "zzzz", 2 * 10**18)
    target = tmp_path / "mine"
    with output_folder(target, "track") as staging:
        assert checks._entries(target) == [MANIFEST, "a.csv", "b.csv"]
        assert (target / "a.csv").read_text() == "newer\n"
        assert (target / "b.csv").read_text() == "newer\n"
        (staging / "a.csv").write_text("x\n")
    assert _leftovers(tmp_path) == []


def test_an_incomplete_old_folder_of_an_absent_output_is_kept_not_deleted(tmp_path, capsys):
    _dead_old(tmp_path, "mine", {"a.csv": "old\n", "b.csv": None}, "aaaa", 10**18)
    with output_folder(tmp_path / "other", "track") as staging:
        (staging / "a.csv").write_text("x\n")
    assert not (tmp_path / "mine").exists()
    [kept] = _leftovers(tmp_path)
    assert kept.startswith(outputs.KEPT_PREFIX)
    assert (tmp_path / kept / "a.csv").read_text() == "old\n"
    assert f"kept the incomplete earlier output of {tmp_path / 'mine'}" in capsys.readouterr().err


def test_a_finished_replace_is_not_undone_in_an_output_merely_incomplete(tmp_path, capsys):
    target = tmp_path / "mine"
    _write_run(target, "new\n", names=("a.csv", "b.csv"))
    (target / "b.csv").unlink()  # the user deleted one file of the new output
    # Killed while deleting the replaced output: the replace had finished (no note).
    _dead_old(tmp_path, "mine", {"a.csv": "old\n", "b.csv": "old\n"}, "aaaa", None)
    with output_folder(target, "track") as staging:
        assert (target / "a.csv").read_text() == "new\n"
        assert not (target / "b.csv").exists()
        assert "put back" not in capsys.readouterr().err
        (staging / "a.csv").write_text("newer\n")
    assert _leftovers(tmp_path) == []


def _handlers(numbers):
    return {n: signal.getsignal(n) for n in numbers}


def test_a_signal_cutting_the_holding_short_leaves_every_handler_as_it_was(monkeypatch):
    class Stop(Exception):
        pass

    def stop(signum, frame):
        raise Stop

    numbers = (signal.SIGINT, signal.SIGTERM)
    saved = _handlers(numbers)
    real = signal.getsignal

    def getsignal(number):
        if number == signal.SIGTERM:  # SIGINT is held already
            os.kill(os.getpid(), signal.SIGTERM)
        return real(number)

    try:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, stop)
        monkeypatch.setattr(commit.signal, "getsignal", getsignal)
        with pytest.raises(Stop), commit._signals_deferred():
            pass
        monkeypatch.undo()
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        assert signal.getsignal(signal.SIGTERM) is stop
    finally:
        for number, handler in saved.items():
            signal.signal(number, handler)


@pytest.mark.parametrize("order", [("HUP", "TERM"), ("TERM", "HUP")])
def test_every_signal_held_during_a_commit_comes_in_the_order_it_came(order):
    numbers = {"HUP": signal.SIGHUP, "TERM": signal.SIGTERM}
    saved = _handlers(numbers.values())
    came: list[str] = []
    try:
        for name, number in numbers.items():
            signal.signal(number, lambda signum, frame, name=name: came.append(name))
        with commit._signals_deferred():
            for name in [*order, order[0]]:  # the first one twice: it runs once
                os.kill(os.getpid(), numbers[name])
            assert came == []
        assert came == list(order)
    finally:
        for number, handler in saved.items():
            signal.signal(number, handler)
