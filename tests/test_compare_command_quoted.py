"""The command line compare's report shows ("command: `...`") is quoted for the shell,
as the run record's is: a trajectory file named ``my run|1.csv`` was shown bare, and the
line pasted into a shell piped into a command ``1.csv``."""

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
