"""The one simulation loop: connects a controller to a plant, fed and judged by a task.

Every run of the library goes through :func:`run_loop`: trajectory tracking
(:func:`ddwmmr.simulate`, the ``track``/``compare`` tools, the GUI) and the thesis's
waypoint protocol (:mod:`ddwmmr.scenarios`). What differs between them is the *task*
(:class:`Task`): where the references come from, what is recorded, when a run ends or
fails. What differs between plants (kinematic, thesis dynamics, physics) is behind
:class:`ddwmmr.plants.base.Plant`. A run prepares the controller and the plant
(:func:`prepare_run`), builds the policy the integrator evaluates at its stages
(:func:`stage_policy`), then takes samples ``k = 0 .. steps``; one (time ``t = k dt``) is::

    obs = plant.observe()                         # measured state at t
    if task.finished(k, t, obs): stop             # e.g. every waypoint reached
    pose_d, velocity_d = task.reference(t, obs)
    command = controller.command(t, obs.q, pose_d, velocity_d)   # timed
    applied, saturated = plant.limit(obs.q, command)             # velocity commands
    task.record(k, t, obs, command, applied, saturated, info, step_ns)
    plant.step(t, applied, dt, policy)            # not after the last sample
    if task.after_step(k, t, plant.observe(), applied): stop      # e.g. tipped over

Controller contract (class attributes, all optional):

* ``interfaces``: the command interfaces it can send, ``"velocity"`` (``command`` returns
  u) and/or ``"force"`` (returns :class:`~ddwmmr.commands.WheelForces`); the
  ``register_controller`` decorator sets it from its ``interfaces`` trait (default
  ``("velocity",)``), the one place a controller declares it.
* ``interface``: the one it sends in this run, when it chooses (the ``mpc`` sets it in
  ``adopt_plant``, from the plant's traits); without it the loop takes the first of
  ``interfaces`` the plant accepts, for each run afresh (:func:`spoken_interface`). An
  ``interface`` outside the ``interfaces`` a registered controller declares still runs,
  with a :class:`FutureWarning` (declare interfaces with ``register_controller``). The
  plant must accept it (:func:`check_interface`).
* ``zero_order_hold``: True for sampled-data controllers (MPC, the thesis controller): the
  command is held over the step. Otherwise the kinematic plant's RK4 re-evaluates the
  control law at its stages (the closed loop integrated as one ODE).
* ``feedback_gains``: the gains K (1/s) of its ``e' = -K e`` error loops (the closed-loop
  methods'); before a run :func:`ddwmmr.sim.simulate.simulate` warns when the largest
  times the step reaches the discrete loop's stability limit
  (:func:`ddwmmr.gains.gain_step_warning`).
* ``wants_base_velocity``: True passes the measured ``base_velocity=(v, w)`` to
  ``command`` (force-level controllers need it).
* ``float_state``: True when ``command`` takes the configuration ``q`` as a tuple of 5
  floats (:attr:`~ddwmmr.plants.base.Observation.values`) instead of an array: the loop
  then passes the floats, and a plant that measures floats never builds an array.
* ``last``: a :class:`~ddwmmr.controllers.base.StepInfo` about the last command (a
  plug-in's checked once, after its first command: :func:`check_info`).
* ``adopt_plant(traits)``: called first with the plant's
  :class:`~ddwmmr.commands.PlantTraits` (its interfaces, whether it judges tipping by its
  physics, its joints' lag and acceleration limits, its base damping, its wheels' force
  limit and lever); a controller may choose the options it was not given for that plant
  (the ``mpc``'s force-level model and dynamic margin on the physics plant).
* ``adopt_control_step(dt)``: called with the loop's step (s) before ``reset``; a
  controller whose commands depend on how long they are held (the MPC's first interval and
  joint targets, the QP's look-ahead) plans with it unless told otherwise.
* ``law(t, q, pose_d, velocity_d) -> (u, ...)``: the control law on lists of floats, with
  no validation and no step info; when present, the integrator's stages call it instead
  of ``command`` (same numbers, a third of the cost). ``u`` is a tuple of 4 floats; any
  other return (``u`` alone, a shorter tuple) is a one-line ParameterError naming ``law``
  and what it must return. A subclass overriding ``command`` below the class defining
  ``law`` gets ``command`` at the stages (:func:`stage_law`).

``reset(trajectory, q0)`` and ``command`` are required. What ``command`` returns is checked
at every sample and integrator stage (:func:`checked_command`): 4 finite numbers (any
sequence; the plant gets them as a float array) on the velocity interface, a
:class:`~ddwmmr.commands.WheelForces` of finite numbers on the force interface; anything
else is a :class:`~ddwmmr.errors.ParameterError` naming the controller's ``command`` and
the step (a command of the other interface too: u from a controller that declares
``interfaces=("force",)``, a ``WheelForces`` from a velocity one). At a sample it goes
through ``task.controller_error`` like any error of the controller; at a stage it comes
out of ``plant.step``.

A plug-in plant (a class from outside the library) is held to its contract the same way,
by the :class:`~ddwmmr.plants.checked.CheckedPlant` the loop puts around it: what its
``observe()`` and ``limit()`` return is checked at every step (a one-line
ParameterError), and anything else its methods raise (but PlantDivergedError, which ends
the run as "diverged") is wrapped in a one-line PluginError naming the plant, the method,
the step and the time. Both go through ``task.controller_error`` (the scenario protocol
records them as the scenario's failure; a tracking run raises them), and so do a plug-in
controller's or plant's errors before the first step (``adopt_plant``,
``adopt_control_step``, ``reset``: :func:`prepare_run`, ``CheckedPlant.reset``). The library's own
plants keep their errors as they are.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from math import isfinite
from typing import Any, NoReturn, Protocol, cast

import numpy as np

from ddwmmr import interrupts
from ddwmmr.commands import FORCE, VELOCITY, WheelForces, traits_of
from ddwmmr.controllers.base import StepInfo
from ddwmmr.errors import (
    FLOAT64,
    ParameterError,
    finite_values,
    name_of,
    plugin_raised,
    raise_as,
    raise_plugin_error,
    shown,
)
from ddwmmr.inheritance import defining_class, from_library, overrides
from ddwmmr.plants.base import Observation, Plant, PlantDivergedError, Policy
from ddwmmr.plants.checked import Failed, PlantFailed, checked_plant
from ddwmmr.user_warnings import warn_user

#: Progress callback: (samples done, samples in all).
Progress = Callable[[int, int], None]


@dataclass(frozen=True, slots=True)
class NoInfo:
    """StepInfo stand-in for controllers that report nothing (all fields at rest)."""

    singular: bool = False
    nonholonomic_residual: float = 0.0
    fallback: bool = False


_NO_INFO = NoInfo()


class Task(Protocol):
    """What a run is for: references in, records and verdicts out."""

    #: Trajectory handed to ``controller.reset`` (None for point-to-point tasks).
    trajectory: Any

    def start(self, obs: Observation) -> bool:  # pragma: no cover - protocol
        """Inspect the start state; True ends the run before the first command."""
        ...

    def finished(self, k: int, t: float, obs: Observation) -> bool:  # pragma: no cover
        """True ends the run at sample k, before commanding."""
        ...

    def reference(self, t: float, obs: Observation) -> tuple[np.ndarray, np.ndarray]:
        """Desired end-effector pose and velocity ``([xE, yE, phiE], rates)`` at t."""
        ...  # pragma: no cover - protocol

    def record(
        self,
        k: int,
        t: float,
        obs: Observation,
        command: Any,
        applied: Any,
        saturated: bool,
        info: Any,
        step_ns: int,
    ) -> None:  # pragma: no cover - protocol
        """Sample k: the state before the step and the command applied over it."""
        ...

    def after_step(
        self, k: int, t: float, obs: Observation, applied: Any
    ) -> bool:  # pragma: no cover - protocol
        """State after the step from sample k; True ends the run (a failure)."""
        ...

    def controller_error(self, k: int, error: Exception) -> bool:  # pragma: no cover
        """A plug-in failed at sample k: the controller raised or returned a bad command,
        or a plug-in plant raised or broke its contract (a :class:`PluginError` or a
        :class:`ParameterError` naming the plant); True ends the run quietly, False
        re-raises."""
        ...

    def diverged(self, k: int, error: PlantDivergedError) -> None:  # pragma: no cover
        """The plant's state blew up in the step from sample k; the run stops."""
        ...


