"""Building an arbiter from a run configuration (the scenario protocol's ``arbiter`` field).

``config.arbiter`` is a registered arbiter name (:func:`available_arbiters`; the
configuration's ``stability`` and ``manipulability`` thresholds and ``arbiter_seed`` are
used) or an arbiter instance, used as it is with its own thresholds (``reset()`` is called
before every run, so an instance can be reused; one that records keeps the history of the
last run). An arbiter class is registered with :func:`ddwmmr.registry.register_arbiter`
and built as ``cls(stability=Hysteresis, manipulability=Hysteresis)``, plus
``seed=config.arbiter_seed`` when its constructor takes a ``seed``, plus
``config.arbiter_options`` (its other keyword parameters: :func:`arbiter_option_specs`).
"""

from __future__ import annotations

import inspect
from typing import TYPE_CHECKING, Any

from ddwmmr.arbiters.state_machine import Hysteresis
from ddwmmr.errors import ParameterError, did_you_mean, shown
from ddwmmr.registry import ARBITERS, CONTROLLERS, build

if TYPE_CHECKING:
    from ddwmmr.controllers.option_specs import OptionSpec

#: The arbiter a run uses when it names none.
DEFAULT_ARBITER = "state-machine"
#: Constructor parameters of an arbiter that the run sets itself (the thresholds, the
#: seed, the arbiter study's recording), not ``arbiter_options``.
ARBITER_ARGUMENTS = ("stability", "manipulability", "seed", "record")


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


def arbiter_option_specs(arbiter: str) -> dict[str, OptionSpec]:
    """The options ``RunConfig.arbiter_options`` (``--arbiter-option NAME=VALUE``) sets on
    the registered arbiter ``arbiter``: its constructor's keyword parameters but
    :data:`ARBITER_ARGUMENTS`, typed as a method's options are (name -> spec). The
    built-in arbiters have none."""
    from ddwmmr.controllers.option_specs import constructor_option_specs

    return constructor_option_specs(ARBITERS.load(arbiter), ARBITER_ARGUMENTS)


def check_arbiter_options(options: Any, arbiter: Any, controller: str) -> None:
    """Refuse (one-line :class:`ParameterError`) ``RunConfig.arbiter_options`` (already
    checked as ``(name, value)`` pairs) that no arbiter would read: given for a controller
    without an arbiter or with an arbiter instance (built already), or naming an option
    the arbiter's constructor does not take (with the closest and the list)."""
    if not options:
        return
    takes = CONTROLLERS.names(arbiter=True)
    if controller not in takes:
        raise ParameterError(
            f"arbiter_options: only the {' or '.join(takes)} controller has an arbiter"
        )
    if not isinstance(arbiter, str):
        raise ParameterError(
            "arbiter_options: only for an arbiter given by name (an instance is built "
            f"already; got {shown(arbiter)})"
        )
    specs = arbiter_option_specs(arbiter)
    for name, _ in options:
        if name not in specs:
            listed = ", ".join(specs) or "none"
            set_by = " (the run sets it)" if name in ARBITER_ARGUMENTS else ""
            raise ParameterError(
                f"arbiter_options: the {arbiter} arbiter has no option {name!r}{set_by}"
                f"{did_you_mean(name, specs)} (options: {listed})"
            )


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
    options.update(getattr(config, "arbiter_options", ()))
    return build(
        cls, f"arbiter: {arbiter}: {cls.__qualname__}(**thresholds)", options=options, quoted=False
    )
