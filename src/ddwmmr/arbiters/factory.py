"""Building an arbiter from a run configuration (the scenario protocol's ``arbiter`` field).

``config.arbiter`` is a name in :data:`ARBITERS` (the configuration's ``stability`` and
``manipulability`` thresholds and ``arbiter_seed`` are used) or an arbiter instance, used as
it is with its own thresholds (``reset()`` is called before every run, so an instance can be
reused; one that records keeps the history of the last run).
"""

from __future__ import annotations

from typing import Any

from ddwmmr.arbiters.competitive import CompetitiveDynamicsArbiter
from ddwmmr.arbiters.state_machine import Hysteresis, StateMachineArbiter
from ddwmmr.errors import ParameterError

#: Arbiter names accepted by ``RunConfig.arbiter`` and ``--arbiter``.
ARBITERS = ("state-machine", "competitive")


def check_arbiter(arbiter: Any, controller: str = "thesis") -> None:
    """Raise :class:`ParameterError` unless ``arbiter`` is a known name or an arbiter."""
    if isinstance(arbiter, str):
        if arbiter not in ARBITERS:
            raise ParameterError(f"arbiter must be one of {', '.join(ARBITERS)} (got {arbiter!r})")
        if arbiter != ARBITERS[0] and controller != "thesis":
            raise ParameterError("arbiter: only the thesis controller has an arbiter")
        return
    if not all(callable(getattr(arbiter, m, None)) for m in ("reset", "select")):
        raise ParameterError(
            "arbiter: need a name or an object with reset() and select() (ddwmmr.arbiters.Arbiter)"
        )
    if controller != "thesis":
        raise ParameterError("arbiter: only the thesis controller has an arbiter")


def make_arbiter(config: Any) -> Any:
    """The arbiter a run configuration asks for (``config.arbiter``, thresholds, seed)."""
    arbiter = config.arbiter
    if not isinstance(arbiter, str):
        return arbiter
    stability = Hysteresis(*config.stability)
    manipulability = Hysteresis(*config.manipulability)
    if arbiter == "competitive":
        return CompetitiveDynamicsArbiter(stability, manipulability, seed=config.arbiter_seed)
    check_arbiter(arbiter)
    return StateMachineArbiter(stability=stability, manipulability=manipulability)
