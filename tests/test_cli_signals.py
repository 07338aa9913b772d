"""Ctrl-C, SIGTERM, SIGHUP, SIGQUIT: one line, exit 128 + the signal, staging removed,
worker processes stopped; SIGKILL of a tool: its workers end with it.

The tools run as a user runs them (``python -m``, a subprocess, from a terminal: the
terminal's signals at their defaults, however the suite was started); the signal is sent
once the staging folder exists (and, with ``--jobs 2``, once the worker processes run).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ddwmmr.outputs.owners import STAGING_PREFIX
from terminal_signals import FROM_A_TERMINAL, end, from_a_terminal

LONG = {
    "track": ["--method", "ats", "--traj", "ellipse", "--duration", "20000", "--no-plots"],
    "compare": ["--methods", "ats", "pi", "--only", "ellipse", "--study", "none",
                "--duration", "4000", "--jobs", "2"],
    "scenarios": ["--n", "60", "--jobs", "2"],
}  # fmt: skip


def children(pid: int) -> set[int]:
    """Processes whose parent is ``pid`` (from /proc)."""
    found = set()
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.add(int(entry.name))
    return found


def alive(pid: int) -> bool:
    """Running (not gone, not a zombie waiting to be reaped)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def wait_for(condition, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.05)


def start(tool: str, folder: Path, **popen) -> subprocess.Popen:
    """``tool`` busy for a long time, writing into ``folder / "out"``; ``popen``: more
    ``subprocess.Popen`` keywords (by default started as from a terminal)."""
    popen = {**FROM_A_TERMINAL, **popen}
    return subprocess.Popen(
        [sys.executable, "-m", f"ddwmmr.{tool}", *LONG[tool], "--no-progress",
         "--out", str(folder / "out")],
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "MPLBACKEND": "Agg"},
        **popen,
    )  # fmt: skip


def staging(folder: Path) -> list[Path]:
    """The run's staging folders in ``folder`` (not its lock, which is made first)."""
    return [p for p in folder.iterdir() if p.name.startswith(STAGING_PREFIX)]


@pytest.mark.parametrize(
    ("tool", "signum", "status", "word"),
    [
        ("track", signal.SIGINT, 130, "interrupted"),
        ("track", signal.SIGTERM, 143, "terminated"),
        ("scenarios", signal.SIGTERM, 143, "terminated"),
        ("compare", signal.SIGINT, 130, "interrupted"),
        ("track", signal.SIGHUP, 129, "terminated (SIGHUP)"),
        ("track", signal.SIGQUIT, 131, "terminated (SIGQUIT)"),
        ("compare", signal.SIGHUP, 129, "terminated (SIGHUP)"),
        ("scenarios", signal.SIGQUIT, 131, "terminated (SIGQUIT)"),
    ],
)
def test_signal_stops_cleanly(tmp_path, tool, signum, status, word):
    process = start(tool, tmp_path)
    workers: set[int] = set()
    try:
        wait_for(lambda: staging(tmp_path) or process.poll() is not None)
        if "--jobs" in LONG[tool]:
            wait_for(lambda: len(children(process.pid)) >= 2 or process.poll() is not None)
        workers = children(process.pid)
        time.sleep(0.3)
        assert process.poll() is None, process.stderr.read()
        process.send_signal(signum)
        _, err = process.communicate(timeout=60)
        assert process.returncode == status, err
        lines = err.strip().splitlines()
        assert len(lines) == 1 and word in lines[0], err
        assert "Traceback" not in err
        assert list(tmp_path.iterdir()) == []  # neither out nor its staging folder
        wait_for(lambda: not any(alive(pid) for pid in workers), timeout=10)
    finally:
        end(process, workers=workers)


def test_ctrl_c_on_the_whole_process_group(tmp_path):
    """A terminal's Ctrl-C reaches the workers too: still one line, no worker traceback."""
    process = start("compare", tmp_path, start_new_session=True)
    workers: set[int] = set()
    try:
        wait_for(lambda: len(children(process.pid)) >= 2 or process.poll() is not None)
        workers = children(process.pid)
        wait_for(lambda: staging(tmp_path) or process.poll() is not None)
        time.sleep(0.5)
        assert process.poll() is None, process.stderr.read()
        os.killpg(process.pid, signal.SIGINT)
        _, err = process.communicate(timeout=60)
        assert process.returncode == 130, err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
        assert list(tmp_path.iterdir()) == []
        wait_for(lambda: not any(alive(pid) for pid in workers), timeout=10)
    finally:
        end(process, workers=workers)


