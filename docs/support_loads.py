"""Support loads on the physics plant: the edge-load model against MuJoCo, and where the
optimisers' unloaded time comes from (docs/physics.md, "Support loads while moving" and
"Why an edge goes unloaded: the optimisers on the scenarios").

Run from the repository root::

    MPLBACKEND=Agg .venv/bin/python docs/support_loads.py [validate] [attribute] [--n 10]
    MPLBACKEND=Agg .venv/bin/python docs/support_loads.py plot

``validate`` runs the moving runs (the sideways reach, a fast turn with the payload out,
the rectangle), compares :class:`ddwmmr.model.support_loads.EdgeLoadModel` with the
contact forces MuJoCo measures and writes ``docs/figures/support_validation.png``;
``attribute`` records the first ``--n`` scenarios (seed 0, 3 kg) of ``qp`` and ``mpc``,
classifies every unloaded step, replays the recorded actuator commands on variants of the
plant and writes ``docs/figures/support_attribution_<controller>.png``. Both print the
tables quoted in docs/physics.md and write their numbers to ``docs/support_loads.json``;
``plot`` redraws the attribution's figures and tables from that file. The runs are
deterministic. tests/test_support_loads.py imports the recording plant from here.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import mujoco
import numpy as np

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.commands import VELOCITY, WheelForces, interface_of
from ddwmmr.model.kinematics import wrap_angle
from ddwmmr.model.support_loads import EdgeLoadModel, support_points
from ddwmmr.model.symbolic import ThesisDynamics
from ddwmmr.model.thesis_base import C1_DEFAULT, C2_DEFAULT
from ddwmmr.plants.mujoco import MujocoPlant
from ddwmmr.plants.mujoco.model import mjcf
from ddwmmr.plants.mujoco.plant import UNLOADED_FRACTION, _heading
from ddwmmr.scenarios import generate
from ddwmmr.scenarios.protocol import (
    RunConfig,
    WaypointTask,
    _Tally,
    make_scenario_controller,
)
from ddwmmr.sim.loop import run_loop

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
NUMBERS = ROOT / "docs" / "support_loads.json"
PAYLOAD = 3.0
ROBOT = Robot().with_payload(PAYLOAD)
MODEL = EdgeLoadModel.from_robot(ROBOT)
#: Edge names in the order of the model's polygon (counter-clockwise from the back right).
EDGES = ("right", "front", "left", "back")
#: The scenario protocol's base damping on the physics plant (docs/thesis.md).
DAMPING = (C1_DEFAULT, C2_DEFAULT)
#: Step of the scenarios (s).
SCENARIO_DT = 0.01


# -- recording ------------------------------------------------------------------------------
#: The engine this study measured (before the plant took the elliptic cone and compliant
#: tyres by default, docs/physics.md "The model, generated from Robot"); variants change it.
PHASE_A_ENGINE: dict[str, Any] = {"cone": "pyramidal", "tyre_stiffness": 0.0}


class RecordingPlant(MujocoPlant):
    """The physics plant, stepped one engine step at a time, recording every control step.

    Per control step it keeps the command, the actuator controls, the support loads the
    plant judges (end of the step) and the motion the edge-load model needs, at the end of
    the step and averaged over its engine steps. The engine runs exactly as in
    :meth:`MujocoPlant.step` (``mj_step`` one step at a time is the same loop; tested
    bit for bit by :func:`check_recording_is_exact`).

    Args:
        robot: the robot; ``edit``: a function of the MJCF text (a prototype of another
            plant model); ``impratio``: MuJoCo's friction-to-normal impedance ratio; the
            rest is :class:`MujocoPlant`'s.
    """

    def __init__(
        self,
        robot: Robot,
        *,
        edit: Callable[[str], str] | None = None,
        impratio: float | None = None,
        **options: Any,
    ) -> None:
        for name, value in PHASE_A_ENGINE.items():  # the plant this study measured
            options.setdefault(name, value)
        super().__init__(robot, **options)
        if edit is not None:
            self.model = mujoco.MjModel.from_xml_string(edit(mjcf(robot, self.options)))
            self.data = mujoco.MjData(self.model)
            self._ids = self._lookup_ids()
            self._geom_support = self._ids["geom_support"].tolist()
            self._kv = self.model.actuator_gainprm[:, 0].copy()
            mass = float(np.sum(self.model.body_mass))
            self.weight_n = mass * -float(self.model.opt.gravity[2])
        if impratio is not None:
            self.model.opt.impratio = impratio
        self.load_model = EdgeLoadModel.from_robot(robot)
        points = support_points(robot)
        self._off = self.load_model.polygon.off_edge(points).astype(float)
        self._dof = {
            name: int(self.model.jnt_dofadr[mujoco.mj_name2id(self.model, 3, name)])
            for name in ("shoulder", "elbow")
        }
        self.samples: list[dict[str, Any]] = []
        self._scratch = mujoco.MjData(self.model)

    def reset(self, q0: np.ndarray, dt: float) -> None:
        super().reset(q0, dt)
        self.samples = []

    def step(self, t: float, command: Any, dt: float, policy: Any = None) -> None:
        """:meth:`MujocoPlant.step`, recording (see the class docstring)."""
        substeps = self._substeps if dt == self._dt else self._check_dt(dt)
        q = self.observe().q
        if interface_of(command) == VELOCITY:
            self._velocity_controls(q, np.asarray(command, dtype=float))
            recorded = tuple(float(c) for c in command)
        else:
            self._force_controls(q, command, dt)
            recorded = (command.left, command.right, command.th1_target, command.th2_target)
        self.run_engine(substeps, t, dt, recorded)

    def run_engine(self, substeps: int, t: float, dt: float, command: tuple) -> None:
        """The engine steps of one control step from the controls set, then the plant's
        own bookkeeping and the record."""
        model, data = self.model, self.data
        inside = []
        for _ in range(substeps):
            inside.append(self._reading_before_step())
            mujoco.mj_step(model, data, 1)
        self._check_state(f"in control step {self._step_count}")
        self._step_count += 1
        mujoco.mj_forward(model, data)
        self._phi += wrap_angle(_heading(data.qpos[3:7]) - self._phi)
        self._cache = self._contacts = None
        self._judge_tipping(t + dt, dt)
        end = self._reading()
        inside = {k: np.array([r[k] for r in inside]) for k in ("measured", "motion")}
        self.samples.append(
            {
                "t": t + dt,
                "command": command,
                "ctrl": data.ctrl.copy(),
                "qpos": data.qpos.copy(),
                "qvel": data.qvel.copy(),
                "q": self.observe().q,
                "v": self.observe().v,
                "tilt": self.base_tilt(),
                "slip": self.wheel_slip(),
                **end,
                "measured_inside": inside["measured"],
                "motion_inside": inside["motion"],
            }
        )

    def _reading_before_step(self) -> dict[str, np.ndarray]:
        """:meth:`_reading` of the state the next engine step starts from, made on a copy
        of the engine's data (``mj_step`` leaves the implicit integrator's accelerations
        behind, not those that balance the contact forces; the run itself is untouched)."""
        scratch = self._scratch
        mujoco.mj_copyData(scratch, self.model, self.data)
        mujoco.mj_forward(self.model, scratch)
        data, contacts, phi = self.data, self._contacts, self._phi
        self.data, self._contacts = scratch, None
        self._phi += wrap_angle(_heading(scratch.qpos[3:7]) - self._phi)
        try:
            return self._reading()
        finally:
            self.data, self._contacts, self._phi = data, contacts, phi

    def _reading(self) -> dict[str, np.ndarray]:
        """Support loads and motion of the engine's current state, after ``mj_forward``:
        ``forces`` per support, ``off`` (the load off each edge, the plant's edge load),
        ``measured`` (the moment-equivalent edge load, the model's quantity) and
        ``motion`` (:meth:`motion`)."""
        forces, points = self.support_forces()
        distances = self.load_model.polygon.distances(points)  # (n, k)
        return {
            "forces": forces,
            "off": self._off @ forces,
            "measured": forces @ distances / self.load_model.polygon.depths,
            "motion": self.motion(),
        }

    def motion(self) -> np.ndarray:
        """``(th1, th2, rate1, rate2, acc1, acc2, a_x, a_y, w, w_dot)`` of the engine's
        current state (rad, rad/s, rad/s^2, m/s^2 in the base's heading frame, rad/s,
        rad/s^2), after ``mj_forward``."""
        data = self.data
        qpos, qvel, qacc = data.qpos, data.qvel, data.qacc
        phi = _heading(qpos[3:7])
        c, s = math.cos(phi), math.sin(phi)
        rotation = data.xmat[self._ids["base"]]
        w = float(rotation[6:9] @ qvel[3:6])
        w_dot = float(rotation[6:9] @ qacc[3:6])  # world z of the body-frame rate
        sh, el = self._dof["shoulder"], self._dof["elbow"]
        return np.array(
            [
                qpos[self._ids["shoulder_qpos"]],
                qpos[self._ids["elbow_qpos"]],
                qvel[sh],
                qvel[el],
                qacc[sh],
                qacc[el],
                c * qacc[0] + s * qacc[1],
                -s * qacc[0] + c * qacc[1],
                w,
                w_dot,
            ]
        )


def predicted_loads(motion: np.ndarray, model: EdgeLoadModel = MODEL) -> np.ndarray:
    """Edge loads (N, (m, 4)) of the model for motions (m, 10) as :meth:`RecordingPlant.motion`
    gives them."""
    m = np.atleast_2d(motion).T
    loads = model.loads(m[0], m[1], m[2:4], m[4:6], m[6:8], m[8], m[9], cos=np.cos, sin=np.sin)
    return np.column_stack(loads)


def static_loads(motion: np.ndarray, model: EdgeLoadModel = MODEL) -> np.ndarray:
    """Edge loads at rest (N, (m, 4)) in the configurations of motions (m, 10)."""
    still = np.zeros_like(np.atleast_2d(motion)[:, 2:])
    return predicted_loads(np.column_stack([np.atleast_2d(motion)[:, :2], still]), model)


def columns(samples: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    """A recording as arrays, one row per control step."""
    return {key: np.array([s[key] for s in samples]) for key in samples[0]}


# -- scenario runs --------------------------------------------------------------------------
def make_controller(name: str, scenario, plant) -> Any:
    """The protocol's controller (the scenario benchmark's options) for the plant."""
    config = RunConfig(controller=name, plant="mujoco", payload=PAYLOAD)
    return make_scenario_controller(ROBOT, scenario, config, plant)


def record_scenario(
    name: str, index: int, seed: int = 0, smooth: bool = False, **engine: Any
) -> dict[str, Any]:
    """Scenario ``index`` (0-based) of ``seed`` run by controller ``name`` on a
    :class:`RecordingPlant` with the protocol's base damping: its metrics and recording.
    ``smooth``: the controller's commands pass through :class:`SmoothCommands`."""
    scenario = generate(index + 1, seed)[index]
    config = RunConfig(controller=name, plant="mujoco", payload=PAYLOAD)
    plant = RecordingPlant(ROBOT, base_damping=DAMPING, **engine)
    controller = make_controller(name, scenario, plant)
    if smooth:
        controller = SmoothCommands(controller, plant)
    q0 = np.array([0.0, 0.0, 0.0, *default_pose(ROBOT)])
    tally = _Tally(ROBOT, scenario, config)
    task = WaypointTask(tally, controller, name == "thesis", plant)
    end = run_loop(plant, controller, task, q0, config.dt, tally.steps)
    outcome = tally.outcome(end.samples * config.dt, end.samples, has_states=name == "thesis")
    return {"metrics": outcome.metrics, "record": columns(plant.samples), "mode": _mode(name)}


class SmoothCommands:
    """A controller whose commands change no faster than the plant's motors follow: joint
    rates by at most the joints' acceleration limits times dt (the ``qp``'s (v, w) already
    change within its slew limits); wheel forces through the servos' lag (20 ms). Every
    other attribute is the wrapped controller's."""

    def __init__(self, controller: Any, plant: MujocoPlant) -> None:
        self.inner = controller
        self.limits = np.array(plant.joint_acceleration_limit) * SCENARIO_DT
        self.lag = SCENARIO_DT / (plant.joint_time_constant + SCENARIO_DT)
        self.previous: Any = None

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)

    def reset(self, trajectory: Any, q0: np.ndarray) -> None:
        self.previous = None
        self.inner.reset(trajectory, q0)

    def command(self, t: float, q: Any, pose_d: Any, velocity_d: Any, **kw: Any) -> Any:
        command = self.inner.command(t, q, pose_d, velocity_d, **kw)
        previous, self.previous = self.previous, command
        if previous is None:
            return command
        if isinstance(command, WheelForces):
            left = previous.left + self.lag * (command.left - previous.left)
            right = previous.right + self.lag * (command.right - previous.right)
            self.previous = WheelForces(left, right, command.th1_target, command.th2_target)
            return self.previous
        u = np.array(command, dtype=float)
        change = np.clip(u[2:4] - previous[2:4], -self.limits, self.limits)
        u[2:4] = np.asarray(previous[2:4]) + change
        self.previous = u
        return u


