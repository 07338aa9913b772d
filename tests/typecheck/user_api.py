"""The public API as a user's type checker sees it: ``make lint`` runs mypy on this file
(strict, the package itself not reported). Nothing here is run by the test suite; each
call is written the way docs/api.md teaches it, and ``assert_type`` pins the types a user
gets back, so a public hint that is missing, narrower than the docs or wrong fails lint.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any, assert_type

import numpy as np
import numpy.typing as npt

from ddwmmr import (
    Ellipse,
    Rectangle,
    Robot,
    SampledTrajectory,
    SimulationResult,
    load_trajectory,
    make_controller,
    register,
    simulate,
)
from ddwmmr.commands import WheelForces
from ddwmmr.controllers import Controller, StepInfo, register_controller
from ddwmmr.plants import Observation, register_plant
from ddwmmr.plants.base import PlantImplementation
from ddwmmr.resolution import kernels
from ddwmmr.trajectories.base import Trajectory

FloatArray = npt.NDArray[np.float64]


@register_controller("typing-p-only", tasks=("tracking", "waypoints"))
class ProportionalOnly:
    """Task-space P control without feed-forward (docs/api.md, Extending)."""

    def __init__(self, robot: Robot, gain: float = 2.0) -> None:
        self.robot, self.gain, self.last = robot, gain, StepInfo()

    def reset(self, trajectory: Any, q0: np.ndarray) -> None:
        self.last = StepInfo()

    def command(
        self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray
    ) -> tuple[float, float, float, float]:
        rates = self.gain * (pose_d - self.robot.fk(q))
        u, singular = kernels.ats(self.robot.L1, self.robot.L2, q[2], q[3], q[4], *rates)
        self.last = StepInfo(singular=singular)
        return u


@register("typing-short-form")
class ShortForm(ProportionalOnly):
    """The short form of the decorator keeps the class."""


@register_plant("typing-ideal", interfaces=("velocity",))
class IdealPlant:
    """Kinematic model by Euler steps, no limits (docs/api.md, Extending)."""

    extra_columns: tuple[str, ...] = ()

    def __init__(self, robot: Robot) -> None:
        self.robot, self.q = robot, [0.0] * 5
        self.u: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0)

    def reset(self, q0: np.ndarray, dt: float) -> None:
        self.q, self.u = [float(a) for a in q0], (0.0, 0.0, 0.0, 0.0)

    def observe(self) -> Observation:
        return Observation(tuple(self.q), self.u[0], self.u[1])

    def limit(self, q: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, bool]:
        return np.asarray(u, dtype=float), False

    def step(self, t: float, command: Any, dt: float, policy: Any = None) -> None:
        x, y, phi, th1, th2 = self.q
        v, w, r1, r2 = self.u = tuple(float(a) for a in command)
        self.q = [x + dt * v * math.cos(phi), y + dt * v * math.sin(phi)]
        self.q += [phi + dt * w, th1 + dt * r1, th2 + dt * r2]

    def extra_values(self) -> tuple[float, ...]:
        return ()

    def summarize(self, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
        return {}


class Straight:
    """A trajectory of plain lists: any 3 numbers will do (docs/api.md, Trajectories)."""

    duration: float = 10.0

    def pose(self, t: float) -> list[float]:
        return [0.1 * t, 0.0, 0.0]

    def velocity(self, t: float) -> tuple[float, float, float]:
        return (0.1, 0.0, 0.0)


def registered_classes_keep_their_type() -> None:
    """The decorators return the class itself, not a bare ``type`` (mypy applies a class
    decorator's type only where it is called as a function, as here)."""
    assert_type(register_controller("typing-call")(ProportionalOnly), type[ProportionalOnly])
    assert_type(register("typing-call-short")(ShortForm), type[ShortForm])
    assert_type(register_plant("typing-call-plant")(IdealPlant), type[IdealPlant])
    assert_type(ProportionalOnly(Robot(), gain=3.0), ProportionalOnly)
    assert_type(ShortForm(Robot()).gain, float)
    assert_type(IdealPlant(Robot()), IdealPlant)


def user_objects_fit_the_protocols() -> None:
    """A controller, plant and trajectory written by a user, none declaring what the
    decorators set (``name``, ``interfaces``)."""
    controller: Controller = ProportionalOnly(Robot())
    plant: PlantImplementation = IdealPlant(Robot())
    trajectory: Trajectory = Straight()
    forces: Controller = ForceOnly()
    print(controller, plant, trajectory, forces)


class ForceOnly:
    """A force controller: ``command`` returns wheel forces."""

    last = StepInfo()

    def reset(self, trajectory: Any, q0: np.ndarray) -> None:
        pass

    def command(
        self, t: float, q: np.ndarray, pose_d: np.ndarray, velocity_d: np.ndarray
    ) -> WheelForces:
        return WheelForces(0.0, 0.0, float(q[3]), float(q[4]))


def simulate_as_documented() -> None:
    """``simulate`` with a method name, a controller object, a plant object, list starts."""
    robot, ellipse = Robot(), Ellipse()
    result = simulate(robot, ellipse, "clrrmc-ts", tau=0.5)
    assert_type(result, SimulationResult)
    simulate(robot, Rectangle(T=60.0), "ats", aux="sum", dt=0.05, initial_offset=(0.0, 0.0))
    simulate(robot, ellipse, make_controller("ats", robot, aux="shoulder"))
    simulate(robot, ellipse, ProportionalOnly(robot, gain=3.0), duration=1.0)
    simulate(robot, ellipse, "ats", plant=IdealPlant(robot), duration=1.0)
    simulate(robot, Straight(), "ats", plant="thesis", duration=1.0)
    simulate(robot, ellipse, "ats", q0=[0.0, 0.0, 0.0, -0.3, 0.6], initial_offset=[0.0, 0.0])
    simulate(None, ellipse, "ats", q0=(0.0, 0.0, 0.0, -0.3, 0.6), progress=lambda k, n: None)


def robot_methods_take_sequences() -> None:
    """Every method taking ``q`` takes any 5 numbers and returns float arrays."""
    robot = Robot()
    q = [0.0, 0.0, 0.3, -0.3, 0.6]
    assert_type(robot.fk(q), FloatArray)
    assert_type(robot.jacobian(np.array(q)), FloatArray)
    assert_type(robot.augmented_jacobian(q, aux="shoulder"), FloatArray)
    assert_type(robot.base_velocity((1.0, 2.0)), FloatArray)
    assert_type(robot.manipulability(q), float)
    assert_type(robot.stability(q), tuple[float, float, float])
    assert_type(robot.stability_gradient(q), FloatArray)
    assert_type(robot.centre_of_mass(q), FloatArray)
    assert_type(robot.wheel_speeds(q, [0.1, 0.0, 0.0, 0.0, 0.0]), FloatArray)
    assert_type(robot.base_for_end_effector([1.0, 0.5, 0.0], -0.3, 0.6), FloatArray)
    assert_type(robot.joints_outside(q), str | None)
    assert_type(robot.com_coefficients.A, float)
    with_q: Callable[[npt.ArrayLike], FloatArray] = robot.fk  # the argument is hinted
    print(with_q, replace(robot, joint_speed_limit=1.0).with_payload(3.0))


def trajectories_from_lists_and_files() -> None:
    """``SampledTrajectory`` from lists (docs/api.md) and ``load_trajectory``."""
    samples = SampledTrajectory(
        times=[0.0, 5.0, 10.0, 15.0], points=[[0, 0], [1, 0.2], [2, 0], [3, -0.2]], name="wave"
    )
    assert_type(samples.times, np.ndarray)
    loaded = load_trajectory("ellipse", a=2.5, T=50.0)
    assert_type(loaded, Ellipse | Rectangle | SampledTrajectory)
    print(samples.pose(2.0), loaded.duration)


def path_figure_on_own_or_given_axes(result: SimulationResult) -> None:
    """``plot_path`` returns its own Figure, or the figure the given axes are on, which
    is a SubFigure for axes in one."""
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

    from ddwmmr.reports.plots import plot_path

    own = plot_path(result)
    assert_type(own, Figure)
    own.savefig("path.png")
    whole = Figure()
    ax: Axes = whole.add_subfigure(whole.add_gridspec(1, 2)[0, 0]).subplots()
    assert_type(plot_path(result, ax=ax), Figure | SubFigure)
