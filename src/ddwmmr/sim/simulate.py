"""``simulate``: one controller tracking one trajectory on one plant (through the loop)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, cast

import numpy as np
import numpy.typing as npt

from ddwmmr.controllers.base import (
    Controller,
    available_methods,
    commanded_steps,
    make_controller,
)
from ddwmmr.errors import (
    MAX_COORDINATE_M,
    ParameterError,
    check_finite,
    check_instance,
    check_positive,
    check_range,
    check_step_count,
    float_values,
    name_of,
    one_of,
    shown,
)
from ddwmmr.gains import gain_step_warning
from ddwmmr.inheritance import from_library
from ddwmmr.model import Robot
from ddwmmr.model.kinematics import check_configuration
from ddwmmr.model.robot import long_lengths
from ddwmmr.model.stability import max_payload, tips_in_every_pose
from ddwmmr.plants import available_plants, make_plant, plant_class
from ddwmmr.plants.base import Plant, PlantImplementation
from ddwmmr.registry import CONTROLLERS, unknown_hint
from ddwmmr.resolution.kernels import length_unit
from ddwmmr.resolution.reference import default_offset, initial_configuration
from ddwmmr.sim.loop import run_loop, spoken_interface
from ddwmmr.sim.result import SimulationResult
from ddwmmr.sim.tracking import COLUMNS, TrackingTask, checked_trajectory
from ddwmmr.sim.verdict import check_summary, verdict
from ddwmmr.trajectories.base import (
    require_trajectory,
    resolution_step,
    sampler,
    trajectory_name,
)
from ddwmmr.user_warnings import warn_user

__all__ = ["COLUMNS", "build_plant", "max_condition_number", "simulate", "summarize"]


def check_trajectory(trajectory: Any) -> Any:
    """Refuse (one-line :class:`ParameterError`) what is not a trajectory: it needs
    ``duration`` (s), ``pose(t)`` and ``velocity(t)``. Returns the trajectory as the run's
    consumers use it (:func:`~ddwmmr.sim.tracking.checked_trajectory`: one written outside
    the library has what its ``pose`` and ``velocity`` return checked at every call)."""
    require_trajectory(trajectory)
    return checked_trajectory(trajectory)


def check_controller(controller: Any) -> Any:
    """Refuse (one-line :class:`ParameterError`) a controller object without the two
    methods the simulation loop calls, ``reset(trajectory, q0)`` and ``command(t, q,
    pose_d, velocity_d)`` (what ``command`` returns is checked at every step:
    :func:`~ddwmmr.sim.loop.checked_command`); returns ``controller``."""
    missing = [
        name for name in ("reset", "command") if not callable(getattr(controller, name, None))
    ]
    if missing:
        raise ParameterError(
            "method must be a method name or a controller with reset(trajectory, q0) and "
            f"command(t, q, pose_d, velocity_d) (got {shown(controller)}, without "
            f"{' and '.join(missing)})"
        )
    return controller


#: What a controller or plant object built for another robot means for the run, by the
#: parameter that passed it (see :func:`warn_other_robot`).
_OTHER_ROBOT = {
    "method": ("the controller", "its model is not the plant's"),
    "plant": (
        "the plant object",
        "the physics runs with its robot, the summary's S and verdict with the simulated one",
    ),
}


def warn_other_robot(holder: Any, robot: Robot, parameter: str = "method") -> None:
    """Warn (:class:`UserWarning`) when ``holder``, the object passed as ``parameter``
    (``"method"``: a controller, ``"plant"``: a plant), holds a ``robot`` other than the
    simulated one, naming the fields that differ: a controller's model, e.g. its stability
    floor's payload, is then not the plant's; a plant simulates other physics than the
    summary judges. That can be meant (a study of model error), so it is not refused.
    The warning names the user's line (:func:`~ddwmmr.user_warnings.warn_user`)."""
    own = getattr(holder, "robot", None)
    if not isinstance(own, Robot) or own == robot:
        return
    differ = [
        f"{f.name} {getattr(own, f.name)!r} vs {getattr(robot, f.name)!r}"
        for f in dataclasses.fields(Robot)
        if f.init and getattr(own, f.name) != getattr(robot, f.name)
    ]
    what, meaning = _OTHER_ROBOT[parameter]
    warn_user(
        f"{parameter}: {what} was built for another robot than the one simulated "
        f"({'; '.join(differ[:3])}{'; ...' if len(differ) > 3 else ''}): {meaning}; "
        "build it with the same Robot unless that is the point"
    )