def _mode(name: str) -> str:
    return VELOCITY if name == "qp" else "force"


def replay(
    recording: dict[str, Any],
    ctrl: np.ndarray | None = None,
    q0: np.ndarray | None = None,
    **engine: Any,
) -> dict[str, np.ndarray]:
    """The recorded actuator controls (or ``ctrl``, (m, 4)) played open loop on a
    :class:`RecordingPlant` with the scenarios' base damping and ``engine`` options, from
    ``q0`` (default: the scenarios' start), every :data:`SCENARIO_DT`; its recording. Same
    plant, same controls: the same run bit for bit (tested)."""
    plant = RecordingPlant(ROBOT, base_damping=DAMPING, **engine)
    start = np.array([0.0, 0.0, 0.0, *default_pose(ROBOT)]) if q0 is None else q0
    plant.reset(np.asarray(start, dtype=float), SCENARIO_DT)
    plant._set_wheel_mode(recording["mode"])
    controls = recording["record"]["ctrl"] if ctrl is None else ctrl
    substeps = plant._substeps
    for k, values in enumerate(controls):
        plant.data.ctrl[:] = values
        plant.run_engine(substeps, k * SCENARIO_DT, SCENARIO_DT, ())
    return columns(plant.samples)


def replay_from(
    record: dict[str, np.ndarray], start: int, steps: int, mode: str, **engine: Any
) -> dict[str, np.ndarray]:
    """Control steps ``start`` to ``start + steps`` of a recording replayed from the
    recorded engine state before them on a :class:`RecordingPlant` with ``engine``
    options of the same model structure (e.g. the friction cone)."""
    plant = RecordingPlant(ROBOT, base_damping=DAMPING, **engine)
    plant.reset(np.array([0.0, 0.0, 0.0, *default_pose(ROBOT)]), SCENARIO_DT)
    plant._set_wheel_mode(mode)
    data = plant.data
    data.qpos[:], data.qvel[:] = record["qpos"][start - 1], record["qvel"][start - 1]
    data.time = record["t"][start - 1]
    mujoco.mj_forward(plant.model, data)
    plant._phi = float(record["q"][start - 1][2])
    for k in range(start, start + steps):
        data.ctrl[:] = record["ctrl"][k]
        plant.run_engine(plant._substeps, record["t"][k - 1], SCENARIO_DT, ())
    return columns(plant.samples)


