"""``Robot.in_length_unit(unit)`` (the mpc's scaled model) with a unit that is no length."""

from __future__ import annotations

import numpy as np
import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot


@pytest.mark.parametrize(
    ("unit", "message"),
    [
        (0, "unit must be > 0 (got 0)"),
        (-1.0, "unit must be > 0 (got -1)"),
        (None, "unit must be a finite number > 0 (got None)"),
        ("1", "unit must be a finite number > 0 (got '1')"),
        (True, "unit must be a finite number > 0 (got True)"),
        (float("nan"), "unit must be a finite number > 0 (got nan)"),
    ],
)
def test_a_robot_in_a_length_unit_refuses_a_unit_that_is_no_length(unit, message):
    """0 raised ZeroDivisionError, None and '1' TypeError, True was taken as 1 m, and -1
    was named as the robot's L1 being -0.35 length units."""
    with pytest.raises(ParameterError) as info:
        Robot().in_length_unit(unit)
    assert str(info.value) == message
    assert pytest.approx(1.0) == Robot().in_length_unit(np.float64(0.35)).L1
