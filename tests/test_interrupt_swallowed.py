"""A stop whose exception Python drops (the handler ran in a weakref callback or a
``__del__``, as the garbage collector runs them at any moment): still one line, the
signal's status, and the output complete or absent; no "Exception ignored in" traceback,
and no run that carries on to status 0 as if no signal had come."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
import weakref
from pathlib import Path

import pytest

from ddwmmr import interrupts
from ddwmmr.cli import common
from ddwmmr.cli.common import run_main
from ddwmmr.outputs import output_folder
from terminal_signals import FROM_A_TERMINAL, at_defaults

INTERRUPTED = "interrupted (Ctrl-C): stopped; unfinished output removed"


class Thing:
    """Something a weakref can point to."""


def signal_in_a_weakref_callback(signum: int = signal.SIGINT) -> None:
    """Deliver ``signum`` while a weakref callback runs: Python prints and drops what the
    handler raises there."""
    thing = Thing()
    ref = weakref.ref(thing, lambda _ref: signal.raise_signal(signum))
    del thing
    assert ref() is None


def run_tool(folder: Path) -> subprocess.CompletedProcess[str]:
    """Run ``folder/tool.py`` in ``folder`` as from a terminal (stderr and stdout caught)."""
    return subprocess.run(
        [sys.executable, "tool.py"],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=60,
        **FROM_A_TERMINAL,
    )


@pytest.fixture(autouse=True)
def no_worker_stop(monkeypatch):
    """The handler stops the tool's workers and silences every logger: not pytest's; the
    terminal's signals at their defaults, as in a tool run from one."""
    monkeypatch.setattr(common, "stop_workers", lambda: None)
    with at_defaults():
        yield
    interrupts.clear()


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_dropped_stop_still_ends_the_tool(capsys, signum):
    def main(_argv) -> int:
        signal_in_a_weakref_callback(signum)
        return 0

    assert run_main(main, []) == 128 + signum
    word = "interrupted (Ctrl-C)" if signum == signal.SIGINT else "terminated (SIGTERM)"
    assert capsys.readouterr().err == f"{word}: stopped; unfinished output removed\n"


def test_a_stop_dropped_before_the_commit_ends_the_tool_with_its_output_complete(tmp_path, capsys):
    out = tmp_path / "out"

    def main(_argv) -> int:
        with output_folder(out, "track") as staging:
            (staging / "summary.json").write_text("{}\n")
            signal_in_a_weakref_callback()
        return 0

    assert run_main(main, []) == 130
    assert capsys.readouterr().err == (
        f"interrupted (Ctrl-C): stopped; the output in {out} is complete\n"
    )
    assert [p.name for p in out.iterdir() if not p.name.startswith(".")] == ["summary.json"]


def test_other_unraisable_errors_are_still_shown(capsys):
    seen = []

    def main(_argv) -> int:
        thing = Thing()
        ref = weakref.ref(thing, lambda _ref: 1 / 0)
        del thing
        assert ref() is None
        return 0

    previous = sys.unraisablehook
    sys.unraisablehook = lambda report: seen.append(report.exc_type)
    try:
        assert run_main(main, []) == 0
    finally:
        sys.unraisablehook = previous
    assert seen == [ZeroDivisionError]


def test_a_tool_process_prints_no_exception_ignored_traceback(tmp_path: Path):
    (tmp_path / "tool.py").write_text(
        textwrap.dedent(
            """
            import signal, sys, weakref
            from ddwmmr.cli.common import run_main

            class Thing:
                pass

            def main(argv):
                thing = Thing()
                ref = weakref.ref(thing, lambda ref: signal.raise_signal(signal.SIGINT))
                del thing
                assert ref() is None
                return 0

            sys.exit(run_main(main, []))
            """
        )
    )
    done = run_tool(tmp_path)
    assert (done.returncode, done.stderr) == (130, INTERRUPTED + "\n")


def test_a_stop_while_the_tool_exits_says_its_output_is_complete(tmp_path: Path):
    """After the run (the process's ``atexit`` functions, a pool's end), the start guard
    says the line: the output the run completed is kept, and the line says so."""
    (tmp_path / "tool.py").write_text(
        textwrap.dedent(
            """
            import atexit, signal, sys
            from ddwmmr.cli.common import run_main
            from ddwmmr.cli.signals import guard_start
            from ddwmmr.outputs import output_folder

            guard_start()  # as the package does for a tool it starts

            def main(argv):
                with output_folder("out", "track") as staging:
                    (staging / "summary.json").write_text("{}\\n")
                return 0

            atexit.register(signal.raise_signal, signal.SIGINT)
            sys.exit(run_main(main, []))
            """
        )
    )
    done = run_tool(tmp_path)
    line = f"interrupted (Ctrl-C): stopped; the output in {tmp_path / 'out'} is complete\n"
    assert (done.returncode, done.stderr) == (130, line)
    assert (tmp_path / "out" / "summary.json").read_text() == "{}\n"


def test_an_error_after_a_dropped_stop_gives_way_to_the_stop(capsys):
    """What the code after a dropped stop raises (a process pool whose workers the
    handler stopped is broken) is not the tool's ending: the stop is."""

    def main(_argv) -> int:
        signal_in_a_weakref_callback()
        raise RuntimeError("a process in the process pool was terminated abruptly")

    assert run_main(main, []) == 130
    assert capsys.readouterr().err == INTERRUPTED + "\n"