def unloaded_steps(record: dict[str, np.ndarray], weight: float) -> np.ndarray:
    """Control steps that ended with an edge unloaded (the plant's judgement)."""
    return np.min(record["off"], axis=1) < UNLOADED_FRACTION * weight


# -- plant variants (replays) -----------------------------------------------------------------
#: Radial stiffness (N/m) of the compliant tyre prototype, now the plant's default
#: (``tyre_stiffness``): a small robot's rubber tyre deflects about 1 mm under 50 N.
TYRE_STIFFNESS = 5e4


def cylinder_wheels(text: str) -> str:
    """MJCF with each drive wheel touching the floor as a cylinder (a tyre as wide as the
    wheel: two contact points across its width) instead of a sphere (one point)."""
    from ddwmmr.plants.mujoco.model import WHEEL_WIDTH

    r = ROBOT.wheel_radius
    for side in ("left", "right"):
        sphere = f'<geom name="wheel_{side}" type="sphere" size="{r:.17g}"'
        assert sphere in text, "the wheel's contact sphere as mjcf() writes it"
        cylinder = (
            f'<geom name="wheel_{side}" type="cylinder" size="{r:.17g} {WHEEL_WIDTH / 2:.17g}" '
            'zaxis="0 1 0"'
        )
        text = text.replace(sphere, cylinder)
    return text


#: The plant variants of the replays (:data:`VARIANT_LABELS` says what each changes):
#: name -> :class:`RecordingPlant` options.
VARIANTS: dict[str, dict[str, Any]] = {
    "plant": {},
    "elliptic": {"cone": "elliptic"},
    "elliptic_hard": {"cone": "elliptic", "impratio": 10.0},
    "timestep_0.5ms": {"timestep": 0.0005},
    "contact_5ms": {"contact_time_constant": 0.005},
    "contact_20ms": {"contact_time_constant": 0.02},
    "impedance": {"solimp": (0.95, 0.99, 0.001)},
    "cylinder": {"edit": cylinder_wheels},
    "tyre": {"tyre_stiffness": TYRE_STIFFNESS},
    "tyre_elliptic": {"tyre_stiffness": TYRE_STIFFNESS, "cone": "elliptic"},
}


# -- attribution -----------------------------------------------------------------------------
#: What unloads an edge, per unloaded control step (see :func:`classify`).
CATEGORIES = ("static", "inertial", "lift", "chatter")
#: The rigid-body load's parts (see :func:`load_parts`).
PARTS = ("forward acceleration", "turning", "yaw", "arm's yaw reaction", "arm acceleration")
#: A load within this share of the weight counts as "predicts the edge unloaded".
DELTA_SHARE = 0.05
_DYNAMICS = ThesisDynamics.from_robot(ROBOT)


def load_parts(motion: np.ndarray) -> dict[str, np.ndarray]:
    """What each part of the motion adds to the edge loads (N, (m, 4)), for motions (m, 10):
    the base's forward acceleration ``a_x`` and lateral one ``a_y`` (turning), the yaw terms
    (``w^2``, Coriolis and the yaw acceleration the wheels drive), the yaw acceleration the
    arm's own motion drives (its reaction, :meth:`ThesisDynamics.arm_yaw_reaction`) and the
    arm's acceleration relative to the base. They sum to the model's loads less the
    static ones (the zero moment point's terms, :mod:`ddwmmr.model.stability`)."""
    m = np.atleast_2d(motion)
    th1, th2, r1, r2, a1, a2, ax, ay, w, w_dot = m.T
    k, terms, polygon = MODEL.com, MODEL.terms, MODEL.polygon
    th12, r12, a12 = th1 + th2, r1 + r2, a1 + a2
    c1, s1, c12, s12 = np.cos(th1), np.sin(th1), np.cos(th12), np.sin(th12)
    x, y = k.A * c1 + k.B * c12, k.A * s1 + k.B * s12
    x_rate = -k.A * s1 * r1 - k.B * s12 * r12
    y_rate = k.A * c1 * r1 + k.B * c12 * r12
    x_acc = -k.A * (c1 * r1**2 + s1 * a1) - k.B * (c12 * r12**2 + s12 * a12)
    y_acc = -k.A * (s1 * r1**2 - c1 * a1) - k.B * (s12 * r12**2 - c12 * a12)
    reaction = np.array(
        [
            float(_DYNAMICS.arm_yaw_reaction(b, c, (d, e), (f, g)))
            for b, c, d, e, f, g in zip(*(v.tolist() for v in (th2, w, r1, r2, a1, a2)))
        ]
    )  # fmt: skip
    hm, zero = terms.arm_moment, np.zeros_like(x)
    shifts = {  # inertial forces' first moments (kg m^2/s^2), base frame
        "forward acceleration": (terms.height_moment * ax, zero),
        "turning": (zero, terms.height_moment * ay),
        "yaw": (
            hm * (-(w_dot - reaction) * y - w**2 * x - 2 * w * y_rate),
            hm * ((w_dot - reaction) * x - w**2 * y + 2 * w * x_rate),
        ),
        "arm's yaw reaction": (hm * -reaction * y, hm * reaction * x),
        "arm acceleration": (hm * x_acc, hm * y_acc),
    }
    return {
        name: -(np.outer(sx, polygon.normals[:, 0]) + np.outer(sy, polygon.normals[:, 1]))
        / polygon.depths
        for name, (sx, sy) in shifts.items()
    }


@dataclass
class Attribution:
    """Unloaded control steps of recorded runs by cause (seconds)."""

    steps: int = 0  # control steps in all
    unloaded: dict[str, float] = field(default_factory=lambda: dict.fromkeys(CATEGORIES, 0.0))
    parts: dict[str, float] = field(default_factory=lambda: dict.fromkeys(PARTS, 0.0))
    edges: dict[str, float] = field(default_factory=lambda: dict.fromkeys(EDGES, 0.0))

    @property
    def total(self) -> float:
        return sum(self.unloaded.values())


