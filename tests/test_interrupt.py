"""Ctrl-C while a tool starts: one line, status 130, no traceback, from the moment the
package is imported (the package's exports load on first use, and the tool's start guard,
``ddwmmr.cli.signals.guard_start``, is in place before the heavy imports begin).

The tools run as a user runs them (``python -m``, a console script, from a terminal:
SIGINT at its default, however the suite was started), in subprocesses; the signal is
sent while they import numpy and the rest, or 0.2 s after they begin to.
"""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import ddwmmr
from ddwmmr.__main__ import TOOLS
from terminal_signals import FROM_A_TERMINAL, end

#: Arguments that would keep each tool busy for a long time after its imports.
BUSY = {
    "track": ["--method", "ats", "--traj", "ellipse", "--duration", "20000", "--no-plots",
              "--no-progress", "--out", "out"],
    "compare": ["--methods", "ats", "--only", "ellipse", "--study", "none", "--duration",
                "4000", "--no-progress", "--out", "out"],
    "scenarios": ["--n", "60", "--jobs", "1", "--no-progress", "--out", "out"],
    "bench": ["--jobs", "1", "--no-progress", "--out", "out.json"],
    "bounds": ["--quick", "--jobs", "1", "--no-progress", "--out", "out"],
    "gui": ["--snapshot", "out.png"],
}  # fmt: skip
#: The file numpy's import maps first: once it is there, the tool is importing.
NUMPY_CORE = "_multiarray_umath"
INTERRUPTED = "interrupted (Ctrl-C): stopped; unfinished output removed"


def start(command: list[str], folder: Path) -> subprocess.Popen:
    return subprocess.Popen(
        command,
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "MPLBACKEND": "Agg"},
        **FROM_A_TERMINAL,
    )


def importing_numpy(pid: int) -> bool:
    try:
        return NUMPY_CORE in Path(f"/proc/{pid}/maps").read_text()
    except OSError:  # gone
        return True


def interrupt(processes: list[subprocess.Popen], when: str) -> None:
    """SIGINT to each of ``processes`` once it maps numpy (``when="numpy"``), or 0.2 s
    after that (``"0.2 s later"``: later in the imports, or just after them on a fast
    machine). Timed from numpy, not from the start: on a loaded machine a fixed time can
    fall in Python's own start-up, before the package is reached."""
    delay = 0.0 if when == "numpy" else 0.2
    due: dict[int, float] = {}  # index into processes -> when to send
    sent: set[int] = set()
    deadline = time.monotonic() + 30.0
    while len(sent) < len(processes):
        now = time.monotonic()
        for i, process in enumerate(processes):
            if i not in due and importing_numpy(process.pid):
                due[i] = now + delay
            if i in due and i not in sent and due[i] <= now:
                process.send_signal(signal.SIGINT)
                sent.add(i)
        assert now < deadline, "the tools did not start importing numpy"
        time.sleep(0.002)


def check_stopped(process: subprocess.Popen, label: str) -> None:
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, f"{label}: status {process.returncode}\n{err}"
    assert "Traceback" not in err, f"{label}:\n{err}"
    assert err.strip().splitlines() == [INTERRUPTED], f"{label}:\n{err}"


@pytest.mark.skipif(not Path("/proc/self/maps").exists(), reason="reads /proc")
@pytest.mark.parametrize("when", ["numpy", "0.2 s later"])
def test_ctrl_c_while_every_tool_starts(tmp_path, when):
    """All six tools at once (a few seconds in all): each is interrupted in its imports."""
    running = []
    try:
        for tool, arguments in BUSY.items():
            folder = tmp_path / tool
            folder.mkdir()
            command = [sys.executable, "-m", f"ddwmmr.{tool}", *arguments]
            running.append((tool, folder, start(command, folder)))
        interrupt([process for _, _, process in running], when)
        for tool, folder, process in running:
            check_stopped(process, tool)
            assert list(folder.iterdir()) == [], tool
    finally:  # a failed check leaves none of the busy tools running
        end(*(process for _, _, process in running))


def test_ctrl_c_while_a_console_script_starts(tmp_path):
    script = Path(sys.executable).with_name("ddwmmr-track")
    if not script.exists():
        pytest.skip("the console scripts are not installed")
    process = start([str(script), *BUSY["track"]], tmp_path)
    try:
        interrupt([process], "numpy")
        check_stopped(process, "ddwmmr-track")
    finally:
        end(process)