@dataclass(frozen=True)
class LoopEnd:
    """How a run ended: ``samples`` is the end index (time ``samples * dt``)."""

    samples: int
    #: "steps", "finished", "failed", "controller_error", "plant_error", "diverged", "start"
    reason: str


def spoken_interface(controller: Any, plant: Plant) -> str:
    """The command interface ``controller`` speaks on ``plant``, unchecked: its
    ``interface`` if it has one, else the first of its declared ``interfaces`` (default
    velocity) that the plant accepts, else the first declared."""
    interface: str | None = getattr(controller, "interface", None)
    if interface is not None:
        return interface
    declared: tuple[str, ...] = tuple(getattr(controller, "interfaces", None) or (VELOCITY,))
    return next((i for i in declared if i in plant.interfaces), declared[0])


def check_interface(controller: Any, plant: Plant) -> str:
    """The command interface ``controller`` sends on ``plant`` (see the module docstring):
    its ``interface`` if it has one, else the first of its declared ``interfaces`` that the
    plant accepts (chosen afresh for every plant: nothing is stored on the controller); a
    one-line :class:`ParameterError` if the plant does not accept it. An ``interface``
    outside the declared ``interfaces`` is a :class:`FutureWarning` naming the user's line
    (:func:`~ddwmmr.user_warnings.warn_user`)."""
    declared = tuple(getattr(controller, "interfaces", None) or (VELOCITY,))
    interface = spoken_interface(controller, plant)
    own = getattr(controller, "interface", None) is not None
    if own and hasattr(controller, "interfaces") and interface not in declared:
        warn_user(
            f"{name_of(controller)} sends {interface} commands (its interface attribute) "
            f"but declares interfaces={declared}: declare them with "
            f"@register_controller(..., interfaces=...); the interface attribute alone is "
            "deprecated",
            FutureWarning,
        )
    if interface not in plant.interfaces:
        name = getattr(controller, "name", type(controller).__name__)
        raise ParameterError(
            f"plant: {plant.name} does not accept {interface} commands from {name} "
            f"(accepts: {', '.join(plant.interfaces)})"
        )
    return interface


