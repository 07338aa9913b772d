"""Simulation results: time series and summary metrics, and their files."""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

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

    def __repr__(self) -> str:
        """The run in one line: method, trajectory, plant, steps, RMS position error and
        verdict (the time series' arrays are left out: thousands of numbers each)."""
        keys = ("method", "trajectory", "plant", "steps", "rms_position_error_m", "verdict")
        fields = [f"{key}={self.summary[key]!r}" for key in keys if key in self.summary]
        fields.append(f"timeseries=<{len(self.timeseries)} columns>")
        return f"{type(self).__name__}({', '.join(fields)})"

    def configurations(self) -> np.ndarray:
        """(n, 5) array of configurations q."""
        return np.column_stack([self.timeseries[k] for k in ("x", "y", "phi", "th1", "th2")])

    def write_csv(self, path: str | Path) -> None:
        """Write the time series as CSV to ``path``, atomically, with
        :func:`write_atomic`: an existing regular file is replaced, a folder, device or
        FIFO is refused, missing parent folders are created. The text goes to the file
        :data:`CSV_BLOCK` rows at a time (:func:`write_csv_rows`): a million-sample run's
        half a gigabyte of text is never held whole."""
        write_atomic(path, self.stream_csv)

    def stream_csv(self, handle: BinaryIO) -> None:
        """Write the bytes of :meth:`write_csv`'s file into the binary ``handle``, piece by
        piece (:func:`write_csv_rows`): the writer :func:`write_atomic` and
        :func:`~ddwmmr.outputs.write_new` take."""
        write_csv_rows(self.timeseries, handle)

    def write_summary(self, path: str | Path, **extra: Any) -> None:
        """Write the summary as JSON to ``path``, with ``extra`` keys (e.g. ``run``),
        atomically, with :func:`write_atomic` (as :meth:`write_csv`). A value JSON cannot
        hold (an object, a set; numpy scalars and non-finite floats are converted,
        :func:`json_safe`), or an extra key the summary has already (``verdict``: the
        file would not say what the run did), is a one-line :class:`ParameterError`
        naming the key, before anything is written."""
        write_atomic(path, self.summary_text(**extra))

    def summary_text(self, **extra: Any) -> str:
        """The text of :meth:`write_summary`'s file (JSON, indented, ending in a newline),
        with its refusals."""
        taken = next((key for key in extra if key in self.summary), None)
        if taken is not None:
            raise ParameterError(
                f"summary: the extra key {taken!r} is one of the run's own summary keys; give "
                "it another name"
            )
        data = json_safe({**self.summary, **extra})
        try:
            text = json.dumps(data, indent=2)
        except (TypeError, ValueError, RecursionError) as exc:  # ValueError: a cycle
            raise _unserialisable(data) from exc
        return text + "\n"


#: Rows of a time series formatted and written together by :func:`write_csv_rows`.
CSV_BLOCK = 8192


def write_csv_rows(timeseries: dict[str, np.ndarray], handle: BinaryIO) -> None:
    """Write ``timeseries`` (column name -> 1-D array, all of one length) as CSV text
    (UTF-8, ``\\r\\n`` line ends, floats as ``repr``) into the binary ``handle``: the
    header, then :data:`CSV_BLOCK` rows per ``handle.write``."""
    columns = list(timeseries)
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(columns)
    handle.write(buffer.getvalue().encode("utf-8"))
    rows = min((len(timeseries[c]) for c in columns), default=0)
    for start in range(0, rows, CSV_BLOCK):
        buffer = io.StringIO()
        writer = csv.writer(buffer)
        block = (timeseries[c][start : start + CSV_BLOCK].tolist() for c in columns)
        writer.writerows([_format(v) for v in row] for row in zip(*block))
        handle.write(buffer.getvalue().encode("utf-8"))


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
