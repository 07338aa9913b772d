"""What a tool records so a run can be repeated: the ``run`` record of its summary.

Every tool writes a record (``summary.json["run"]`` for track and scenarios, ``run.json``
for compare) with the tool, the package version, the git commit of the source when it is
a git checkout, a command that repeats the run and the working folder, what decides the
last bits of the numbers (the numerical libraries' versions, NumPy's and SciPy's BLAS and
the CPU: :func:`numerics_record`), and the tool's inputs in full: method and every option
with its default filled in, the robot (all fields), the trajectory (its parameters, or
its file's path and SHA-256), step, integrator, offset,
plant and seed. Values are JSON: tuples become lists, non-finite floats the strings
``"inf"``, ``"-inf"``, ``"nan"`` (:func:`decode` turns them back). The record of a
tracking run (:class:`RunInputs`, :func:`run_record`) is written by ``track`` and by the
simulator's data export alike, and read back by ``track --rerun``.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import importlib
import importlib.metadata
import inspect
import math
import os
import platform
import re
import shlex
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ddwmmr.controllers.base import method_options
from ddwmmr.errors import ParameterError, one_line, shown
from ddwmmr.model import Robot
from ddwmmr.outputs import package_version
from ddwmmr.registry import PLUGINS_VARIABLE, plugin_modules, script_note, used_plugins
from ddwmmr.trajectories.files import (
    SHAPES,
    check_shape_keys,
    file_sha256,
    is_name,
    package_folder,
    shape_keys,
)
from ddwmmr.trajectories.sampled import SampledTrajectory, read_csv
from ddwmmr.trajectories.scaled import ScaledTrajectory, check_scale
from ddwmmr.user_warnings import warn_user

#: Version of the record layout (bump when a key changes meaning).
RECORD_VERSION = 1
#: The command of the tracking tool: what a tracking run's record (:func:`run_record`)
#: gives as the command that repeats it, whichever tool wrote the record.
TRACK_PROG = "python -m ddwmmr.track"
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


def command_record(
    prog: str, argv: Sequence[str] | None, plugins: Mapping[str, Mapping[str, str]] | None = None
) -> dict[str, Any]:
    """``command``: a command that repeats the run, ``prog`` (the tool's ``python -m``
    form, also when the run was started by its console script) and the arguments, quoted
    for this platform's shell (POSIX ``sh``; ``cmd.exe`` on Windows), after the setting
    of ``DDWMMR_PLUGINS`` to the modules of ``plugins`` when the run used a plug-in
    (:func:`ddwmmr.registry.used_plugins`; ``DDWMMR_PLUGINS=p_only python -m ...``);
    ``command_note``, only when a plug-in was registered by a script in its own
    ``__main__``, which no setting loads: what the command needs besides
    (:func:`ddwmmr.registry.script_note`); ``argv``: the arguments as given (``argv``, or
    ``sys.argv[1:]``); ``cwd``: the working folder; ``plugins``: the plug-ins, only when
    there are any (a run of the built-ins has the record it had before plug-ins were
    recorded)."""
    arguments = list(argv if argv is not None else sys.argv[1:])
    words = [*shlex.split(prog), *arguments]
    # cmd.exe passes single quotes on literally: Windows gets its own quoting
    command = subprocess.list2cmdline(words) if os.name == "nt" else shlex.join(words)
    modules = ",".join(plugin_modules(plugins or {}))
    if modules and os.name == "nt":
        command = f'set "{PLUGINS_VARIABLE}={modules}" && {command}'
    elif modules:
        command = f"{PLUGINS_VARIABLE}={shlex.quote(modules)} {command}"
    record: dict[str, Any] = {"command": command}
    note = script_note(plugins or {})
    if note:
        record["command_note"] = note
    record.update(argv=arguments, cwd=os.getcwd())
    if plugins:
        record["plugins"] = {label: dict(named) for label, named in plugins.items()}
    return record


def header(
    tool: str,
    prog: str,
    argv: Sequence[str] | None,
    plugins: Mapping[str, Mapping[str, str]] | None = None,
) -> dict[str, Any]:
    """The start of every record: tool, versions, commit, the command that repeats the
    run and the plug-ins it used (:func:`command_record`), and what decides the last bits
    of the numbers (:func:`numerics_record`)."""
    return {
        "record_version": RECORD_VERSION,
        "tool": tool,
        "version": package_version(),
        **git_record(),
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        **numerics_record(),
        **command_record(prog, argv, plugins),
    }


#: The numerical libraries a run's numbers pass through (solvers, LQR design, physics),
#: recorded with their versions where installed.
NUMERIC_LIBRARIES = ("casadi", "scipy", "control", "daqp", "mujoco", "qpsolvers", "osqp")

#: Environment variables that choose OpenBLAS's or MKL's kernels in place of the CPU's own.
BLAS_VARIABLES = ("OPENBLAS_CORETYPE", "MKL_CBWR", "MKL_ENABLE_INSTRUCTIONS")


def numerics_record() -> dict[str, Any]:
    """``{"libraries", "blas", "machine"}``: what, beside the inputs, decides a run's last
    bits. The same record on the same machine gives the same numbers bit for bit; another
    BLAS kernel (another CPU, or one chosen by :data:`BLAS_VARIABLES`) sums in another order,
    and the numbers then differ by rounding (docs/cli.md, "Repeating a run").

    ``libraries``: ``{name: version}`` of the installed :data:`NUMERIC_LIBRARIES`;
    ``blas``: NumPy's and SciPy's BLAS as their builds describe it (name, version,
    configuration; None where the build does not say) and the :data:`BLAS_VARIABLES` that
    are set; ``machine``: operating system, architecture and CPU model. Read once per
    process, as none of it changes while a process runs, the variables aside,
    which BLAS reads once as it loads.
    """
    return copy.deepcopy(_numerics())  # a copy: a caller may edit its record


@functools.cache
def _numerics() -> dict[str, Any]:
    libraries = {}
    for name in NUMERIC_LIBRARIES:
        try:
            libraries[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            continue
    blas: dict[str, Any] = {"numpy": _blas_of("numpy"), "scipy": _blas_of("scipy")}
    blas.update({k: os.environ[k] for k in BLAS_VARIABLES if k in os.environ})
    machine = {"system": platform.system(), "machine": platform.machine(), "cpu": _cpu()}
    return {"libraries": libraries, "blas": blas, "machine": machine}


def _blas_of(package: str) -> str | None:
    """The BLAS ``package``'s build links, as its ``show_config`` reports it, or None."""
    try:
        config = importlib.import_module(f"{package}.__config__").CONFIG
        blas = config["Build Dependencies"]["blas"]
    except (ImportError, AttributeError, KeyError, TypeError):
        return None
    text = blas.get("openblas configuration") or " ".join(
        str(blas.get(k, "")) for k in ("name", "version")
    )
    return str(text).strip() or None