def run_python(code: str, *options: str, **popen) -> list[str]:
    out = subprocess.run(
        [sys.executable, *options, "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        **popen,
    )
    assert out.returncode == 0, out.stderr
    return out.stdout.split()


def test_import_ddwmmr_is_light_and_leaves_the_signals_alone():
    """``import ddwmmr`` imports neither numpy nor CasADi and installs no signal handler
    (a library's import must not); the first public name used imports its module. Started
    as from a terminal: Python's own SIGINT handler is there to be left alone."""
    code = (
        "import signal, sys; import ddwmmr; "
        "print('numpy' in sys.modules, 'casadi' in sys.modules, "
        "signal.getsignal(signal.SIGINT) is signal.default_int_handler, "
        "signal.getsignal(signal.SIGTERM) is signal.SIG_DFL); "
        "ddwmmr.Robot; print('numpy' in sys.modules)"
    )
    assert run_python(code, **FROM_A_TERMINAL) == ["False", "False", "True", "True", "True"]


def test_every_public_name_resolves():
    code = (
        "from ddwmmr import *; import ddwmmr; "
        "print(all(name in globals() for name in ddwmmr.__all__))"
    )
    assert run_python(code) == ["True"]
    for name in ddwmmr.__all__:
        assert getattr(ddwmmr, name) is not None, name
    assert set(ddwmmr.__all__) <= set(dir(ddwmmr))
    assert ddwmmr.Robot is __import__("ddwmmr.model", fromlist=["Robot"]).Robot
    with pytest.raises(AttributeError, match="no attribute 'Robbot'"):
        _ = ddwmmr.Robbot


def test_the_lazy_exports_match_the_typing_imports():
    """What type checkers see (the ``TYPE_CHECKING`` imports) is what ``__getattr__``
    imports, and together with ``__version__`` it is ``__all__``."""
    tree = ast.parse(Path(ddwmmr.__file__).read_text())
    guarded = next(
        node
        for node in tree.body
        if isinstance(node, ast.If) and getattr(node.test, "id", None) == "TYPE_CHECKING"
    )
    typed = {
        alias.name: node.module
        for node in guarded.body
        if isinstance(node, ast.ImportFrom)
        for alias in node.names
    }
    assert typed == ddwmmr._EXPORTS
    assert sorted([*typed, "__version__"]) == sorted(ddwmmr.__all__)


def test_the_tool_list_starts_without_a_warning():
    """``python -m ddwmmr`` (the list of tools) is no tool: its package does not import
    its ``__main__`` early (runpy would warn)."""
    out = subprocess.run(
        [sys.executable, "-W", "error", "-m", "ddwmmr"], capture_output=True, text=True
    )
    assert out.returncode == 0 and out.stderr == ""
    assert len(out.stdout.splitlines()) == len(TOOLS) + 1


DASK_WORKER_MASK = """
import os, signal
from pathlib import Path
from ddwmmr.scenarios.executors import DaskWorkers

with DaskWorkers(1) as client:
    pid = next(iter(client.run(os.getpid).values()))
    status = Path(f"/proc/{pid}/status").read_text()
blocked = int(next(l for l in status.splitlines() if l.startswith("SigBlk:")).split()[1], 16)
print(*(bool(blocked >> (s - 1) & 1) for s in (signal.SIGINT, signal.SIGHUP, signal.SIGQUIT)))
"""


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc")
def test_dask_workers_do_not_take_the_terminals_signals():
    """The LocalCluster's worker processes block SIGINT as well as SIGHUP and SIGQUIT: a
    Ctrl-C while they import printed their tracebacks. In a fresh process: the resource
    tracker must not be running yet, as in a tool."""
    pytest.importorskip("distributed")
    assert run_python(DASK_WORKER_MASK) == ["True", "True", "True"]


def test_a_spawned_worker_of_a_tool_is_no_tool():
    """multiprocessing's spawn gives a worker its tool's ``sys.argv`` (here a console
    script's) before the worker imports the package: it must not install the tool's guard,
    or each worker the tool stops would say a line of its own."""
    script = str(Path(sys.executable).with_name("ddwmmr-scenarios"))
    code = (
        f"import signal, sys; sys.argv = [{script!r}, '--executor', 'dask']; import ddwmmr; "
        "print(signal.getsignal(signal.SIGTERM) is signal.SIG_DFL)"
    )
    assert run_python(code) == ["True"]
