"""Name lookups and recorded paths: one lookup for obstacle names (track, the API, the
GUI), FIFOs found by name and refused when read, a rerun whose file became a folder."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from ddwmmr import ParameterError, Robot, make_controller
from ddwmmr.cli.gui import main as gui_main
from ddwmmr.cli.track import main as track_main
from ddwmmr.qp.limits import load_obstacles
from ddwmmr.trajectories import available_trajectories
from ddwmmr.trajectories.files import find_obstacle_file


@pytest.mark.parametrize("method", ["qp", "mpc"])
def test_the_obstacles_option_looks_up_shipped_names_as_track_does(method):
    # gui --option obstacles=ellipse_post said "cannot read ellipse_post"
    shipped = load_obstacles(find_obstacle_file("ellipse_post"))
    controller = make_controller(method, Robot(), obstacles="ellipse_post")
    assert list(controller.obstacles) == shipped


def test_gui_takes_a_shipped_obstacle_name(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    args = ["--snapshot", "s.png", "--duration", "0.2", "--dpi", "10", "--method", "qp"]
    assert gui_main([*args, "--option", "obstacles=ellipse_post"]) == 0, capsys.readouterr().err
    assert (tmp_path / "s.png").is_file()


def test_a_fifo_found_by_name_is_refused_as_not_a_regular_file(tmp_path, monkeypatch, capsys):
    # it said "unknown trajectory 'fifo' (known: ... fifo ...)"
    monkeypatch.chdir(tmp_path)
    (tmp_path / "trajectories" / "obstacles").mkdir(parents=True)
    os.mkfifo(tmp_path / "trajectories" / "fifo.csv")
    os.mkfifo(tmp_path / "trajectories" / "obstacles" / "pipe.toml")
    (tmp_path / "trajectories" / "folder.csv").mkdir()
    assert "fifo" not in available_trajectories() and "folder" not in available_trajectories()
    base = ["--method", "qp", "--duration", "0.1", "--no-plots", "--out", "out"]
    assert track_main([*base, "--traj", "fifo"]) == 2
    assert "trajectories/fifo.csv is not a regular file" in capsys.readouterr().err
    assert track_main([*base, "--traj", "ellipse", "--obstacles", "pipe"]) == 2
    assert "obstacles/pipe.toml is not a regular file" in capsys.readouterr().err
    assert track_main([*base, "--traj", "folder"]) == 2
    assert "unknown trajectory 'folder'" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_rerun_whose_trajectory_file_became_a_folder_says_so(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    source = Path(__file__).parents[1] / "trajectories" / "figure8.csv"
    shutil.copy(source, tmp_path / "path.csv")
    args = ["--method", "ats", "--traj", "path.csv", "--duration", "0.5", "--no-plots"]
    assert track_main([*args, "--no-progress", "--out", "first"]) == 0
    record = json.loads((tmp_path / "first" / "summary.json").read_text())
    assert Path(record["run"]["trajectory"]["file"]).name == "path.csv"
    (tmp_path / "path.csv").unlink()
    (tmp_path / "path.csv").mkdir()
    assert track_main(["--rerun", "first/summary.json", "--out", "again"]) == 2
    err = capsys.readouterr().err
    assert "path.csv is now a folder" in err and "is gone" not in err
    (tmp_path / "path.csv").rmdir()
    assert track_main(["--rerun", "first/summary.json", "--out", "again"]) == 2
    assert "path.csv is gone" in capsys.readouterr().err


def test_an_unknown_obstacle_name_lists_regular_files_only(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "trajectories" / "obstacles").mkdir(parents=True)
    os.mkfifo(tmp_path / "trajectories" / "obstacles" / "pipe.toml")
    with pytest.raises(ParameterError, match="unknown obstacle file 'nope'") as error:
        find_obstacle_file("nope")
    assert "pipe" not in str(error.value)
