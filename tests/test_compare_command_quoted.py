"""compare and file names with a shell's or a list's separators in them: the command line
its report shows ("command: `...`") is quoted for the shell, as the run record's is (a
trajectory file named ``my run|1.csv`` was shown bare, and the line pasted into a shell
piped into a command ``1.csv``), and a --traj file named with a comma is one file."""

from __future__ import annotations

import shlex
import shutil
from pathlib import Path

from ddwmmr.cli.compare import build_parser, config_from_arguments

FIGURE8 = Path(__file__).resolve().parents[1] / "trajectories" / "figure8.csv"


def test_the_reports_command_repeats_the_run_when_pasted(tmp_path):
    path = tmp_path / "my run|1.csv"
    shutil.copy(FIGURE8, path)
    argv = ["--methods", "ats", "--traj", str(path), "--duration", "0.5"]
    config = config_from_arguments(build_parser().parse_args(argv), argv)
    assert config.command == shlex.join(["python", "-m", "ddwmmr.compare", *argv])
    assert shlex.split(config.command)[3:] == argv


def test_a_trajectory_file_with_a_comma_in_its_name_is_one_trajectory(tmp_path):
    """--traj 'run 3,4.csv' was split at the comma: "traj: 'run 3' is neither a
    trajectory name ... nor a .toml/.csv path"."""
    path = tmp_path / "run 3,4.csv"
    shutil.copy(FIGURE8, path)
    for option in ("--traj", "--only"):
        argv = ["--methods", "ats", option, str(path), "--duration", "0.5"]
        config = config_from_arguments(build_parser().parse_args(argv), argv)
        assert config.shown_names["run_3_4"] == "run 3,4"
    argv = ["--methods", "ats", "--only", "ellipse,rectangle", "--duration", "0.5"]
    config = config_from_arguments(build_parser().parse_args(argv), argv)
    assert list(config.trajectories) == ["ellipse", "rectangle"]