def check_start(
    robot: Robot,
    q: Sequence[float] | npt.NDArray[np.float64],
    obstacles: Sequence[Any] = (),
    name: str = "payload",
    start: str | None = "the start (q0, initial_offset)",
) -> None:
    """Refuse (one-line :class:`ParameterError`) a start configuration ``q`` (x, y m, phi
    rad, th1, th2 rad) with an arm joint outside the robot's ``joint_limits``, in which the
    robot has already tipped over (static S <= 1: the centre of mass outside the support
    polygon) or its base overlaps one of the ``obstacles`` (circles or (x, y, radius)
    triples, m). ``name`` (what holds the payload) and ``start`` (what sets the start
    pose; None: nothing the user sets) word the message: a command line names its own
    options.

    The command-line tools and the app refuse such a run as bad input; :func:`simulate`
    warns and runs it (a design study may want to see ``min_stability`` below 1, as
    examples/own_robot.py does), or refuses it with ``tipped_start="refuse"``."""
    outside = robot.joints_outside(q)
    if outside is not None:
        change = "the robot's joint_limits" + ("" if start is None else f" or {start}")
        raise ParameterError(f"the start pose: {outside}; change {change}")
    if obstacles:
        from ddwmmr.qp.limits.obstacles import as_circles, check_start_clear

        check_start_clear(robot, as_circles(obstacles), q)
    message = tipping_message(robot, q, name, start)
    if message is not None:
        raise ParameterError(message)


def start_stability(robot: Robot, q: Sequence[float] | npt.NDArray[np.float64]) -> float:
    """The static tip-over stability margin S of configuration ``q`` (S <= 1: tipped)."""
    return float(robot.stability(np.asarray(q, dtype=float))[2])


def tipping_message(
    robot: Robot,
    q: Sequence[float] | npt.NDArray[np.float64],
    name: str = "payload",
    start: str | None = "the start (q0, initial_offset)",
) -> str | None:
    """None if the robot stands in configuration ``q`` (static S > 1), else the one line
    saying that it has tipped over, naming S and the cause (see :func:`check_start` for
    ``name`` and ``start``): the payload where the robot would stand without it (with the
    heaviest the pose holds, :func:`~ddwmmr.model.stability.max_payload`), else the arm's
    reach against the base, and lengths that look like millimetres
    (:func:`~ddwmmr.model.robot.long_lengths`). The one wording of the tools' refusal and
    the API's warning."""
    s = start_stability(robot, q)
    if s > 1.0:
        return None
    lengths = long_lengths(robot)
    doubt = f"; its lengths may be in millimetres ({', '.join(lengths)})" if lengths else ""
    unloaded = robot.with_payload(0.0) if robot.payload > 0.0 else robot
    if unloaded is not robot and start_stability(unloaded, q) > 1.0:
        held = max_payload(robot, float(q[3]), float(q[4]))
        return (
            f"{name}: a {robot.payload:g} kg payload tips the robot over in this run's start "
            f"pose (S = {s:.3g} <= 1), which holds at most {held:.10g} kg; lighten the payload"
            + ("" if start is None else f" or change {start}")
            + doubt
        )
    return _arm_tips_message(robot, q, s, start) + doubt


def _arm_tips_message(
    robot: Robot, q: Sequence[float] | npt.NDArray[np.float64], s: float, start: str | None
) -> str:
    """:func:`tipping_message` for a robot that tips in the start pose ``q`` even without
    its payload: the arm's reach and masses against the base's footprint are the cause,
    and a start pose the advice only where some arm pose might stand."""
    every = tips_in_every_pose(robot.com_coefficients)
    x_com, y_com = robot.centre_of_mass(q)
    without = (
        f"even without its {robot.payload:g} kg payload" if robot.payload > 0.0 else "unloaded"
    )
    return (
        f"robot: the robot tips over in this run's start pose (S = {s:.3g} <= 1), {without}: "
        f"its arm (reach L1 + L2 = {robot.reach:g} m) puts the centre of mass "
        f"{math.hypot(x_com, y_com):.3g} m from the base centre, outside the "
        f"{robot.base_length:g} m x {robot.base_width:g} m base"
        + (" in every arm pose" if every else "")
        + "; change the robot"
        + ("" if start is None or every else f" or {start}")
    )


#: What :func:`simulate` does with a start in which the robot has tipped over.
TIPPED_START = ("warn", "refuse", "allow")