def classify(record: dict[str, np.ndarray], delta: float, into: Attribution) -> None:
    """Add the unloaded control steps of a recording to ``into``, each under one cause, in
    this order (loads on the edge that ended the step unloaded, delta in N):

    * ``static``: the static load (the weight at the centre of mass: S) is <= delta;
    * ``inertial``: the rigid-body model with the measured accelerations predicts <= delta
      on average over the step's engine steps (the contacts, with their 10 ms time
      constant, answer to the step's mean rather than to a spike within it), under the
      part of :func:`load_parts` that takes most off the edge;
    * ``lift``: the model predicts more, but the side carried <= delta on average over
      the step (a wheel or the base hopping: the 3-D contact dynamics);
    * ``chatter``: the side carried more than delta on average over the step and nothing
      at its end (its load oscillating within the step).
    """
    weight = MODEL.weight
    unloaded = unloaded_steps(record, weight)
    into.steps += len(unloaded)
    for k in np.flatnonzero(unloaded):
        edge = int(np.argmin(record["off"][k]))
        into.edges[EDGES[edge]] += SCENARIO_DT
        inside = record["motion_inside"][k]
        if static_loads(record["motion"][k])[0, edge] <= delta:
            cause = "static"
        elif predicted_loads(inside)[:, edge].mean() <= delta:
            cause = "inertial"
            parts = {p: v[:, edge].mean() for p, v in load_parts(inside).items()}
            into.parts[min(PARTS, key=parts.__getitem__)] += SCENARIO_DT
        elif record["measured_inside"][k][:, edge].mean() <= delta:
            cause = "lift"
        else:
            cause = "chatter"
        into.unloaded[cause] += SCENARIO_DT


def commanded_motion(record: dict[str, np.ndarray], mode: str) -> np.ndarray:
    """The motion (m, 10) a controller could predict for each control step from its command
    and the plant's traits, at the step's start (the state the step began from):

    * velocity commands (``qp``): each joint, each wheel's speed and so the base's v and w
      approach their command through the servos' lag (20 ms), their accelerations clipped
      at the motors' (the joints' limits, ``2 wheel_force_limit / M``, the yaw's
      ``2 wheel_force_limit (track/2) / I(th2)``); ``a_y = v w``;
    * force commands (``mpc``): ``M vdot = F_l + F_r - c1 v``, ``I(th2) wdot = (F_r - F_l)
      track/2 - c2 w`` plus the arm's yaw reaction, the joints through the same lag towards
      the rate that reaches their target in one step.
    """
    plant = MujocoPlant(ROBOT, base_damping=DAMPING)
    tau = plant.joint_time_constant
    limits = np.array(plant.joint_acceleration_limit)
    mass = MODEL.weight / 9.81
    force, lever = plant.wheel_force_limit, plant.wheel_lever
    c1, c2 = DAMPING
    rows = []
    motions, speeds = record["motion"], record["v"]
    for k in range(1, len(motions)):
        th1, th2, r1, r2, _, _, _, _, w, _ = motions[k - 1]
        v = speeds[k - 1]
        command = record["command"][k]
        inertia = float(_DYNAMICS.inertia(th2))
        if mode == VELOCITY:
            target = np.array(command[2:4])
            v_dot = np.clip((command[0] - v) / tau, -2 * force / mass, 2 * force / mass)
            yaw_limit = 2 * force * lever / inertia
            w_dot = np.clip((command[1] - w) / tau, -yaw_limit, yaw_limit)
        else:
            left, right, th1_target, th2_target = command
            speed = ROBOT.joint_speed_limit
            target = np.clip(
                (np.array([th1_target, th2_target]) - (th1, th2)) / SCENARIO_DT, -speed, speed
            )
            v_dot = (left + right - c1 * v) / mass
            w_dot = ((right - left) * lever - c2 * w) / inertia
        accelerations = np.clip((target - (r1, r2)) / tau, -limits, limits)
        if mode != VELOCITY:
            w_dot += float(_DYNAMICS.arm_yaw_reaction(th2, w, (r1, r2), tuple(accelerations)))
        rows.append([th1, th2, r1, r2, *accelerations, v_dot, v * w, w, w_dot])
    return np.array(rows)


# -- validation runs -------------------------------------------------------------------------
#: The fast turn: arm out to the left, payload 3 kg, static S 1.59 at the start.
TURN_POSE = (0.5 * math.pi, 1.5)
TURN_DT = 0.01


def turn_command(t: float) -> np.ndarray:
    """Velocity command (v, w, th1dot, th2dot) of the fast turn at t (s): speed up to
    1 m/s, turn right at 1.5 rad/s with the payload out to the left (the outer side),
    swing the arm by +-0.4 rad on the way, brake, turn back left."""
    ramp = lambda a, b: min(1.0, max(0.0, (t - a) / (b - a)))  # noqa: E731
    v = 1.0 * ramp(0.3, 1.0) - 1.0 * ramp(4.0, 4.6)
    w = -1.5 * (ramp(1.0, 1.5) - ramp(3.0, 3.5)) + 1.2 * (ramp(4.6, 5.0) - ramp(5.6, 6.0))
    swing = 0.4 * 2.0 * math.pi / 1.5 * math.cos(2.0 * math.pi * (t - 1.0) / 1.5)
    th1dot = swing if 1.0 <= t <= 4.0 else 0.0
    return np.array([v, w, th1dot, 0.0])


def fast_turn(duration: float = 6.5, **engine: Any) -> dict[str, np.ndarray]:
    """The fast turn (:func:`turn_command`) on a :class:`RecordingPlant` with the
    protocol's base damping: its recording."""
    plant = RecordingPlant(ROBOT, base_damping=DAMPING, **engine)
    plant.reset(np.array([0.0, 0.0, 0.0, *TURN_POSE]), TURN_DT)
    for k in range(round(duration / TURN_DT)):
        t = k * TURN_DT
        applied, _ = plant.limit(plant.observe().q, turn_command(t))
        plant.step(t, applied, TURN_DT)
    return columns(plant.samples)


def sideways_reach() -> dict[str, np.ndarray]:
    """``qp`` (S >= 1.25) on trajectories/sideways_reach.csv with 3 kg, as docs/physics.md
    runs it (no base damping, dt 0.02 s): the recording."""
    trajectory = load_trajectory("sideways_reach")
    q0 = ROBOT.base_for_end_effector(trajectory.pose(0.0), 1.0, 1.6)
    plant = RecordingPlant(ROBOT)
    simulate(ROBOT, trajectory, "qp", stability_min=1.25, plant=plant, q0=q0, dt=0.02)
    return columns(plant.samples)


def rectangle() -> dict[str, np.ndarray]:
    """``mpc`` on the default rectangle (40 s, dt 0.02 s) with 3 kg, on the plant with the
    protocol's base damping: the recording."""
    plant = RecordingPlant(ROBOT, base_damping=DAMPING)
    simulate(ROBOT, load_trajectory("rectangle"), "mpc", plant=plant, dt=0.02)
    return columns(plant.samples)


RUNS: dict[str, Callable[[], dict[str, np.ndarray]]] = {
    "sideways reach (qp)": sideways_reach,
    "fast turn, payload out": fast_turn,
    "rectangle (mpc)": rectangle,
}


