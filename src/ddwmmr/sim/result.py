"""Simulation results: time series and summary metrics, and their files."""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ddwmmr.errors import ParameterError, shown
from ddwmmr.outputs import write_atomic


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
        """Write the time series as CSV to ``path``, atomically, with
        :func:`write_atomic`: an existing regular file is replaced, a folder, device or
        FIFO is refused, missing parent folders are created."""
        buffer = io.StringIO()
        writer = csv.writer(buffer)
        columns = list(self.timeseries)
        writer.writerow(columns)
        for row in zip(*(self.timeseries[c].tolist() for c in columns)):
            writer.writerow([_format(v) for v in row])
        write_atomic(path, buffer.getvalue())

    def write_summary(self, path: str | Path, **extra: Any) -> None:
        """Write the summary as JSON to ``path``, with ``extra`` keys (e.g. ``run``),
        atomically, with :func:`write_atomic` (as :meth:`write_csv`). A value JSON cannot
        hold (an object, a set; numpy scalars and non-finite floats are converted,
        :func:`json_safe`) is a one-line :class:`ParameterError` naming its key, before
        anything is written."""
        data = json_safe({**self.summary, **extra})
        try:
            text = json.dumps(data, indent=2)
        except (TypeError, ValueError, RecursionError) as exc:  # ValueError: a cycle
            raise _unserialisable(data) from exc
        write_atomic(path, text + "\n")


def _unserialisable(data: dict[str, Any]) -> ParameterError:
    """The refusal naming the first key of ``data`` whose value ``json.dumps`` fails on."""
    for key, value in data.items():
        try:
            json.dumps({key: value})
        except (TypeError, ValueError, RecursionError):
            return ParameterError(
                f"summary: {key} must be JSON data (numbers, text, true/false, None, lists "
                f"and dicts of them) (got {shown(value, 60)})"
            )
    return ParameterError("summary: the keys must be text")  # pragma: no cover


def _format(value: float) -> str:
    return repr(float(value)) if isinstance(value, float) else str(value)


def json_safe(value: Any, undefined_as_null: bool = False) -> Any:
    """Convert numpy scalars and non-finite floats for JSON output: the floats as strings
    (``"nan"``, ``"inf"``), or as None with ``undefined_as_null``."""
    if isinstance(value, dict):
        return {k: json_safe(v, undefined_as_null) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v, undefined_as_null) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None if undefined_as_null else str(value)
    return value