def simulate(
    robot: Robot | None,
    trajectory: Any,
    method: str | Controller,
    *,
    dt: float | None = None,
    duration: float | None = None,
    integrator: str | None = None,
    initial_offset: Sequence[float] | None = None,
    q0: npt.ArrayLike | None = None,
    plant: str | PlantImplementation = "kinematic",
    plant_options: dict[str, Any] | None = None,
    progress: Callable[[int, int], None] | None = None,
    tipped_start: str = "warn",
    **controller_options: Any,
) -> SimulationResult:
    """Simulate ``method`` tracking ``trajectory`` on a plant.

    Args:
        robot: the robot (default ``Robot()``).
        trajectory: any object with ``duration`` (s), ``pose(t)`` and ``velocity(t)``,
            which return 3 finite numbers each (any sequence; anything else is a
            :class:`ParameterError` naming ``pose`` or ``velocity`` and t).
        method: a registered method name (see ``available_methods()``) or a controller
            object with ``reset(trajectory, q0)`` and ``command(t, q, pose_d,
            velocity_d)``, which must return 4 finite numbers ``[v, w, th1dot, th2dot]``
            (or a ``WheelForces`` on the force interface; anything else is a
            :class:`ParameterError` naming the step). A controller holding another
            ``robot`` than this one runs after a :class:`UserWarning` naming the fields
            that differ.
        dt: control/integration step (s); default ``duration / samples`` of the trajectory
            (its resolution N), or duration / 1000, rounded to a whole multiple of the
            plant's engine ``timestep`` if it has one.
        duration: simulated time (s); default one trajectory period. The run takes the
            nearest whole number of steps ``dt`` (at least one; 0.5 s at dt = 0.3 s runs
            0.6 s), and the summary's ``duration`` and ``steps`` record what it ran.
        integrator: ``"rk4"`` (default) or ``"euler"``; the kinematic plant's integrator
            (the other plants integrate their own dynamics and take no integrator).
        initial_offset: end-effector offset (dx, dy) in m in the end effector's start frame
            (dx along the desired start orientation phiE_d(0), dy to its left), applied
            with the arm joints to the start configuration, so closed-loop convergence
            shows. None (default): the robot's own (:func:`default_offset`), 0.03 of its
            length unit ``L1 / 0.35 m`` behind and as much to the right: (-0.03, -0.03) m
            for the default robot (on the default ellipse the world offset (0.03, -0.03)
            m). ``(0, 0)`` starts on the trajectory.
        q0: explicit start configuration (overrides the construction above). Either
            start must hold the arm joints within the robot's ``joint_limits``
            (:class:`ParameterError` otherwise).
        plant: ``"kinematic"`` (default), ``"thesis"`` (force-driven base, velocity servo),
            any name of :func:`ddwmmr.plants.available_plants`, or a plant object (one
            holding another ``robot`` than this one runs after a :class:`UserWarning`
            naming the fields that differ).
        plant_options: keyword options of the named plant.
        progress: optional callback ``progress(step, steps)``.
        tipped_start: a start in which the robot has already tipped over (static S <= 1,
            e.g. a heavy payload; the command-line tools refuse it): ``"warn"`` (default)
            runs it after a :class:`UserWarning` naming S and the payload, ``"refuse"``
            raises :class:`ParameterError`, ``"allow"`` runs it silently. Either way the
            summary records ``start_stability`` and ``start_tipped``.
        **controller_options: passed to :func:`make_controller` when ``method`` is a name.

    Returns:
        A :class:`SimulationResult` with ``.timeseries`` and ``.summary``. If the plant's
        state blows up, the run stops there: ``summary["diverged_at_step"]`` says where and
        the time series hold what was recorded until then. ``summary["verdict"]`` says
        whether the run tracked (:mod:`ddwmmr.sim.verdict`).
    """
    # The inputs, checked and built in this order (the first bad one is the error), all
    # before the first step: a bad input costs no simulated time.
    robot = check_instance("robot", robot if robot is not None else Robot(), Robot)
    if progress is not None and not callable(progress):
        raise ParameterError(
            f"progress must be a callable progress(step, steps) (got {shown(progress)})"
        )
    controller = _controller_for(method, robot, controller_options)
    reference = check_trajectory(trajectory)
    duration = check_positive("duration", trajectory.duration if duration is None else duration)
    the_plant = build_plant(plant, robot, integrator, plant_options)
    if not isinstance(plant, str):
        warn_other_robot(the_plant, robot, "plant")
    if dt is None:
        dt = engine_multiple(resolution_step(trajectory), the_plant)
    dt = check_positive("dt", dt)
    steps = check_step_count(duration, dt)  # within MAX_STEPS, before anything is allocated
    warn_gain_step(controller, the_plant, dt)
    # the rectangle's corner windows (its corner metric), before the run: a duration with
    # more corners than they allow is refused now, not after every step has been simulated
    corners = getattr(trajectory, "corner_windows", None)
    windows = corners(duration) if corners is not None else ()
    q = _start_pose(robot, reference, initial_offset, q0)
    tipped = _tipped_start(robot, q, tipped_start)
    # The run: how it ended is in what the task recorded (its length, diverged_at).
    task = TrackingTask(reference, the_plant, grid=(dt, steps))
    run_loop(the_plant, controller, task, q, dt, steps, progress)
    # The summary: metrics, what was run, the plug-ins' own keys, then the verdict, which
    # reads all of them.
    timeseries = task.timeseries(robot)
    summary = summarize(timeseries, robot, windows)
    summary.update(_run_keys(timeseries, robot, trajectory, reference, controller, the_plant, dt))
    if task.diverged_at is not None:
        summary.update(diverged_at_step=task.diverged_at, diverged=task.diverged_message)
    _add_plug_in_summaries(summary, the_plant, controller, timeseries)
    summary.update(start_stability=start_stability(robot, q), start_tipped=tipped)
    summary.update(verdict(summary))
    return SimulationResult(timeseries, summary, robot, trajectory, controller)


