"""Windows and macOS behaviour, emulated on Linux (CI runs Linux only): what a platform
lacks or does differently is patched in (no ``os.fchmod``, a rename that never replaces,
an ``fsync`` that needs write access, ``os.name == "nt"``, ``sys.platform == "win32"``,
the ``spawn`` start method), and each test checks that ddwmmr still works there. Linux's
own behaviour is checked alongside where it must stay as it was."""

from __future__ import annotations

import ctypes
import errno
import fcntl
import importlib.util
import math
import os
import shlex
import shutil
import signal
import subprocess
import sys
import textwrap
import time
import types
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ddwmmr import provenance, workers
from ddwmmr.bench import mpc_floor
from ddwmmr.errors import ParameterError
from ddwmmr.outputs import atomic, commit, output_folder, owners
from ddwmmr.outputs.lock import lock_file, output_lock

ROOT = Path(__file__).resolve().parents[1]


def _os_like(**changes: Any) -> types.SimpleNamespace:
    """A stand-in for the ``os`` module of one ddwmmr module: the real one with
    ``changes`` (``name="nt"``...). Only that module sees them: pathlib, which picks its
    Windows or POSIX classes by ``os.name``, keeps working."""
    fake = types.SimpleNamespace(**vars(os))
    for key, value in changes.items():
        setattr(fake, key, value)
    return fake


def _fsync_needing_write(fd: int) -> None:
    """Windows' ``os.fsync``: ``FlushFileBuffers`` needs a handle opened for writing."""
    if fcntl.fcntl(fd, fcntl.F_GETFL) & os.O_ACCMODE == os.O_RDONLY:
        raise OSError(errno.EBADF, "Bad file descriptor")
    os.fsync(fd)


def _rename_never_replacing(source: str | Path, destination: str | Path) -> None:
    """Windows' ``os.rename``: an existing destination (an empty folder too) is refused."""
    if os.path.lexists(destination):
        raise FileExistsError(errno.EEXIST, "Cannot create a file when that file already exists")
    os.rename(source, destination)


# -- files without os.fchmod (Windows before Python 3.13) --------------------------------


def test_files_and_locks_are_written_without_fchmod(tmp_path, monkeypatch):
    monkeypatch.delattr(os, "fchmod")
    old_mask = os.umask(0o027)  # a mode the temporary file's 0600 does not have
    try:
        atomic.write_atomic(tmp_path / "a.json", "{}\n")
        written = atomic.write_new(tmp_path / "a.json", b"[]\n")
        with output_lock(tmp_path / "out", "out"):
            lock = lock_file(tmp_path / "out")
            assert lock.read_text(encoding="utf-8") == owners.owner_token()
            assert lock.stat().st_mode & 0o777 == 0o640
    finally:
        os.umask(old_mask)
    assert written == tmp_path / "a-2.json"
    assert (tmp_path / "a.json").read_text() == "{}\n" and written.read_bytes() == b"[]\n"
    for path in (tmp_path / "a.json", written):
        assert path.stat().st_mode & 0o777 == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-2.json", "a.json"]


# -- the commit: fsync of read-only files, renames that never replace ---------------------


def _staged_folder(root: Path) -> Path:
    folder = root / "staging"
    (folder / "sub").mkdir(parents=True)
    for name in ("a.csv", "sub/b.json"):
        (folder / name).write_text(name)
    return folder


def test_files_are_synced_where_fsync_needs_write_access(tmp_path, monkeypatch):
    synced: list[int] = []

    def fsync(fd: int) -> None:
        _fsync_needing_write(fd)
        synced.append(fd)

    monkeypatch.setattr(commit, "os", _os_like(name="nt", fsync=fsync))
    commit._sync_files(_staged_folder(tmp_path))
    assert len(synced) == 2


def test_linux_syncs_files_opened_read_only(tmp_path, monkeypatch):
    flags: list[int] = []

    def open_(path: Any, mode: int, *args: Any) -> int:
        flags.append(mode & os.O_ACCMODE)
        return os.open(path, mode, *args)

    monkeypatch.setattr(commit, "os", _os_like(open=open_))
    commit._sync_files(_staged_folder(tmp_path))
    assert flags == [os.O_RDONLY, os.O_RDONLY]  # a file the umask made read-only still syncs


