"""Pool workers show the library's warnings as the process that started them does, and no
thread of a progress phase is alive when a pool forks its workers."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

WARNING_SCRIPT = textwrap.dedent(
    """
    import multiprocessing, sys, warnings
    from ddwmmr.cli.common import one_line_warnings
    from ddwmmr.model import kinematics
    from ddwmmr.workers import process_pool

    def warn(text):
        warnings.warn_explicit(text, UserWarning, kinematics.__file__, 1)

    if __name__ == "__main__":
        context = multiprocessing.get_context(sys.argv[1])
        display = one_line_warnings() if sys.argv[2] == "one line" else open(__file__)
        with display, process_pool(1, context) as pool:
            pool.submit(warn, "from a\\n  worker").result()
    """
)


def run_script(tmp_path, name: str, text: str, *args: str) -> subprocess.CompletedProcess:
    script = tmp_path / name
    script.write_text(text)
    return subprocess.run(
        [sys.executable, str(script), *args], capture_output=True, text=True, timeout=120
    )


@pytest.mark.parametrize("method", ["spawn", "forkserver", "fork"])
def test_a_worker_shows_the_librarys_warning_as_one_line_whatever_the_start_method(
    tmp_path, method
):
    done = run_script(tmp_path, "warn.py", WARNING_SCRIPT, method, "one line")
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines() == ["warning: from a worker"]


def test_a_worker_keeps_pythons_display_when_its_parent_does(tmp_path):
    done = run_script(tmp_path, "warn.py", WARNING_SCRIPT, "spawn", "python's")
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert lines[0].endswith("kinematics.py:1: UserWarning: from a")
    assert lines[1] == "  worker"


# The hook is registered before ddwmmr.progress is imported: "before" hooks run in reverse
# order of registration, so it sees the threads as they are when the fork happens.
FORK_SCRIPT = textwrap.dedent(
    """
    import io, multiprocessing, os, threading, time
    seen = []
    os.register_at_fork(before=lambda: seen.append(
        sorted(t.name for t in threading.enumerate() if t is not threading.main_thread())))
    from ddwmmr import progress
    from ddwmmr.workers import process_pool

    progress.LOG_INTERVAL_S = 0.2
    stream = io.StringIO()
    beats = lambda: stream.getvalue().count("test: pool: still running after")
    began = time.perf_counter()
    with progress.phase("test: pool", stream=stream):
        with process_pool(2, multiprocessing.get_context("fork")) as pool:
            assert list(pool.map(abs, [-1, -2])) == [1, 2]
        forked = beats()
        deadline = time.monotonic() + 30
        while beats() == forked and time.monotonic() < deadline:
            time.sleep(0.05)  # the heartbeat goes on after the fork (however late it wakes)
        time.sleep(0.5)
    elapsed = time.perf_counter() - began
    print(seen)
    print(forked, beats(), elapsed)
    """
)


def test_no_phase_thread_is_alive_when_a_pool_forks_and_the_phase_beats_on(tmp_path):
    done = run_script(tmp_path, "fork.py", FORK_SCRIPT)
    assert done.returncode == 0, done.stderr
    seen, counts = done.stdout.splitlines()
    assert seen == "[[], []]"  # two workers forked, each with only the main thread alive
    forked, beats, elapsed = counts.split()
    assert int(beats) > int(forked)  # it beat on after the fork
    # ... on time: its lines are due at multiples of 0.2 s after the phase's start, never
    # sooner (so not two heartbeats at once), however long a loaded machine made the phase
    assert int(beats) <= float(elapsed) / 0.2, counts


FORKSERVER_POOL_SCRIPT = textwrap.dedent(
    """
    import multiprocessing, os, time
    from ddwmmr.workers import process_pool

    def pid(_):
        time.sleep(0.1)  # each worker gets some of the calls
        return os.getpid()

    if __name__ == "__main__":
        with process_pool(2, multiprocessing.get_context("forkserver")) as pool:
            print(*sorted(set(pool.map(pid, range(8)))), flush=True)
            time.sleep(120)
    """
)


def alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, ended but not yet reaped, does not)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_forkserver_workers_run_and_end_with_their_parent(tmp_path):
    """A fork server's worker is not its pool's child: it must neither take itself for
    an orphan at start nor outlive the pool's process."""
    script = tmp_path / "pool.py"
    script.write_text(FORKSERVER_POOL_SCRIPT)
    # stderr dropped: the pool is killed, so the resource tracker reports its semaphores
    process = subprocess.Popen(
        [sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True
    )
    workers: list[int] = []
    try:
        workers = [int(pid) for pid in process.stdout.readline().split()]
        assert 1 <= len(workers) <= 2 and process.poll() is None
        process.kill()
        process.wait(timeout=60)
        deadline = time.monotonic() + 10
        while any(alive(pid) for pid in workers) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(alive(pid) for pid in workers)
    finally:
        process.kill()
        for pid in workers:
            if alive(pid):  # do not leave them behind
                os.kill(pid, signal.SIGKILL)
