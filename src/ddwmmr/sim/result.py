"""Simulation results: time series, summary metrics, atomic file output."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ddwmmr.outputs import file_mode, folder_mode


@dataclass
class SimulationResult:
    """Outcome of :func:`ddwmmr.simulate`.

    Attributes:
        timeseries: column name -> 1-D array, one entry per recorded instant (steps + 1).
        summary: scalar metrics (see ``docs/cli.md`` for the meaning of each key).
        robot, trajectory, controller: what was simulated.
    """

    timeseries: dict[str, np.ndarray]
    summary: dict[str, Any]
    robot: Any = None
    trajectory: Any = None
    controller: Any = field(default=None, repr=False)

    def configurations(self) -> np.ndarray:
        """(n, 5) array of configurations q."""
        return np.column_stack([self.timeseries[k] for k in ("x", "y", "phi", "th1", "th2")])

    def write_csv(self, path: str | Path) -> None:
        """Write the time series as CSV (atomically)."""
        buffer = io.StringIO()
        writer = csv.writer(buffer)
        columns = list(self.timeseries)
        writer.writerow(columns)
        for row in zip(*(self.timeseries[c].tolist() for c in columns)):
            writer.writerow([_format(v) for v in row])
        write_atomic(path, buffer.getvalue())

    def write_summary(self, path: str | Path, **extra: Any) -> None:
        """Write the summary as JSON (atomically), with ``extra`` keys (e.g. ``run``)."""
        write_atomic(path, json.dumps(json_safe({**self.summary, **extra}), indent=2) + "\n")


def _format(value: float) -> str:
    return repr(float(value)) if isinstance(value, float) else str(value)


def json_safe(value: Any) -> Any:
    """Convert numpy scalars and non-finite floats (as strings) for JSON output."""
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def write_atomic(path: str | Path, data: str | bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and an atomic rename.

    The file gets the user's umask (``0644`` for umask 022), like any normal file, not
    the ``0600`` of the temporary file; text is written as UTF-8.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True, mode=folder_mode())
    payload = data if isinstance(data, bytes) else data.encode("utf-8")
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".ddwmmr-", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            os.fchmod(handle.fileno(), file_mode())
            handle.write(payload)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
