"""track builds the run's plant once: the plant that refuses a control step before the
run (MuJoCo's engine step) is the one simulate runs."""

from __future__ import annotations

import functools

from ddwmmr.cli import track
from ddwmmr.plants import plant_class


def test_a_mujoco_track_run_with_its_dt_builds_the_plant_once(tmp_path, monkeypatch):
    cls = plant_class("mujoco")
    builds = []
    original = cls.__init__

    @functools.wraps(original)  # the signature lists the plant's options
    def counted(self, *args, **kwargs):
        builds.append(kwargs)
        original(self, *args, **kwargs)

    monkeypatch.setattr(cls, "__init__", counted)
    argv = ["--method", "pi", "--traj", "ellipse", "--plant", "mujoco", "--dt", "0.02",
            "--duration", "0.2", "--no-plots", "--no-progress",
            "--out", str(tmp_path / "r")]  # fmt: skip
    assert track.main(argv) == 0
    assert builds == [{}]
