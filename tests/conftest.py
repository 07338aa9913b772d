"""Shared fixtures: a headless matplotlib backend and the default robot."""

import os

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np
import pytest
from hypothesis import settings

from ddwmmr import Robot

# Property tests draw the same examples on every run (reproducible, and CI cannot turn red
# by drawing a new case; search wider by hand with --hypothesis-seed / HYPOTHESIS_PROFILE);
# no deadlines: the 2-core machine is often shared.
settings.register_profile("ddwmmr", derandomize=True, deadline=None)
settings.register_profile("explore", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ddwmmr"))


@pytest.fixture(autouse=True)
def terminal_width(monkeypatch) -> None:
    """An 80-column terminal for every test (and the tools it starts, which inherit the
    environment): argparse wraps ``--help`` at ``$COLUMNS``, so help-text assertions would
    depend on the width of the terminal pytest runs in. A test may set its own."""
    monkeypatch.setenv("COLUMNS", "80")


@pytest.fixture
def robot() -> Robot:
    """The thesis robot (docs/theory.md, "Model"; payload 1.25 kg)."""
    return Robot()


@pytest.fixture
def registered():
    """``registered(registry, name, cls, **traits)``: register ``cls`` under ``name`` in a
    registry of :mod:`ddwmmr.registry` for this test only (removed afterwards)."""
    added = []

    def register(registry, name, cls, **traits):
        registry.register(name, **traits)(cls)
        added.append((registry, name))
        return cls

    yield register
    for registry, name in added:
        registry.unregister(name)


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded random generator: tests are reproducible."""
    return np.random.default_rng(12345)