def _controller_for(method: str | Controller, robot: Robot, options: dict[str, Any]) -> Any:
    """The controller ``simulate`` runs: ``method`` built by name for ``robot`` with
    ``options``, or ``method`` itself, a checked controller object (a
    :class:`UserWarning` if it holds another robot; options with it are a
    :class:`ParameterError`)."""
    if isinstance(method, str):
        check_tracks(method)
        return make_controller(method, robot, **options)
    if options:
        raise ParameterError("controller options are only accepted with a method name")
    controller = check_controller(method)
    warn_other_robot(controller, robot)
    return controller


def _start_pose(
    robot: Robot,
    reference: Any,
    initial_offset: Sequence[float] | None,
    q0: npt.ArrayLike | None,
) -> np.ndarray:
    """The run's start configuration ``[x, y, phi, th1, th2]`` (m, m, rad, rad, rad, world
    frame): ``q0`` checked (x, y within ``MAX_COORDINATE_M``), else the start on
    ``reference`` with the end effector ``initial_offset`` (dx, dy, m, in its start frame;
    None: :func:`default_offset`) away. Arm joints outside the robot's ``joint_limits``
    are a :class:`ParameterError` naming which start."""
    if q0 is None:
        if initial_offset is None:
            initial_offset = default_offset(robot)
        values = float_values(initial_offset, 2)  # a 0-d array, a mapping: no pair
        if values is None:
            raise ParameterError(
                f"initial_offset must be two numbers dx, dy in m (got {shown(initial_offset)})"
            )
        offset = tuple(check_finite("initial_offset", v) for v in values)
        q = initial_configuration(robot, reference, offset)
    else:
        q = np.array(check_configuration(q0))
        for i, axis in enumerate("xy"):  # the run's errors are finite within the
            # trajectories' own bound (a position beyond it made the rms error inf)
            check_range(f"q0 {axis}", q[i], -MAX_COORDINATE_M, MAX_COORDINATE_M, "m")
    outside = robot.joints_outside(q)
    if outside is not None:  # the kinematic plant would snap it inside, the thesis plant
        # run outside its limits, MuJoCo refuses it: no plant gives a meaningful run
        where = "q0" if q0 is not None else "the start pose (initial_offset applied)"
        raise ParameterError(f"{where}: {outside}")
    return q


def _run_keys(
    timeseries: dict[str, np.ndarray],
    robot: Robot,
    trajectory: Any,
    reference: Any,
    controller: Any,
    plant: Plant,
    dt: float,
) -> dict[str, Any]:
    """The summary's keys naming the run: method, trajectory and its extent (m), the
    robot's length unit (m), plant, integrator, command interface, ``dt`` (s), the
    recorded duration (s) and steps, and the start's end-effector offset (m)."""
    recorded_steps = len(timeseries["t"]) - 1
    return dict(
        method=getattr(controller, "name", type(controller).__name__),
        trajectory=trajectory_name(trajectory),
        trajectory_extent_m=trajectory_extent(reference, timeseries),
        # the verdict's absolute error limits are in the robot's own length unit
        length_unit_m=length_unit(robot.L1),
        plant=plant.name,
        integrator=getattr(plant, "integrator", None),
        # the interface the controller spoke (the mpc chooses its own for the plant)
        command_interface=spoken_interface(controller, plant),
        dt=dt,
        duration=recorded_steps * dt,
        steps=recorded_steps,
        initial_offset_m=float(timeseries["position_error_m"][0]),
    )


