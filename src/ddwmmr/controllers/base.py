"""The controller interface and the method registry.

A controller turns the current configuration and the desired end-effector motion into an
input command ``u = (v, w, th1dot, th2dot)`` (m/s, rad/s, rad/s, rad/s)::

    controller = make_controller("ats", Robot(), aux="sum")
    controller.reset(trajectory, q0)          # optional for most methods
    u = controller.command(t, q, pose_d, velocity_d)
    controller.last                           # StepInfo of that command

Controllers never see the plant: the simulation loop (``ddwmmr.sim``) connects them.
A new controller is one class decorated with :func:`register_controller` (the registry is
:data:`ddwmmr.registry.CONTROLLERS`).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from ddwmmr.commands import PlantTraits, WheelForces
from ddwmmr.errors import ParameterError, check_instance, shown
from ddwmmr.model import Robot
from ddwmmr.registry import CONTROLLERS, PluginClass, build
from ddwmmr.trajectories.base import resolution_step


@dataclass
class StepInfo:
    """What a controller reports about its last command.

    Attributes:
        singular: damping was applied because the robot was near a singularity.
        nonholonomic_residual: sideways base speed (m/s) the method asked for and the
            differential drive cannot produce (dropped from the command).
        fallback: the method could not produce its nominal command and used a safe one.
        extra: method-specific values (e.g. QP slack, active stability constraint).
    """

    singular: bool = False
    nonholonomic_residual: float = 0.0
    fallback: bool = False
    extra: dict[str, float] = field(default_factory=dict)


def commanded_steps(column: Any) -> np.ndarray:
    """A recorded time-series column at a run's commanded steps.

    A run of N steps records N + 1 samples (sample 0 the start, sample N the end); the
    command recorded at each of the first N is held over its step, the last sample's is
    recorded but never applied. Counts of commands (singular, saturated, fallback steps)
    are taken over these N, so that they are counts "of N steps" (``summary["steps"]``).
    """
    return np.asarray(column)[:-1]


def step_results(column: Any) -> np.ndarray:
    """A recorded time-series column at the end of each of a run's N steps: samples 1 to
    N of its N + 1 (the start, sample 0, is no step's result). Counts of states (steps
    that ended with S below a floor) are taken over these N."""
    return np.asarray(column)[1:]


def control_step(
    option: float | None, loop_step: float | None, trajectory: Any, default: float
) -> float:
    """The control step (s) a sampled-data controller plans with: its own ``dt`` option,
    else the step the loop holds commands for (``adopt_control_step``), else the
    trajectory's resolution ``duration / samples``, else ``default``."""
    if option is not None:
        return option
    if loop_step is not None:
        return loop_step
    if getattr(trajectory, "samples", None) and getattr(trajectory, "duration", None):
        return resolution_step(trajectory)
    return default


class Controller(Protocol):
    """Structural type of every controller.

    Optional members the simulation loop looks for (:mod:`ddwmmr.sim.loop`): ``interface``,
    ``zero_order_hold``, ``wants_base_velocity``, ``law(t, q, pose_d, velocity_d)`` (the
    control law on lists of floats that the integrator's stages call instead of
    :meth:`command`; the closed-form methods have it) and ``adopt_control_step(dt)``
    (called before :meth:`reset` with the loop's step, s: controllers whose commands
    depend on how long they are held plan with it, see :func:`control_step`), and before
    it ``adopt_plant(traits)`` (the plant's :class:`~ddwmmr.commands.PlantTraits`: a
    controller may choose the options it was not given for that plant).

    The class attributes ``name`` and ``interfaces`` that :func:`register_controller` sets
    are not members: a controller object needs no registration to be simulated (the loop
    reads them with defaults), and a type checker does not see what a decorator sets.
    """

    last: StepInfo

    def reset(self, trajectory: Any, q0: np.ndarray) -> None:  # pragma: no cover - protocol
        """Prepare for a run of ``trajectory`` from configuration ``q0``."""
        ...

    def command(
        self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray
    ) -> npt.ArrayLike | WheelForces:  # pragma: no cover - protocol
        """Input ``u = [v, w, th1dot, th2dot]`` (m/s, rad/s, rad/s, rad/s) for time t (s)
        and configuration q: 4 finite numbers (an array, a list, a tuple), or a
        :class:`~ddwmmr.commands.WheelForces` from a force controller."""
        ...


@dataclass(frozen=True)
class WaypointRun:
    """What a controller of the waypoint task learns of the run it is built for (the
    scenario protocol, :mod:`ddwmmr.scenarios.protocol`): plain data, never the plant.

    A controller registered with ``tasks`` including ``"waypoints"`` provides the class
    method ``waypoint_options(run: WaypointRun) -> dict``: the options the protocol builds
    it with (``make_controller(name, robot, **options)``).

    Attributes:
        scenario: the scenario (``waypoints``, and ``obstacles`` as (x, y, radius) in m).
        config: the run configuration (:class:`ddwmmr.scenarios.RunConfig`: ``dt`` in s,
            ``qp_stability_min``, ``qp_max_speed`` in m/s, ``controller_options``, the
            arbiter and its thresholds).
        plant: the traits of the plant it will command.
        robot: the robot it is built for (the :class:`~ddwmmr.model.Robot` the protocol
            simulates, payload included).
        velocity_envelope: options that keep a velocity command within what the plant's
            force-limited base can follow (the plant's ``velocity_envelope()``), None when
            the plant has no such limit.
    """

    scenario: Any
    config: Any
    plant: PlantTraits
    robot: Any
    velocity_envelope: dict[str, Any] | None = None


