"""Running ``python -m ddwmmr.scenarios`` with bad input, as the CLI tests do."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def bad_scenarios_run(tmp_path: Path, args: list[str]) -> str:
    """Run the scenarios tool with ``args`` and ``--out tmp_path/bad``; check that it
    exits with status 2, prints one line and no traceback, and writes nothing. Returns
    the line."""
    out = tmp_path / "bad"
    result = subprocess.run(
        [sys.executable, "-m", "ddwmmr.scenarios", *args, "--out", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []
    return lines[0]