def _add_plug_in_summaries(
    summary: dict[str, Any], plant: Plant, controller: Any, timeseries: dict[str, np.ndarray]
) -> None:
    """``summary`` updated with the plant's ``summarize()`` keys, then the controller's
    (if it has ``summarize``), then its ``aux`` row (if set)."""
    _add_plug_in_keys(summary, plant, "plant", plant.summarize(timeseries))
    if hasattr(controller, "summarize"):
        _add_plug_in_keys(summary, controller, "method", controller.summarize(timeseries))
    if getattr(controller, "aux", None) is not None:
        summary["aux"] = controller.aux  # the verdict's likely cause names the slides' row


def _add_plug_in_keys(
    summary: dict[str, Any], owner: Any, role: str, keys: Mapping[str, Any]
) -> None:
    """``summary`` updated with the ``keys`` that ``owner``'s ``summarize()`` returned; a
    plug-in's keys that the verdict cannot read (:func:`check_summary`: a count above the
    run's steps, a flag that is no boolean) are a one-line :class:`ParameterError` naming
    the plug-in (``role`` ``"plant"`` or ``"method"``), not the summary; so is a plug-in's
    ``summarize()`` that returned no mapping."""
    if from_library(owner):
        summary.update(keys)
        return
    if not isinstance(keys, Mapping):
        raise ParameterError(
            f"{role}: {name_of(owner)}.summarize() must return a mapping of summary keys "
            f"(a dict, {{}} for none; got {shown(keys, 60)})"
        )
    summary.update(keys)
    try:
        check_summary(summary)
    except ParameterError as error:
        raise ParameterError(f"{role}: {name_of(owner)}.summarize() returned {error}") from None


def _tipped_start(robot: Robot, q: np.ndarray, policy: str) -> bool:
    """Whether the robot has tipped over in the start ``q``; warns or refuses as
    ``policy`` (one of :data:`TIPPED_START`, see :func:`simulate`) says."""
    if not one_of(policy, TIPPED_START):
        raise ParameterError(
            f"tipped_start must be one of {', '.join(TIPPED_START)} (got {shown(policy)})"
        )
    message = tipping_message(robot, q)
    if message is None:
        return False
    if policy == "refuse":
        raise ParameterError(message)
    if policy == "warn":
        warn_user(
            f"{message}; simulating anyway (summary['start_tipped'] is True; "
            'tipped_start="refuse" refuses, "allow" silences this)'
        )
    return True


def warn_gain_step(controller: Any, plant: Any, dt: float) -> None:
    """Warn (:class:`UserWarning`) when the controller's ``feedback_gains`` (1/s, those of
    its ``e' = -K e`` loops) are too large for the control step ``dt`` (s) on ``plant``
    (:func:`~ddwmmr.gains.gain_step_warning`): the kinematic plant's ``rk4`` evaluates the
    law at its stages, unless the controller holds its command (``zero_order_hold``);
    every other plant and integrator holds it over the step. Not refused: the unstable
    run may be what the user wants to see."""
    gains = getattr(controller, "feedback_gains", ())
    stages = getattr(plant, "integrator", None) == "rk4"
    scheme = "rk4" if stages and not getattr(controller, "zero_order_hold", False) else "hold"
    message = gain_step_warning(gains, dt, scheme)
    if message is not None:
        warn_user(message)


def check_tracks(method: str) -> None:
    """Raise :class:`ParameterError` unless ``method`` names a registered controller that
    tracks trajectories (``tasks`` includes ``"tracking"``); a refusal names the tracking
    ones, the only ones a tracking run can take."""
    tracking = available_methods()
    if method in tracking:
        return
    if method not in CONTROLLERS.names():
        raise ParameterError(
            f"method: unknown method {shown(method)} (tracking: {', '.join(tracking)})"
            + unknown_hint(method, tracking)
        )
    tasks = CONTROLLERS.traits(method)["tasks"]
    raise ParameterError(
        f"method: the {method} controller does not track trajectories (it does: "
        f"{', '.join(tasks)}; tracking: {', '.join(tracking)})"
    )


