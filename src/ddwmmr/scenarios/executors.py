"""Running many scenarios: in-process, on a local process pool, or on a Dask cluster.

Every scenario is deterministic (the generator is seeded, the simulation has no
randomness), and results are put back in scenario order, so the output is identical
whatever the executor and job count. Work is sent in chunks of consecutive scenarios to
keep the per-task overhead small next to a scenario's ~30 ms.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import signal
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import as_completed
from multiprocessing import resource_tracker
from types import ModuleType
from typing import Any

from ddwmmr import interrupts
from ddwmmr.errors import MAX_JOBS, ParameterError, check_finite, check_int_at_least, one_of, shown
from ddwmmr.scenarios.generator import Scenario
from ddwmmr.scenarios.protocol import Outcome, RunConfig, run_scenario
from ddwmmr.workers import process_pool, worker_display

EXECUTORS = ("local", "dask")
#: Seconds a Dask scheduler has to answer, and then to have a worker (``--connect-timeout``).
CONNECT_TIMEOUT = 10.0
MAX_CONNECT_TIMEOUT = 600.0
#: One task = (configuration, scenarios) -> outcomes.
Task = tuple[RunConfig, tuple[Scenario, ...]]


def run_chunk(config: RunConfig, scenarios: Sequence[Scenario]) -> list[Outcome]:
    """Run consecutive scenarios in this process (the unit of work sent to workers)."""
    return [run_scenario(s, config) for s in scenarios]


def default_jobs() -> int:
    """Worker count when none is given: the CPUs this process may use, at most
    :data:`~ddwmmr.errors.MAX_JOBS` (what ``run_many`` and the tools accept)."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not on Linux
        cpus = os.cpu_count() or 1
    return min(MAX_JOBS, max(1, cpus))


