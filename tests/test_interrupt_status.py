"""A Ctrl-C that surfaces through code run by ``exec`` of a string still ends a tool with
status 130 (CPython would otherwise end the process by SIGINT at exit)."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
import time

import pytest

from terminal_signals import FROM_A_TERMINAL, end


@pytest.mark.skipif(not hasattr(signal, "SIGINT"), reason="needs SIGINT")
def test_a_ctrl_c_inside_exec_code_still_exits_130(tmp_path):
    tool = tmp_path / "slow_tool.py"
    tool.write_text(
        textwrap.dedent(
            """
            import sys, time
            from ddwmmr.cli.common import run_main

            def main(argv):
                print("ready", flush=True)
                # as a dataclass's generated methods run while a module imports
                exec("import time\\nwhile True: time.sleep(0.01)")
                return 0

            sys.exit(run_main(main, []))
            """
        )
    )
    process = subprocess.Popen(
        [sys.executable, "-m", "slow_tool"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **FROM_A_TERMINAL,  # Ctrl-C in a terminal: SIGINT at its default
    )
    try:
        assert process.stdout.readline().strip() == "ready"
        time.sleep(0.1)
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=30)
    finally:
        end(process)
    assert process.returncode == 130, err
    assert err.strip() == "interrupted (Ctrl-C): stopped; unfinished output removed"