def build_plant(
    plant: str | PlantImplementation,
    robot: Robot,
    integrator: str | None = None,
    options: dict[str, Any] | None = None,
) -> Plant:
    """The plant object :func:`simulate` runs for its ``plant``/``integrator``/
    ``plant_options`` (a plant object as it is, after the checks). A tool that needs the
    run's plant before the run (to refuse a control step it will refuse) builds it here
    and passes the object to :func:`simulate`, which then builds none."""
    if options is not None and not isinstance(options, dict):
        raise ParameterError(
            f"plant_options must be a dict of plant options (got {shown(options)})"
        )
    if not isinstance(plant, str):
        if not callable(getattr(plant, "step", None)):
            raise ParameterError(
                f"plant must be a plant name ({', '.join(available_plants())}) or a plant "
                f"object (got {shown(plant)})"
            )
        if integrator is not None or options:
            raise ParameterError("integrator and plant_options need a plant name, not an object")
        # cast: a plant object runs as given; the loop reads a Plant's name and interfaces
        # from it (register_plant sets them) and its checked calls name what is missing
        return cast(Plant, plant)
    options = dict(options or {})
    resolved = plant_integrator(plant, integrator)
    if resolved is not None:
        options.setdefault("integrator", resolved)
    return make_plant(plant, robot, **options)


def default_step(
    trajectory: Any, plant: str, robot: Robot, plant_options: dict[str, Any] | None = None
) -> float:
    """The control step (s) ``simulate`` takes by default on the plant named ``plant``
    built with ``plant_options`` (as ``simulate(..., plant_options=...)`` builds it):
    :func:`resolution_step`, rounded to the engine ``timestep`` of a physics plant (which
    is built for it; other plants are not)."""
    step = resolution_step(trajectory)
    if hasattr(plant_class(plant), "timestep"):
        step = engine_multiple(step, make_plant(plant, robot, **(plant_options or {})))
    return step


def engine_multiple(dt: float, plant: Plant) -> float:
    """``dt`` (s) rounded to the nearest whole multiple (at least one) of the plant's engine
    ``timestep``, for plants that have one (a physics engine); else ``dt`` unchanged."""
    quantum = getattr(plant, "timestep", None)
    return max(1, round(dt / quantum)) * quantum if quantum else dt


def plant_integrator(plant: str, integrator: str | None) -> str | None:
    """The integrator a run on the plant named ``plant`` uses: the kinematic plant's
    (``"rk4"`` by default), None for the other plants, which integrate their own dynamics
    (asking one for an integrator is a :class:`ParameterError`)."""
    if plant == "kinematic":
        return "rk4" if integrator is None else integrator
    if integrator is not None:
        raise ParameterError(
            f"integrator: only the kinematic plant takes an integrator (plant {shown(plant)})"
        )
    return None


#: Share of the run's (corner-free) samples, at its end, over which the final error is
#: taken: the last sample alone can sit on a transient (the rectangle ends on a corner).
FINAL_WINDOW_FRACTION = 0.05
#: A wheel speed within this share of ``wheel_speed_limit``, or a joint rate within it of
#: ``joint_speed_limit``, is at its rate limit (``wheel_limit_steps``,
#: ``joint_rate_limit_steps``): the qp and the mpc bound the rates a hair inside the limit
#: (1e-6 of it), and the mpc's real-time iteration ends within 1e-3 of its bound.
RATE_LIMIT_TOLERANCE = 1e-3
#: A joint angle within this (rad) of an end of its ``joint_limits`` range, or beyond it,
#: is at that position limit (``joint_limit_steps``): the plants clamp a joint to the
#: limit itself, up to rounding.
JOINT_LIMIT_TOLERANCE_RAD = 1e-6


