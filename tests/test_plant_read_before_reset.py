"""A plant read before its first ``reset`` (``observe``, ``extra_values``...) says to reset."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ddwmmr import Robot
from ddwmmr.errors import ParameterError
from ddwmmr.plants import KinematicPlant, MujocoPlant, PlantNotResetError, ThesisPlant
from ddwmmr.plants.thesis import ThesisState

ROBOT = Robot()
Q = np.array([0.1, -0.05, 0.02, 0.31, 0.52])


@pytest.mark.parametrize(
    ("kind", "name"),
    [(KinematicPlant, "kinematic"), (ThesisPlant, "thesis"), (MujocoPlant, "mujoco")],
)
def test_reading_a_plant_before_its_reset_says_to_reset(kind, name):
    """observe() and extra_values() gave a zero state (the robot at the origin) before
    reset(); step() already said to reset first."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plant = kind(ROBOT)
    readers = {"observe": plant.observe, "extra_values": plant.extra_values}
    if kind is MujocoPlant:
        readers |= {
            "support_forces": plant.support_forces,
            "base_tilt": plant.base_tilt,
            "wheel_slip": plant.wheel_slip,
            "torque_use": plant.torque_use,
        }
    if kind is ThesisPlant:  # its public state, read as observe() reads it
        readers["state"] = lambda: plant.state
    for method, read in readers.items():
        with pytest.raises(PlantNotResetError) as info:
            read()
        assert str(info.value) == f"{name} plant: call reset(q0, dt) before {method}"
    applied, saturated = plant.limit(Q, np.array([0.1, 0.0, 0.1, 0.1]))  # reads no state
    assert applied.tolist() == [0.1, 0.0, 0.1, 0.1] and not saturated
    plant.reset(Q, 0.02)
    assert plant.observe().q[:2] == pytest.approx(Q[:2], abs=1e-3)
    assert len(plant.extra_values()) == len(plant.extra_columns)


def test_a_physics_plants_tallies_read_not_yet_before_its_reset():
    """tip_time and unloaded_time_s tally a run since its reset: before the first they
    read None and 0 (the plant contract, docs/api.md) rather than raising as the state
    readings do; the kinematic and thesis plants judge no tipping and have neither (the
    loop tells physics plants by ``tip_time``)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plant = MujocoPlant(ROBOT)
    assert plant.tip_time is None and plant.unloaded_time_s == 0.0
    plant.reset(Q, 0.02)
    assert plant.tip_time is None and plant.unloaded_time_s == 0.0
    for kind in (KinematicPlant, ThesisPlant):
        other = kind(ROBOT)
        assert not hasattr(other, "tip_time") and not hasattr(other, "unloaded_time_s")


def test_the_thesis_plants_state_says_to_reset_before_its_first_reset():
    """ThesisPlant.state read zeros (the robot at the origin) before reset() while
    observe() raised; setting it before then is refused the same way, after it takes only
    a ThesisState (one line naming ``state``)."""
    plant = ThesisPlant(ROBOT)
    with pytest.raises(
        PlantNotResetError, match=r"^thesis plant: call reset\(q0, dt\) before state$"
    ):
        plant.state = ThesisState()
    plant.reset(Q, 0.02)
    assert plant.state.q == tuple(Q.tolist())
    with pytest.raises(ParameterError, match=r"^state must be a ThesisState \(got "):
        plant.state = (0.0,) * 7
    plant.state = ThesisState(1.0, 2.0, 0.0, 0.3, 0.5, 0.1, 0.0)
    assert plant.observe().values == (1.0, 2.0, 0.0, 0.3, 0.5)
