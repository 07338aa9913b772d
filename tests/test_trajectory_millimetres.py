"""A CSV trajectory in millimetres draws a one-line warning before the run."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from ddwmmr.cli.track import main as track
from ddwmmr.trajectories.sampled import SampledTrajectory, read_csv


def _ellipse_csv(path, scale: float):
    t = np.linspace(0.0, 40.0, 401)
    x, y = 2.0 * scale * np.cos(t * math.pi / 20.0), scale * np.sin(t * math.pi / 20.0)
    rows = "".join(f"{a:.6g},{b:.6f},{c:.6f}\n" for a, b, c in zip(t, x, y))
    path.write_text("t,x,y\n" + rows)
    return path


def test_a_csv_trajectory_in_millimetres_warns_at_once(tmp_path):
    with pytest.warns(UserWarning) as caught:
        read_csv(_ellipse_csv(tmp_path / "mm.csv", 1000.0))
    assert [str(w.message) for w in caught] == [
        "trajectory mm: x spans 4000 m and y spans 2000 m, above 10 m: positions are read "
        "in metres (given in millimetres? divide them by 1000); taken as given"
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_csv(_ellipse_csv(tmp_path / "m.csv", 1.0))
        # an offset is no length: a 4 m path 100 m from the origin is taken silently
        (tmp_path / "far.csv").write_text("t,x,y\n0,100,0\n1,104,1\n2,100,2\n")
        read_csv(tmp_path / "far.csv")
        # samples given in code may be scaled on purpose (the simulator's placement)
        SampledTrajectory([0.0, 1.0, 2.0], [[0.0, 0.0], [40.0, 10.0], [0.0, 20.0]])


def test_track_warns_of_a_millimetre_trajectory_before_the_run(tmp_path, capsys):
    path = _ellipse_csv(tmp_path / "mm.csv", 1000.0)
    out = tmp_path / "out"
    argv = ["--method", "pi", "--traj", str(path), "--duration", "0.2", "--no-plots"]
    assert track([*argv, "--out", str(out)]) == 0
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("warning: trajectory mm: x spans 4000 m and y spans 2000 m")
    assert not any("warning: trajectory" in line for line in lines[1:])
