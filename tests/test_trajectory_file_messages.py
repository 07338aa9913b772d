"""What load_trajectory says about a file: a shipped trajectory's file name typed where
there is no such file (``--traj ellipse.toml`` outside the project folder) points to its
name; a bad override of a file's value names it as given, not as the file's."""

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


@pytest.mark.parametrize(
    ("overrides", "tail"),
    [
        ({"a": -1}, " with a given: a must be in [1e-06, 1000] m (got -1)"),
        ({"T": "x", "a": 2.0}, " with T, a given: T must be a number (got 'x')"),
        ({"phi": 0.5}, " with phi given: phi is used only with orientation"),
    ],
)
def test_a_bad_override_of_a_file_is_not_blamed_on_the_file(overrides, tail):
    """load_trajectory("ellipse", a=-1) said "traj: .../ellipse.toml: a must be ...
    (got -1)", as if the shipped file held a = -1."""
    with pytest.raises(ParameterError) as info:
        load_trajectory("ellipse", **overrides)
    message = str(info.value)
    assert message.startswith("traj: ") and "ellipse.toml" + tail in message
