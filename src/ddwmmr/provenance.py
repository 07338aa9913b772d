"""What a tool records so a run can be repeated: the ``run`` record of its summary.

Every tool writes a record (``summary.json["run"]`` for track and scenarios, ``run.json``
for compare) with the tool, the package version, the git commit of the source when it is
a git checkout, the exact command line and working folder, and the tool's inputs in full:
method and every option with its default filled in, the robot (all fields), the
trajectory (its parameters, or its file's path and SHA-256), step, integrator, offset,
plant and seed. Values are JSON: tuples become lists, non-finite floats the strings
``"inf"``, ``"-inf"``, ``"nan"`` (:func:`decode` turns them back). The record of a
tracking run (:class:`RunInputs`, :func:`run_record`) is written by ``track`` and by the
simulator's data export alike, and read back by ``track --rerun``.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
import os
import shlex
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ddwmmr.controllers.base import method_options
from ddwmmr.errors import ParameterError, shown
from ddwmmr.model import Robot
from ddwmmr.outputs import package_version
from ddwmmr.trajectories.files import SHAPES, file_sha256
from ddwmmr.trajectories.sampled import SampledTrajectory, read_csv

#: Version of the record layout (bump when a key changes meaning).
RECORD_VERSION = 1
_NON_FINITE = {"inf": math.inf, "-inf": -math.inf, "nan": math.nan}


def encode(value: Any) -> Any:
    """A JSON-ready copy of ``value`` (see the module docstring); unknown objects: repr."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: encode(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): encode(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [encode(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return {"repr": repr(value)}


def decode(value: Any) -> Any:
    """Inverse of :func:`encode` for numbers: ``"inf"`` etc. back to floats."""
    if isinstance(value, dict):
        return {k: decode(v) for k, v in value.items()}
    if isinstance(value, list):
        return [decode(v) for v in value]
    if isinstance(value, str) and value in _NON_FINITE:
        return _NON_FINITE[value]
    return value


#: ``git_note`` when the package is not ``<top>/src/ddwmmr`` of a git work tree.
NOT_A_CHECKOUT = "installed package, not a git checkout: no commit to record"