def _cpu() -> str:
    """The CPU's model name (``/proc/cpuinfo`` on Linux), else what :mod:`platform` says."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as info:
            for line in info:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Processor", "cpu model"):
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def software_differences(record: dict[str, Any]) -> list[str]:
    """What of the software and machine a ``record`` names differs from this process's:
    ``"numpy 1.26.4 -> 2.4.6"`` per difference, over the package version, git commit,
    Python, NumPy, the :data:`NUMERIC_LIBRARIES`, BLAS and CPU. A key the record lacks
    (written before it was recorded) is not compared."""
    now = header("", "", [])
    pairs: list[tuple[str, Any, Any]] = [
        (k, record.get(k), now[k]) for k in ("version", "python", "numpy") if k in record
    ]
    if "git" in record:
        pairs.append(("commit", _commit(record["git"]), _commit(now["git"])))
    for section, prefix in (("libraries", ""), ("blas", "blas.")):
        was = record.get(section)
        if isinstance(was, dict):
            names = [*was, *(k for k in now[section] if k not in was)]
            pairs += [(prefix + one_line(k, 40), was.get(k), now[section].get(k)) for k in names]
    machine = record.get("machine")
    if isinstance(machine, dict):
        pairs.append(("cpu", machine.get("cpu"), now["machine"]["cpu"]))
    return [f"{k} {_shown(a)} -> {_shown(b)}" for k, a, b in pairs if a != b]


def _commit(git: Any) -> Any:
    return git.get("commit") if isinstance(git, dict) else None


def _shown(value: Any) -> str:
    """A recorded or current value for the note: a text as it is, on one line."""
    if value is None:
        return "none"
    return one_line(value, 90) if isinstance(value, str) else shown(value)


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
    record: dict[str, Any] = encode(merged)
    return record


def trajectory_record(
    trajectory: Any, source: Path | None, sha256: str | None = None
) -> dict[str, Any]:
    """Parameters of a parametric trajectory, and the file it was read from (path and
    SHA-256: ``sha256`` if given, the digest recorded when it was read, else the file's
    now). A :class:`~ddwmmr.trajectories.ScaledTrajectory` is ``{"name", "type":
    "scaled", "scale", "trajectory": <its base's record>}`` (a type that versions without
    scaling refuse to rebuild, rather than rebuild it unscaled); ``source`` and ``sha256``
    are its base's."""
    if isinstance(trajectory, ScaledTrajectory):
        return {
            "name": trajectory.name,
            "type": SCALED,
            "scale": trajectory.scale,
            "trajectory": trajectory_record(trajectory.trajectory, source, sha256),
        }
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


