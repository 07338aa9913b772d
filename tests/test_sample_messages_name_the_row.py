"""A sampled trajectory's non-finite or too large value is named by its row (from 1, the
data rows of a CSV file) and column: "points must be finite numbers (m, rad)" alone left
a user searching a million-row file for the NaN."""

from __future__ import annotations

import math

import pytest

from ddwmmr import SampledTrajectory, load_trajectory
from ddwmmr.errors import ParameterError

TIMES = [0.0, 1.0, 2.0, 3.0]
POINTS = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.5], [3.0, 0.0]]


@pytest.mark.parametrize(
    ("times", "points", "tail"),
    [
        (TIMES, [*POINTS[:2], [2.0, math.nan], POINTS[3]], "(got nan in row 3, column y)"),
        (
            TIMES,
            [[0, 0, 0], [1, 0, math.inf], [2, 0, 0], [3, 0, 0]],
            "(got inf in row 2, column phi)",
        ),
        ([0.0, 1.0, math.nan, 3.0], POINTS, "(got nan in row 3)"),
        (TIMES, [*POINTS[:3], [-5e6, 0.0]], "(got -5e+06 in row 4, column x)"),
        ([0.0, 1.0, 2.0, 2e9], POINTS, "(got 2e+09 in row 4)"),
    ],
)
def test_a_bad_sample_is_named_by_row_and_column(times, points, tail):
    with pytest.raises(ParameterError) as info:
        SampledTrajectory(times, points)
    assert str(info.value).endswith(tail)


def test_a_csv_files_nan_is_named_by_its_data_row(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text("# a log\nt,x,y\n0,0,0\n1,1,0\n2,nan,0\n3,3,0\n")
    with pytest.raises(ParameterError) as info:
        load_trajectory(path)
    assert str(info.value) == (
        f"traj: {path}: trajectory samples: points must be finite numbers (m, rad) "
        "(got nan in row 3, column x)"
    )