#: Registers a controller class: ``@register_controller(name, tasks=..., interfaces=...,
#: arbiter=...)`` (see :mod:`ddwmmr.registry`); it sets the class attribute ``interfaces``,
#: from which the simulation loop picks the command interface it sends (``"force"`` alone:
#: ``command`` returns a :class:`~ddwmmr.commands.WheelForces`).
register_controller = CONTROLLERS.register


def register(name: str) -> Callable[[PluginClass], PluginClass]:
    """Class decorator adding a trajectory-tracking controller under ``name``: the short
    form of :func:`register_controller` with its default traits."""
    return CONTROLLERS.register(name)


def available_controllers(task: str | None = None) -> list[str]:
    """Registered controller names in listing order; ``task`` (``"tracking"`` or
    ``"waypoints"``) keeps those that do it."""
    return CONTROLLERS.names() if task is None else CONTROLLERS.names(tasks=task)


def available_methods() -> list[str]:
    """The methods that track trajectories (``simulate``, ``track``, ``compare``,
    ``bench``, the GUI), in listing order."""
    return available_controllers("tracking")


def method_description(name: str) -> str:
    """First docstring line of a registered controller."""
    return CONTROLLERS.describe(name)


def controller_traits(name: str) -> dict[str, Any]:
    """The registered traits of controller ``name`` (``tasks``, ``interfaces``,
    ``arbiter``; see :mod:`ddwmmr.registry`)."""
    return CONTROLLERS.traits(name)


def controller_class(name: str) -> type:
    """The class registered as ``name``; an unknown name is a :class:`ParameterError`."""
    return CONTROLLERS.load(name)


def method_options(name: str) -> dict[str, Any]:
    """Options of method ``name`` and their defaults (``inspect.Parameter.empty`` if none).

    The options are the named parameters of the ``__init__`` of the method's class and of
    its parents (the MRO, most derived first: a subclass's default wins), without
    ``self``, ``robot``, ``*args`` and ``**kwargs``: what ``make_controller`` accepts.
    """
    return {option: p.default for option, p in method_parameters(name).items()}


def method_parameters(name: str) -> dict[str, inspect.Parameter]:
    """The parameters behind :func:`method_options` (name -> ``inspect.Parameter``, with
    the annotation of the class that sets the default)."""
    parameters: dict[str, inspect.Parameter] = {}
    for klass in inspect.getmro(controller_class(name)):
        init = klass.__dict__.get("__init__")
        if init is None or klass is object:
            continue
        for parameter in list(inspect.signature(init).parameters.values())[1:]:
            variadic = parameter.kind in (parameter.VAR_POSITIONAL, parameter.VAR_KEYWORD)
            if not variadic and parameter.name != "robot":
                parameters.setdefault(parameter.name, parameter)
    return parameters


def check_known_options(method: str, options: Iterable[str], accepted: Iterable[str]) -> None:
    """Refuse (one-line :class:`ParameterError`) the first of ``options`` (names, in sorted
    order) that method ``method`` does not accept, listing the ``accepted`` ones."""
    known = set(accepted)
    unknown = sorted(set(options) - known)
    if unknown:
        raise ParameterError(
            f"method {method}: unknown option {shown(unknown[0])} "
            f"(accepted: {', '.join(sorted(known)) or 'none'})"
        )


def make_controller(
    name: str, robot: Robot | None = None, preset: str | None = None, **options: Any
) -> Controller:
    """Build the registered controller ``name`` for ``robot`` (default: ``Robot()``).

    ``preset`` (``"default"`` or ``"slides"``, see :mod:`ddwmmr.controllers.presets`)
    supplies option values; explicit ``options`` override them. Unknown method names,
    presets and options (see :func:`method_options`) raise :class:`ParameterError`, and so
    does a :class:`NumberText` value: the method's own check words it with the allowed
    range, and a method that would take it unchecked never receives it. Anything else
    the constructor of a plug-in (a class from outside the library) raises is a one-line
    :class:`~ddwmmr.errors.PluginError` naming the method, its class and what it raised
    (the ``__cause__``).
    """
    cls = controller_class(name)
    robot = check_instance("robot", robot if robot is not None else Robot(), Robot)
    if preset is not None:  # preset hook: explicit options win
        from ddwmmr.controllers.presets import preset_options

        options = {**preset_options(name, preset), **options}
    check_known_options(name, options, method_options(name))
    texts = [(option, value) for option, value in options.items() if isinstance(value, NumberText)]
    if not texts:
        call = f"method: {name}: {cls.__qualname__}(robot, **options)"
        controller: Controller = build(cls, call, (robot,), options)
        return controller
    try:  # the method's own check refuses the text, naming the allowed range
        cls(robot, **options)
    except ParameterError:
        raise
    except Exception:  # it computed with the text unchecked (any error): refused below
        pass
    option, text = texts[0]  # a method that takes the text without a word
    raise ParameterError(f"{option} must be {text.expected} (got {shown(text)})")


class NumberText(str):
    """The text given for a number option that is not one number of its kind
    (``damping=abc``, ``horizon=1.5``), as the option parser
    (:meth:`ddwmmr.controllers.option_specs.OptionSpec.parse`) passes it on.

    The method's own check refuses it as it refuses nan, naming the allowed range (the
    range is known there only): "damping must be a finite number > 0 (got 'abc')".
    :func:`make_controller` refuses it ("must be " + :attr:`expected`) if the method does
    not. ``expected``: what the option takes ("a number", "one number", "an integer").
    """

    expected: str

    def __new__(cls, text: str, expected: str = "a number") -> NumberText:
        value = super().__new__(cls, text)
        value.expected = expected
        return value