@pytest.mark.parametrize("tool", ["compare", "scenarios"])
def test_workers_end_with_a_killed_tool(tmp_path, tool):
    """``kill -9`` of the tool: nothing can clean up in it, but its workers end too."""
    process = start(tool, tmp_path)
    workers: set[int] = set()
    try:
        wait_for(lambda: len(children(process.pid)) >= 2 or process.poll() is not None)
        workers = children(process.pid)
        time.sleep(0.3)
        assert process.poll() is None, process.stderr.read()
        process.kill()
        process.communicate(timeout=60)
        wait_for(lambda: not any(alive(pid) for pid in workers), timeout=10)
    finally:
        end(process, workers=workers)  # do not leave them to the next test


POOL_SCRIPT = """
import os, sys, time
import ddwmmr.workers as workers
if sys.argv[1] == "watchdog only":
    workers._ask_kernel_for_death_signal = lambda: False
with workers.process_pool(2) as pool:
    list(pool.map(time.sleep, [0.2, 0.2]))  # both workers started
    print("ready", flush=True)
    time.sleep(120)
"""


@pytest.mark.parametrize("mechanism", ["both", "watchdog only"])
def test_pool_workers_end_with_their_parent(tmp_path, mechanism):
    """Each mechanism alone ends the workers: the kernel's parent-death signal (Linux) and
    the watchdog thread on the parent's sentinel (every platform)."""
    process = subprocess.Popen(
        [sys.executable, "-c", POOL_SCRIPT, mechanism],
        stdout=subprocess.PIPE,
        text=True,
    )
    workers: set[int] = set()
    try:
        assert process.stdout.readline().strip() == "ready"
        workers = children(process.pid)
        assert len(workers) == 2
        process.kill()
        process.wait(timeout=60)
        wait_for(lambda: not any(alive(pid) for pid in workers), timeout=10)
    finally:
        end(process, workers=workers)


def test_the_next_run_removes_a_killed_runs_staging_folder(tmp_path):
    process = start("track", tmp_path)
    try:
        wait_for(lambda: staging(tmp_path) or process.poll() is not None)
        left = staging(tmp_path)
        process.kill()
        process.communicate(timeout=60)
    finally:
        end(process)
    assert [p.name for p in staging(tmp_path)] == [p.name for p in left]  # nobody cleaned up
    again = subprocess.run(
        [sys.executable, "-m", "ddwmmr.track", "--method", "ats", "--traj", "ellipse",
         "--duration", "0.2", "--no-plots", "--no-progress", "--out", str(tmp_path / "out")],
        cwd=tmp_path, capture_output=True, text=True, timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )  # fmt: skip
    assert again.returncode == 0, again.stderr
    notes = [line for line in again.stderr.splitlines() if line.startswith("note: removed")]
    assert any(left[0].name in note for note in notes), again.stderr
    # The kill can also land while the run has a temporary file open beside the folder:
    # the next run removes that too, in a note of its own. Every note names a leftover of
    # the killed run (its host-pid-start token), never anything else.
    killed_run = left[0].name.removeprefix(STAGING_PREFIX).rsplit("-", 1)[0]
    assert len(notes) <= 2 and all(killed_run in note for note in notes), again.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_a_tool_started_under_nohup_ignores_sighup(tmp_path):
    """``nohup`` starts a tool with SIGHUP ignored: a closed terminal must not stop it,
    while SIGTERM still does."""

    def ignore_hangup() -> None:  # nohup, typed in a terminal
        from_a_terminal()
        signal.signal(signal.SIGHUP, signal.SIG_IGN)

    proc = start("track", tmp_path, preexec_fn=ignore_hangup)
    try:
        wait_for(lambda: staging(tmp_path) or proc.poll() is not None)
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(signal.SIGHUP)
        time.sleep(1.0)
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        end(proc)
    assert proc.returncode == 143, err
    assert "terminated (SIGTERM)" in err


def test_say_writes_a_line_in_one_write(monkeypatch):
    """Two processes sharing stderr (pool workers warning at once) cannot glue their lines
    together: the text and its newline go out in one write."""
    import io

    from ddwmmr.cli.signals import say

    writes: list[str] = []

    class Recorder(io.StringIO):
        def write(self, text: str) -> int:
            writes.append(text)
            return len(text)

    monkeypatch.setattr(sys, "stderr", Recorder())
    say("warning: from a worker")
    assert writes == ["warning: from a worker\n"]
    monkeypatch.setattr(sys, "stderr", None)
    say("nowhere to go")  # a missing stderr (pythonw) is not an error
