"""clrrmc's reference step cap reads the ratio period / reference_step as a run's step cap
does (ddwmmr.errors.check_step_count): a few ulps of round-off past MAX_STEPS are the cap,
more is refused in one line naming reference_step."""

from __future__ import annotations

import pytest

from ddwmmr import Ellipse, Robot
from ddwmmr.controllers import clrrmc
from ddwmmr.controllers.base import make_controller
from ddwmmr.errors import MAX_STEPS, ParameterError


class _Long:
    """The ellipse's path with a longer ``duration`` (s): only the cap check reads it."""

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self._path = Ellipse()

    def pose(self, t):
        return self._path.pose(t)

    def velocity(self, t):
        return self._path.velocity(t)


@pytest.fixture
def built(monkeypatch) -> list[float]:
    """The horizons (s) of the references reset built (not integrated: a million steps)."""
    horizons: list[float] = []
    monkeypatch.setattr(
        clrrmc, "ReferenceTrajectory", lambda *args, horizon, **kw: horizons.append(horizon)
    )
    return horizons


def _reset(period: float, step: float) -> None:
    controller = make_controller("clrrmc-cs", Robot(), reference_step=step)
    trajectory = _Long(period)
    controller.reset(trajectory, clrrmc.start_configuration(Robot(), trajectory))


def test_a_period_an_ulp_past_the_cap_is_the_cap(built):
    ratio = 600.0 / 0.0006
    assert ratio > MAX_STEPS and ratio - MAX_STEPS < 1e-9  # the round-off the slack is for
    _reset(600.0, 0.0006)
    assert built == [600.0]


def test_more_than_the_cap_is_refused_naming_reference_step(built):
    with pytest.raises(ParameterError) as refused:
        _reset(600.001, 0.0006)
    assert str(refused.value) == (
        f"reference_step: 600.001 s / 0.0006 s is more than {MAX_STEPS} reference steps; "
        "use a larger reference_step"
    )
    assert built == []
