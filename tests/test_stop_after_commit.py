"""A stop that comes after a tool committed its output: the tool's line says the output is
complete (not removed), and the status is still the signal's (docs/cli.md, Interrupts)."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

from ddwmmr import interrupts
from ddwmmr.cli import common, track
from ddwmmr.cli.common import run_main
from ddwmmr.outputs import output_folder
from terminal_signals import at_defaults

SIGNALS = [signal.SIGINT, signal.SIGTERM, *([signal.SIGHUP] if hasattr(signal, "SIGHUP") else [])]


@pytest.fixture(autouse=True)
def no_worker_stop(monkeypatch):
    """The handler stops the tool's workers and silences every logger: not pytest's. The
    terminal's signals at their defaults (as in a tool run from one), whatever the suite's
    start: the tool leaves a signal it was started ignoring ignored."""
    monkeypatch.setattr(common, "stop_workers", lambda: None)
    with at_defaults():
        yield
    interrupts.clear()


def tool(out: Path, after_commit, before_commit=None):
    """A tool's ``_main`` that writes one file into ``out``; the callables run inside the
    output's with-block (``before_commit``) and after it (``after_commit``)."""

    def main(_argv) -> int:
        with output_folder(out, "track") as staging:
            (staging / "summary.json").write_text("{}\n")
            if before_commit is not None:
                before_commit()
        after_commit()
        return 0

    return main


@pytest.mark.parametrize("signum", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_a_signal_after_the_commit_says_the_output_is_complete(tmp_path, capsys, signum):
    out = tmp_path / "out"
    status = run_main(tool(out, lambda: signal.raise_signal(signum)), [])
    assert status == 128 + signum
    what = "interrupted (Ctrl-C)" if signum == signal.SIGINT else "terminated"
    err = capsys.readouterr().err
    assert err.startswith(what)
    assert err.endswith(f": stopped; the output in {out} is complete\n")
    assert (out / "summary.json").read_text() == "{}\n"


def test_a_pending_stop_raised_after_the_commit_says_the_output_is_complete(tmp_path, capsys):
    """A stop a solver swallowed (:mod:`ddwmmr.interrupts`), raised once the output is in."""
    out = tmp_path / "out"

    def late() -> None:
        interrupts.record(common.Terminated(signal.SIGTERM))
        interrupts.raise_pending()

    assert run_main(tool(out, late), []) == 143
    assert capsys.readouterr().err == (
        f"terminated (SIGTERM): stopped; the output in {out} is complete\n"
    )
    assert (out / "summary.json").is_file()


def test_a_stop_before_the_commit_still_removes_the_unfinished_output(tmp_path, capsys):
    out = tmp_path / "out"

    def stop() -> None:
        signal.raise_signal(signal.SIGINT)

    assert run_main(tool(out, lambda: None, stop), []) == 130
    assert capsys.readouterr().err == "interrupted (Ctrl-C): stopped; unfinished output removed\n"
    assert not out.exists()
    # and the commit of an earlier call is not this one's
    assert run_main(tool(out, lambda: None), []) == 0
    assert run_main(tool(tmp_path / "b", lambda: None, stop), []) == 130
    assert capsys.readouterr().err.endswith("; unfinished output removed\n")


def test_track_stopped_while_printing_its_table_keeps_and_names_its_output(
    tmp_path, capsys, monkeypatch
):
    table = track.format_table

    def stopped_while_printing(summary) -> str:
        signal.raise_signal(signal.SIGTERM)
        return table(summary)

    monkeypatch.setattr(track, "format_table", stopped_while_printing)
    out = tmp_path / "run"
    argv = ["--method", "ats", "--traj", "ellipse", "--duration", "0.5", "--no-plots"]
    assert track.main([*argv, "--no-progress", "--out", str(out)]) == 143
    assert capsys.readouterr().err == (
        f"terminated (SIGTERM): stopped; the output in {out} is complete\n"
    )
    assert {p.name for p in out.iterdir()} >= {"summary.json", "timeseries.csv"}
