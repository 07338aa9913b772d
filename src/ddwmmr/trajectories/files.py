"""Load trajectories by name or path: parametric TOML and sampled CSV files.

A *name* (``ellipse``, ``figure8``...: letters, digits, ``_``, ``-`` and inner dots, no
path separator) is looked up as ``<name>.toml`` or ``<name>.csv`` in the trajectory
folders, in order: ``$DDWMMR_TRAJECTORIES`` (os.pathsep-separated), ``./trajectories``
and the named trajectories shipped inside the package (``ddwmmr/trajectories/data``, the
same files as the project's top-level ``trajectories/`` folder, so a wheel install has
them). The names ``ellipse`` and ``rectangle`` fall back to the built-in defaults if no
folder holds them. Anything else (a value with a path separator or a ``.toml`` / ``.csv``
suffix, in any case: ``RUN.CSV`` too) is a *path* and is read as given; a name never
resolves outside the folders.

Obstacle files (``--obstacles``) resolve the same way, in the ``obstacles/`` subfolder.

Parametric TOML::

    [trajectory]
    shape = "ellipse"        # or "rectangle"
    x0 = 0.0                 # centre (m)
    y0 = 0.0
    a = 1.0                  # semi-axes (m)
    b = 0.6
    beta = 0.0               # rotation (rad)
    N = 1000                 # samples per period
    T = 20.0                 # period (s)
    orientation = "tangent"  # or "constant" (with phi = ... in rad)
"""

from __future__ import annotations

import hashlib
import os
import re
from collections.abc import Iterable
from dataclasses import fields
from importlib import resources
from pathlib import Path
from typing import Any

from ddwmmr.errors import ParameterError, as_path, check_number_type, load_toml, shown
from ddwmmr.trajectories.base import file_name
from ddwmmr.trajectories.parametric import PHI_NEEDS_CONSTANT, Ellipse, Rectangle
from ddwmmr.trajectories.sampled import SampledTrajectory, read_csv

SHAPES: dict[str, type[Ellipse] | type[Rectangle]] = {"ellipse": Ellipse, "rectangle": Rectangle}
SUFFIXES = (".toml", ".csv")
#: A trajectory or obstacle-file name: no separator, no leading dot, no "..".
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")
#: Keys of a parametric TOML trajectory and the type each must have.
_STRING_KEYS = {"shape", "orientation", "name"}


def package_folder() -> Path:
    """The named trajectories shipped inside the package (``ddwmmr/trajectories/data``)."""
    return Path(str(resources.files("ddwmmr.trajectories").joinpath("data")))


def trajectory_folders() -> list[Path]:
    """Folders searched for trajectory names, in order."""
    folders = [Path(p) for p in os.environ.get("DDWMMR_TRAJECTORIES", "").split(os.pathsep) if p]
    folders += [Path.cwd() / "trajectories", package_folder()]
    return folders


def file_suffix(path: str | Path) -> str:
    """The suffix of a trajectory or obstacle path in lower case (``.csv`` of
    ``RUN.CSV``): the one rule that matches a path's suffix against :data:`SUFFIXES`,
    without regard to case as most tools do."""
    return Path(path).suffix.lower()


def is_name(value: str) -> bool:
    """Whether ``value`` is a trajectory/obstacle *name* rather than a path (a value
    ending in a suffix of :data:`SUFFIXES`, in any case, is a path)."""
    return bool(_NAME.fullmatch(value)) and ".." not in value and file_suffix(value) not in SUFFIXES


def available_trajectories() -> list[str]:
    """Names that :func:`load_trajectory` resolves (files in the folders plus built-ins)."""
    names = set(SHAPES)
    for folder in trajectory_folders():
        if folder.is_dir():
            names.update(
                p.stem
                for p in folder.iterdir()
                if p.suffix in SUFFIXES and is_name(p.stem) and p.is_file()
            )
    return sorted(names)


def _named_file(candidates: Iterable[Path]) -> Path | None:
    """The first candidate that is there and not a folder: a regular file, or a FIFO, a
    socket or a dangling link, which reading then refuses as not a regular file (skipping
    them said "unknown trajectory 'fifo'" while listing fifo among the known names, which
    list regular files only)."""
    for candidate in candidates:
        try:
            if candidate.is_file() or (os.path.lexists(candidate) and not candidate.is_dir()):
                return candidate
        except OSError:  # e.g. a name longer than the file system takes: not there
            continue
    return None


