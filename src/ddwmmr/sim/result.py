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

    def write_summary(self, path: str | Path) -> None:
        """Write the summary as JSON (atomically)."""
        write_atomic(path, json.dumps(json_safe(self.summary), indent=2) + "\n")


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
    """Write ``data`` to ``path`` through a temporary file and an atomic rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    mode = "wb" if isinstance(data, bytes) else "w"
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, mode) as handle:
            handle.write(data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
