"""Regenerate the docs figures that are outputs of the command-line tools.

Runs ``track``, ``compare`` and ``scenarios`` into ``runs/docs/`` and copies the figures the
pages show into ``docs/figures/`` (``make docs`` calls this after ``make_figures.py`` and
``qp_figures.py``). Usage: ``python docs/make_run_figures.py``.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIGURES = ROOT / "docs" / "figures"
RUNS = ROOT / "runs" / "docs"

_THESIS = ("times", "speed", "stability", "manipulability", "paths", "timeline")

#: (tool and arguments, {figure the tool writes: name in docs/figures}).
JOBS: list[tuple[list[str], dict[str, str]]] = [
    (
        ["track", "--method", "clrrmc-ts", "--traj", "rectangle"],
        {"path.png": "track_rectangle_path.png", "errors.png": "track_rectangle_errors.png"},
    ),
    (
        ["compare"],
        {
            f"{name}.png": f"compare_{name}.png"
            for name in (
                "paths_ellipse",
                "paths_rectangle",
                "errors_rectangle",
                "methods_ellipse",
                "study_tau",
                "study_dt",
                "study_init",
                "study_corners",
            )
        },
    ),
    (["scenarios"], {f"{n}.png": f"thesis_{n}.png" for n in _THESIS}),
    (
        ["scenarios", "--stability", "1.4", "1.7"],
        {
            f"{n}.png": f"thesis_highstab_{n}.png"
            for n in ("times", "stability", "timeline", "paths")
        },
    ),
    (
        ["scenarios", "--controller", "qp", "--plant", "kinematic"],
        {f"{n}.png": f"thesis_qp_kinematic_{n}.png" for n in ("paths", "timeline", "times")},
    ),
    (
        ["scenarios", "--controller", "qp", "--plant", "thesis"],
        {f"{n}.png": f"thesis_qp_thesisplant_{n}.png" for n in ("paths", "timeline", "times")},
    ),
    (
        ["scenarios", "--study", "obstacles"],
        {"obstacle_paths.png": "thesis_obstacle_paths.png"},
    ),
    (
        ["scenarios", "--study", "obstacles", "--controller", "qp", "--plant", "kinematic"],
        {"obstacle_paths.png": "thesis_qp_obstacle_paths.png"},
    ),
]


def run(index: int, arguments: list[str], figures: dict[str, str]) -> None:
    """Run one tool into ``runs/docs/<index>`` and copy its figures."""
    out = RUNS / f"{index:02d}-{arguments[0]}"
    tool, *rest = arguments
    command = [sys.executable, "-m", f"ddwmmr.{tool}", *rest, "--out", str(out), "--no-progress"]
    print(" ".join(command[1:]), flush=True)
    subprocess.run(command, check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
    for produced, name in figures.items():
        shutil.copyfile(out / produced, FIGURES / name)


def main() -> int:
    """Run every job in order."""
    FIGURES.mkdir(parents=True, exist_ok=True)
    for index, (arguments, figures) in enumerate(JOBS):
        run(index, arguments, figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
