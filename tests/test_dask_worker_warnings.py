"""A LocalCluster's Dask workers show the library's warnings as the tool does (one line),
and no thread of tqdm's is alive when a process with a progress bar on a terminal forks."""

from __future__ import annotations

import os
import pty
import subprocess
import sys
import textwrap

import pytest

from test_workers_warnings import run_script

DASK_SCRIPT = textwrap.dedent(
    """
    import warnings
    from ddwmmr.cli.common import one_line_warnings
    from ddwmmr.model import kinematics
    from ddwmmr.scenarios.executors import DaskWorkers

    def warn(text):
        warnings.warn_explicit(text, UserWarning, kinematics.__file__, 1)
        return 1

    if __name__ == "__main__":
        with one_line_warnings(), DaskWorkers(1) as client:
            assert client.submit(warn, "from a dask\\n  worker", pure=False).result() == 1
    """
)


def test_a_local_clusters_worker_shows_the_librarys_warning_as_one_line(tmp_path):
    """The worker is a process of its own (a LocalCluster's default) writing to the tool's
    stderr; Dask may add log lines of its own on a loaded machine."""
    pytest.importorskip("distributed")
    done = run_script(tmp_path, "dask_warn.py", DASK_SCRIPT)
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert "warning: from a dask worker" in lines, done.stderr
    assert "UserWarning" not in done.stderr and "  worker" not in lines


# The hook is registered before tqdm is imported (see tests/test_workers_warnings.py): it
# sees the threads as they are when the fork happens. stderr is a pseudo-terminal, so the
# bar is tqdm's.
FORK_SCRIPT = textwrap.dedent(
    """
    import multiprocessing, os, sys, threading
    seen = []
    os.register_at_fork(before=lambda: seen.append(
        sorted(t.name for t in threading.enumerate() if t is not threading.main_thread())))
    from ddwmmr.progress import ProgressBar
    from ddwmmr.workers import process_pool

    assert sys.stderr.isatty()
    with ProgressBar(4, "test: bar") as bar:
        assert bar._bar is not None  # tqdm's bar, not the lines of a log
        bar.advance()
        with process_pool(2, multiprocessing.get_context("fork")) as pool:
            assert list(pool.map(abs, [-1, -2])) == [1, 2]
        bar.advance(3)
    print(seen, threading.active_count(), flush=True)
    """
)


@pytest.mark.skipif(not hasattr(os, "fork"), reason="forks")
def test_no_tqdm_thread_is_alive_when_a_process_with_a_bar_forks(tmp_path):
    script = tmp_path / "bar_fork.py"
    script.write_text(FORK_SCRIPT)
    leader, follower = pty.openpty()
    try:
        done = subprocess.run(
            [sys.executable, str(script)],
            stdout=subprocess.PIPE,
            stderr=follower,
            text=True,
            timeout=120,
        )
    finally:
        os.close(follower)
    bar = _read_all(leader)
    assert done.returncode == 0, bar
    assert done.stdout.split() == ["[[],", "[]]", "1"]  # two forks, only the main thread
    assert "test: bar: 100%" in bar and "4/4" in bar


def _read_all(fd: int) -> str:
    """What was written to the pseudo-terminal whose leader is ``fd`` (closes it)."""
    chunks = []
    try:
        while chunk := os.read(fd, 65536):
            chunks.append(chunk)
    except OSError:  # EIO: the follower side is closed and everything was read
        pass
    finally:
        os.close(fd)
    return b"".join(chunks).decode(errors="replace")
