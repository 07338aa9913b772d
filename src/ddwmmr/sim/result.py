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

from ddwmmr.outputs import check_file_target, existing_folder, file_mode, folder_mode


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
        atomically, with :func:`write_atomic` (as :meth:`write_csv`)."""
        write_atomic(path, json.dumps(json_safe({**self.summary, **extra}), indent=2) + "\n")


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


def write_atomic(path: str | os.PathLike[str], data: str | bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and an atomic rename.

    ``path`` must be a non-empty ``str`` or :class:`os.PathLike`; if something exists
    there it must be a regular file, which is replaced. A folder, a device (``/dev/null``),
    a FIFO or a socket is refused with a one-line
    :class:`~ddwmmr.errors.ParameterError` naming the path before anything is created:
    the rename would put a regular file in its place (see
    :func:`ddwmmr.outputs.check_file_target`). Missing parent folders are created, as
    ``mkdir -p`` would (the tools rely on it: the GUI's ``--snapshot figs/run.png``, the
    bench's ``--out``, the per-run sub-folders of a GUI export); a path through something
    that is not a folder is refused.
    Failures of the write itself (permission, full disk) raise :class:`OSError`.

    The file gets the user's umask (``0644`` for umask 022), like any normal file, not
    the ``0600`` of the temporary file; text is written as UTF-8.
    """
    path = check_file_target(path)
    existing_folder("path", path.parent)
    path.parent.mkdir(parents=True, exist_ok=True, mode=folder_mode())
    payload = data if isinstance(data, bytes) else data.encode("utf-8")
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".ddwmmr-", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            os.fchmod(handle.fileno(), file_mode())
            handle.write(payload)
        # Once more just before the rename: a FIFO or folder made there during the write
        # would be replaced as well.
        check_file_target(path)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
