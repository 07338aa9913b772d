"""Load trajectories by name or path: parametric TOML and sampled CSV files.

A name (``ellipse``, ``figure8``...) is looked up as ``<name>.toml`` or ``<name>.csv`` in the
trajectory folders: ``$DDWMMR_TRAJECTORIES`` (os.pathsep-separated), ``./trajectories`` and
the project's top-level ``trajectories/`` folder. The names ``ellipse`` and ``rectangle``
fall back to the built-in defaults if no folder holds them.

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

import os
from pathlib import Path

from ddwmmr.errors import ParameterError, load_toml
from ddwmmr.trajectories.parametric import Ellipse, Rectangle
from ddwmmr.trajectories.sampled import read_csv

SHAPES = {"ellipse": Ellipse, "rectangle": Rectangle}
_PROJECT_FOLDER = Path(__file__).resolve().parents[3] / "trajectories"


def trajectory_folders() -> list[Path]:
    """Folders searched for trajectory names, in order."""
    folders = [Path(p) for p in os.environ.get("DDWMMR_TRAJECTORIES", "").split(os.pathsep) if p]
    folders += [Path.cwd() / "trajectories", _PROJECT_FOLDER]
    return folders


def available_trajectories() -> list[str]:
    """Names that :func:`load_trajectory` resolves (files in the folders plus built-ins)."""
    names = set(SHAPES)
    for folder in trajectory_folders():
        if folder.is_dir():
            names.update(p.stem for p in folder.iterdir() if p.suffix in (".toml", ".csv"))
    return sorted(names)


def load_trajectory(name_or_path: str | Path, **overrides):
    """Resolve a trajectory name or file path; ``overrides`` replace TOML parameters."""
    path = Path(name_or_path)
    if path.suffix in (".toml", ".csv") or path.exists():
        if not path.is_file():
            raise ParameterError(f"traj: no such file {path}")
        return _load_file(path, overrides)
    for folder in trajectory_folders():
        for suffix in (".toml", ".csv"):
            candidate = folder / f"{name_or_path}{suffix}"
            if candidate.is_file():
                return _load_file(candidate, overrides)
    if str(name_or_path) in SHAPES:
        return SHAPES[str(name_or_path)](**overrides)
    raise ParameterError(
        f"traj: unknown trajectory {str(name_or_path)!r} "
        f"(known: {', '.join(available_trajectories())}; or give a .toml/.csv path)"
    )


def _load_file(path: Path, overrides: dict):
    if path.suffix == ".csv":
        if overrides:
            raise ParameterError(f"traj: {path.name} is sampled; parameters cannot be overridden")
        return read_csv(path)
    return read_toml(path, **overrides)


def read_toml(path: str | Path, **overrides):
    """Load a parametric trajectory (ellipse or rectangle) from a TOML file."""
    path = Path(path)
    data = load_toml(path, "traj")
    table = dict(data.get("trajectory", data))
    shape = table.pop("shape", None)
    if shape not in SHAPES:
        raise ParameterError(f"traj: {path} needs shape = one of {', '.join(SHAPES)}")
    table.setdefault("name", path.stem)
    table.update(overrides)
    try:
        return SHAPES[shape](**table)
    except TypeError as exc:
        raise ParameterError(f"traj: {path}: {exc}") from None
