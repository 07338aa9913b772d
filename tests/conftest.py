"""Shared fixtures: a headless matplotlib backend and the default robot."""

import os

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np
import pytest

from ddwmmr import Robot


@pytest.fixture
def robot() -> Robot:
    """The thesis robot of SPEC §1 (payload 1.25 kg)."""
    return Robot()


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded random generator: tests are reproducible."""
    return np.random.default_rng(12345)