def checked_command(command: Any, force: bool, controller: Any, k: int, t: float) -> Any:
    """``command``, as returned by ``controller.command`` at step ``k`` (time ``t`` s), if
    it is a command the plant can apply: on the velocity interface 4 finite numbers
    ``u = [v, w, th1dot, th2dot]`` (any sequence, returned as a float array:
    :func:`finite_values`), on the force interface (``force``) a
    :class:`~ddwmmr.commands.WheelForces` of 4 finite numbers. Anything else (NaN, None, 3
    values, text) is a one-line :class:`ParameterError` naming the controller's command and
    the step: a plant would otherwise fail on it deep inside, or (the thesis plant) drive
    its wheels at full force from a NaN. Registered controllers always return a finite
    command (they fall back), so for them this only costs a few C calls a step."""
    if type(command) is np.ndarray and command.dtype is FLOAT64 and command.shape == (4,):
        # what every registered velocity controller returns: :func:`finite_values`'s test
        # inlined, as it runs at every sample and stage
        a, b, c, d = command.tolist()
        if not force and isfinite(a + b + c + d):
            return command
    if force:
        if isinstance(command, WheelForces):
            fields = (command.left, command.right, command.th1_target, command.th2_target)
            try:  # four floats, the common case: one sum (finite only if every term is)
                finite = isfinite(sum(fields))
            except (TypeError, OverflowError):  # text, None, an integer beyond a float
                finite = False
            if finite or finite_values(fields, 4) is not None:
                return command
        wanted = (
            "a WheelForces(left, right, th1_target, th2_target) of 4 finite numbers "
            "(N, N, rad, rad)"
        )
    else:
        array = finite_values(command, 4)
        if array is not None:
            return array
        wanted = "4 finite numbers u = [v, w, th1dot, th2dot] (m/s, rad/s, rad/s, rad/s)"
    raise ParameterError(
        f"method: {name_of(controller)}.command() must return {wanted} (got "
        f"{shown(command, 60)} at step {k}, t = {t:g} s)"
    )


