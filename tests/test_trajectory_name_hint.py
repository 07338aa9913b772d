"""A shipped trajectory's file name typed where there is no such file (``--traj
ellipse.toml`` outside the project folder): the refusal says the name finds it."""

from __future__ import annotations

import pytest

from ddwmmr import load_trajectory
from ddwmmr.errors import ParameterError


@pytest.mark.parametrize("given", ["ellipse.toml", "figure8.CSV", "rectangle.csv"])
def test_a_missing_file_named_like_a_trajectory_points_to_its_name(tmp_path, monkeypatch, given):
    monkeypatch.chdir(tmp_path)
    stem = given.split(".")[0]
    with pytest.raises(ParameterError) as info:
        load_trajectory(given)
    assert str(info.value) == (
        f"traj: no such file {given} here (the trajectory {stem} is found by its name: {stem})"
    )
    assert load_trajectory(stem).duration > 0


@pytest.mark.parametrize("given", ["nosuch.csv", "sub/ellipse.toml"])
def test_other_missing_files_get_no_hint(tmp_path, monkeypatch, given):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ParameterError) as info:
        load_trajectory(given)
    assert str(info.value) == f"traj: no such file {given}"
