"""An output folder no file can be created in is refused in one wording for every tool."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from ddwmmr.cli.compare import main as compare
from ddwmmr.cli.scenarios import main as scenarios
from ddwmmr.cli.track import main as track
from ddwmmr.errors import ParameterError
from ddwmmr.gui.paths import check_export_root
from ddwmmr.outputs import check_writable

needs_proc = pytest.mark.skipif(
    not os.path.isdir("/proc/self"), reason="needs Linux's /proc, which takes no new files"
)

#: /proc exists, but creating a file in it fails with "No such file or directory".
PROC_REFUSAL = (
    "out: cannot write in /proc: /proc takes no new files or folders; choose a folder elsewhere"
)


@needs_proc
def test_a_folder_that_takes_no_files_is_named_without_a_misleading_reason() -> None:
    with pytest.raises(ParameterError) as refused:
        check_writable("out", Path("/proc"))
    assert str(refused.value) == PROC_REFUSAL
    assert isinstance(refused.value.__cause__, OSError)


@needs_proc
def test_a_missing_folder_below_it_is_named_as_the_one_that_cannot_be_made() -> None:
    with pytest.raises(ParameterError) as refused:
        check_writable("out", Path("/proc/ddwmmr-a/b"), "p/b")
    assert str(refused.value) == (
        "out: cannot make the folder p/b: /proc takes no new files or folders; "
        "choose a folder elsewhere"
    )


def test_the_reason_of_the_system_is_kept_when_it_explains(tmp_path, monkeypatch) -> None:
    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr("tempfile.mkstemp", refuse)
    with pytest.raises(ParameterError) as refused:
        check_writable("out", tmp_path)
    assert str(refused.value) == (
        f"out: cannot write in {tmp_path}: {tmp_path} takes no new files or folders "
        "(Permission denied); choose a folder elsewhere"
    )


@needs_proc
@pytest.mark.parametrize(
    ("tool", "argv"),
    [
        (track, ["--method", "pi", "--traj", "ellipse", "--no-progress"]),
        (compare, ["--no-progress"]),
        (scenarios, ["--no-progress"]),
    ],
)
def test_every_tool_gives_that_wording_before_it_runs(tool, argv, capsys) -> None:
    assert tool([*argv, "--out", "/proc/ddwmmr-x"]) == 2
    captured = capsys.readouterr()
    assert captured.err == f"error: {PROC_REFUSAL}\n"


@needs_proc
def test_the_gui_export_folder_uses_the_same_wording() -> None:
    with pytest.raises(ParameterError) as refused:
        check_export_root("/proc")
    assert str(refused.value) == (
        "export: cannot write in /proc: /proc takes no new files or folders; "
        "choose a folder elsewhere"
    )