def raise_wrapped(controller: Any, error: Exception, k: int, t: float, method: str) -> NoReturn:
    """Raise what a run raises when ``controller.<method>`` raised ``error`` at step ``k``
    (time ``t`` s; called from an ``except`` block): a :class:`ParameterError` (bad input,
    one line naming it already), a :class:`PluginError`, or anything a controller of the
    library raised, as it is (a bug of ours keeps its traceback); anything a controller
    from outside the library raised, wrapped in a one-line :class:`PluginError` naming it,
    what it raised and where (``error`` its ``__cause__``)."""
    if from_library(controller):
        raise error
    call = f"method: {name_of(controller)}.{method}()"
    raise_plugin_error(call, error, f" at step {k}, t = {t:g} s", quoted=True)


def prepare(controller: Any, method: str, *args: Any, failed: Failed | None = None) -> bool:
    """Call ``controller.<method>(*args)`` before the first step (``adopt_plant``,
    ``adopt_control_step``, ``reset``). What a controller from outside the library raises
    there is a one-line :class:`PluginError` naming it, the call and what it raised (the
    ``__cause__``); a ParameterError, and anything a library controller raises, pass as
    they are. A plug-in's error is handed to ``failed`` (the task's
    ``controller_error(0, error)``) first: True (returned) when the task ends the run on
    it, as on an error of ``command``; else it is raised."""
    try:
        getattr(controller, method)(*args)
    except Exception as error:
        if from_library(controller):
            raise
        call = f"method: {name_of(controller)}.{method}()"
        wrapped = plugin_raised(call, error, " before the first step", quoted=True)
        if failed is not None and failed(0, wrapped):
            return True
        raise_as(wrapped, error)
    return False


def check_info(controller: Any, info: Any, k: int, t: float) -> None:
    """Refuse, in one line naming ``controller``, a step info ``info`` (its ``last`` after
    the command of step ``k``, time ``t`` s) that is not a
    :class:`~ddwmmr.controllers.base.StepInfo`: the run records its fields at every step.
    The loop checks a plug-in's once, at its first step."""
    if not isinstance(info, StepInfo | NoInfo):
        raise ParameterError(
            f"method: {name_of(controller)}.last must be a StepInfo(singular, "
            f"nonholonomic_residual, fallback, extra) (got {shown(info, 60)} after the "
            f"command of step {k}, t = {t:g} s)"
        )


def bad_law(controller: Any, result: Any, k: int, t: float) -> NoReturn:
    """Raise the one-line :class:`ParameterError` for what ``controller.law`` returned at a
    stage of step ``k`` (time ``t`` s) when it is not ``(u, ...)`` with ``u`` 4 numbers."""
    raise ParameterError(
        f"method: {name_of(controller)}.law() must return (u, ...) with u 4 numbers "
        f"(v, w, th1dot, th2dot) (got {shown(result, 60)} at step {k}, t = {t:g} s)"
    )


def stage_law(controller: Any) -> Callable[..., Any] | None:
    """The controller's ``law`` if the integrator may call it at its stages, else None.

    ``law`` stands for ``command`` only where ``command`` is not overridden below the class
    that defines ``law``: a subclass that changes ``command`` (adds noise, clips, logs)
    without a matching ``law`` has ``command`` called at every stage, as before ``law``
    existed."""
    law = getattr(controller, "law", None)
    owner = defining_class(type(controller), "law")
    if law is None or owner is None:
        return law  # none, or an instance attribute: the controller's own word
    return None if overrides(controller, owner, "command") else law