def _windows_commit(monkeypatch, rename=_rename_never_replacing) -> None:
    fake = _os_like(name="nt", rename=rename, fsync=_fsync_needing_write)
    monkeypatch.setattr(commit, "os", fake)


def _fresh_run(target: Path, who: str) -> Path:
    folder = output_folder(target, "track", fresh=True)
    with folder as staging:
        (staging / "summary.json").write_text(who)
    return folder.path


def test_fresh_outputs_commit_where_a_rename_never_replaces(tmp_path, monkeypatch):
    _windows_commit(monkeypatch)
    target = tmp_path / "runs" / "track-20260101-000000"
    assert _fresh_run(target, "A") == target
    assert _fresh_run(target, "B") == target.with_name(f"{target.name}-2")
    assert (target / "summary.json").read_text() == "A"
    assert (target.with_name(f"{target.name}-2") / "summary.json").read_text() == "B"
    assert sorted(p.name for p in target.parent.iterdir()) == [target.name, f"{target.name}-2"]


def test_a_fresh_name_taken_just_before_the_rename_goes_to_the_next(tmp_path, monkeypatch):
    target = tmp_path / "track-20260101-000000"
    calls: list[Path] = []

    def rename(source: str | Path, destination: str | Path) -> None:
        if not calls:  # another run takes the name between the look and the rename
            Path(destination).mkdir()
        calls.append(Path(destination))
        _rename_never_replacing(source, destination)

    _windows_commit(monkeypatch, rename)
    assert _fresh_run(target, "A") == target.with_name(f"{target.name}-2")
    assert calls == [target, target.with_name(f"{target.name}-2")]
    assert list(target.iterdir()) == []  # the other run's folder is left alone


# -- whether the run holding a lock still runs (Windows) ---------------------------------


class FakeKernel32:
    """kernel32's process functions over ``processes``: pid -> (exit code, creation time);
    a pid absent from it has no process (``OpenProcess`` fails with ``last_error``)."""

    def __init__(self, processes: dict[int, tuple[int, int]], last_error: int = 87) -> None:
        self.processes, self.last_error = processes, last_error
        self.open: set[int] = set()

    def OpenProcess(self, access: int, inherit: bool, pid: int) -> int:
        assert access == 0x1000 and not inherit
        if pid not in self.processes:
            return 0
        self.open.add(pid)
        return pid

    def GetExitCodeProcess(self, handle: int, code: Any) -> int:
        code._obj.value = self.processes[handle][0]
        return 1

    def GetProcessTimes(self, handle: int, *times: Any) -> int:
        assert len(times) == 4 and all(isinstance(t._obj, ctypes.c_ulonglong) for t in times)
        times[0]._obj.value = self.processes[handle][1]
        return 1

    def CloseHandle(self, handle: int) -> int:
        self.open.remove(handle)
        return 1


STARTED = 133_000_000_000_000_000  # a creation time, 100 ns since 1601 (in 2022)


def _windows(monkeypatch, kernel32: FakeKernel32) -> None:
    monkeypatch.setattr(owners, "os", _os_like(name="nt"))
    monkeypatch.setattr(owners, "_kernel32", lambda: kernel32)
    monkeypatch.setattr(owners, "_last_error", lambda: kernel32.last_error)


def test_windows_tells_a_running_process_from_an_ended_or_reused_one(monkeypatch):
    kernel32 = FakeKernel32({10: (259, STARTED), 11: (0, STARTED), 12: (259, STARTED + 1)})
    _windows(monkeypatch, kernel32)
    assert owners._running(10, STARTED) and owners._running(10, 0)
    assert not owners._running(11, STARTED)  # exited, its handle still held somewhere
    assert not owners._running(12, STARTED)  # the id now names a later process
    assert not owners._running(13, STARTED)  # no such process
    assert owners._process_start(10) == STARTED and owners._process_start(13) == 0
    assert kernel32.open == set()  # every handle closed
    denied = FakeKernel32({}, last_error=5)  # another user's process: in doubt, running
    _windows(monkeypatch, denied)
    assert owners._running(10, STARTED)