def summarize(
    ts: dict[str, np.ndarray],
    robot: Robot,
    corner_windows: Sequence[tuple[float, float]] = (),
) -> dict[str, Any]:
    """Scalar metrics of a recorded run (errors in m and rad, speeds in rad/s and m/s).

    ``final_position_error_m`` is the RMS position error over the settled end of the run:
    the last :data:`FINAL_WINDOW_FRACTION` of the samples outside every corner window
    (``(start, end)`` times in s, e.g. :meth:`Rectangle.corner_windows`).
    ``end_position_error_m`` is the error at the last sample and
    ``corner_position_error_m`` the largest error inside the corner windows (None
    without corners).
    ``singular_steps``, ``saturated_steps``, ``fallback_steps`` and the counts of
    :func:`limit_counts` count the run's N commanded steps, not its N + 1 samples
    (:func:`~ddwmmr.controllers.base.commanded_steps`: the last sample's command is never
    applied), so each is at most ``summary["steps"]``.
    """
    position = ts["position_error_m"]
    orientation = ts["orientation_error_rad"]
    q = np.column_stack([ts[k] for k in ("x", "y", "phi", "th1", "th2")])
    in_corner = np.zeros(len(position), dtype=bool)
    for start, end in corner_windows:
        in_corner |= (ts["t"] >= start) & (ts["t"] <= end)
    settled = position[~in_corner] if not np.all(in_corner) else position
    window = settled[-max(1, round(FINAL_WINDOW_FRACTION * len(settled))) :]
    return {
        "rms_position_error_m": float(np.sqrt(np.mean(position**2))),
        "max_position_error_m": float(np.max(position)),
        "final_position_error_m": float(np.sqrt(np.mean(window**2))),
        "end_position_error_m": float(position[-1]),
        "corner_position_error_m": (
            float(np.max(position[in_corner])) if np.any(in_corner) else None
        ),
        "rms_orientation_error_rad": float(np.sqrt(np.mean(orientation**2))),
        "max_orientation_error_rad": float(np.max(np.abs(orientation))),
        "max_nonholonomic_residual_m_s": float(np.max(np.abs(ts["nonholonomic_residual_m_s"]))),
        "max_wheel_speed_rad_s": float(np.max(wheel_speeds(ts))),
        "min_manipulability": float(np.min(ts["manipulability"])),
        "mean_manipulability": float(np.mean(ts["manipulability"])),
        "min_stability": float(np.min(ts["stability"])),
        "singular_steps": int(np.sum(commanded_steps(ts["singular"]))),
        "saturated_steps": int(np.sum(commanded_steps(ts["saturated"]))),
        **limit_counts(ts, robot),
        "fallback_steps": int(np.sum(commanded_steps(ts["fallback"]))),
        "max_condition_number": max_condition_number(robot, q),
        "median_step_us": float(np.median(ts["step_us"])),
    }


def limit_counts(ts: dict[str, np.ndarray], robot: Robot) -> dict[str, Any]:
    """The run's commanded steps at a limit of ``robot`` (summary keys).

    ``wheel_limit_steps``: a wheel speed (:func:`wheel_speeds`) within
    :data:`RATE_LIMIT_TOLERANCE` of ``robot.wheel_speed_limit``; ``joint_rate_limit_steps``:
    a joint rate (:func:`joint_rates`) within that share of ``robot.joint_speed_limit``.
    Each is a rate limit held, whether the plant clipped the command (``saturated_steps``
    counts those too) or a controller kept it within the limit itself (the qp's and the
    mpc's bounds). ``joint_limit_steps``: a joint angle at a position limit of
    ``robot.joint_limits`` (within :data:`JOINT_LIMIT_TOLERANCE_RAD`), and
    ``joint_limit_held`` the limit held on most of them (``"th2 = 0.3 rad"``; None where
    none was): ``saturated_steps`` counts a step the plant stopped a joint at its limit
    just as one it clipped at a rate limit, which these tell apart.
    """
    tolerance = 1.0 - RATE_LIMIT_TOLERANCE
    at_wheel_limit = wheel_speeds(ts) >= robot.wheel_speed_limit * tolerance
    at_rate_limit = joint_rates(ts) >= robot.joint_speed_limit * tolerance
    at_joint_limit, held = joint_limits_held(ts, robot)
    return {
        "wheel_limit_steps": int(np.sum(commanded_steps(at_wheel_limit))),
        "joint_rate_limit_steps": int(np.sum(commanded_steps(at_rate_limit))),
        "joint_limit_steps": int(np.sum(commanded_steps(at_joint_limit))),
        "joint_limit_held": held,
    }


def wheel_speeds(ts: dict[str, np.ndarray]) -> np.ndarray:
    """Per sample, the faster wheel's speed (rad/s, absolute): of the wheel speeds of
    :func:`~ddwmmr.sim.tracking.derive_columns`."""
    speeds: np.ndarray = np.maximum(np.abs(ts["wheel_left_rad_s"]), np.abs(ts["wheel_right_rad_s"]))
    return speeds


