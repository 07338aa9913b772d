"""Regenerate the competitive-arbiter figures and tables of docs/thesis.md.

Runs the side-by-side study (``python -m ddwmmr.scenarios --study arbiters``: both
arbiters on 100 scenarios over the threshold variants, weight statistics, noise seeds and
levels) into ``runs/docs/arbiters`` and copies its weight figures to
``docs/figures/competitive_weights_*.png``; the tables it prints (also in
``runs/docs/arbiters/arbiters.md``) are the ones in the docs. Takes several minutes on two
cores. Usage: ``python docs/competitive_figures.py [--jobs N]``.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIGURES = ROOT / "docs" / "figures"
OUT = ROOT / "runs" / "docs" / "arbiters"
#: Figures of the study shown in the docs (study output name -> docs/figures name).
COPIED = {
    f"competitive_weights_{key}.png": f"competitive_weights_{key}.png"
    for key in ("baseline", "stab-1.50-1.70", "stab-nohyst-1.50")
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2, help="worker processes (default: 2)")
    args = parser.parse_args()
    command = [
        sys.executable,
        "-m",
        "ddwmmr.scenarios",
        "--study",
        "arbiters",
        "--jobs",
        str(args.jobs),
        "--out",
        str(OUT),
    ]
    print(" ".join(command[1:]), flush=True)
    subprocess.run(command, check=True, cwd=ROOT)
    for produced, name in COPIED.items():
        shutil.copyfile(OUT / produced, FIGURES / name)
        print(f"copied {name}")


if __name__ == "__main__":
    main()