def prediction_errors(record: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Model minus measurement (N, (m, 4)) per control step: ``end`` at the step's end
    (what the plant reads), ``mean`` averaged over the step's engine steps, ``static``
    the weight at the centre of mass against the step's mean."""
    inside = record["motion_inside"]
    steps, substeps = inside.shape[:2]
    predicted = predicted_loads(inside.reshape(-1, 10)).reshape(steps, substeps, 4)
    measured_mean = record["measured_inside"].mean(axis=1)
    return {
        "end": predicted_loads(record["motion"]) - record["measured"],
        "mean": predicted.mean(axis=1) - measured_mean,
        "static": static_loads(record["motion"]) - measured_mean,
    }


def error_table(errors: dict[str, dict[str, np.ndarray]]) -> tuple[str, dict]:
    """Markdown table of |model - measured| per run and edge: median and 95th percentile
    in N and as a share of the weight."""
    weight = MODEL.weight
    lines = [
        "| run | edge | model, step end: median / 95 % (N) | step mean: median / 95 % (N) "
        "| step mean, share of the weight | static model, step mean: median / 95 % (N) |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    numbers: dict[str, Any] = {}
    for run, err in errors.items():
        numbers[run] = {}
        for e, edge in enumerate(EDGES):
            stats = {
                kind: (float(np.median(np.abs(v[:, e]))), float(np.percentile(np.abs(v[:, e]), 95)))
                for kind, v in err.items()
            }
            numbers[run][edge] = stats
            end, mean, static = stats["end"], stats["mean"], stats["static"]
            lines.append(
                f"| {run} | {edge} | {end[0]:.2f} / {end[1]:.2f} | {mean[0]:.2f} / {mean[1]:.2f} "
                f"| {100 * mean[0] / weight:.2f} % / {100 * mean[1] / weight:.2f} % "
                f"| {static[0]:.2f} / {static[1]:.2f} |"
            )
    return "\n".join(lines), numbers


# -- the attribution study ---------------------------------------------------------------------
def replay_variant(recording: dict[str, Any], variant: str) -> dict[str, np.ndarray] | None:
    """:func:`replay` on a plant variant of :data:`VARIANTS` (None if the engine diverged)."""
    from ddwmmr.plants.base import PlantDivergedError

    options = dict(VARIANTS[variant])
    solimp = options.pop("solimp", None)
    try:
        if solimp is None:
            return replay(recording, **options)
        return replay(recording, edit=lambda text: _with_solimp(text, solimp), **options)
    except PlantDivergedError:
        return None


def _with_solimp(text: str, solimp: tuple[float, ...]) -> str:
    anchor = '<geom solref="'
    assert anchor in text, "mjcf() sets the default geom's solref"
    return text.replace(anchor, f'<geom solimp="{" ".join(map(str, solimp))}" solref="', 1)


def _scenario_job(job: tuple[str, int, str]) -> dict[str, Any]:
    """One scenario of the study (a worker's job): the controller's run on the plant, its
    attribution, replays and closed-loop variants."""
    name, index, what = job
    weight = MODEL.weight
    out: dict[str, Any] = {"controller": name, "scenario": index + 1, "what": what}
    if what == "record":
        run = record_scenario(name, index)
        record = run["record"]
        out["metrics"] = _plain(run["metrics"])
        out["slip_share"] = float(np.mean(record["slip"] > SLIP_M_S))
        for share in (0.02, DELTA_SHARE, 0.10):
            attribution = Attribution()
            classify(record, share * weight, attribution)
            out[f"attribution_{share:g}"] = {
                "unloaded": attribution.unloaded,
                "parts": attribution.parts,
                "edges": attribution.edges,
            }
        out["errors"] = _model_errors(record, run["mode"])
        replays = {v: replay_variant(run, v) for v in VARIANTS if v != "plant"}
        out["replays"] = {v: _replay_summary(again, record) for v, again in replays.items()}
        out["window"] = _window(record, run["mode"])
        return out
    engine = {} if what in ("smooth", "plant") else dict(VARIANTS[what])
    run = record_scenario(name, index, smooth=what == "smooth", **engine)
    out["metrics"] = _plain(run["metrics"])
    out["slip_share"] = float(np.mean(run["record"]["slip"] > SLIP_M_S))
    return out


#: A wheel slips when its contact point moves faster than this over the floor (m/s).
SLIP_M_S = 0.05


def _plain(metrics: dict[str, Any]) -> dict[str, Any]:
    return {k: (float(v) if isinstance(v, float | np.floating) else v) for k, v in metrics.items()}


def _replay_summary(record: dict[str, np.ndarray] | None, original: dict[str, np.ndarray]) -> Any:
    if record is None:
        return None
    weight = MODEL.weight
    drift = np.abs(record["q"][:, 3:5] - original["q"][: len(record["q"]), 3:5])
    return {
        "unloaded_s": float(np.sum(unloaded_steps(record, weight)) * SCENARIO_DT),
        "slip_share": float(np.mean(record["slip"] > SLIP_M_S)),
        "max_joint_drift_rad": float(drift.max()),
        "min_static_load_n": float(static_loads(record["motion"]).min()),
    }


def _model_errors(record: dict[str, np.ndarray], mode: str) -> dict[str, np.ndarray]:
    """Prediction minus measured step mean on each step's lightest edge (N): the rigid
    model with the measured motion (``rigid``) and with the motion the command predicts
    (``commanded``, :func:`commanded_motion`), and which steps ended unloaded."""
    inside = record["motion_inside"]
    steps, substeps = inside.shape[:2]
    rigid = predicted_loads(inside.reshape(-1, 10)).reshape(steps, substeps, 4).mean(axis=1)
    measured = record["measured_inside"].mean(axis=1)
    commanded = np.vstack([rigid[:1], predicted_loads(commanded_motion(record, mode))])
    edge = np.argmin(measured, axis=1)
    rows = np.arange(steps)
    return {
        "rigid": rigid[rows, edge] - measured[rows, edge],
        "commanded": commanded[rows, edge] - measured[rows, edge],
        "unloaded": unloaded_steps(record, MODEL.weight),
    }


#: Length (s) of the engine-resolution trace of each controller's figure.
WINDOW_S = 0.4


def _window(record: dict[str, np.ndarray], mode: str) -> dict[str, Any]:
    """The stretch of the run with the most unloaded steps in :data:`WINDOW_S`: the
    lightest edge's measured load at every engine step (as run, and replayed on the
    elliptic cone from the same state: :func:`replay_from`), the rigid model's and the
    static one."""
    unloaded = unloaded_steps(record, MODEL.weight).astype(float)
    width = round(WINDOW_S / SCENARIO_DT)
    if len(unloaded) <= width:
        return {}
    counts = np.convolve(unloaded, np.ones(width), mode="valid")
    start = int(np.argmax(counts))
    span = slice(start, start + width)
    edge = int(np.argmin(record["off"][span].min(axis=0)))
    inside = record["motion_inside"][span]
    substeps = inside.shape[1]
    t0 = record["t"][start] - SCENARIO_DT
    times = t0 + np.arange(width * substeps) * (SCENARIO_DT / substeps)
    traces = {"measured": record["measured_inside"][span][:, :, edge].ravel()}
    elliptic = replay_from(record, start, width, mode, cone="elliptic")
    traces["elliptic"] = elliptic["measured_inside"][:, :, edge].ravel()
    elliptic_unloaded = int(np.sum(unloaded_steps(elliptic, MODEL.weight)))
    traces["model"] = predicted_loads(inside.reshape(-1, 10))[:, edge]
    traces["static"] = static_loads(inside.reshape(-1, 10))[:, edge]
    return {
        "edge": EDGES[edge],
        "count": int(counts[start]),
        "elliptic_count": elliptic_unloaded,
        "t": times.tolist(),
        "step_end_t": record["t"][span].tolist(),
        "step_end_unloaded": unloaded[span].astype(bool).tolist(),
        **{k: (None if v is None else np.asarray(v).tolist()) for k, v in traces.items()},
    }


def study_jobs(n: int) -> list[tuple[str, int, str]]:
    """The attribution study's jobs: each optimiser's runs with attribution and replays,
    the thesis controller's runs, and the closed-loop variants."""
    jobs = [(name, i, "record") for name in ("mpc", "qp") for i in range(n)]
    jobs += [("thesis", i, "plant") for i in range(n)]
    for what in ("smooth", "elliptic", "tyre_elliptic"):
        names = ("mpc", "qp") if what == "smooth" else ("mpc", "qp", "thesis")
        jobs += [(name, i, what) for name in names for i in range(n)]
    return jobs


def summarise(results: list[dict[str, Any]], n: int) -> dict[str, Any]:
    """The study's numbers per controller (seconds per scenario, shares, errors)."""
    summary: dict[str, Any] = {"scenarios": n, "seed": 0, "payload_kg": PAYLOAD}
    for name in ("qp", "mpc", "thesis"):
        mine = [r for r in results if r["controller"] == name]
        entry: dict[str, Any] = {"closed_loop": {}}
        for what in ("record", "plant", "smooth", "elliptic", "tyre_elliptic"):
            runs = [r for r in mine if r["what"] == what]
            if not runs:
                continue
            metrics = [r["metrics"] for r in runs]
            label = "as run" if what in ("record", "plant") else what
            entry["closed_loop"][label] = {
                "mean_time_s": float(np.mean([m["time_s"] for m in metrics])),
                "unloaded_s": float(np.mean([m["unloaded_time_s"] for m in metrics])),
                "failed": sum(not m["success"] for m in metrics),
                "min_stability": float(min(m["min_stability"] for m in metrics)),
                "slip_share": float(np.mean([r["slip_share"] for r in runs]))
                if all("slip_share" in r for r in runs)
                else None,
            }
        records = [r for r in mine if r["what"] == "record"]
        if records:
            entry["attribution"] = {
                f"{share:g}": _mean_attribution([r[f"attribution_{share:g}"] for r in records], n)
                for share in (0.02, DELTA_SHARE, 0.10)
            }
            entry["replays"] = _mean_replays([r["replays"] for r in records])
            entry["model_error"] = _error_stats([r["errors"] for r in records])
            entry["window"] = max((r["window"] for r in records), key=lambda w: w.get("count", 0))
        summary[name] = entry
    return summary


def _mean_attribution(items: list[dict[str, dict[str, float]]], n: int) -> dict[str, Any]:
    return {
        group: {key: sum(item[group][key] for item in items) / n for key in items[0][group]}
        for group in ("unloaded", "parts", "edges")
    }


def _mean_replays(items: list[dict[str, Any]]) -> dict[str, Any]:
    out = {}
    for variant in items[0]:
        runs = [item[variant] for item in items]
        done = [r for r in runs if r is not None]
        out[variant] = {
            "unloaded_s": float(np.mean([r["unloaded_s"] for r in done])),
            "slip_share": float(np.mean([r["slip_share"] for r in done])),
            "max_joint_drift_rad": float(max(r["max_joint_drift_rad"] for r in done)),
            "min_static_load_n": float(min(r["min_static_load_n"] for r in done)),
            "diverged": len(runs) - len(done),
        }
    return out


def _error_stats(items: list[dict[str, np.ndarray]]) -> dict[str, Any]:
    unloaded = np.concatenate([i["unloaded"] for i in items])
    out = {}
    for label in ("rigid", "commanded"):
        err = np.concatenate([i[label] for i in items])
        out[label] = {
            "all": [float(np.median(np.abs(err))), float(np.percentile(np.abs(err), 95))],
            "unloaded": [
                float(np.median(np.abs(err[unloaded]))),
                float(np.percentile(np.abs(err[unloaded]), 95)),
            ],
            "unloaded_signed_median": float(np.median(err[unloaded])),
        }
    return out


# -- figures and tables ------------------------------------------------------------------------
CAUSE_COLOURS = {
    "static": "#7f7f7f",
    "forward acceleration": "#1f77b4",
    "turning": "#17becf",
    "yaw": "#2ca02c",
    "arm's yaw reaction": "#98df8a",
    "arm acceleration": "#9467bd",
    "lift": "#ff7f0e",
    "chatter": "#d62728",
}
VARIANT_LABELS = {
    "elliptic": "elliptic cone",
    "elliptic_hard": "elliptic cone, impratio 10",
    "timestep_0.5ms": "engine step 0.5 ms",
    "contact_5ms": "contact time constant 5 ms",
    "contact_20ms": "contact time constant 20 ms",
    "impedance": "solimp 0.95-0.99",
    "cylinder": "cylinder wheels",
    "tyre": "compliant tyres",
    "tyre_elliptic": "compliant tyres + elliptic cone",
}


def attribution_figure(name: str, entry: dict[str, Any], scenarios: int, path: Path) -> None:
    """Three panels: the unloaded time by cause, the same commands replayed on other plant
    models (and the controller in closed loop on some), the lightest edge's load at
    engine resolution where it goes unloaded most."""
    fig = plt.figure(figsize=(11.5, 8.2))
    grid = fig.add_gridspec(2, 2, height_ratios=(1.0, 1.05), width_ratios=(1.0, 1.25))
    causes, replays, trace = (
        fig.add_subplot(grid[0, 0]),
        fig.add_subplot(grid[0, 1]),
        fig.add_subplot(grid[1, :]),
    )
    _cause_bars(causes, entry)
    _replay_bars(replays, entry)
    _trace(trace, entry["window"])
    run = entry["closed_loop"]["as run"]
    fig.suptitle(
        f"{name} on MuJoCo: where the unloaded time comes from "
        f"({scenarios} scenarios, seed 0, 3 kg; {run['unloaded_s']:.2f} s unloaded per scenario)",
        fontsize=11,
    )
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _cause_bars(ax, entry: dict[str, Any]) -> None:
    rows = []
    for share in ("0.02", f"{DELTA_SHARE:g}", "0.1"):
        a = entry["attribution"][share]
        parts = a["parts"]
        segments = [("static", a["unloaded"]["static"])]
        segments += [(p, parts[p]) for p in PARTS]
        segments += [("lift", a["unloaded"]["lift"]), ("chatter", a["unloaded"]["chatter"])]
        rows.append((f"delta {100 * float(share):g} % of W", segments))
    for y, (_, segments) in enumerate(rows):
        left = 0.0
        for cause, value in segments:
            ax.barh(
                y, value, left=left, color=CAUSE_COLOURS[cause], edgecolor="white", linewidth=0.5
            )
            left += value
    ax.set_yticks(range(len(rows)), [r[0] for r in rows], fontsize=8)
    ax.invert_yaxis()
    total = sum(v for _, v in rows[0][1])
    ax.set_xlim(0, total * 1.02)
    ax.set_xlabel("unloaded time per scenario (s)")
    ax.set_title("each unloaded step by its cause", fontsize=10)
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in CAUSE_COLOURS.values()]
    labels = [("inertial: " if k in PARTS else "") + k for k in CAUSE_COLOURS]
    ax.legend(
        handles,
        labels,
        fontsize=7,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.2),
        ncol=3,
        frameon=False,
    )


