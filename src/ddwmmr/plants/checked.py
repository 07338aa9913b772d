"""A plant from outside the library, its calls checked where the simulation loop makes them.

The library's plants keep their contract by construction: what ``observe()`` and
``limit()`` return is finite and well formed, and ``step()`` raises only a one-line
:class:`~ddwmmr.errors.ParameterError` or :class:`~ddwmmr.plants.base.PlantDivergedError`.
A plug-in plant is held to the same contract by :class:`CheckedPlant`, which the loop
(:func:`ddwmmr.sim.loop.run_loop`) puts around it once, through :func:`checked_plant`:

* an ``observe()`` that is not an :class:`~ddwmmr.plants.base.Observation` of finite
  numbers, or a ``limit()`` that is not ``(u, saturated)`` with ``u`` 4 finite numbers, is
  a one-line ParameterError naming the plant, the step and the time;
* anything else its ``reset()``, ``observe()``, ``limit()`` or ``step()`` raise becomes a
  one-line :class:`~ddwmmr.errors.PluginError` "plant: <name>.<method>() raised <type>:
  '<message>' at step <k>, t = <t> s" ("before the first step" for ``reset()``;
  :func:`~ddwmmr.errors.plugin_raised`, the message
  quoted), the exception it raised its ``__cause__``; but a ParameterError or a
  PluginError passes as it is (already one line), a PlantDivergedError from ``step()``
  ends the run as "diverged", and whatever ``step()`` raises after the control law it
  was given raised is the controller's error, routed as such.

Each such error is handed to the run's task first (``failed``, the loop's
``task.controller_error``): if the task ends the run on it (the scenario protocol records
it as the scenario's failure), :class:`PlantFailed` tells the loop where the run ended;
otherwise the error is raised (a tracking run). The library's own plants are not wrapped.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NoReturn

import numpy as np

from ddwmmr.errors import (
    ParameterError,
    finite_values,
    name_of,
    plugin_raised,
    raise_as,
    shown,
)
from ddwmmr.inheritance import from_library
from ddwmmr.plants.base import Observation, Plant, PlantDivergedError, Policy

#: The task's verdict on a plug-in plant's failure at sample ``k``: True ends the run
#: quietly, False raises the error.
Failed = Callable[[int, Exception], bool]


class PlantFailed(Exception):
    """A plug-in plant failed and the task ended the run on it (the error is the task's
    now): the loop stops with ``samples`` samples (the end index, time ``samples * dt``)."""

    def __init__(self, samples: int) -> None:
        super().__init__(samples)
        self.samples = samples


def checked_plant(plant: Plant, failed: Failed) -> Plant:
    """``plant`` as the simulation loop calls it: wrapped in :class:`CheckedPlant` when its
    class is from outside the library (:func:`~ddwmmr.inheritance.from_library`); the
    library's own plants, as they are, so their runs keep their speed and their numbers."""
    return plant if from_library(plant) else CheckedPlant(plant, failed)


def checked_extra_values(plant: Plant) -> Callable[[], Any]:
    """``plant.extra_values`` as a run's recorder calls it, once per sample: the library's
    plants' as it is; a plug-in's checked to return one number per name of its
    ``extra_columns``, else a one-line :class:`~ddwmmr.errors.ParameterError` naming the
    plant (the values are recorded as columns of the time series)."""
    extra_values = plant.extra_values
    if from_library(plant):
        return extra_values
    names = tuple(plant.extra_columns)

    def checked() -> tuple[float, ...]:
        values = extra_values()
        try:
            row = tuple(float(value) for value in values)
        except (TypeError, ValueError):
            row = None
        if row is None or len(row) != len(names):
            raise ParameterError(
                f"plant: {name_of(plant)}.extra_values() must return {len(names)} numbers, "
                f"one per extra_columns name ({', '.join(names)}) (got {shown(values, 60)})"
            )
        return row

    return checked


