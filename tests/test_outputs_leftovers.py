"""What a run killed outright leaves inside a later ``--out`` (its staging folder and its
lock, when its own ``--out`` was a sub-folder) is not the user's: it neither refuses that
``--out`` nor survives its commit, unless that run still runs. And the lock of a folder
is found whatever spelling of the folder a run was given."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from ddwmmr import outputs
from ddwmmr.errors import ParameterError
from ddwmmr.outputs import lock, output_folder, owners
from ddwmmr.outputs.lock import lock_file, output_lock

FILES = ("summary.json", "timeseries.csv")


@pytest.fixture
def child() -> Iterator[subprocess.Popen]:
    """A process standing for a run writing ``--out S/a``; killed at the end."""
    process = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    yield process
    process.kill()
    process.wait()


def _leave_run(folder: Path, pid: int) -> tuple[Path, Path]:
    """The staging folder (holding a staged file) and the lock that the run ``pid``
    writing ``folder/a`` has in ``folder``."""
    token = f"{owners._host()}-{pid}-{owners._process_start(pid)}"
    staging = folder / f"{owners.STAGING_PREFIX}{token}-k3x9q2"
    staging.mkdir()
    (staging / "summary.json").write_text("{}\n")
    held = lock_file(folder / "a")
    held.write_text(token, encoding="utf-8")
    return staging, held


def _write(target: Path, who: str) -> None:
    with output_folder(target, "track") as staging:
        for name in FILES:
            (staging / name).write_text(f"{who}\n")


def test_a_child_runs_leftovers_refuse_out_while_it_runs_and_go_once_it_was_killed(
    tmp_path, child, capsys
):
    out = tmp_path / "S"
    out.mkdir()
    staging, held = _leave_run(out, child.pid)
    with pytest.raises(ParameterError) as caught:
        outputs.check_output_folder(out, "track")
    assert str(caught.value) == (
        f"out: {out} holds files no ddwmmr track run wrote ({held.name}, "
        f"{staging.name}/, ...); choose another --out, or add --force "
        "(deletes only files a ddwmmr manifest lists)"
    )
    child.kill()
    child.wait()  # killed outright: its staging folder and lock stay
    assert outputs.inspect(out, "track") == outputs.Existing("empty")
    assert outputs.check_output_folder(out, "track") == out
    _write(out, "B")
    assert sorted(os.listdir(out)) == sorted([outputs.MANIFEST, *FILES])
    assert sorted(os.listdir(tmp_path)) == ["S"]
    assert capsys.readouterr().err == (
        f"note: removed 1 folder left in {out} by runs that were killed ({staging.name})\n"
    )


def test_an_earlier_output_holding_a_killed_runs_leftovers_is_replaced_whole(
    tmp_path, child, capsys
):
    out = tmp_path / "S"
    _write(out, "A")
    _leave_run(out, child.pid)
    child.kill()
    child.wait()
    existing = outputs.inspect(out, "track")
    assert (existing.kind, existing.listed, existing.foreign) == ("own", sorted(FILES), [])
    _write(out, "B")
    assert {name: (out / name).read_text() for name in FILES} == dict.fromkeys(FILES, "B\n")
    assert sorted(os.listdir(out)) == sorted([outputs.MANIFEST, *FILES])
    assert sorted(os.listdir(tmp_path)) == ["S"]  # nothing kept aside, no lock left
    assert "warning" not in capsys.readouterr().err


def test_a_case_insensitive_file_system_gives_every_case_of_a_name_one_lock(tmp_path, monkeypatch):
    monkeypatch.setattr(lock, "_case_insensitive", lambda folder: True)
    assert lock_file(tmp_path / "Results") == lock_file(tmp_path / "results")
    with (
        output_lock(tmp_path / "Results", "Results"),
        pytest.raises(ParameterError) as caught,
        output_lock(tmp_path / "results", "x"),
    ):
        pass
    assert str(caught.value) == f"out: x is being written by another ddwmmr run (pid {os.getpid()})"
    assert os.listdir(tmp_path) == []


def test_a_case_sensitive_file_system_keeps_one_lock_per_spelling(tmp_path):
    assert not lock._case_insensitive(tmp_path)  # the probe's file is gone again
    assert os.listdir(tmp_path) == []
    assert lock_file(tmp_path / "out").name == ".ddwmmr-lock-" + (
        "762069bc"  # sha256(b"out")[:8], as before the probe existed
    )
    with output_lock(tmp_path / "Results", "Results"), output_lock(tmp_path / "results", "r"):
        assert len(os.listdir(tmp_path)) == 2


def test_the_probe_sees_a_file_system_that_ignores_case(tmp_path, monkeypatch):
    real = os.path.lexists

    def ignoring_case(path: str) -> bool:
        folder, name = os.path.split(path)
        return real(path) or name.lower() in {n.lower() for n in os.listdir(folder)}

    monkeypatch.setattr(os.path, "lexists", ignoring_case)
    assert lock._case_insensitive(tmp_path)
    monkeypatch.undo()
    assert os.listdir(tmp_path) == []


def test_without_a_probe_the_usual_file_systems_of_windows_and_macos_ignore_case(
    tmp_path, monkeypatch
):
    missing = tmp_path / "missing"  # no file can be made there
    assert not lock._case_insensitive(missing)
    monkeypatch.setattr(sys, "platform", "darwin")
    assert lock._case_insensitive(missing)


def test_a_folder_reached_through_a_symbolic_link_shares_its_lock(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "alias").symlink_to(real)
    with (
        output_lock(real / "out", "real/out"),
        pytest.raises(ParameterError),
        output_lock(tmp_path / "alias" / "out", "alias/out"),
    ):
        pass