def test_windows_takes_over_the_lock_of_a_killed_run(tmp_path, monkeypatch):
    _windows(monkeypatch, FakeKernel32({os.getpid(): (259, STARTED)}))
    target = tmp_path / "out"
    lock = lock_file(target)
    lock.write_text(f"{owners._host()}-999999-{STARTED}", encoding="utf-8")
    with output_lock(target, "out"):
        assert lock.read_text(encoding="utf-8") == f"{owners._host()}-{os.getpid()}-{STARTED}"
    assert not lock.exists()


def test_a_lock_of_another_host_is_refused_naming_the_file_to_delete(tmp_path):
    target = tmp_path / "out"
    lock = lock_file(target)
    lock.write_text("Foo.local-4242-123", encoding="utf-8")
    with pytest.raises(ParameterError) as caught, output_lock(target, "runs/out"):
        pass
    assert str(caught.value) == (
        "out: runs/out is being written by another ddwmmr run (pid 4242 on Foo.local); "
        f"if that run has ended, delete {lock}"
    )
    assert lock.read_text(encoding="utf-8") == "Foo.local-4242-123"


def test_ctrl_break_stops_the_tools_where_the_platform_has_it():
    linux = (signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT)
    from ddwmmr.cli.signals import STOP_SIGNALS
    from ddwmmr.scenarios.executors import _TERMINAL_SIGNALS

    assert linux == STOP_SIGNALS
    assert (signal.SIGINT, *linux) == commit._DEFERRED_SIGNALS
    assert _TERMINAL_SIGNALS == (signal.SIGINT, signal.SIGHUP, signal.SIGQUIT)
    code = textwrap.dedent(
        """
        import signal
        signal.SIGBREAK = 21  # Windows' number for Ctrl-Break
        from ddwmmr.cli.signals import STOP_SIGNALS
        from ddwmmr.outputs.commit import _DEFERRED_SIGNALS
        from ddwmmr.scenarios.executors import _TERMINAL_SIGNALS
        print(STOP_SIGNALS[-1], _DEFERRED_SIGNALS[-1], _TERMINAL_SIGNALS[-1])
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["21", "21", "21"]


# -- worker pools: at most 61 workers on Windows ------------------------------------------


@pytest.mark.parametrize(
    ("platform", "jobs", "workers_started"),
    [
        ("win32", 64, 61),
        ("win32", 256, 61),
        ("win32", 4, 4),
        ("linux", 64, 64),
    ],
)
def test_process_pools_keep_to_the_platforms_worker_limit(
    monkeypatch, platform, jobs, workers_started
):
    monkeypatch.setattr(sys, "platform", platform)  # what ProcessPoolExecutor checks
    pool = workers.process_pool(jobs)  # no worker starts before the first task
    try:
        assert pool._max_workers == workers_started
    finally:
        pool.shutdown()


# -- the MPC floor's clock --------------------------------------------------------------


def test_a_clock_too_coarse_for_the_steps_leaves_the_ratios_unknown():
    log = mpc_floor.StepLog()
    zero = {"step": 0.0, "hpipm": 0.0, "iterations": 1.0, "hpipm_iterations": 5.0}
    log.steps = [dict(zero) for _ in range(120)]  # every step read 0 on a 15.6 ms tick
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        row = {"case": "tracking ellipse (kinematic plant)", **mpc_floor.floor_summary(log)}
    assert math.isnan(row["step_over_hpipm"]) and math.isnan(row["p99_over_median"])
    assert mpc_floor.floor_verdicts(row) == {
        "step_over_hpipm": None,
        "p99_over_median": None,
        "max_us": True,
    }
    lines = mpc_floor.format_floor_lines([row])
    assert lines[2].split()[-5:] == ["nan", "-", "nan", "-", "ok"] and len(lines) == 3


def test_the_floor_times_wall_clock_on_windows_and_thread_time_elsewhere(monkeypatch):
    assert mpc_floor.DEFAULT_CLOCK is time.thread_time_ns
    assert mpc_floor.StepLog().solver_stat == "t_proc_solver"
    spec = importlib.util.spec_from_file_location("mpc_floor_on_nt", mpc_floor.__file__)
    assert spec is not None and spec.loader is not None
    on_nt = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, on_nt)
    with monkeypatch.context() as windows:
        windows.setattr(os, "name", "nt")  # while the module is imported, nothing else
        spec.loader.exec_module(on_nt)
    assert on_nt.DEFAULT_CLOCK is time.perf_counter_ns
    assert on_nt.StepLog().solver_stat == "t_wall_solver"
    assert on_nt.format_floor_lines([])[0].startswith(
        "mpc step against its HPIPM solve in mpc's own closed-loop runs (wall time, not "
    )


# -- the command that repeats a run -----------------------------------------------------

ARGUMENTS = ["--out", "my runs/a b", "--traj", "it's.csv", "--duration", "2"]


def test_the_repeat_command_is_quoted_for_cmd_exe_on_windows(monkeypatch):
    monkeypatch.setattr(provenance, "os", _os_like(name="nt"))
    record = provenance.command_record("python -m ddwmmr.track", ARGUMENTS)
    assert record["command"] == (
        'python -m ddwmmr.track --out "my runs/a b" --traj it\'s.csv --duration 2'
    )
    assert record["argv"] == ARGUMENTS


def test_the_repeat_command_is_quoted_for_sh_elsewhere():
    record = provenance.command_record("python -m ddwmmr.track", ARGUMENTS)
    assert record["command"] == shlex.join(["python", "-m", "ddwmmr.track", *ARGUMENTS])
    assert shlex.split(record["command"])[3:] == ARGUMENTS


# -- shipped data under Git for Windows (core.autocrlf=true) -----------------------------


def _tracked_data() -> list[str]:
    done = subprocess.run(
        ["git", "-C", str(ROOT), "ls-files", "*.csv", "*.toml", "*.json", "*.npz"],
        capture_output=True,
        text=True,
    )
    return done.stdout.split() if done.returncode == 0 else []


@pytest.mark.skipif(shutil.which("git") is None or not _tracked_data(), reason="no git checkout")
def test_a_windows_checkout_keeps_the_data_files_bytes():
    paths = _tracked_data()
    assert "src/ddwmmr/trajectories/data/figure8.csv" in paths
    for path in paths:
        blob = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", f"HEAD:{path}"],
            capture_output=True,
            text=True,
        ).stdout.strip()
        if not blob:
            continue  # not committed yet
        stored = subprocess.run(
            ["git", "-C", str(ROOT), "cat-file", "blob", blob], capture_output=True, check=True
        ).stdout
        checkout = subprocess.run(
            [
                "git",
                "-C",
                str(ROOT),
                "-c",
                "core.autocrlf=true",
                "cat-file",
                "--filters",
                f"--path={path}",
                blob,
            ],
            capture_output=True,
            check=True,
        ).stdout
        assert checkout == stored, path


# -- the run_many snippet under spawn (macOS, Windows) ----------------------------------


def _python_block(page: Path, containing: str) -> str:
    """The first ```python block of ``page`` containing ``containing``."""
    blocks = page.read_text(encoding="utf-8").split("```python\n")[1:]
    return next(b.split("```", 1)[0] for b in blocks if containing in b)


def test_the_thesis_run_many_snippet_runs_under_spawn(tmp_path):
    script = tmp_path / "snippet.py"
    start = "import multiprocessing\nmultiprocessing.set_start_method('spawn', force=True)\n"
    script.write_text(start + _python_block(ROOT / "docs/thesis.md", "run_many("))
    done = subprocess.run(
        [sys.executable, str(script)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "high stability" in done.stdout and "bootstrapping" not in done.stderr
    assert np.isfinite(float(done.stdout.split()[1]))  # the first run's time_s