def git_record() -> dict[str, Any]:
    """``{"git": {"commit", "dirty"}}`` of the source checkout this package runs from, or
    ``{"git": None, "git_note": why}``.

    Only when the package is ``<top>/src/ddwmmr`` of a git work tree (an editable
    install) is there a commit: an installed wheel has none (:data:`NOT_A_CHECKOUT`), and
    a checkout where git cannot run says so.
    """
    package = Path(__file__).resolve().parent  # this module sits in the package itself
    top = package.parents[1]
    if package != top / "src" / "ddwmmr" or not (top / ".git").exists():
        return {"git": None, "git_note": NOT_A_CHECKOUT}
    try:
        commit = _git(top, "rev-parse", "HEAD")
        status = _git(top, "status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.SubprocessError) as exc:
        return {"git": None, "git_note": f"a git checkout, but git could not run ({exc})"}
    return {"git": {"commit": commit, "dirty": bool(status)}}


def _git(top: Path, *arguments: str) -> str:
    done = subprocess.run(
        ["git", "-C", str(top), *arguments],
        capture_output=True,
        text=True,
        timeout=10,
        check=True,
    )
    return done.stdout.strip()


def command_record(prog: str, argv: Sequence[str] | None) -> dict[str, Any]:
    """The exact command line (``argv`` as given, or ``sys.argv[1:]``) and working folder."""
    arguments = list(argv if argv is not None else sys.argv[1:])
    return {
        "command": shlex.join([*shlex.split(prog), *arguments]),
        "argv": arguments,
        "cwd": os.getcwd(),
    }


def header(tool: str, prog: str, argv: Sequence[str] | None) -> dict[str, Any]:
    """The start of every record: tool, versions, commit, command line."""
    return {
        "record_version": RECORD_VERSION,
        "tool": tool,
        "version": package_version(),
        **git_record(),
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        **command_record(prog, argv),
    }


def robot_record(robot: Robot) -> dict[str, Any]:
    """Every constructor field of the robot (payload included)."""
    return {f.name: encode(getattr(robot, f.name)) for f in dataclasses.fields(robot) if f.init}


#: Robot fields every run record has named since records began (later fields, e.g. the
#: physics plant's, take their defaults in older records, as the version that wrote
#: them had no such field).
RECORDED_ROBOT_FIELDS = (
    "L1", "L2", "wheel_radius", "track_width", "base_length", "base_width", "base_mass",
    "base_inertia", "link_masses", "payload", "joint_limits", "joint_speed_limit",
    "wheel_speed_limit", "home_pose",
)  # fmt: skip


def robot_from_record(record: dict[str, Any]) -> Robot:
    """The robot a :func:`robot_record` describes; a record without one of the
    :data:`RECORDED_ROBOT_FIELDS` is incomplete, not a request for the default."""
    missing = [name for name in RECORDED_ROBOT_FIELDS if name not in record]
    if missing:
        raise ParameterError(f"the robot record lacks {', '.join(missing[:3])}")
    return Robot.from_dict(decode(record))


def options_record(method: str, given: dict[str, Any]) -> dict[str, Any]:
    """Every option of ``method``: the given value, else its default."""
    defaults = method_options(method)
    merged = {k: v for k, v in defaults.items() if v is not inspect.Parameter.empty}
    merged.update(given)
    return encode(merged)


def trajectory_record(
    trajectory: Any, source: Path | None, sha256: str | None = None
) -> dict[str, Any]:
    """Parameters of a parametric trajectory, and the file it was read from (path and
    SHA-256: ``sha256`` if given, the digest recorded when it was read, else the file's
    now)."""
    record: dict[str, Any] = {"name": str(getattr(trajectory, "name", ""))}
    if source is not None:
        record["file"] = str(Path(source).resolve())
        record["sha256"] = sha256 if sha256 is not None else file_sha256(source)
    shape = next((k for k, cls in SHAPES.items() if type(trajectory) is cls), None)
    if shape is not None:
        record["type"] = shape
        record["parameters"] = encode(trajectory)
    elif isinstance(trajectory, SampledTrajectory):
        record["type"] = "samples"
    else:
        record["type"] = type(trajectory).__name__
    return record


def trajectory_from_record(record: dict[str, Any]) -> Any:
    """The trajectory a :func:`trajectory_record` describes (a changed file is an error)."""
    kind = record.get("type")
    if kind in SHAPES:
        return SHAPES[kind](**decode(record["parameters"]))
    if kind == "samples":
        path = Path(record["file"])
        if not path.exists():
            raise ParameterError(f"the trajectory file {path} is gone")
        if not path.is_file():  # checked before hashing: a FIFO would block the read
            now = "a folder" if path.is_dir() else "not a regular file"
            raise ParameterError(f"the trajectory file {path} is now {now}")
        if file_sha256(path) != record["sha256"]:
            raise ParameterError(
                f"the trajectory file {path} changed since the run (SHA-256 differs)"
            )
        return read_csv(path)
    raise ParameterError(f"cannot rebuild a trajectory of type {shown(kind)}")


@dataclass
class RunInputs:
    """Everything a tracking run simulates (from a tool's options, or from a record)."""

    method: str
    options: dict[str, Any]
    robot: Robot
    trajectory: Any
    trajectory_file: Path | None
    dt: float
    duration: float
    integrator: str | None
    offset: tuple[float, float]
    label: str  # trajectory as the user named it (for the default folder name)
    plant: str
    # A rerun's: the file's digest as the first run read it. Its trajectory is rebuilt
    # from the record, so the file may since have changed or gone.
    trajectory_sha256: str | None = None


def run_record(
    inputs: RunInputs,
    argv: Sequence[str] | None,
    rerun: str | None,
    tool: str,
    prog: str,
) -> dict:
    """What summary.json["run"] holds: enough to repeat the run (``--rerun``); ``tool``
    and ``prog`` name what wrote it (the simulator's export writes the same record)."""
    record = header(tool, prog, argv)
    record.update(
        method=inputs.method,
        options=options_record(inputs.method, inputs.options),
        robot=robot_record(inputs.robot),
        trajectory=trajectory_record(
            inputs.trajectory, inputs.trajectory_file, inputs.trajectory_sha256
        ),
        dt=inputs.dt,
        duration=inputs.duration,
        integrator=inputs.integrator,
        initial_offset=list(inputs.offset),
        plant={"name": inputs.plant},
        seed=None,  # nothing random in a track run
    )
    if rerun is not None:
        record["rerun_of"] = str(Path(rerun).resolve())
    return record