#: The ``type`` of a scaled trajectory's record (:func:`trajectory_record`).
SCALED = "scaled"


def base_trajectory_record(record: dict[str, Any]) -> dict[str, Any]:
    """The record of the trajectory a :func:`trajectory_record` scales (the one that names
    its file and digest), ``record`` itself when it is not a scaled one's; a scaled one's
    whose ``trajectory`` is no record is a one-line :class:`ParameterError`."""
    while record.get("type") == SCALED:
        base = record.get("trajectory")
        if not isinstance(base, dict):
            raise ParameterError(f"trajectory.trajectory must be a record (got {shown(base)})")
        record = base
    return record


def trajectory_from_record(record: dict[str, Any]) -> Any:
    """The trajectory a :func:`trajectory_record` describes (a changed file is an error;
    a gone one that the package ships is read there, with a ``UserWarning`` saying so:
    :func:`read_trajectory_record`)."""
    trajectory, _, note = read_trajectory_record(record)
    if note is not None:
        warn_user(note)
    return trajectory


def _shape_from_record(kind: str, parameters: Any) -> Any:
    """The ``kind`` (a key of ``SHAPES``) a record's ``trajectory.parameters`` describe;
    a value that is no table, or a key the shape does not have, is a one-line
    :class:`ParameterError` naming ``trajectory.parameters`` (not the ``TypeError`` the
    class would raise)."""
    if not isinstance(parameters, dict):
        raise ParameterError(
            f"trajectory.parameters must be a table of the {kind}'s parameters "
            f"({', '.join(shape_keys(kind))}) (got {shown(parameters)})"
        )
    check_shape_keys("trajectory.parameters", kind, parameters)
    return SHAPES[kind](**parameters)


def read_trajectory_record(record: dict[str, Any]) -> tuple[Any, Path | None, str | None]:
    """``(trajectory, file, note)``: the trajectory a :func:`trajectory_record` describes,
    its file (the one its samples were read from; a parametric one's as recorded, as it is
    rebuilt from its parameters; None if the record names none) and a one-line note when
    the samples were read from another file than the recorded one, else None.

    A recorded file that is gone is replaced by the trajectory the package ships under
    the record's name or file name (:func:`~ddwmmr.trajectories.files.package_folder`) if
    that file's SHA-256 is the recorded one: the install path of a shipped trajectory
    changes with the environment (another venv, machine, or checkout), its bytes do not.
    A file whose SHA-256 differs from the record's is refused (:class:`ParameterError`).
    A scaled trajectory's record is rebuilt scaled, its file and note its base's; a
    recorded scale out of range is a one-line :class:`ParameterError` naming
    ``trajectory.scale``.
    """
    kind = record.get("type")
    if kind == SCALED:
        scale = check_scale(decode(record.get("scale")), "trajectory.scale")
        base = record.get("trajectory")
        if not isinstance(base, dict):
            raise ParameterError(f"trajectory.trajectory must be a record (got {shown(base)})")
        trajectory, file, note = read_trajectory_record(base)  # itself scaled, maybe
        return ScaledTrajectory(trajectory, scale), file, note
    if kind in SHAPES:
        source = record.get("file")
        file = Path(source) if isinstance(source, str) and source else None
        return _shape_from_record(kind, decode(record["parameters"])), file, None
    if kind != "samples":
        raise ParameterError(f"cannot rebuild a trajectory of type {shown(kind)}")
    path = Path(_recorded_file(record))
    digest = recorded_sha256(record)
    note = None
    if not path.exists():
        path = _shipped_stand_in(record, path)
        note = (
            f"the trajectory file {record['file']} is gone; read the one this package "
            f"ships, {path}, which has the recorded SHA-256"
        )
    if not path.is_file():  # checked before hashing: a FIFO would block the read
        now = "a folder" if path.is_dir() else "not a regular file"
        raise ParameterError(f"the trajectory file {path} is now {now}")
    if file_sha256(path) != digest:
        raise ParameterError(f"the trajectory file {path} changed since the run (SHA-256 differs)")
    return read_csv(path), path, note