def find_trajectory_file(name_or_path: str | Path) -> Path | None:
    """The file a trajectory name or path refers to; None for a built-in-only name.

    Raises :class:`ParameterError` for an unknown name or a path that is not a
    ``.toml``/``.csv`` file.
    """
    text = str(name_or_path)
    if not is_name(text):
        path = Path(text)
        if file_suffix(path) not in SUFFIXES:
            known = ", ".join(available_trajectories())
            raise ParameterError(
                f"traj: {shown(text)} is neither a trajectory name ({known}) nor a .toml/.csv path"
            )
        if not os.path.lexists(path):
            raise ParameterError(f"traj: no such file {path}{_name_hint(path)}")
        return path
    found = _named_file(f / f"{text}{suffix}" for f in trajectory_folders() for suffix in SUFFIXES)
    if found is not None:
        return found
    if text in SHAPES:
        return None
    raise ParameterError(
        f"traj: unknown trajectory {shown(text)} "
        f"(known: {', '.join(available_trajectories())}; or give a .toml/.csv path)"
    )


def _name_hint(path: Path) -> str:
    """For a bare file name that is not there but names a trajectory the folders have
    (``ellipse.toml`` typed in another folder), the hint to give the name instead."""
    if path.parent != Path(".") or path.stem not in available_trajectories():
        return ""
    return f" here (the trajectory {path.stem} is found by its name: {path.stem})"


def load_trajectory(
    name_or_path: str | Path, **overrides: Any
) -> Ellipse | Rectangle | SampledTrajectory:
    """Resolve a trajectory name or file path; ``overrides`` replace TOML parameters.

    The overrides are the keyword arguments of :class:`Ellipse` / :class:`Rectangle`
    (``x0``, ``a``, ``T``, ``orientation``, ``phi``...), checked as a file's keys are
    (:func:`read_toml`). ``shape`` is not one: the file (or the built-in name) sets it, so
    overriding it is refused. A sampled (CSV) trajectory takes no overrides.
    """
    path = find_trajectory_file(name_or_path)
    if path is None:
        name = str(name_or_path)
        _check_overrides(name, overrides)
        shape: Ellipse | Rectangle = SHAPES[name](**overrides)
        return shape
    return _load_file(path, overrides)


def find_obstacle_file(name_or_path: str | Path) -> Path:
    """The obstacle TOML a name (``ellipse_post``) or a path refers to."""
    text = str(name_or_path)
    if not is_name(text):
        return Path(text)
    found = _named_file(folder / "obstacles" / f"{text}.toml" for folder in trajectory_folders())
    if found is not None:
        return found
    known = sorted(
        {
            p.stem
            for f in trajectory_folders()
            for p in (f / "obstacles").glob("*.toml")
            if p.is_file()
        }
    )
    raise ParameterError(
        f"obstacles: unknown obstacle file {shown(text)} (known: {', '.join(known) or 'none'}; "
        "or give a .toml path)"
    )