def _chunks(scenarios: Sequence[Scenario], jobs: int) -> list[tuple[Scenario, ...]]:
    # 16 chunks per worker: the last ones to finish are short, so no worker idles long, and
    # a chunk still outlasts its task overhead many times (docs/thesis.md, "Speed and
    # scale-out").
    size = max(1, len(scenarios) // (16 * jobs))
    return [tuple(scenarios[i : i + size]) for i in range(0, len(scenarios), size)]


def run_many(
    scenarios: Sequence[Scenario],
    config: RunConfig,
    *,
    jobs: int = 1,
    executor: str = "local",
    scheduler: str | None = None,
    connect_timeout: float = CONNECT_TIMEOUT,
    cluster_options: dict[str, Any] | None = None,
    client: Any = None,
    on_done: Callable[[int], None] | None = None,
) -> list[Outcome]:
    """Run ``scenarios`` under ``config``; outcomes in scenario order.

    Args:
        jobs: worker processes (local) or LocalCluster workers (dask without scheduler),
            an integer in [1, :data:`~ddwmmr.errors.MAX_JOBS`] (else a one-line
            :class:`ParameterError`, as ``--jobs``); never more than there are scenarios.
        executor: ``"local"`` (process pool; in-process when jobs == 1) or ``"dask"``.
        scheduler: address of a running Dask scheduler (``tcp://host:8786``); without it
            a LocalCluster is started and closed.
        connect_timeout: seconds a scheduler has to answer (see :func:`check_scheduler`).
        cluster_options: extra LocalCluster keyword arguments (tests: processes=False).
        client: a connected Dask client to use (:class:`DaskWorkers`) instead of
            connecting, or starting a cluster, for this call.
        on_done: called with the number of scenarios finished by each completed chunk.
    """
    if not one_of(executor, EXECUTORS):
        raise ParameterError(
            f"executor must be one of {', '.join(EXECUTORS)} (got {shown(executor)})"
        )
    jobs = min(check_int_at_least("jobs", jobs, 1, MAX_JOBS), max(1, len(scenarios)))
    chunks = _chunks(scenarios, jobs)
    if executor == "dask" and client is not None:
        results = _run_dask(chunks, config, client, on_done)
    elif executor == "dask":
        with DaskWorkers(jobs, scheduler, connect_timeout, cluster_options) as own:
            results = _run_dask(chunks, config, own, on_done)
    elif jobs == 1:
        results = []
        for chunk in chunks:
            results.append(run_chunk(config, chunk))
            if on_done is not None:
                on_done(len(chunk))
    else:
        results = _run_pool(chunks, config, jobs, on_done)
    return [outcome for chunk in results for outcome in chunk]


def _run_pool(
    chunks: Sequence[tuple[Scenario, ...]],
    config: RunConfig,
    jobs: int,
    on_done: Callable[[int], None] | None,
) -> list[list[Outcome]]:
    results: list[list[Outcome] | None] = [None] * len(chunks)
    with process_pool(jobs) as pool:
        futures = {pool.submit(run_chunk, config, c): i for i, c in enumerate(chunks)}
        for future in as_completed(futures):
            interrupts.raise_pending()  # the stop, not the broken pool its handler left
            i = futures[future]
            results[i] = future.result()
            if on_done is not None:
                on_done(len(chunks[i]))
    return results  # type: ignore[return-value]


# client is Any: a dask.distributed Client, as run_many takes it (dask is optional)
def _run_dask(
    chunks: Sequence[tuple[Scenario, ...]],
    config: RunConfig,
    client: Any,
    on_done: Callable[[int], None] | None,
) -> list[list[Outcome]]:
    futures = [client.submit(run_chunk, config, c, pure=False) for c in chunks]
    index = {f.key: i for i, f in enumerate(futures)}
    results: list[list[Outcome] | None] = [None] * len(chunks)
    for future, result in _dask_completed(futures):
        i = index[future.key]
        results[i] = result
        if on_done is not None:
            on_done(len(chunks[i]))
    return results  # type: ignore[return-value]


# -- Dask -----------------------------------------------------------------------------------
#: Seconds between two looks for a stop while waiting for a Dask result.
_POLL_S = 0.1


def _dask_completed(futures: Sequence[Any]) -> Iterator[tuple[Any, Any]]:
    """``(future, result)`` for each of ``futures`` (Dask's) in the order they complete
    (a task's exception is raised), raising, before each and every :data:`_POLL_S` s of
    waiting, a stop the tools' signal handler recorded (:mod:`ddwmmr.interrupts`).

    The handler runs in the main thread wherever it is, a garbage collector's callback
    included (Dask registers one), and such a callback prints and drops what it raises:
    the batch would otherwise run to its end on the workers the nannies restart. The
    results are fetched in Dask's thread, so that this wait never blocks on one (a
    result on a worker the handler stopped is computed again)."""
    from dask.distributed import as_completed as dask_completed

    # ignore: distributed's as_completed has no hints on these methods
    completed = dask_completed(futures, with_results=True)  # type: ignore[no-untyped-call]
    while not completed.is_empty():  # type: ignore[no-untyped-call]
        interrupts.raise_pending()
        if completed.has_ready():  # type: ignore[no-untyped-call]
            future, result = next(completed)
            if future.status == "cancelled":  # queued with its cancellation as the result
                future.result()  # raises it, as waiting on the future does
            yield future, result
            continue
        with completed.thread_condition:
            completed.thread_condition.wait(_POLL_S)


def _import_distributed() -> ModuleType:
    try:
        import distributed
    except ImportError:  # pragma: no cover - dask is an optional extra
        raise ParameterError(
            "executor: dask is not installed (pip install 'dask[distributed]')"
        ) from None
    return distributed


def check_connect_timeout(seconds: float) -> float:
    """``seconds`` as a float if in (0, :data:`MAX_CONNECT_TIMEOUT`], else a one-line
    :class:`ParameterError` naming connect-timeout."""
    value = check_finite("connect-timeout", seconds)
    if not 0.0 < value <= MAX_CONNECT_TIMEOUT:
        raise ParameterError(
            f"connect-timeout must be in (0, {MAX_CONNECT_TIMEOUT:g}] s (got {value:g})"
        )
    return value


def check_scheduler(address: str, timeout: float = CONNECT_TIMEOUT) -> None:
    """Raise a one-line :class:`ParameterError` unless a Dask scheduler answers at
    ``address`` within ``timeout`` s.

    Asks it who it is (Dask's ``identity`` call) under one deadline for the connection,
    the handshake and the answer: Dask's own connect waits for the handshake without a
    limit, so a listener that never answers (or an HTTP server) would hang it, and an
    address answering garbage, or a scheme it cannot use (``tls://`` without TLS
    settings, ``ucx://`` without UCX), fails with an exception of any type.
    """
    _import_distributed()
    outcome: dict[str, Any] = {}

    def probe() -> None:
        try:
            outcome["reply"] = asyncio.run(asyncio.wait_for(_identity(address), timeout))
        except BaseException as exc:  # handed to the caller's thread
            outcome["error"] = exc

    thread = threading.Thread(target=probe, name="ddwmmr-scheduler-probe", daemon=True)
    thread.start()
    thread.join(timeout + 5.0)  # the deadline above ends it; this is a backstop
    error = outcome.get("error")
    if thread.is_alive() or isinstance(error, TimeoutError):
        raise ParameterError(
            f"scheduler: no Dask scheduler answered at {shown(address)} within {timeout:g} s "
            "(--connect-timeout)"
        )
    if error is not None:
        reason = _first_line(error)
        raise ParameterError(f"scheduler: cannot connect to {shown(address)} ({reason})")
    reply = outcome.get("reply")
    if not (isinstance(reply, dict) and reply.get("type") == "Scheduler"):
        raise ParameterError(f"scheduler: {shown(address)} answered, but not as a Dask scheduler")


async def _identity(address: str) -> Any:
    """What the server at ``address`` says it is (a dict; ``type`` is ``Scheduler``)."""
    # ignore: distributed.comm re-exports connect without __all__, and it has no hints
    from distributed.comm import connect  # type: ignore[attr-defined]

    comm = await connect(address)  # type: ignore[no-untyped-call]
    try:
        await comm.write({"op": "identity", "reply": True})
        return await comm.read()
    finally:
        comm.abort()


def _first_line(error: BaseException) -> str:
    text = str(error).strip()
    line = text.splitlines()[0] if text else ""
    return f"{type(error).__name__}: {line}" if line else type(error).__name__


#: Signals a terminal sends to a whole process group (Ctrl-C, a closed terminal, Ctrl-\\,
#: Windows' Ctrl-Break).
_TERMINAL_SIGNALS = tuple(
    getattr(signal, name)
    for name in ("SIGINT", "SIGHUP", "SIGQUIT", "SIGBREAK")
    if hasattr(signal, name)
)


@contextlib.contextmanager
def _terminal_signals_blocked() -> Iterator[None]:
    """Block :data:`_TERMINAL_SIGNALS` in this thread for the block (POSIX).

    Threads started in the block, and processes they start (a LocalCluster's event loop,
    its worker processes and multiprocessing's resource tracker), keep the blocked mask:
    a Ctrl-C or a closed terminal then reaches only this process, which stops them
    itself, instead of killing them half-way with messages of their own (a worker still
    importing would print a traceback). Signals arriving meanwhile are delivered here when
    the block ends.

    multiprocessing's resource tracker is started here, in the block: the first spawned
    process would start it, and starting it unblocks SIGINT and SIGTERM in the starting
    thread afterwards, so from the cluster's thread every worker spawned after it would
    take Ctrl-C. Here the block is put back after it."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, _TERMINAL_SIGNALS)
    try:
        resource_tracker.ensure_running()
        signal.pthread_sigmask(signal.SIG_BLOCK, _TERMINAL_SIGNALS)
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _warnings_display_plugin(display: Callable[[], None]) -> Any:
    """A Dask worker plugin that runs ``display`` (a :func:`ddwmmr.workers.worker_display`
    of this process) in every worker of the cluster, those that join later (a worker
    restarted by its nanny) included, so that the workers show warnings as this process
    does. A LocalCluster's worker processes write to this process's stderr (they inherit
    it through their nanny), so their warnings reach the same terminal.

    Defined here, not at module level, because ``distributed`` is an optional extra
    imported only when used; Dask pickles the class by value."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class WarningsDisplay(WorkerPlugin):
        name = "ddwmmr-warnings-display"

        def setup(self, worker: Any) -> None:
            display()

    return WarningsDisplay()


class DaskWorkers:
    """A connected Dask client for the ``with`` block: to the scheduler at ``scheduler``
    (checked first, :func:`check_scheduler`, then given ``connect_timeout`` s for a worker
    to be there), or to a LocalCluster of ``jobs`` single-threaded workers started for
    the block, which show warnings as this process does (:func:`_warnings_display_plugin`;
    a remote scheduler's workers keep their own display, and their output goes to their
    own logs). Every failure to get there is a one-line :class:`ParameterError`."""

    def __init__(
        self,
        jobs: int,
        scheduler: str | None = None,
        connect_timeout: float = CONNECT_TIMEOUT,
        cluster_options: dict[str, Any] | None = None,
    ) -> None:
        self.jobs = jobs
        self.scheduler = scheduler
        self.connect_timeout = check_connect_timeout(connect_timeout)
        self.cluster_options = cluster_options or {}
        self._cluster: Any = None
        self._client: Any = None

    def __enter__(self) -> Any:
        distributed = _import_distributed()
        if self.scheduler is None:
            # No dashboard; the scheduler's HTTP server (health routes) on a free port, not
            # 8787: with two runs at once Dask would warn that the port is taken
            options = {
                "n_workers": self.jobs,
                "threads_per_worker": 1,
                "dashboard_address": None,
                "scheduler_kwargs": {"dashboard_address": ":0"},
            }
            options.update(self.cluster_options)
            with _terminal_signals_blocked():  # inherited by the cluster's threads and workers
                self._cluster = distributed.LocalCluster(**options)
                self._client = distributed.Client(self._cluster)
            display = worker_display()
            if display is not None:
                self._client.register_plugin(_warnings_display_plugin(display))
            return self._client
        check_scheduler(self.scheduler, self.connect_timeout)
        try:
            self._client = distributed.Client(self.scheduler, timeout=self.connect_timeout)
            self._client.wait_for_workers(1, timeout=self.connect_timeout)
        except TimeoutError:
            self.close()
            raise ParameterError(
                f"scheduler: the Dask scheduler at {shown(self.scheduler)} has no worker "
                f"(none joined within {self.connect_timeout:g} s)"
            ) from None
        except (OSError, ValueError) as exc:
            self.close()
            raise ParameterError(
                f"scheduler: cannot connect to {shown(self.scheduler)} ({_first_line(exc)})"
            ) from None
        return self._client

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the client and the cluster started for it (if any)."""
        if self._client is not None:
            self._client.close()
            self._client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None