#: A SHA-256 as :func:`~ddwmmr.trajectories.files.file_sha256` gives it.
_SHA256 = re.compile(r"[0-9a-f]{64}")


def recorded_sha256(record: dict[str, Any]) -> str:
    """The SHA-256 a :func:`trajectory_record` gives its file: a string of 64 hex digits
    (lowercase), else a one-line :class:`ParameterError` naming ``trajectory.sha256`` (a
    :class:`KeyError` when the record lacks it). A malformed record is refused as such,
    not as a file changed since the run."""
    digest = record["sha256"]
    if not isinstance(digest, str) or _SHA256.fullmatch(digest) is None:
        raise ParameterError(
            f"trajectory.sha256 must be a string of 64 hex digits (0-9, a-f) (got {shown(digest)})"
        )
    return digest


def _recorded_file(record: dict[str, Any]) -> str:
    """The path a samples :func:`trajectory_record` gives its file: a non-empty string,
    else a one-line :class:`ParameterError` naming ``trajectory.file``."""
    file = record["file"]
    if not isinstance(file, str) or not file or "\0" in file:
        raise ParameterError(
            f"trajectory.file must be a file path, a non-empty string (got {shown(file)})"
        )
    return file


def _shipped_stand_in(record: dict[str, Any], gone: Path) -> Path:
    """The shipped CSV trajectory named as the record's ``name`` or its file's name whose
    SHA-256 is the record's; else the refusal that ``gone`` is gone."""
    differs = ""
    for stem in sorted({str(record.get("name")), gone.name.removesuffix(".csv")}):
        shipped = package_folder() / f"{stem}.csv"
        if not (is_name(stem) and shipped.is_file()):  # a name never leaves the folder
            continue
        if file_sha256(shipped) == recorded_sha256(record):
            return shipped
        differs = f" (the package's own {shipped.name} has another SHA-256)"
    raise ParameterError(f"the trajectory file {gone} is gone{differs}")


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
    # The plant's constructor options that were given (the others take its defaults).
    plant_options: dict[str, Any] = dataclasses.field(default_factory=dict)


def plant_record(name: str, options: dict[str, Any]) -> dict[str, Any]:
    """``{"name": name}``, with ``"options"`` (the constructor options given) when any
    were: a run on the plant's defaults is recorded as before the options existed."""
    return {"name": name, "options": encode(options)} if options else {"name": name}


def run_record(
    inputs: RunInputs,
    argv: Sequence[str] | None,
    rerun: str | None,
    tool: str,
    prog: str,
) -> dict[str, Any]:
    """What summary.json["run"] holds: enough to repeat the run (``--rerun``); ``tool``
    names what wrote it, ``prog`` and ``argv`` the command that repeats it (the
    simulator's export writes the same record, with the :data:`TRACK_PROG` arguments of
    its settings)."""
    plugins = used_plugins(method=[inputs.method], plant=[inputs.plant])
    record = header(tool, prog, argv, plugins)
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
        plant=plant_record(inputs.plant, inputs.plant_options),
        seed=None,  # nothing random in a track run
    )
    if rerun is not None:
        record["rerun_of"] = str(Path(rerun).resolve())
    return record
