"""A hand-written CSV header with spaces after its commas (``t, x, y``) names the same
columns as ``t,x,y``: its values were read with their spaces, its names were refused as
``' x'``."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr import load_trajectory
from ddwmmr.errors import ParameterError

ROWS = "0, 0, 0, 0\n1, 1, 0, 0.1\n2, 2, 1, 0.2\n3, 3, 1, 0.3\n"


@pytest.mark.parametrize("header", ["t, x, y, phi", " t ,x , y,phi ", "t,\tx, y, phi"])
def test_spaces_around_column_names_are_not_part_of_them(tmp_path, header):
    plain = tmp_path / "plain.csv"
    plain.write_text(f"t,x,y,phi\n{ROWS}")
    spaced = tmp_path / "spaced.csv"
    spaced.write_text(f"{header}\n{ROWS}")
    a, b = load_trajectory(str(plain)), load_trajectory(str(spaced))
    np.testing.assert_array_equal(a.times, b.times)
    np.testing.assert_array_equal(a.points, b.points)


def test_a_name_with_a_space_inside_is_still_refused(tmp_path):
    path = tmp_path / "odd.csv"
    path.write_text(f"t, x, y, p hi\n{ROWS}")
    with pytest.raises(ParameterError, match=r"unknown column\(s\) 'p hi'"):
        load_trajectory(str(path))