def prepare_run(
    plant: Plant, controller: Any, task: Task, q0: np.ndarray, dt: float
) -> str | LoopEnd:
    """Make ``controller`` and the (checked) ``plant`` ready for a run from ``q0``
    (``[x, y, phi, th1, th2]``, m and rad) with control step ``dt`` (s), in this order:
    ``controller.adopt_plant(traits)`` (if it has it: it may choose its interface for this
    plant), the command interface (:func:`check_interface`), ``plant.reset(q0, dt)``,
    ``controller.adopt_control_step(dt)`` (if it has it) and ``controller.reset(trajectory,
    q0)`` with the task's trajectory and a float copy of ``q0``.

    Returns the interface the controller sends (``"velocity"`` or ``"force"``), or the
    :class:`LoopEnd` at sample 0 when a plug-in failed here and the task ended the run on
    it (``"controller_error"``, ``"plant_error"``). Anything else is raised (:func:`prepare`).
    """
    failed = task.controller_error  # its verdict on a plug-in's error: end the run?
    try:
        adopt = getattr(controller, "adopt_plant", None) is not None
        if adopt and prepare(controller, "adopt_plant", traits_of(plant), failed=failed):
            return LoopEnd(0, "controller_error")
        interface = check_interface(controller, plant)
        plant.reset(q0, dt)
        adopt = getattr(controller, "adopt_control_step", None) is not None
        if adopt and prepare(controller, "adopt_control_step", dt, failed=failed):
            return LoopEnd(0, "controller_error")
        q_start = np.array(q0, dtype=float)
        if prepare(controller, "reset", task.trajectory, q_start, failed=failed):
            return LoopEnd(0, "controller_error")
    except PlantFailed:  # a plug-in plant's reset failed; the task ended the run on it
        return LoopEnd(0, "plant_error")
    return interface


class Stages:
    """What the loop and its integrator-stage policy (:func:`stage_policy`) share in a run:
    ``k``, the sample whose step the plant is taking (the loop sets it before each
    ``plant.step``; the messages of a failure at a stage name it), and ``errors``, the
    controller's errors raised at the stages. Those reach the loop out of ``plant.step``,
    not where they arose: the loop tells them from the plant's own by this list."""

    __slots__ = ("errors", "k")

    def __init__(self) -> None:
        self.k = 0
        self.errors: list[Exception] = []


def stage_policy(
    controller: Any,
    reference: Callable[[float, Any], tuple[np.ndarray, np.ndarray]],
    force: bool,
    stages: Stages,
) -> Policy | None:
    """The policy ``(t, q) -> u`` the kinematic plant's integrator evaluates at its stages
    (t in s, q and u as in ``command``; not recorded), or None when the command is held
    over the step: force commands, and a ``zero_order_hold`` controller.

    The policy is the closed-loop law against the task's ``reference`` (called with no
    observation): the controller's ``command`` checked as at a sample
    (:func:`checked_command`), or its float-level ``law`` where that may stand for it
    (:func:`stage_law`). A failure there is raised as at a sample, named with step
    ``stages.k``, and kept in ``stages.errors`` on its way out of ``plant.step``."""
    law = stage_law(controller)
    command_of = controller.command

    def policy(t: float, q: list[float]) -> np.ndarray:
        """The closed-loop law at an integrator stage, through ``command``."""
        pose_d, velocity_d = reference(t, None)
        try:
            try:
                command = command_of(t, np.array(q), pose_d, velocity_d)
            except Exception as error:
                raise_wrapped(controller, error, stages.k, t, "command")
            checked: np.ndarray = checked_command(command, False, controller, stages.k, t)
            return checked
        except Exception as error:
            stages.errors.append(error)
            raise

    def law_policy(t: float, q: list[float]) -> Sequence[float] | np.ndarray:
        """The same through the controller's float-level ``law`` (no validation, no step
        info: stage states are the integrator's own finite floats). A non-finite result
        goes through ``command`` (:func:`policy`), whose validation names the argument that
        made it."""
        pose_d, velocity_d = reference(t, None)
        try:
            try:
                # cast: law_policy is the stage policy only when law is not None (below)
                result = cast("Callable[..., Any]", law)(t, q, pose_d.tolist(), velocity_d.tolist())
            except Exception as error:
                raise_wrapped(controller, error, stages.k, t, "law")
            try:
                u = result[0]
                finite = isfinite(u[0] + u[1] + u[2] + u[3]) if len(u) == 4 else None
            except Exception:  # not (u, ...): a plain u of floats, None, text
                finite = None
            if finite is None:
                bad_law(controller, result, stages.k, t)
        except Exception as error:
            stages.errors.append(error)
            raise
        return u if finite else policy(t, q)

    if force or getattr(controller, "zero_order_hold", False):
        return None
    return policy if law is None else law_policy