def _replay_bars(ax, entry: dict[str, Any]) -> None:
    run = entry["closed_loop"]["as run"]["unloaded_s"]
    labels, values, colours = ["as run"], [run], ["#444444"]
    for variant, label in VARIANT_LABELS.items():
        replay_stats = entry["replays"].get(variant)
        if replay_stats is None:
            continue
        labels.append(f"same commands: {label}")
        values.append(replay_stats["unloaded_s"])
        colours.append("#4c72b0")
    for what, label in (
        ("smooth", "commands smoothed"),
        ("elliptic", "elliptic cone"),
        ("tyre_elliptic", "tyres + elliptic cone"),
    ):
        closed = entry["closed_loop"].get(what)
        if closed is not None:
            labels.append(f"closed loop: {label}")
            values.append(closed["unloaded_s"])
            colours.append("#55a868")
    y = np.arange(len(values))
    ax.barh(y, values, color=colours)
    for yi, value in zip(y, values):
        ax.text(value, yi, f" {value:.2f}", va="center", fontsize=7)
    ax.set_yticks(y, labels, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlim(0, max(values) * 1.18)
    ax.set_xlabel("unloaded time per scenario (s)")
    ax.set_title("same commands on other plants (blue); closed loop (green)", fontsize=10)


def _trace(ax, window: dict[str, Any]) -> None:
    if not window:
        ax.set_axis_off()
        return
    t = np.array(window["t"])
    styles = (
        ("measured", "as run (measured)", dict(color="#d62728", lw=1.0)),
        ("elliptic", "same state and commands, elliptic cone", dict(color="#4c72b0", lw=0.9)),
        ("model", "rigid-body model, measured motion", dict(color="black", lw=1.0, ls="--")),
        ("static", "static (S)", dict(color="#7f7f7f", lw=1.0, ls=":")),
    )
    for key, label, style in styles:
        if window.get(key) is not None:
            ax.plot(t, window[key], label=label, **style)
    ends = np.array(window["step_end_t"])
    marks = np.array(window["step_end_unloaded"])
    ax.plot(ends[marks], np.zeros(marks.sum()), "kv", ms=4, label="control step ends unloaded")
    # The axes hold every curve (the model may predict a negative load) and every mark.
    drawn = [window[k] for k, *_ in styles if window.get(k) is not None]
    top, bottom = max(max(v) for v in drawn), min(0.0, min(min(v) for v in drawn))
    start, end = min(t[0], *ends[marks]), max(t[-1], *ends[marks])
    pad = 0.01 * (end - start)
    ax.set_xlim(start - pad, end + pad)
    ax.set_ylim(bottom - 0.05 * (top - bottom), top + 0.35 * (top - bottom))
    ax.set_xlabel("t (s)")
    ax.set_ylabel(f"load off the {window['edge']} edge (N)")
    ax.set_title(
        "the lightest edge at every engine step (2 ms), where it goes unloaded most", fontsize=10
    )
    ax.legend(fontsize=7, ncol=3, loc="upper left")


def validation_figure(records: dict[str, dict[str, np.ndarray]], path: Path) -> None:
    """Per run, the lightest edge's load over time: measured (step mean) against the model
    (measured motion) and the static load; last panel, the error distribution."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    weight = MODEL.weight
    for ax, (run, record) in zip(axes.flat, records.items()):
        inside = record["motion_inside"]
        steps, substeps = inside.shape[:2]
        predicted = predicted_loads(inside.reshape(-1, 10)).reshape(steps, substeps, 4).mean(axis=1)
        measured = record["measured_inside"].mean(axis=1)
        edge = int(np.argmin(measured.min(axis=0)))
        t = record["t"]
        ax.plot(t, measured[:, edge], color="#d62728", lw=1.0, label="measured (MuJoCo)")
        ax.plot(
            t, predicted[:, edge], color="black", lw=0.9, ls="--", label="model, measured motion"
        )
        ax.plot(
            t,
            static_loads(record["motion"])[:, edge],
            color="#7f7f7f",
            lw=1.0,
            ls=":",
            label="static (S)",
        )
        top = max(measured[:, edge].max(), predicted[:, edge].max())
        ax.set_ylim(min(0.0, predicted[:, edge].min()) - 2, top * 1.3)
        ax.set_xlim(t[0], t[-1])
        ax.set_title(f"{run}: the load off the {EDGES[edge]} edge", fontsize=10)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("edge load, mean over each control step (N)")
        ax.legend(fontsize=7, loc="upper right", ncol=3)
    ax = axes.flat[-1]
    smallest = 1e-3  # % of the weight: the axis reaches down to the smallest error drawn
    for (run, record), colour in zip(records.items(), ("#1f77b4", "#ff7f0e", "#2ca02c")):
        errors = prediction_errors(record)
        for kind, style in (("mean", "-"), ("static", ":")):
            values = np.sort(np.abs(errors[kind]).ravel()) / weight * 100
            share = np.arange(1, len(values) + 1) / len(values)
            label = f"{run}, {'model' if kind == 'mean' else 'static'}"
            ax.plot(values, share, color=colour, ls=style, label=label)
            if np.any(values > 0):
                smallest = min(smallest, values[values > 0][0])
    ax.set_xscale("log")
    ax.set_xlim(10 ** np.floor(np.log10(smallest)), 100)
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("|predicted - measured| edge load, step mean (% of the weight)")
    ax.set_ylabel("share of steps x edges")
    ax.set_title("error distribution, all four edges", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def attribution_table(summary: dict[str, Any]) -> str:
    """Markdown: per optimiser, the unloaded time per scenario by cause."""
    lines = [
        "| controller | unloaded (s per scenario) | static | inertial (rigid-body model) "
        "| of it: forward / turning / yaw / arm's yaw reaction / arm | lift (hop) | chatter |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for name in ("qp", "mpc"):
        a = summary[name]["attribution"][f"{DELTA_SHARE:g}"]
        u, p = a["unloaded"], a["parts"]
        total = sum(u.values())
        parts = " / ".join(f"{p[k]:.2f}" for k in PARTS)
        lines.append(
            f"| `{name}` | {total:.2f} | {u['static']:.2f} | {u['inertial']:.2f} | {parts} "
            f"| {u['lift']:.2f} | {u['chatter']:.2f} ({100 * u['chatter'] / total:.0f} %) |"
        )
    return "\n".join(lines)


def replay_table(summary: dict[str, Any]) -> str:
    """Markdown: the same commands on other plants, and closed-loop variants."""
    lines = [
        "| plant (same actuator commands, open loop) | `qp`: unloaded (s) | wheel slipping "
        "| largest joint drift (rad) | `mpc`: unloaded (s) | wheel slipping "
        "| largest joint drift (rad) |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    qp, mpc = summary["qp"], summary["mpc"]

    def cells(entry, variant):
        r = entry["replays"][variant]
        drift = r["max_joint_drift_rad"]
        return f"{r['unloaded_s']:.2f} | {100 * r['slip_share']:.0f} % | {drift:.2f}"

    as_run = [entry["closed_loop"]["as run"] for entry in (qp, mpc)]
    lines.append(
        "| as run | "
        + " | ".join(f"{r['unloaded_s']:.2f} | {100 * r['slip_share']:.0f} % | 0" for r in as_run)
        + " |"
    )
    for variant, label in VARIANT_LABELS.items():
        lines.append(f"| {label} | {cells(qp, variant)} | {cells(mpc, variant)} |")
    lines += [
        "",
        "| closed loop | `qp`: mean time (s) | unloaded (s) | failed | `mpc`: mean time (s) "
        "| unloaded (s) | failed | thesis controller: mean time (s) | unloaded (s) | failed |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for what, label in (
        ("as run", "as run"),
        ("smooth", "commands smoothed"),
        ("elliptic", "elliptic cone"),
        ("tyre_elliptic", "compliant tyres + elliptic cone"),
    ):
        row = [label]
        for name in ("qp", "mpc", "thesis"):
            c = summary[name]["closed_loop"].get(what)
            row.append(
                "-"
                if c is None
                else f"{c['mean_time_s']:.2f} | {c['unloaded_s']:.2f} | {c['failed']}"
            )
            if c is None:
                row[-1] = "- | - | -"
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def error_lines(summary: dict[str, Any]) -> str:
    """The rigid-body model's and the command model's errors on the lightest edge."""
    lines = [
        "| controller | model | all steps: median / 95 % (N) "
        "| unloaded steps: median / 95 % (N) | unloaded steps: median signed error (N) |",
        "| --- | --- | --- | --- | --- |",
    ]
    for name in ("qp", "mpc"):
        for label, key in (
            ("rigid-body, measured motion", "rigid"),
            ("from the command and the plant's traits", "commanded"),
        ):
            e = summary[name]["model_error"][key]
            lines.append(
                f"| `{name}` | {label} | {e['all'][0]:.2f} / {e['all'][1]:.2f} "
                f"| {e['unloaded'][0]:.2f} / {e['unloaded'][1]:.2f} "
                f"| {e['unloaded_signed_median']:+.2f} |"
            )
    return "\n".join(lines)


# -- main --------------------------------------------------------------------------------------
def validate() -> dict[str, Any]:
    records = {run: make() for run, make in RUNS.items()}
    table, numbers = error_table({run: prediction_errors(r) for run, r in records.items()})
    print(f"## edge-load model against MuJoCo\n{table}\n", flush=True)
    validation_figure(records, FIGURES / "support_validation.png")
    extremes = {run: _extremes(r) for run, r in records.items()}
    lag = lag_profile(records["sideways reach (qp)"])
    tipping = tyre_tipping()
    print(f"runs: {extremes}\nsideways reach, 95 % error per engine step: {lag}", flush=True)
    print(f"stretched left, tyres: {tipping}\n", flush=True)
    return {"errors": numbers, "runs": extremes, "lag_p95_n": lag, "tyre_tipping": tipping}


def _extremes(record: dict[str, np.ndarray]) -> dict[str, float]:
    """A run's unloaded time (s) and its lightest edge's smallest load: measured (step end),
    predicted (the model, measured motion) and static (N)."""
    edge = int(np.argmin(record["measured"].min(axis=0)))
    return {
        "edge": EDGES[edge],
        "unloaded_s": float(np.sum(unloaded_steps(record, MODEL.weight)))
        * float(record["t"][1] - record["t"][0]),
        "min_measured_n": float(record["measured"][:, edge].min()),
        "min_predicted_n": float(predicted_loads(record["motion"])[:, edge].min()),
        "min_static_n": float(static_loads(record["motion"])[:, edge].min()),
    }


def lag_profile(record: dict[str, np.ndarray]) -> list[float]:
    """95th percentile of |model - measured| (N, all edges) at each engine step of the
    control steps: the contacts catching up with a command's new inertial forces."""
    inside = record["motion_inside"]
    steps, substeps = inside.shape[:2]
    predicted = predicted_loads(inside.reshape(-1, 10)).reshape(steps, substeps, 4)
    error = np.abs(predicted - record["measured_inside"])
    return [float(np.percentile(error[:, j], 95)) for j in range(substeps)]


def tyre_tipping(hold_s: float = 1.0) -> dict[str, float]:
    """With the arm stretched to the left: the payload (kg) at which the robot tips over,
    by bisection to 1 g, and the static S there, on the plant, on the elliptic cone and
    with compliant tyres; the base's tilt (rad) at rest with 2.5 kg."""
    out: dict[str, float] = {}
    variants = (("plant", "plant"), ("elliptic", "elliptic"), ("tyres", "tyre"))
    for label, variant in variants:
        low, high = 2.5, 3.2
        while high - low > 1e-3:
            middle = 0.5 * (low + high)
            tipped, _ = _hold_stretched_left(middle, variant, hold_s)
            low, high = (low, middle) if tipped else (middle, high)
        robot = Robot().with_payload(high)
        out[f"{label}_payload_kg"] = high
        out[f"{label}_s_at_tipping"] = robot.stability([0.0, 0.0, 0.0, 0.5 * math.pi, 0.0])[2]
        out[f"{label}_tilt_at_rest_rad"] = _hold_stretched_left(2.5, variant, hold_s)[1]
    return out


def _hold_stretched_left(payload: float, variant: str, hold_s: float) -> tuple[bool, float]:
    """Hold the arm stretched to the left with ``payload`` on a plant variant of
    :data:`VARIANTS`: tipped?, final tilt (rad)."""
    robot = Robot().with_payload(payload)
    plant = RecordingPlant(robot, **VARIANTS[variant])
    plant.reset(np.array([0.0, 0.0, 0.0, 0.5 * math.pi, 0.0]), 0.02)
    for k in range(round(hold_s / 0.02)):
        plant.step(k * 0.02, np.zeros(4), 0.02)
    return plant.tip_time is not None, plant.base_tilt()


def attribute(n: int, jobs: int) -> dict[str, Any]:
    from concurrent.futures import ProcessPoolExecutor

    work = study_jobs(n)
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        results = []
        for done, result in enumerate(pool.map(_scenario_job, work), start=1):
            results.append(result)
            print(
                f"  {done}/{len(work)} {result['controller']} {result['scenario']} "
                f"{result['what']}",
                file=sys.stderr,
                flush=True,
            )
    summary = _rounded(summarise(results, n))  # what the numbers file keeps
    draw_attribution(summary)
    return summary


def draw_attribution(summary: dict[str, Any]) -> None:
    """The attribution figures and tables of a study's numbers."""
    for name in ("qp", "mpc"):
        path = FIGURES / f"support_attribution_{name}.png"
        attribution_figure(name, summary[name], summary["scenarios"], path)
    print(
        f"## attribution\n{attribution_table(summary)}\n\n{replay_table(summary)}\n\n"
        f"{error_lines(summary)}\n",
        flush=True,
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "parts", nargs="*", default=["validate", "attribute"], help="validate, attribute, plot"
    )
    parser.add_argument("--n", type=int, default=10, help="scenarios of the attribution")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    numbers = json.loads(NUMBERS.read_text()) if NUMBERS.exists() else {}
    if "validate" in args.parts:
        numbers["validation"] = _rounded(validate())
    if "attribute" in args.parts:
        numbers["attribution"] = attribute(args.n, args.jobs)
    if "validate" in args.parts or "attribute" in args.parts:
        NUMBERS.write_text(json.dumps(numbers, indent=1) + "\n")
    if "plot" in args.parts:  # the attribution's figures and tables from the numbers file
        draw_attribution(numbers["attribution"])
    return 0


def _rounded(value: Any) -> Any:
    """JSON-ready numbers, rounded to 6 significant digits (the figures' and tables' text
    does not depend on the last bits)."""
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_rounded(v) for v in value]
    if isinstance(value, float):
        return float(f"{value:.6g}")
    return value


if __name__ == "__main__":
    sys.exit(main())
