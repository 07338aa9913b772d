"""``scenarios --executor dask``: schedulers the tests start on 127.0.0.1, worker counts,
and signals (one line, Dask's own log lines silenced).

Addresses that are not Dask schedulers (silent listeners, HTTP, garbage, tls/ucx without
their setup): tests/test_cli_fuzz.py.
"""

from __future__ import annotations

import logging
import os
import signal
import socket
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest

from ddwmmr import interrupts
from ddwmmr.cli import common
from ddwmmr.cli.scenarios import main as cli
from ddwmmr.scenarios import RunConfig, executors, generate
from terminal_signals import FROM_A_TERMINAL, end
from test_cli_signals import alive, children, staging, wait_for

distributed = pytest.importorskip("distributed")
FAST = ["--n", "2", "--time-limit", "3", "--no-progress", "--executor", "dask"]
#: The scheduler's HTTP server (health routes, served even without the dashboard) on a
#: free port: on Dask's default 8787 a cluster of a parallel test, or any other on this
#: machine, would collide ("Port 8787 is already in use").
NO_FIXED_PORT = {"dashboard_address": ":0"}


def local_cluster(n_workers: int):
    """A cluster of ``n_workers`` threads in this process, reached over TCP on 127.0.0.1 (as
    ``--scheduler`` reaches a remote one), its scheduler on a free port."""
    return distributed.LocalCluster(
        n_workers=n_workers,
        processes=False,
        dashboard_address=None,
        protocol="tcp",
        host="127.0.0.1",
        scheduler_kwargs=NO_FIXED_PORT,
    )