def joint_rates(ts: dict[str, np.ndarray]) -> np.ndarray:
    """Per sample, the faster joint's rate (rad/s, absolute) over the step the sample
    starts: the applied command (``th1dot``, ``th2dot``) where it was a velocity command,
    and where the controller sent wheel forces and joint targets (those columns NaN) the
    rate the joints moved at, (th(k+1) - th(k)) / (t(k+1) - t(k)). The last sample starts
    no step: NaN there where it is measured. A time series without the command columns
    is measured throughout."""
    missing = np.full(len(ts["t"]), np.nan)
    rate_1, rate_2 = (np.asarray(ts.get(key, missing), dtype=float) for key in ("th1dot", "th2dot"))
    commanded = np.maximum(np.abs(rate_1), np.abs(rate_2))
    measured = np.full(len(commanded), np.nan)
    if len(commanded) > 1:
        span = np.diff(ts["t"])
        moved = np.maximum(np.abs(np.diff(ts["th1"])), np.abs(np.diff(ts["th2"])))
        measured[:-1] = moved / span
    return np.where(np.isnan(rate_1) | np.isnan(rate_2), measured, commanded)


def joint_limits_held(ts: Mapping[str, np.ndarray], robot: Robot) -> tuple[np.ndarray, str | None]:
    """Per sample, whether a joint angle (``th1``, ``th2``, rad) is at a position limit
    of ``robot.joint_limits`` (within :data:`JOINT_LIMIT_TOLERANCE_RAD`, or beyond), and
    the limit held on most of the commanded steps in words (``"th2 = 0.3 rad"``), None
    where no joint reached one."""
    at_any = np.zeros(len(ts["th1"]), dtype=bool)
    most, held = 0, None
    for name, (low, high) in zip(("th1", "th2"), robot.joint_limits, strict=True):
        angle = ts[name]
        for bound, at in (
            (low, angle <= low + JOINT_LIMIT_TOLERANCE_RAD),
            (high, angle >= high - JOINT_LIMIT_TOLERANCE_RAD),
        ):
            at_any |= at
            count = int(np.sum(commanded_steps(at)))
            if count > most:
                most, held = count, f"{name} = {bound:.4g} rad"
    return at_any, held


#: Samples of one trajectory duration over which :func:`trajectory_extent` takes its size.
EXTENT_SAMPLES = 1001


def trajectory_extent(trajectory: Any, ts: dict[str, np.ndarray]) -> float:
    """The trajectory's size (m): the diagonal of the bounding box of its desired
    end-effector positions, at :data:`EXTENT_SAMPLES` times over one ``duration`` and at
    the run's samples (``xE_d``, ``yE_d``: a run longer than one duration may go beyond).
    The whole trajectory's, not only the part a short run covers: the verdict holds the
    errors to a share of it (:func:`ddwmmr.sim.verdict.error_limit`)."""
    times = np.linspace(0.0, float(trajectory.duration), EXTENT_SAMPLES)
    sample = sampler(trajectory)
    if sample is not None:
        poses = np.asarray(sample(times)[0], dtype=float)
    else:
        poses = np.array([trajectory.pose(t) for t in times.tolist()], dtype=float)
    x = np.concatenate([poses[:, 0], ts["xE_d"]])
    y = np.concatenate([poses[:, 1], ts["yE_d"]])
    return float(np.hypot(np.ptp(x), np.ptp(y)))


def max_condition_number(robot: Robot, q: np.ndarray) -> float:
    """Largest 2-norm condition number of the 4x5 Jacobian J(q) over the configurations.

    Computed from a 4x4 matrix with the same singular values: J's columns for phi and th1
    are equal, so an orthogonal change of input coordinates merges them into one column
    sqrt(2) times as long (and a zero column); rotating the xE, yE rows by -phi and the x, y
    columns by phi (orthogonal too) leaves a matrix of th1 and th2 alone. A third cheaper
    than the SVD of J itself, and the same to rounding (tests/test_simulation.py).
    """
    th1, th12 = q[:, 3], q[:, 3] + q[:, 4]
    e, f = -robot.L2 * np.sin(th12), robot.L2 * np.cos(th12)
    root2 = math.sqrt(2.0)
    m = np.zeros((len(q), 4, 4))
    m[:, 0, 0] = m[:, 1, 1] = m[:, 3, 1] = m[:, 2, 3] = 1.0
    m[:, 0, 2] = root2 * (-robot.L1 * np.sin(th1) + e)
    m[:, 1, 2] = root2 * (robot.L1 * np.cos(th1) + f)
    m[:, 2, 2] = root2
    m[:, 0, 3], m[:, 1, 3] = e, f
    sv = np.linalg.svd(m, compute_uv=False)
    with np.errstate(divide="ignore"):
        return float(np.max(sv[:, 0] / sv[:, -1]))