def run_loop(
    plant: Plant,
    controller: Any,
    task: Task,
    q0: np.ndarray,
    dt: float,
    steps: int,
    progress: Progress | None = None,
) -> LoopEnd:
    """Run ``controller`` on ``plant`` from ``q0`` (``[x, y, phi, th1, th2]``, m and rad)
    for up to ``steps`` steps of ``dt`` (s), ``task`` giving the references and judging;
    ``progress(k, steps)`` (optional) is called after each step, k the steps done.

    Samples ``k = 0 .. steps`` at ``t = k dt``: each is recorded, every one but the last
    is followed by a step. Returns how the run ended (:class:`LoopEnd`). See the module
    docstring for one sample's sequence and the controller contract, :func:`prepare_run`
    for what comes before the first sample.
    """
    plant = checked_plant(plant, task.controller_error)  # a plug-in's calls checked
    interface = prepare_run(plant, controller, task, q0, dt)
    if isinstance(interface, LoopEnd):
        return interface
    force = interface == FORCE  # wheel forces: applied as sent, held over the step
    # what every sample needs, looked up once: the loop below runs per step, and its own
    # overhead is a share of a cheap controller's step
    wants_velocity = getattr(controller, "wants_base_velocity", False)
    float_state = getattr(controller, "float_state", False)
    command_of = controller.command
    stages = Stages()
    policy = stage_policy(controller, task.reference, force, stages)
    unchecked_info = not from_library(controller)  # a plug-in's step info, checked once
    clock = time.perf_counter_ns

    # One sample per pass, inline (no function per sample: a call costs a share of a cheap
    # controller's step).
    try:
        obs = plant.observe()
        if task.start(obs):
            return LoopEnd(0, "start")
        for k in range(steps + 1):
            t = k * dt
            interrupts.raise_pending()  # one a solver swallowed in the last step
            if task.finished(k, t, obs):
                return LoopEnd(k, "finished")
            pose_d, velocity_d = task.reference(t, obs)

            # the command; step_us times the controller's call alone
            try:
                q = obs.values if float_state else obs.q
                start = clock()
                if wants_velocity:
                    command = command_of(t, q, pose_d, velocity_d, base_velocity=(obs.v, obs.w))
                else:
                    command = command_of(t, q, pose_d, velocity_d)
                elapsed = clock() - start
                command = checked_command(command, force, controller, k, t)
                info = getattr(controller, "last", _NO_INFO)
                if unchecked_info:
                    check_info(controller, info, k, t)
                    unchecked_info = False
            except Exception as error:
                if task.controller_error(k, error):
                    return LoopEnd(k, "controller_error")
                raise_wrapped(controller, error, k, t, "command")

            # what the plant applies: velocities within its limits, wheel forces as sent
            if force:
                applied, saturated = command, False
            else:
                applied, saturated = plant.limit(obs.q, command)
            task.record(k, t, obs, command, applied, saturated, info, elapsed)
            if k == steps:
                break  # the last sample is recorded, not stepped

            # the step to sample k + 1
            stages.k = k
            try:
                plant.step(t, applied, dt, policy)
            except PlantDivergedError as error:
                task.diverged(k, error)
                return LoopEnd(k + 1, "diverged")
            except Exception:
                if not stages.errors:
                    raise  # the plant's own (a plug-in's one line, from CheckedPlant)
                # the controller failed at a stage, inside the plant's step: its error
                if task.controller_error(k, stages.errors[-1]):
                    return LoopEnd(k, "controller_error")
                raise
            obs = plant.observe()
            if task.after_step(k, t, obs, applied):
                return LoopEnd(k + 1, "failed")
            if progress is not None:
                progress(k + 1, steps)
    except PlantFailed as failure:  # a plug-in plant failed; the task ended the run on it
        return LoopEnd(failure.samples, "plant_error")
    return LoopEnd(steps, "steps")