class CheckedPlant:
    """Plug-in ``plant`` with its ``observe()``, ``limit()`` and ``step()`` checked (see
    the module docstring); ``failed(k, error)`` is the task's verdict on a failure.

    The wrapper counts the samples as the loop takes them, for the messages: ``reset``
    starts at sample 0, time 0; each ``step(t, command, dt)`` moves on to the next sample,
    observed at ``t + dt`` (s); ``limit`` is called at sample ``k``, time ``k dt``. Every
    other attribute (``name``, ``interfaces``, the traits, ``extra_values()``) is read
    from the plant.
    """

    def __init__(self, plant: Plant, failed: Failed) -> None:
        self.plant = plant
        self._failed = failed
        self._k = 0  # the sample being taken
        self._dt = 0.0  # the control step (s), as given to reset
        self._observed_at = 0.0  # the time (s) of the sample, as the loop computes it
        self._stage_failed = False  # a control law passed to step raised in this run

    def __getattr__(self, attribute: str) -> Any:
        if attribute == "plant":  # not set yet (copy, unpickling): no recursion
            raise AttributeError(attribute)
        return getattr(self.plant, attribute)

    def reset(self, q0: Any, dt: float) -> None:
        """The plant's ``reset(q0, dt)``; the count starts again at sample 0. What it raises
        is a one-line PluginError naming the plant (a ParameterError passes as it is),
        handed to the task as a failure of any other method is (PlantFailed at 0 samples
        if the task ends the run on it)."""
        try:
            self.plant.reset(q0, dt)
        except Exception as error:
            call = f"plant: {name_of(self.plant)}.reset()"
            wrapped = plugin_raised(call, error, " before the first step", quoted=True)
            if self._failed(0, wrapped):
                raise PlantFailed(0) from None
            raise_as(wrapped, error)
        self._k, self._dt, self._observed_at, self._stage_failed = 0, dt, 0.0, False

    def observe(self) -> Observation:
        """The plant's ``observe()`` if it is an :class:`Observation` of finite numbers."""
        k, t = self._k, self._observed_at
        try:
            obs = self.plant.observe()
            if not (isinstance(obs, Observation) and obs.finite()):
                wanted = "an Observation(q, v, w) of 5 + 2 finite numbers"
                raise ParameterError(
                    f"plant: {name_of(self.plant)}.observe() must return {wanted} (got "
                    f"{shown(obs, 80)} at step {k}, t = {t:g} s; a plant whose state blows "
                    "up raises PlantDivergedError in step())"
                )
        except Exception as error:
            self._fail("observe", error, k, t, k)
        return obs

    def limit(self, q: np.ndarray, command: np.ndarray) -> tuple[np.ndarray, bool]:
        """The plant's ``limit(q, command)`` if it is ``(u, saturated)`` with ``u`` 4 finite
        numbers (returned as a float array)."""
        k = self._k
        t = k * self._dt
        try:
            result = self.plant.limit(q, command)
            if isinstance(result, tuple) and len(result) == 2:
                applied = finite_values(result[0], 4)
                if applied is not None:
                    return applied, bool(result[1])
            raise ParameterError(
                f"plant: {name_of(self.plant)}.limit(q, u) must return (u, saturated) with u 4 "
                f"finite numbers (got {shown(result, 80)} at step {k}, t = {t:g} s)"
            )
        except Exception as error:
            self._fail("limit", error, k, t, k)

    def step(self, t: float, command: Any, dt: float, policy: Policy | None = None) -> None:
        """The plant's ``step``. A PlantDivergedError passes as it is; so does anything the
        plant raises once the control law ``policy`` raised in this run (the error is the
        controller's, which the loop routes as such)."""
        if policy is not None:
            policy = self._watched(policy)
        try:
            self.plant.step(t, command, dt, policy)
        except PlantDivergedError:
            raise
        except Exception as error:
            if self._stage_failed:
                raise
            self._fail("step", error, self._k, t, self._k + 1)
        self._k += 1
        self._observed_at = t + dt

    def _watched(self, policy: Policy) -> Policy:
        """``policy``, noting when it raises (the controller failed at a stage)."""

        def watched(t: float, q: list[float]) -> Any:
            try:
                return policy(t, q)
            except Exception:
                self._stage_failed = True
                raise

        return watched

    def _fail(self, method: str, error: Exception, k: int, t: float, samples: int) -> NoReturn:
        """``error``, raised by the plant's ``method`` at sample ``k`` (time ``t`` s; called
        from the ``except`` block), as its one-line error, handed to the task: PlantFailed
        (the run ends with ``samples`` samples) if the task ends the run on it, else the
        one-line error raised (``from error`` where it wraps it)."""
        call = f"plant: {name_of(self.plant)}.{method}()"
        wrapped = plugin_raised(call, error, f" at step {k}, t = {t:g} s", quoted=True)
        if self._failed(k, wrapped):
            raise PlantFailed(samples)
        raise_as(wrapped, error)
