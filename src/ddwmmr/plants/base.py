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
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol

import numpy as np

#: A continuous-time control law for integrator stages: ``(t, q) -> u``, time in s, the
#: configuration as a list of 5 floats, the velocity command as 4 numbers (a tuple of
#: floats or an array).
Policy = Callable[[float, list[float]], Sequence[float]]


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

    def __init__(self, q: np.ndarray | tuple[float, ...], v: float, w: float) -> None:
        if type(q) is tuple:
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

    def __repr__(self) -> str:
        return f"Observation(q={list(self.values)!r}, v={self.v!r}, w={self.w!r})"


class PlantDivergedError(RuntimeError):
    """The plant's state became non-finite (or left the engine's valid range) in a step.

    The loop stops the run there, keeps what was recorded and reports the step.
    """


class Plant(Protocol):
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
    polygon unloaded; ``joint_time_constant`` (s), the lag with which the joints follow
    their rate targets, and ``damping``, the base's viscous damping ``(c1, c2)`` (N s/m,
    N m s/rad): what the loop tells controllers of the plant
    (:func:`ddwmmr.commands.traits_of`; the ``mpc`` models both).
    """

    name: str
    interfaces: tuple[str, ...]
    robot: Any
    extra_columns: tuple[str, ...]

    def reset(self, q0: np.ndarray, dt: float) -> None:  # pragma: no cover - protocol
        """Place the robot at rest at configuration ``q0`` for a run with control step dt (s).

        Raises :class:`~ddwmmr.errors.ParameterError` if dt does not suit the plant (e.g.
        not a multiple of a physics engine's timestep).
        """
        ...

    def observe(self) -> Observation:  # pragma: no cover - protocol
        """The current measured state."""
        ...

    def limit(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:  # pragma: no cover
        """Velocity command ``u`` as the plant's actuator limits will apply it at ``q``, and
        whether a limit was hit (recorded as the run's commanded input)."""
        ...

    def step(
        self, t: float, command: Any, dt: float, policy: Policy | None = None
    ) -> None:  # pragma: no cover - protocol
        """Advance the state by ``dt`` (s) from time ``t`` under ``command``.

        ``command`` is a velocity array u or a :class:`~ddwmmr.commands.WheelForces`,
        whichever of ``interfaces`` it belongs to. Raises :class:`PlantDivergedError` when
        the new state is not finite.
        """
        ...

    def extra_values(self) -> Sequence[float]:  # pragma: no cover - protocol
        """Values of ``extra_columns`` at the current state."""
        ...

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:  # pragma: no cover
        """Plant-specific summary keys computed from a recorded run (may be empty)."""
        ...
