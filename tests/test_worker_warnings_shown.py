"""A pool worker does not repeat a warning line its parent's display has already shown,
whatever the start method: a display that keeps its shown lines (``workers.SHOWN``) hands
them to the workers (a forked worker holds a copy anyway; a spawned one starts afresh)."""

from __future__ import annotations

import textwrap

import pytest

from test_workers_warnings import run_script

SCRIPT = textwrap.dedent(
    """
    import multiprocessing, sys, warnings
    from ddwmmr.workers import IN_WORKERS, SHOWN, process_pool

    def install():
        shown = set()

        def show(message, category, filename, lineno, file=None, line=None):
            if str(message) not in shown:
                shown.add(str(message))
                print(message, file=sys.stderr, flush=True)

        setattr(show, IN_WORKERS, install)
        setattr(show, SHOWN, shown)
        warnings.showwarning = show

    def warn(*texts):
        for text in texts:  # no registry: Python's filter would show each every time
            warnings.warn_explicit(text, UserWarning, "lib.py", 1)

    if __name__ == "__main__":
        install()
        warn("about the robot")  # the parent says it before the pool starts
        with process_pool(1, multiprocessing.get_context(sys.argv[1])) as pool:
            pool.submit(warn, "about the robot", "from a run", "from a run").result()
    """
)


@pytest.mark.parametrize("method", ["spawn", "forkserver"])
def test_a_worker_does_not_repeat_a_line_its_parent_showed(tmp_path, method):
    done = run_script(tmp_path, "once.py", SCRIPT, method)
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines() == ["about the robot", "from a run"]
