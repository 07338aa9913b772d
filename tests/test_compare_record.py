"""compare's run.json: the provenance header of track's record, and trajectory digests a user
can check as docs/comparing.md says (nothing in the package reads run.json back)."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import provenance
from ddwmmr.cli.compare import main
from ddwmmr.errors import ParameterError
from ddwmmr.trajectories import load_trajectory
from ddwmmr.trajectories.files import file_sha256, find_trajectory_file

#: What decides a run's last bits besides its inputs: recorded by compare as by track.
HEADER_KEYS = ("version", "python", "numpy", "git", "libraries", "blas", "machine")


@pytest.fixture(scope="module")
def compared(tmp_path_factory) -> tuple[dict, Path]:
    """run.json of a 0.2 s comparison of ``pi`` on a copy of figure8.csv, and that copy."""
    folder = tmp_path_factory.mktemp("h131")
    samples = folder / "loop.csv"
    shutil.copyfile(find_trajectory_file("figure8"), samples)
    out = folder / "report"
    argv = ["--methods", "pi", "--only", str(samples), "--study", "none", "--duration", "0.2"]
    assert main([*argv, "--jobs", "1", "--no-progress", "--out", str(out)]) == 0
    return json.loads((out / "run.json").read_text()), samples


def test_compare_records_the_software_and_machine_as_track_does(compared):
    record, _ = compared
    now = provenance.header("track", "python -m ddwmmr.track", [])
    assert {k: record[k] for k in HEADER_KEYS} == {k: now[k] for k in HEADER_KEYS}
    assert record["machine"]["cpu"] and "numpy" in record["blas"]
    assert provenance.software_differences(record) == []


def test_a_recorded_digest_is_the_sha256_of_the_file_bytes(compared):
    record, samples = compared
    (entry,) = record["trajectories"].values()
    assert entry["type"] == "samples" and entry["file"] == str(samples.resolve())
    assert entry["sha256"] == hashlib.sha256(samples.read_bytes()).hexdigest()
    assert entry["sha256"] == file_sha256(samples)


def test_the_documented_check_rebuilds_the_samples_and_refuses_a_changed_file(compared, tmp_path):
    record, samples = compared
    (entry,) = record["trajectories"].values()
    rebuilt = provenance.trajectory_from_record(entry)
    original = load_trajectory(str(samples))
    for t in (0.0, 0.07, 0.2, 31.3):
        np.testing.assert_allclose(rebuilt.pose(t), original.pose(t), rtol=0, atol=1e-15)
    changed = tmp_path / "loop.csv"
    changed.write_text("# edited\n" + samples.read_text())  # same samples, other bytes
    with pytest.raises(ParameterError, match="changed since the run"):
        provenance.trajectory_from_record({**entry, "file": str(changed)})
