"""Running the scenarios tool with bad input, as the CLI tests do: in a fresh
``python -m ddwmmr.scenarios`` process, or in-process through its ``main(argv)``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from ddwmmr.cli.scenarios import main
from in_process import call_main


def _checked(tmp_path: Path, out: Path, status: object, stderr: str) -> str:
    """Check exit status 2, one line on stderr, no traceback and nothing written below
    ``tmp_path``; return the line."""
    assert status == 2, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert "Traceback" not in stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []
    return lines[0]


def bad_scenarios_run(tmp_path: Path, args: list[str]) -> str:
    """Run ``python -m ddwmmr.scenarios`` with ``args`` and ``--out tmp_path/bad``; check
    that it exits with status 2, prints one line and no traceback, and writes nothing.
    Returns the line."""
    out = tmp_path / "bad"
    result = subprocess.run(
        [sys.executable, "-m", "ddwmmr.scenarios", *args, "--out", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    return _checked(tmp_path, out, result.returncode, result.stderr)


def bad_scenarios_main(tmp_path: Path, args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """As :func:`bad_scenarios_run`, through ``main(argv)`` in this process: an exception
    ``main`` lets out fails the test, as a traceback on a real stderr would."""
    out = tmp_path / "bad"
    capsys.readouterr()  # only this run's output
    status, _, err = call_main(main, [*args, "--out", str(out)], capsys)
    return _checked(tmp_path, out, status, err)
