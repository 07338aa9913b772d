"""An installed wheel (not the editable source) has the named trajectories and obstacles.

Builds the wheel offline from a copy of the sources (pyproject.toml, README.md, src/),
installs it into a temporary target folder and runs ``python -m ddwmmr.track --traj
figure8`` from a folder without ``trajectories/``. The dependencies come from the test
environment; ddwmmr itself must come from the wheel (asserted).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _run(arguments: list[str], **options) -> subprocess.CompletedProcess:
    done = subprocess.run(arguments, capture_output=True, text=True, timeout=300, **options)
    assert done.returncode == 0, done.stdout + done.stderr
    return done


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """A target folder holding ddwmmr installed from a freshly built wheel."""
    base = tmp_path_factory.mktemp("wheel")
    source = base / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    shutil.copytree(
        ROOT / "src", source / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info")
    )
    pip = [sys.executable, "-m", "pip"]
    quiet = ["--quiet", "--disable-pip-version-check", "--no-index", "--no-deps"]
    _run([*pip, "wheel", *quiet, "--no-build-isolation", "-w", str(base / "dist"), str(source)])
    wheels = list((base / "dist").glob("ddwmmr-*.whl"))
    assert len(wheels) == 1
    target = base / "target"
    _run([*pip, "install", *quiet, "--target", str(target), str(wheels[0])])
    return target


def _env(target: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "DDWMMR_TRAJECTORIES"}
    return {**env, "PYTHONPATH": str(target), "MPLBACKEND": "Agg"}


def test_wheel_ships_the_trajectory_files(installed):
    shipped = {
        p.relative_to(installed / "ddwmmr" / "trajectories" / "data").as_posix()
        for p in (installed / "ddwmmr" / "trajectories" / "data").rglob("*")
        if p.is_file()
    }
    project = {
        p.relative_to(ROOT / "trajectories").as_posix()
        for p in (ROOT / "trajectories").rglob("*")
        if p.is_file()
    }
    assert shipped == project


def test_installed_package_runs_a_named_trajectory(installed, tmp_path):
    env = _env(installed)
    probe = _run(
        [sys.executable, "-c", "import ddwmmr, ddwmmr.trajectories as t; print(ddwmmr.__file__);"
         "print(' '.join(t.available_trajectories()))"],
        cwd=tmp_path, env=env,
    )  # fmt: skip
    where, names = probe.stdout.splitlines()
    assert Path(where).is_relative_to(installed)  # the wheel, not the editable source
    assert set(names.split()) >= {"ellipse", "rectangle", "figure8", "sideways_reach"}
    out = tmp_path / "run"
    done = _run(
        [sys.executable, "-m", "ddwmmr.track", "--method", "ats", "--traj", "figure8",
         "--duration", "1", "--no-plots", "--no-progress", "--out", str(out)],
        cwd=tmp_path, env=env,
    )  # fmt: skip
    assert "ats on figure8" in done.stdout
    record = json.loads((out / "summary.json").read_text())["run"]
    assert record["git"] is None  # and it says why
    assert record["git_note"] == "installed package, not a git checkout: no commit to record"
    done = _run(
        [sys.executable, "-m", "ddwmmr.track", "--method", "qp", "--traj", "ellipse",
         "--obstacles", "ellipse_post", "--duration", "0.5", "--no-plots", "--no-progress",
         "--out", str(tmp_path / "qp")],
        cwd=tmp_path, env=env,
    )  # fmt: skip
    assert "min obstacle clearance" in done.stdout


def test_wheel_ships_the_type_marker(installed):
    """PEP 561: without py.typed a user's type checker ignores the package's annotations."""
    assert (installed / "ddwmmr" / "py.typed").is_file()


def _project_files(folder: str) -> set[str]:
    """The files of a project folder, as paths from the project root (no caches)."""
    return {
        p.relative_to(ROOT).as_posix()
        for p in (ROOT / folder).rglob("*")
        if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc"
    }


def test_sdist_holds_the_test_suite_and_what_it_reads(tmp_path):
    """The source distribution holds the whole test suite (conftest, helper modules, golden
    files, plug-ins) and the folders its tests read: built from a copy of the project."""
    source = tmp_path / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md", "LICENSE", "MANIFEST.in", "Makefile", "mkdocs.yml"):
        shutil.copy(ROOT / name, source / name)
    folders = ("src", "tests", "docs", "examples", "trajectories", "benchmarks")
    for folder in folders:
        shutil.copytree(
            ROOT / folder,
            source / folder,
            ignore=shutil.ignore_patterns("__pycache__", "*.egg-info", "*.pyc"),
        )
    code = (
        "import sys; from setuptools import build_meta; print(build_meta.build_sdist(sys.argv[1]))"
    )
    done = _run([sys.executable, "-c", code, str(tmp_path / "dist")], cwd=source)
    archive = tmp_path / "dist" / done.stdout.split()[-1]
    with tarfile.open(archive) as tar:
        top = tar.getnames()[0].split("/")[0]
        shipped = {n.split("/", 1)[1] for n in tar.getnames() if "/" in n}
    for folder in ("tests", "docs", "examples", "trajectories"):
        missing = _project_files(folder) - shipped
        assert not missing, f"{top}: {sorted(missing)[:5]}"
