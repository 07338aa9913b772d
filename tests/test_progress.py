"""Progress output (ddwmmr.progress): tqdm on a terminal, short lines elsewhere."""

from __future__ import annotations

import io

from ddwmmr import progress
from ddwmmr.progress import ProgressBar, phase


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_not_a_terminal_prints_one_summary_line():
    stream = io.StringIO()
    with ProgressBar(50, "track: steps", stream=stream) as bar:
        for _ in range(50):
            bar.advance()
    lines = stream.getvalue().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("track: steps: 50/50 done in ")


def test_long_phase_prints_a_line_now_and_then(monkeypatch):
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)
    stream = io.StringIO()
    with ProgressBar(3, "runs", stream=stream) as bar:
        bar.advance(2)
        bar.advance()
    assert stream.getvalue().splitlines()[0].startswith("runs: 2/3 after ")
    assert stream.getvalue().splitlines()[-1].startswith("runs: 3/3 done in ")


def test_off_a_terminal_the_progress_lines_carry_an_eta(monkeypatch):
    """40 of 100 items in 177 s: 60 more at that rate take 265.5 s."""
    clock = iter([1000.0, 1177.0, 1177.0, 1500.0])
    monkeypatch.setattr(progress.time, "perf_counter", lambda: next(clock))
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 30.0)
    stream = io.StringIO()
    with ProgressBar(100, "scenarios", stream=stream) as bar:
        bar.advance(40)
    lines = stream.getvalue().splitlines()
    assert lines[0] == "scenarios: 40/100 after 177 s, ETA 4 min 26 s"


def test_eta_and_durations():
    assert progress.eta(177.0, 40, 100) == 177.0 * 60 / 40
    assert progress.eta(5.0, 0, 10) == float("inf")
    assert [progress._duration(s) for s in (4.4, 59.6, 265.5, 3725.0, float("inf"))] == [
        "4 s",
        "1 min 00 s",
        "4 min 26 s",
        "1 h 02 min",
        "unknown",
    ]


def test_terminal_gets_a_tqdm_bar():
    stream = Terminal()
    with ProgressBar(4, "compare: runs", stream=stream, unit="run") as bar:
        for _ in range(4):
            bar.advance()
    text = stream.getvalue()
    assert "compare: runs" in text and "4/4" in text and "\r" in text


def test_disabled_or_interrupted_prints_nothing():
    stream = io.StringIO()
    with ProgressBar(5, "x", enabled=False, stream=stream) as bar:
        bar.advance(5)
    try:
        with ProgressBar(5, "y", stream=stream) as bar:
            bar.advance()
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    assert stream.getvalue() == ""  # the interrupt's own line says what happened


def test_phase_lines(monkeypatch):
    stream = Terminal()
    with phase("compare: writing the report", stream=stream):
        pass
    assert stream.getvalue().splitlines() == [
        "compare: writing the report ...",
        "compare: writing the report: done in 0.0 s",
    ]
    quiet = io.StringIO()
    with phase("short", stream=quiet):  # not a terminal, under QUIET_PHASE_S: silent
        pass
    monkeypatch.setattr(progress, "QUIET_PHASE_S", 0.0)
    with phase("long", stream=quiet):
        pass
    assert quiet.getvalue().splitlines() == ["long: done in 0.0 s"]
