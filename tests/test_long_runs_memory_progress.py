"""Long runs: the time series kept compactly, the CSV written in blocks, and progress that
shows (a heartbeat in long phases, an honest ETA, a bar on an unsized terminal)."""

from __future__ import annotations

import csv
import io
import os
import pty
import re
import select
import time
import tracemalloc

import numpy as np
import pytest

import ddwmmr.outputs.atomic as atomic
import ddwmmr.sim.result as result_module
from ddwmmr import progress, simulate
from ddwmmr.model import Robot
from ddwmmr.progress import ProgressBar, phase
from ddwmmr.sim.result import SimulationResult, _format
from ddwmmr.sim.tracking import RowStore
from ddwmmr.trajectories import Ellipse


def _whole_text(timeseries: dict[str, np.ndarray]) -> bytes:
    """The CSV as one text: what the file must hold, byte for byte."""
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    columns = list(timeseries)
    writer.writerow(columns)
    for row in zip(*(timeseries[c].tolist() for c in columns)):
        writer.writerow([_format(v) for v in row])
    return buffer.getvalue().encode("utf-8")


def _series(rows: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(7)
    return {
        "t": np.arange(rows) * 0.02,
        "x": rng.normal(size=rows) * 10.0 ** rng.integers(-200, 200, rows),
        "odd": np.where(np.arange(rows) % 3 == 0, np.nan, -0.0),
        "label": np.array(['a,"b"'] * rows),
    }


def test_csv_is_written_in_blocks_with_the_same_bytes(tmp_path, monkeypatch):
    monkeypatch.setattr(result_module, "CSV_BLOCK", 10)
    writes: list[int] = []
    real_fdopen = atomic.os.fdopen

    class Spy:
        def __init__(self, handle):
            self.handle = handle

        def __getattr__(self, name):
            return getattr(self.handle, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return self.handle.__exit__(*exc)

        def write(self, data):
            writes.append(len(data))
            return self.handle.write(data)

    monkeypatch.setattr(atomic.os, "fdopen", lambda *a, **k: Spy(real_fdopen(*a, **k)))
    series = _series(95)
    target = tmp_path / "timeseries.csv"
    SimulationResult(series, {}).write_csv(target)
    expected = _whole_text(series)
    assert target.read_bytes() == expected
    assert len(writes) == 1 + 10  # the header, then 10 blocks of at most 10 rows
    assert max(writes) < len(expected) / 5  # no write holds the whole text


def test_csv_writer_failing_midway_leaves_the_old_file(tmp_path, monkeypatch):
    monkeypatch.setattr(result_module, "CSV_BLOCK", 10)
    calls = {"n": 0}

    def failing(value):
        calls["n"] += 1
        if calls["n"] > 50:  # in the second block: the first is already in the file
            raise OSError("disk full")
        return _format(value)

    monkeypatch.setattr(result_module, "_format", failing)
    target = tmp_path / "timeseries.csv"
    target.write_text("old\n")
    with pytest.raises(OSError, match="disk full"):
        SimulationResult(_series(40), {}).write_csv(target)
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["timeseries.csv"]


@pytest.mark.parametrize("capacity", [0, 5, 10_000])
def test_row_store_gives_the_numbers_of_one_array(monkeypatch, capacity):
    monkeypatch.setattr(RowStore, "BLOCK", 4)
    rng = np.random.default_rng(3)
    rows = [tuple(rng.normal(size=3).tolist()) for _ in range(23)]
    rows[5] = (1, True, np.float32(0.1))  # what np.array makes of them, unchanged
    store = RowStore(3, capacity)
    for row in rows:
        store.append(row)
    assert len(store) == 23
    got = store.array()
    want = np.array(rows, dtype=float)
    assert got.shape == (23, 3)
    assert got.tobytes() == want.tobytes()
    assert RowStore(2).array().shape == (0, 2)


def test_a_long_run_keeps_no_python_float_per_sample():
    """A tuple of Python floats per sample cost about 730 bytes on top of the time series
    (31 columns of 8 bytes); the run's peak stays below 1000 bytes per sample."""
    robot, ellipse = Robot(), Ellipse()
    simulate(robot, ellipse, "clrrmc-ts", duration=1.0)  # imports and caches outside
    tracemalloc.start()
    try:
        result = simulate(robot, ellipse, "clrrmc-ts", duration=400.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    samples = len(result.timeseries["t"])
    assert samples == 20001
    assert peak / samples < 1000.0


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_phase_prints_a_heartbeat_while_it_lasts(monkeypatch):
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.01)
    monkeypatch.setattr(progress, "QUIET_PHASE_S", 0.0)
    stream = io.StringIO()  # not a terminal: the CI log of a long write
    with phase("track: writing timeseries.csv", stream=stream):
        deadline = time.monotonic() + 60.0
        while "still running" not in stream.getvalue() and time.monotonic() < deadline:
            time.sleep(0.01)
    lines = stream.getvalue().splitlines()
    assert re.fullmatch(r"track: writing timeseries\.csv: still running after \d+ s", lines[0])
    assert lines[-1].startswith("track: writing timeseries.csv: done in ")
    assert all("still running" in line for line in lines[:-1])
    settled = stream.getvalue()
    time.sleep(0.05)
    assert stream.getvalue() == settled  # the heartbeat stopped with the phase


def test_bar_eta_is_at_the_average_rate_of_the_run(monkeypatch):
    import tqdm.std

    clock = [1000.0]
    monkeypatch.setattr(tqdm.std, "time", lambda: clock[0])
    with ProgressBar(100, "steps", stream=_Terminal(), unit="step") as bar:
        for seconds in [1.0] * 10 + [0.01] * 10:  # ten slow steps, then ten fast ones
            clock[0] += seconds
            bar.advance()
        shown = re.search(r"<(\d\d):(\d\d)", str(bar._bar))
    left = 60 * int(shown.group(1)) + int(shown.group(2))
    assert left == int(progress.eta(10.1, 20, 100))  # 40 s: 80 steps at 20 per 10.1 s


def _read_all(fd: int) -> str:
    chunks = []
    while select.select([fd], [], [], 0.5)[0]:
        chunks.append(os.read(fd, 65536))
    return b"".join(chunks).decode("utf-8", "replace")


def test_bar_shows_on_a_terminal_that_reports_no_size():
    master, slave = pty.openpty()  # a new pseudo-terminal: 0 columns, 0 lines
    try:
        assert os.get_terminal_size(slave) == (0, 0)
        stream = os.fdopen(os.dup(slave), "w", encoding="utf-8")
        with stream, ProgressBar(5, "track: steps", stream=stream, unit="step") as bar:
            for _ in range(5):
                bar.advance()
        shown = _read_all(master)
    finally:
        os.close(master)
        os.close(slave)
    last = shown.replace("\r\n", "\n").split("\r")[-1].strip()
    assert last.startswith("track: steps: 100%|")
    assert "5/5" in last
    assert len(last) <= progress.FALLBACK_COLUMNS