def file_sha256(path: str | Path) -> str:
    """Hex SHA-256 of a file's bytes (recorded so a rerun can tell the file changed)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _load_file(path: Path, overrides: dict[str, Any]) -> Ellipse | Rectangle | SampledTrajectory:
    if file_suffix(path) == ".csv":
        if overrides:
            raise ParameterError(f"traj: {path.name} is sampled; parameters cannot be overridden")
        return read_csv(path)
    return read_toml(path, **overrides)


def read_toml(path: str | Path, **overrides: Any) -> Ellipse | Rectangle:
    """Load a parametric trajectory (ellipse or rectangle) from a TOML file.

    The keys are either all top-level or all in one ``[trajectory]`` table: beside that
    table nothing else may be in the file (a key above it would be ignored). Unknown keys
    are refused naming the first, and ``phi`` only counts with ``orientation =
    "constant"``, so it is refused with the tangent orientation (the default) instead of
    being ignored. Every value must have its documented type (numbers for lengths,
    angles, N and T, strings for shape, orientation and name): ``N = "2000"`` is an error
    naming ``N``.
    """
    path = as_path(path, "traj")
    data = load_toml(path, "traj")
    if "trajectory" in data:
        for key, value in data.items():
            if key != "trajectory":
                what = f"table [{key}]" if isinstance(value, dict | list) else f"key {shown(key)}"
                raise ParameterError(
                    f"traj: {path}: {what} outside [trajectory] (the keys go at the top or "
                    "all under one [trajectory] table)"
                )
    table = data.get("trajectory", data)
    if not isinstance(table, dict):
        raise ParameterError(
            f"traj: {path}: [trajectory] must be one table (got {type(table).__name__})"
        )
    table = dict(table)
    shape = table.pop("shape", None)
    if not isinstance(shape, str) or shape not in SHAPES:  # an array or table is unhashable
        got = (
            "no shape key at the top or in a [trajectory] table"
            if shape is None
            else f"got {shown(shape)}"
        )
        raise ParameterError(f"traj: {path} needs shape = one of {', '.join(SHAPES)} ({got})")
    table.setdefault("name", file_name(path))
    if "shape" in overrides:
        _refuse_shape_override(f"traj: {path}", shape, "the file", overrides["shape"])
    table.update(overrides)
    # a value given as an override is not the file's: the message says which were given
    given = ", ".join(sorted(map(str, overrides)))
    where = f"traj: {path} with {given} given" if overrides else f"traj: {path}"
    known = shape_keys(shape)
    unknown = sorted(set(table) - set(known))
    if unknown:
        raise ParameterError(
            f"{where}: unknown key {shown(unknown[0])} (known: shape, {', '.join(known)})"
        )
    _check_types(where, table)
    if "phi" in table and table.get("orientation", "tangent") == "tangent":
        raise ParameterError(f"{where}: {PHI_NEEDS_CONSTANT}")
    try:
        return SHAPES[shape](**table)
    except TypeError as exc:
        raise ParameterError(f"{where}: {exc}") from None
    except ParameterError as exc:
        raise ParameterError(f"{where}: {exc}") from None


def _refuse_shape_override(where: str, shape: str, setter: str, value: Any) -> None:
    """Refuse ``shape`` among the overrides: the file or the name chose the class."""
    raise ParameterError(
        f"{where}: shape cannot be overridden (got {shown(value)}): {setter} sets it to "
        f"{shape}; load another shape by its own name or file"
    )


def _check_overrides(name: str, overrides: dict[str, Any]) -> None:
    """The overrides of a built-in shape (no file), refused as :func:`read_toml` refuses
    a file's keys (shape, an unknown key, phi with the tangent orientation) rather than
    by a ``TypeError`` from the class."""
    where = f"traj: {name}"
    if "shape" in overrides:
        _refuse_shape_override(where, name, "the name", overrides["shape"])
    check_shape_keys(where, name, overrides)
    if "phi" in overrides and overrides.get("orientation", "tangent") == "tangent":
        raise ParameterError(f"{where}: {PHI_NEEDS_CONSTANT}")


def shape_keys(shape: str) -> list[str]:
    """The keyword arguments (parameters) of the built-in shape named ``shape``."""
    return [f.name for f in fields(SHAPES[shape])]


def check_shape_keys(where: str, shape: str, keys: Iterable[Any]) -> None:
    """Refuse a key the built-in ``shape`` does not take: one line, ``{where}: unknown key
    K (known: ...)``, the first unknown key in sorted order (rather than the class's
    ``TypeError``)."""
    known = shape_keys(shape)
    unknown = sorted(set(keys) - set(known), key=str)
    if unknown:
        raise ParameterError(
            f"{where}: unknown key {shown(unknown[0])} (known: {', '.join(known)})"
        )


def _check_types(where: str, table: dict[str, Any]) -> None:
    for key, value in table.items():
        if key in _STRING_KEYS:
            if not isinstance(value, str):
                raise ParameterError(f"{where}: {key} must be a string (got {shown(value)})")
        else:
            try:
                check_number_type(key, value)
            except ParameterError as exc:
                raise ParameterError(f"{where}: {exc}") from None