def test_a_scheduler_without_workers_is_refused_before_the_output(tmp_path, capsys):
    with local_cluster(0) as cluster:
        # 3 s: the scheduler must answer within it, even on a loaded machine
        args = ["--scheduler", cluster.scheduler_address, "--connect-timeout", "3"]
        status = cli([*FAST, *args, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 2, err
    assert err.strip() == (
        f"error: scheduler: the Dask scheduler at {cluster.scheduler_address!r} has no "
        "worker (none joined within 3 s)"
    )
    assert list(tmp_path.iterdir()) == []


def test_a_scheduler_with_a_worker_runs_the_batch(tmp_path, capsys):
    with local_cluster(1) as cluster:
        status = cli(
            [*FAST, "--scheduler", cluster.scheduler_address, "--out", str(tmp_path / "o")]
        )
    assert status == 0, capsys.readouterr().err
    assert (tmp_path / "o" / "scenarios.csv").read_text().count("\n") == 3


def test_workers_are_capped_to_the_scenarios(tmp_path, capsys, monkeypatch):
    """``--jobs 256 --n 1`` starts one worker, not 256."""
    started = []

    class Recording(distributed.LocalCluster):
        def __init__(self, **options):
            started.append(options["n_workers"])
            super().__init__(**{**options, "processes": False})

    monkeypatch.setattr(distributed, "LocalCluster", Recording)
    args = ["--n", "1", "--time-limit", "3", "--no-progress", "--executor", "dask"]
    assert cli([*args, "--jobs", "256", "--out", str(tmp_path / "o")]) == 0
    assert started == [1]
    assert "(1 dask worker)" in capsys.readouterr().err
    assert executors.run_many([], None, jobs=8) == []  # nothing to run: no worker at all


def test_a_run_beside_another_cluster_says_nothing_of_ports(tmp_path, capsys, monkeypatch):
    """Dask's scheduler serves HTTP (health routes) even without its dashboard, on 8787 by
    default: a second run at the same time warned "Port 8787 is already in use"."""

    class InProcess(distributed.LocalCluster):
        def __init__(self, **options):
            super().__init__(**{**options, "processes": False})

    monkeypatch.setattr(distributed, "LocalCluster", InProcess)
    taken = socket.socket()
    try:
        taken.bind(("", 8787))
        taken.listen()
    except OSError:
        pass  # already taken by something else: the same test
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            status = cli([*FAST, "--jobs", "1", "--out", str(tmp_path / "o")])
    finally:
        taken.close()
    assert status == 0, capsys.readouterr().err
    assert not [w for w in caught if "already in use" in str(w.message)]
    assert "8787" not in capsys.readouterr().err


def test_stopping_the_workers_silences_every_dask_logger():
    """Dask's configuration gives ``distributed.client`` a level of its own, so a level
    on the ``distributed`` logger does not reach it: its "Couldn't gather" warning once
    came out beside the tool's one line."""
    client_log = logging.getLogger("distributed.client")
    assert client_log.isEnabledFor(logging.WARNING)  # Dask's default, or this proves nothing
    try:
        common.stop_workers()
        for name in ("distributed", "distributed.client", "distributed.nanny", "tornado"):
            assert not logging.getLogger(name).isEnabledFor(logging.CRITICAL), name
    finally:
        logging.disable(logging.NOTSET)


@pytest.mark.parametrize(
    ("signum", "status", "group"),
    [(signal.SIGTERM, 143, False), (signal.SIGHUP, 129, True)],
)
def test_a_signal_during_a_dask_run_says_one_line(tmp_path, signum, status, group):
    """SIGTERM to the tool, or a closed terminal's SIGHUP to its whole process group: the
    scheduler and nannies in the tool would log every lost worker, the workers and
    multiprocessing's resource tracker would die with messages of their own. Started as
    from a terminal (SIGHUP at its default, under a suite started by ``nohup`` too)."""
    process = subprocess.Popen(
        [sys.executable, "-m", "ddwmmr.scenarios", "--n", "400", "--jobs", "2",
         "--no-progress", "--executor", "dask", "--out", str(tmp_path / "out")],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "MPLBACKEND": "Agg"}, start_new_session=True, **FROM_A_TERMINAL,
    )  # fmt: skip
    workers: set[int] = set()
    try:
        # two Dask workers and the resource tracker, then the batch under way
        wait_for(lambda: len(children(process.pid)) >= 3 or process.poll() is not None)
        wait_for(lambda: staging(tmp_path) or process.poll() is not None)
        workers = children(process.pid)
        time.sleep(0.5)
        assert process.poll() is None, process.stderr.read()
        if group:
            os.killpg(process.pid, signum)
        else:
            process.send_signal(signum)
        try:
            _, err = process.communicate(timeout=60)  # about 3 s, on a loaded machine too
        except subprocess.TimeoutExpired:
            process.kill()
            pytest.fail(f"still running 60 s after the signal; stderr:\n{process.communicate()[1]}")
        assert process.returncode == status, err
        assert len(err.strip().splitlines()) == 1 and "terminated" in err, err
        assert list(Path(tmp_path).iterdir()) == []
        wait_for(lambda: not any(alive(pid) for pid in workers), timeout=20)
    finally:
        end(process, workers=workers)


@pytest.mark.parametrize(("executor", "jobs"), [("dask", 1), ("local", 2)])
def test_a_stop_the_handler_could_not_raise_still_ends_the_run(executor, jobs):
    """The tools' signal handler runs in the main thread wherever it is, in a garbage
    collector's callback too (Dask registers one), which prints and drops the exception:
    the stop it recorded must end the run after the chunk under way, not let the batch run
    to its end (a SIGHUP once left a Dask run going with the tool's output to come)."""
    scenarios = generate(3, 5)
    done: list[int] = []

    def finished(count: int) -> None:  # the first chunk's result: then the signal
        done.append(count)
        interrupts.record(common.Terminated(signal.SIGHUP))

    try:
        with pytest.raises(common.Terminated):
            # worker processes: a worker thread would raise the recorded stop itself
            executors.run_many(
                scenarios, RunConfig(time_limit=3.0), jobs=jobs, executor=executor,
                on_done=finished,
            )  # fmt: skip
    finally:
        interrupts.clear()
    assert done == [1]  # three chunks of one scenario; the stop came after the first


def _nap(seconds: float) -> list[float]:
    time.sleep(seconds)
    return [seconds]


def test_a_cancelled_dask_task_raises_not_returns():
    """Dask's as_completed(with_results=True) queues a cancelled future with its
    cancellation as the result: the wait raises it, as waiting on the future does, rather
    than hand the batch an exception object for a chunk's outcomes."""
    from distributed import Client
    from distributed.client import FutureCancelledError

    with Client(
        processes=False, n_workers=1, threads_per_worker=2, dashboard_address=None,
        scheduler_kwargs=NO_FIXED_PORT,
    ) as client:  # fmt: skip
        futures = [client.submit(_nap, 0.1, pure=False), client.submit(_nap, 1.0, pure=False)]
        waiting = executors._dask_completed(futures)
        first, result = next(waiting)
        assert first is futures[0] and result == [0.1]
        futures[1].cancel()
        with pytest.raises(FutureCancelledError):
            next(waiting)
