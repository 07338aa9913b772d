"""The plant interface: what every plant (kinematic, thesis dynamics, physics) provides.

A plant holds the robot's physical state and advances it under actuator commands
(:mod:`ddwmmr.commands`). The one simulation loop (:mod:`ddwmmr.sim`) drives any plant the
same way::

    plant.reset(q0, dt)                      # start state, control step (s)
    obs = plant.observe()                    # what the sensors report now
    applied, saturated = plant.limit(obs.q, u)   # velocity command after actuator limits
    plant.step(t, command, dt, policy)       # advance by one control step
    plant.extra_values()                     # plant-specific columns at the current state

Plants never see controllers. ``policy`` (optional) lets an integrator of the kinematic
plant re-evaluate a continuous-time control law at its intermediate stages (RK4); every
other plant holds the command over the step (zero-order hold) and ignores it.

The arguments of ``reset``, ``limit`` and ``step`` are checked by every plant with the
helpers here (:func:`check_control_step`, :func:`check_limit`, :func:`check_step`,
:func:`check_policy`) and the start configuration's own check
(:func:`~ddwmmr.model.kinematics.check_configuration`): anything
but finite numbers of the right shape (a ``policy`` that is not callable) is a one-line
:class:`~ddwmmr.errors.ParameterError` naming ``q0``, ``dt``, ``q``, ``u``, ``t``,
``command`` or ``policy``, before the state changes. Whatever reads or advances the
state (``step``, ``observe``, ``extra_values``, and a plant's own state readings: the
thesis plant's ``state``, the MuJoCo plant's ``base_tilt()``...) before the first
``reset`` is a :class:`PlantNotResetError` (a ``RuntimeError``): the plant has no start
state yet.
``limit`` reads only its arguments (and the robot's limits) and works before it.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Sequence
from typing import Any, Protocol

import numpy as np

from ddwmmr.commands import FORCE, VELOCITY, WheelForces
from ddwmmr.errors import FLOAT64, ParameterError, check_finite, check_positive, float_values, shown
from ddwmmr.model.kinematics import check_configuration

#: A continuous-time control law for integrator stages: ``(t, q) -> u``, time in s, the
#: configuration as a list of 5 floats, the velocity command as 4 numbers (a tuple of
#: floats or an array).
Policy = Callable[[float, list[float]], Sequence[float] | np.ndarray]


class Observation:
    """The plant's measured state at one instant (read-only by convention: one is made
    every control step).

    Attributes:
        q: configuration ``[x, y, phi, th1, th2]`` as an array (world frame; m, m, rad,
            rad, rad).
        values: the same configuration as a tuple of 5 Python floats.
        v: forward speed of the base along its heading (m/s).
        w: yaw rate of the base (rad/s).

    A plant may give ``q`` either way: as an array, or as a tuple of floats (cheaper for a
    plant whose state is floats: the array is then built only if someone reads ``q``).
    """

    __slots__ = ("_q", "_values", "v", "w")
    _q: np.ndarray | None  # one of the two is given, the other built on first use
    _values: tuple[float, ...] | None

    def __init__(self, q: np.ndarray | tuple[float, ...], v: float, w: float) -> None:
        if isinstance(q, tuple):  # a named tuple too: ``q`` is then built as an array
            self._q, self._values = None, q
        else:
            self._q, self._values = q, None
        self.v = v
        self.w = w

    @property
    def q(self) -> np.ndarray:
        """Configuration as a float array (built once, on first use)."""
        q = self._q
        if q is None:
            q = self._q = np.array(self._values, dtype=float)
        return q

    @property
    def values(self) -> tuple[float, ...]:
        """Configuration as a tuple of Python floats (converted once, on first use)."""
        values = self._values
        if values is None:
            values = self._values = tuple(np.asarray(self._q, dtype=float).tolist())
        return values

    def finite(self) -> bool:
        """Whether ``q``, ``v`` and ``w`` are 5 + 2 finite numbers (checked one by one; the
        simulation loop asks it of a plug-in plant's observations only)."""
        try:
            q = np.asarray(self._values if self._values is not None else self._q, dtype=float)
            return q.shape == (5,) and all(map(math.isfinite, [*q.tolist(), self.v, self.w]))
        except (TypeError, ValueError, OverflowError):  # text, None, an integer too large
            return False

    def __repr__(self) -> str:
        q: Any = self._values if self._values is not None else self._q
        with contextlib.suppress(TypeError, ValueError, OverflowError):  # else as given
            q = [float(x) for x in q]
        return f"Observation(q={q!r}, v={self.v!r}, w={self.w!r})"


class PlantDivergedError(RuntimeError):
    """The plant's state became non-finite (or left the engine's valid range) in a step.

    The loop stops the run there, keeps what was recorded and reports the step.
    """


class PlantNotResetError(RuntimeError):
    """A plant was stepped or read (``step``, ``observe``, ``extra_values``) before its
    first ``reset(q0, dt)``, so it has no start state.

    The simulation loop always resets first; a caller driving a plant by hand must too.
    The message is one line naming the plant and the method called (``method``).
    """

    def __init__(self, plant: str, method: str = "step") -> None:
        super().__init__(f"{plant} plant: call reset(q0, dt) before {method}")


#: What each command interface takes, for messages.
_COMMAND_FORMS = {
    VELOCITY: "4 finite numbers u = [v, w, th1dot, th2dot] (m/s, rad/s, rad/s, rad/s)",
    FORCE: (
        "a WheelForces(left, right, th1_target, th2_target) of 4 finite numbers (N, N, rad, rad)"
    ),
}
_INF = math.inf
_isfinite = math.isfinite


def arm_rates(
    th1: float,
    th2: float,
    r1: float,
    r2: float,
    speed: float,
    limits: tuple[tuple[float, float], tuple[float, float]],
) -> tuple[float, float]:
    """The joint rates (rad/s) an arm applies at joint angles (th1, th2) (rad) for the
    commanded rates (r1, r2): each within ``+-speed`` (rad/s), and 0 for a joint at (or
    beyond) a limit of ``limits`` (``joint_limits``, rad) that would move further out. The
    one joint-limit rule of the plants that take velocity commands."""
    (low1, high1), (low2, high2) = limits
    r1 = r1 if -speed <= r1 <= speed else math.copysign(speed, r1)
    if (th1 >= high1 and r1 > 0) or (th1 <= low1 and r1 < 0):
        r1 = 0.0
    r2 = r2 if -speed <= r2 <= speed else math.copysign(speed, r2)
    if (th2 >= high2 and r2 > 0) or (th2 <= low2 and r2 < 0):
        r2 = 0.0
    return r1, r2


def check_control_step(dt: Any) -> float:
    """``dt`` (s) as a float if it is a finite number > 0, else :class:`ParameterError`
    naming ``dt``: the control step of ``Plant.reset`` and ``Plant.step``."""
    return check_positive("dt", dt)


def check_policy(policy: Any) -> None:
    """Refuse (one-line :class:`ParameterError` naming ``policy``) a ``policy`` argument of
    ``Plant.step`` that is neither None nor a callable ``(t, q) -> u`` (:data:`Policy`)."""
    if policy is not None and not callable(policy):
        raise ParameterError(
            f"policy must be None or a callable (t, q) -> u (got {shown(policy, 60)})"
        )


def check_limit(q: Any, u: Any) -> tuple[float, float, list[float]]:
    """The arguments of ``Plant.limit`` checked: ``(th1, th2, u)``, the joint angles of
    ``q`` (rad) and ``u`` as a list of 4 floats.

    Args:
        q: configuration ``[x, y, phi, th1, th2]`` (m, m, rad, rad, rad), 5 finite numbers.
        u: velocity command ``[v, w, th1dot, th2dot]`` (m/s, rad/s, rad/s, rad/s), 4 finite
            numbers (any flat sequence).

    Raises:
        ParameterError: naming ``q`` or ``u`` and what it must be.

    It runs every control step: float64 arrays of shapes (5,) and (4,) (what the simulation
    loop passes) cost two ``tolist`` and one sum (finite only if every term is); anything
    else takes the slow path, which names the fault and clears sums that merely overflowed.
    """
    try:
        arrays = type(q) is np.ndarray and type(u) is np.ndarray
        if arrays and q.dtype is FLOAT64 and u.dtype is FLOAT64:
            x, y, phi, th1, th2 = q.tolist()  # another shape fails to unpack here
            v, w, r1, r2 = values = u.tolist()
            if _isfinite(x + y + phi + th1 + th2 + v + w + r1 + r2):
                return th1, th2, values
    except (TypeError, ValueError):  # another shape: rows that are lists, too few values
        pass
    return _check_limit_slowly(q, u)


def _check_limit_slowly(q: Any, u: Any) -> tuple[float, float, list[float]]:
    """:func:`check_limit` for any argument: name the first fault, else return as it does."""
    configuration = float_values(q, 5)
    if configuration is None or not all(map(_isfinite, configuration)):
        # raises: its test is this one, and its message names q (5 finite numbers ...)
        configuration = check_configuration(q, "q")
    values = float_values(u, 4)
    if values is None or not all(map(_isfinite, values)):
        raise ParameterError(command_refusal("u", u))
    return configuration[3], configuration[4], values


def command_refusal(name: str, value: Any, interfaces: Sequence[str] = (VELOCITY,)) -> str:
    """The message refusing ``value`` as a command named ``name`` on ``interfaces``."""
    wanted = " or ".join(_COMMAND_FORMS[i] for i in (VELOCITY, FORCE) if i in interfaces)
    return f"{name} must be {wanted} (got {shown(value, 60)})"


def check_step(
    t: Any, command: Any, dt: Any, interfaces: Sequence[str] = (VELOCITY,)
) -> list[float] | WheelForces:
    """The arguments of ``Plant.step`` checked, before anything changes.

    Args:
        t: time at the start of the step (s), a finite number.
        command: on the ``"velocity"`` interface 4 finite numbers ``u = [v, w, th1dot,
            th2dot]`` (m/s, rad/s, rad/s, rad/s; any flat sequence); on the ``"force"``
            interface a :class:`~ddwmmr.commands.WheelForces` of 4 finite numbers (N, N,
            rad, rad). Only the interfaces in ``interfaces`` are accepted.
        dt: length of the step (s), a finite number > 0.

    Returns:
        A velocity command as a list of 4 floats, a ``WheelForces`` as it is.

    Raises:
        ParameterError: naming ``t``, ``dt`` or ``command`` and what it must be.

    It runs every control step: a float64 array of shape (4,) (what the simulation loop
    passes) or a ``WheelForces`` of floats, with a float dt (numpy's float64 too), costs
    one ``tolist``, one sum (a sum is finite only if every term is) and the comparisons
    of ``dt``; anything else takes the slow path, which names the fault and clears sums
    that merely overflowed.
    """
    values: list[float]  # the command's tolist() below
    try:
        if isinstance(dt, float) and 0.0 < dt < _INF:
            if type(command) is np.ndarray and command.dtype is FLOAT64:
                # another shape than (4,) fails here: too many or too few values to unpack
                # (ValueError), or rows that are lists, not floats (TypeError in the sum)
                a, b, c, d = values = command.tolist()
                if _isfinite(a + b + c + d + t) and VELOCITY in interfaces:
                    return values
            elif type(command) is WheelForces and FORCE in interfaces:
                total = command.left + command.right + command.th1_target + command.th2_target
                if _isfinite(total + t):
                    return command
    except (TypeError, ValueError, OverflowError):  # text, None, an int like 10**400
        pass
    return _check_step_slowly(t, command, dt, interfaces)


def _check_step_slowly(
    t: Any, command: Any, dt: Any, interfaces: Sequence[str]
) -> list[float] | WheelForces:
    """:func:`check_step` for any argument: name the first fault, else return as it does."""
    check_finite("t", t, "in s")
    check_control_step(dt)
    forces = isinstance(command, WheelForces)
    values = None
    if forces and FORCE in interfaces:
        fields = (command.left, command.right, command.th1_target, command.th2_target)
        values = float_values(fields, 4)
    elif not forces and VELOCITY in interfaces:
        values = float_values(command, 4)
    if values is not None and all(map(_isfinite, values)):
        return command if forces else values
    raise ParameterError(command_refusal("command", command, interfaces))


class PlantImplementation(Protocol):
    """What a plant class implements itself: every member of :class:`Plant` but ``name``
    and ``interfaces``, which its :func:`~ddwmmr.registry.register_plant` decorator sets
    on the class (a type checker does not see what a decorator sets). ``simulate(...,
    plant=...)`` takes a plant object by this type; a plant the loop runs is a
    :class:`Plant` (registered, or declaring both attributes itself).
    """

    robot: Any
    extra_columns: tuple[str, ...]

    def reset(self, q0: np.ndarray, dt: float) -> None:  # pragma: no cover - protocol
        """Place the robot at rest at configuration ``q0`` for a run with control step dt (s).

        Raises :class:`~ddwmmr.errors.ParameterError` if ``q0`` is not 5 finite numbers
        (:func:`~ddwmmr.model.kinematics.check_configuration`) or dt does not suit the
        plant (not finite and > 0, :func:`check_control_step`; not a multiple of a physics
        engine's timestep).
        """
        ...

    def observe(self) -> Observation:  # pragma: no cover - protocol
        """The current measured state; :class:`PlantNotResetError` before the first
        ``reset``."""
        ...

    def limit(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:  # pragma: no cover
        """Velocity command ``u`` as the plant's actuator limits will apply it at ``q``, and
        whether a limit was hit (recorded as the run's commanded input). A ``q`` that is
        not 5 finite numbers or a ``u`` that is not 4 is a one-line
        :class:`~ddwmmr.errors.ParameterError` naming it (:func:`check_limit`)."""
        ...

    def step(
        self, t: float, command: Any, dt: float, policy: Policy | None = None
    ) -> None:  # pragma: no cover - protocol
        """Advance the state by ``dt`` (s) from time ``t`` under ``command``.

        ``command`` is a velocity array u or a :class:`~ddwmmr.commands.WheelForces`,
        whichever of ``interfaces`` it belongs to. Raises
        :class:`~ddwmmr.errors.ParameterError` for a command of another interface, a
        non-finite or misshapen one, a non-finite t or a dt that is not > 0
        (:func:`check_step`) or a ``policy`` that is neither None nor callable
        (:func:`check_policy`), :class:`PlantDivergedError` when the new state is not
        finite and :class:`PlantNotResetError` before the first ``reset``. Anything else
        a plug-in plant (a class from outside the library) raises here is wrapped by the
        simulation loop in a one-line
        :class:`~ddwmmr.errors.PluginError` naming the plant, the step and the time
        (:class:`ddwmmr.plants.checked.CheckedPlant`).
        """
        ...

    def extra_values(self) -> Sequence[float]:  # pragma: no cover - protocol
        """Values of ``extra_columns`` at the current state; :class:`PlantNotResetError`
        before the first ``reset``."""
        ...

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:  # pragma: no cover
        """Plant-specific summary keys computed from a recorded run (may be empty)."""
        ...


class Plant(PlantImplementation, Protocol):
    """Structural type of every plant.

    Attributes:
        name: short name used in reports (``"kinematic"``, ``"thesis"``, ``"mujoco"``).
        interfaces: command interfaces accepted (``"velocity"``, ``"force"``).
        robot: the :class:`~ddwmmr.model.Robot` it simulates.
        extra_columns: names of plant-specific time-series columns (may be empty).

    Optional: ``timestep`` (s), an engine step that control steps must be whole multiples
    of (``simulate`` rounds its default step to one); ``tip_time`` (s or None), on plants
    that judge tipping over by their own physics (contact forces): when the robot tipped
    since the reset, None while it has not (the scenario protocol fails a run on it), and
    with it ``unloaded_time_s``, the time (s) since the reset with an edge of the support
    polygon unloaded. Unlike ``observe()`` and the state readings, these two tally a run
    and raise no :class:`PlantNotResetError`: before the first ``reset`` they read None
    and 0, true of a run not yet started. ``joint_time_constant`` (s), the lag with which
    the joints follow their rate targets, and ``damping``, the base's viscous damping
    ``(c1, c2)`` (N s/m, N m s/rad): what the loop tells controllers of the plant
    (:func:`ddwmmr.commands.traits_of`; the ``mpc`` models both).
    """

    name: str
    interfaces: tuple[str, ...]
