"""Building an arbiter from a run configuration (the scenario protocol's ``arbiter`` field).

``config.arbiter`` is a registered arbiter name (:func:`available_arbiters`; the
configuration's ``stability`` and ``manipulability`` thresholds and ``arbiter_seed`` are
used) or an arbiter instance, used as it is with its own thresholds (``reset()`` is called
before every run, so an instance can be reused; one that records keeps the history of the
last run). An arbiter class is registered with :func:`ddwmmr.registry.register_arbiter`
and built as ``cls(stability=Hysteresis, manipulability=Hysteresis)``, plus
``seed=config.arbiter_seed`` when its constructor takes a ``seed``.
"""

from __future__ import annotations

import inspect
from typing import Any

from ddwmmr.arbiters.state_machine import Hysteresis
from ddwmmr.errors import ParameterError, shown
from ddwmmr.registry import ARBITERS, CONTROLLERS, build

#: The arbiter a run uses when it names none.
DEFAULT_ARBITER = "state-machine"


def available_arbiters() -> list[str]:
    """Registered arbiter names (``RunConfig.arbiter``, ``--arbiter``), in listing order."""
    return ARBITERS.names()


def arbiter_description(name: str) -> str:
    """First docstring line of a registered arbiter."""
    return ARBITERS.describe(name)


def check_arbiter(arbiter: Any, controller: str = "thesis") -> None:
    """Raise :class:`ParameterError` unless ``arbiter`` is a registered name or an arbiter,
    and ``controller`` takes one (anything but the default name needs a controller
    registered with ``arbiter=True``)."""
    takes = CONTROLLERS.names(arbiter=True)
    refusal = f"arbiter: only the {' or '.join(takes)} controller has an arbiter"
    if isinstance(arbiter, str):
        ARBITERS.entry(arbiter)  # an unknown name: one line naming the known ones
        if arbiter != DEFAULT_ARBITER and controller not in takes:
            raise ParameterError(refusal)
        return
    if not all(callable(getattr(arbiter, m, None)) for m in ("reset", "select")):
        raise ParameterError(
            "arbiter: need a name or an object with reset() and select() (ddwmmr.arbiters.Arbiter)"
        )
    if controller not in takes:
        raise ParameterError(refusal)


def make_arbiter(config: Any) -> Any:
    """The arbiter a run configuration asks for (``config.arbiter``, thresholds, seed);
    ``config`` is a :class:`~ddwmmr.scenarios.protocol.RunConfig` (one without
    ``arbiter``, such as a name, is a one-line :class:`ParameterError` naming it). Anything
    but a ParameterError a plug-in's constructor raises is a one-line
    :class:`~ddwmmr.errors.PluginError` naming the arbiter (the ``__cause__`` what it
    raised)."""
    if not hasattr(config, "arbiter"):
        raise ParameterError(
            f"config must be a RunConfig (ddwmmr.scenarios.protocol) (got {shown(config)})"
        )
    arbiter = config.arbiter
    if not isinstance(arbiter, str):
        return arbiter
    cls = ARBITERS.load(arbiter)
    options: dict[str, Any] = {
        "stability": Hysteresis(*config.stability),
        "manipulability": Hysteresis(*config.manipulability),
    }
    parameters = inspect.signature(cls).parameters
    any_keyword = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters.values())
    missing = [name for name in options if name not in parameters and not any_keyword]
    if missing:  # a plug-in's constructor: say what the interface passes, not a TypeError
        raise ParameterError(
            f"arbiter: {arbiter}: its constructor must take the keyword arguments stability "
            f"and manipulability (ddwmmr.arbiters.Hysteresis thresholds; lacks {missing[0]})"
        )
    if "seed" in parameters:
        options["seed"] = config.arbiter_seed
    return build(
        cls, f"arbiter: {arbiter}: {cls.__qualname__}(**thresholds)", options=options, quoted=False
    )
