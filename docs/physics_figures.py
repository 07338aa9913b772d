"""Figures and numbers of docs/physics.md (the MuJoCo physics plant).

Run from the repository root::

    MPLBACKEND=Agg .venv/bin/python docs/physics_figures.py

Writes ``docs/figures/physics_*.png`` and ``physics_tipping.gif`` and prints the tables
quoted in docs/physics.md (markdown). The dynamic runs are ``simulate(..., plant="mujoco")``
(the library's one loop); tests/test_mujoco_validation.py imports helpers from here.
"""

from __future__ import annotations

import math
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")  # MuJoCo's offscreen renderer without a display

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ddwmmr import Ellipse, Robot, load_trajectory, simulate
from ddwmmr.plants.mujoco import MujocoPlant
from ddwmmr.plants.mujoco.plant import TIP_TILT_RAD, UNLOADED_FRACTION
from ddwmmr.reports.legends import place_legend
from ddwmmr.resolution.reference import (
    DEFAULT_INITIAL_OFFSET,
    offset_configuration,
    start_configuration,
)

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
DT = 0.02
#: Static holds: how long a pose is held after the reset's settling (s).
HOLD_S = 0.5
#: Bisection resolution of the static tipping searches (kg and rad).
PAYLOAD_RESOLUTION_KG = 1e-3
ANGLE_RESOLUTION_RAD = 1e-4


# -- static holds -------------------------------------------------------------------------
def hold_pose(robot: Robot, th1: float, th2: float, hold_s: float = HOLD_S, **engine) -> dict:
    """Hold the arm at (th1, th2) with the base still; the physics summary of the hold."""
    plant = MujocoPlant(robot, **engine)
    plant.reset(np.array([0.0, 0.0, 0.0, th1, th2]), DT)
    rows = []
    for k in range(round(hold_s / DT) + 1):
        rows.append([k * DT, *plant.extra_values()])
        plant.step(k * DT, np.zeros(4), DT)
    data = np.array(rows)
    timeseries = {c: data[:, i] for i, c in enumerate(("t", *plant.extra_columns))}
    return plant.summarize(timeseries)


def _bisect(tips, low: float, high: float, resolution: float) -> float:
    """Midpoint of the last bracket [low (stands), high (tips)] of a bisection."""
    if tips(low) or not tips(high):
        raise ValueError(f"no tipping boundary in [{low}, {high}]")
    while high - low > resolution:
        middle = 0.5 * (low + high)
        if tips(middle):
            high = middle
        else:
            low = middle
    return 0.5 * (low + high)


def tipping_payload(direction: float, base: Robot | None = None, **engine) -> tuple[float, float]:
    """Smallest payload (kg) that tips the arm stretched towards ``direction`` (rad, base
    frame), found by bisection in MuJoCo, and the kinematic S of that pose."""
    base = base or Robot()

    def tips(payload: float) -> bool:
        return hold_pose(base.with_payload(payload), direction, 0.0, **engine)["tipped"]

    payload = _bisect(tips, 0.0, 40.0, PAYLOAD_RESOLUTION_KG)
    return payload, base.with_payload(payload).stability([0, 0, 0, direction, 0.0])[2]


def tipping_elbow(payload: float, th1: float, **engine) -> tuple[float, float]:
    """Elbow angle th2 (rad, in [0, pi/2]) at which unfolding the arm from th2 = pi/2 to a
    stretch along th1 tips the robot (bisection), and the kinematic S there."""
    robot = Robot().with_payload(payload)

    def tips(th2: float) -> bool:
        # smaller th2 = more stretched = less stable: "tips" is monotone in -th2
        return hold_pose(robot, th1, 0.5 * math.pi - th2, **engine)["tipped"]

    folded = _bisect(tips, 0.0, 0.5 * math.pi, ANGLE_RESOLUTION_RAD)
    th2 = 0.5 * math.pi - folded
    return th2, robot.stability([0, 0, 0, th1, th2])[2]


DIRECTIONS = {
    "forward": 0.0,
    "front-left": 0.25 * math.pi,
    "left": 0.5 * math.pi,
    "back-left": 0.75 * math.pi,
    "back": math.pi,
    "right": -0.5 * math.pi,
}


def static_agreement() -> str:
    """S at the physical tipping boundary, per direction (stretched arm, payload bisected)
    and per payload (elbow unfolded sideways or forwards)."""
    rows = []
    for label, direction in DIRECTIONS.items():
        payload, s = tipping_payload(direction)
        rows.append([label, "stretched", f"{payload:.3f}", f"{s:.4f}", f"{s - 1:+.4f}"])
    for payload, label, th1 in [
        (3.5, "left", 0.5 * math.pi),
        (4.0, "left", 0.5 * math.pi),
        (6.0, "left", 0.5 * math.pi),
        (8.0, "left", 0.5 * math.pi),
        (6.0, "forward", 0.0),
        (8.0, "forward", 0.0),
    ]:
        th2, s = tipping_elbow(payload, th1)
        rows.append([label, f"th2 = {th2:.4f}", f"{payload:g}", f"{s:.4f}", f"{s - 1:+.4f}"])
    header = ["direction", "arm at tipping", "payload (kg)", "S at tipping", "S - 1"]
    return _table(header, rows)


def tipping_map() -> str:
    """Grid of stretched-arm directions x payloads: MuJoCo tipped or not, against S = 1."""
    directions = np.linspace(-math.pi, math.pi, 25)
    payloads = np.linspace(0.5, 8.0, 16)
    tipped = np.zeros((len(payloads), len(directions)), dtype=bool)
    margins = np.zeros_like(tipped, dtype=float)
    disagreements = 0
    for i, payload in enumerate(payloads):
        robot = Robot().with_payload(payload)
        for j, direction in enumerate(directions):
            tipped[i, j] = hold_pose(robot, direction, 0.0)["tipped"]
            margins[i, j] = robot.stability([0, 0, 0, direction, 0.0])[2]
            disagreements += int(tipped[i, j] != (margins[i, j] <= 1.0))
    # The map reaches half a grid step beyond the outer poses: their marks are whole.
    half_d, half_p = 0.5 * (directions[1] - directions[0]), 0.5 * (payloads[1] - payloads[0])
    fine_d = np.linspace(-math.pi - half_d, math.pi + half_d, 373)
    fine_p = np.linspace(0.5 - half_p, 8.0 + half_p, 321)
    # One robot per payload row (building one per cell was most of the map's time).
    rows = (Robot().with_payload(p) for p in fine_p)
    grid = np.array([[robot.stability([0, 0, 0, d, 0])[2] for d in fine_d] for robot in rows])
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    contour = ax.contourf(
        np.degrees(fine_d),
        fine_p,
        np.clip(grid, 0.6, 2.0),
        levels=np.linspace(0.6, 2.0, 15),
        cmap="RdYlGn",
    )
    fig.colorbar(contour, ax=ax, label="kinematic S")
    ax.contour(np.degrees(fine_d), fine_p, grid, levels=[1.0], colors="red", linewidths=1.5)
    dd, pp = np.meshgrid(np.degrees(directions), payloads)
    ax.scatter(dd[tipped], pp[tipped], marker="x", color="k", label="MuJoCo: tipped")
    ax.scatter(
        dd[~tipped],
        pp[~tipped],
        marker="o",
        s=10,
        color="w",
        edgecolors="k",
        label="MuJoCo: stands",
    )
    ax.set_xlabel("direction of the stretched arm th1 (deg, 0 = forward, 90 = left)")
    ax.set_ylabel("payload (kg)")
    ax.set_title("Static holds: MuJoCo tipping vs the kinematic S = 1 line (red)")
    # Below the map: every spot inside it holds a pose.
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=8)
    fig.tight_layout()
    fig.savefig(FIGURES / "physics_tipping_map.png", dpi=110)
    plt.close(fig)
    return f"{tipped.size} poses, {disagreements} where MuJoCo disagrees with S <= 1"


def slow_sideways_reach(payload: float = 3.2, rate: float = 0.05) -> str:
    """Unfold the arm sideways slowly (quasi-static); the right side's load against S."""
    robot = Robot().with_payload(payload)
    plant = MujocoPlant(robot)
    th1, th2 = 0.5 * math.pi, 1.6
    plant.reset(np.array([0.0, 0.0, 0.0, th1, th2]), DT)
    names = [s.name for s in plant.supports]
    right = [i for i, s in enumerate(plant.supports) if s.point[1] < 0]
    records = []
    steps = round(th2 / rate / DT) + round(1.0 / DT)
    column = plant.extra_columns.index  # by name: the plant's columns may grow
    physics, tilt = column("physics_stability"), column("base_tilt_rad")
    for k in range(steps):
        obs = plant.observe()
        values = plant.extra_values()
        forces = np.array(values[1 : 1 + len(names)])
        records.append([k * DT, robot.stability(obs.q)[2], *forces, values[physics], values[tilt]])
        plant.step(k * DT, np.array([0.0, 0.0, 0.0, -rate if obs.q[4] > 0 else 0.0]), DT)
    data = np.array(records)
    t, s = data[:, 0], data[:, 1]
    forces = data[:, 2 : 2 + len(names)]
    right_load = forces[:, right].sum(axis=1)
    weight = plant.weight_n
    closed_form = np.where(s > 1.0, 0.5 * weight * (1.0 - 1.0 / s), 0.0)
    standing = s > 1.0 + 1e-3
    worst = float(np.max(np.abs(right_load - closed_form)[standing]))
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for i in right:
        ax1.plot(s, forces[:, i], lw=0.8, label=names[i])
    ax1.plot(s, right_load, color="k", label="right side total")
    ax1.plot(s, closed_form, "r--", label="statics: W (1 - 1/S) / 2")
    ax1.set_xlim(s.max() + 0.02, s.min() - 0.02)  # S decreases left to right
    ax1.set_xlabel("kinematic S (decreasing as the arm unfolds)")
    ax1.set_ylabel("floor normal force (N)")
    ax1.set_title(f"Slow sideways reach, payload {payload:g} kg", fontsize=10)
    ax1.legend(fontsize=8)
    fell = int(np.argmax(data[:, -1] > TIP_TILT_RAD))
    # Until the base has tilted 1 degree: the margins of a falling robot mean nothing, and
    # its growing tilt would flatten the margins' curves.
    leaning = np.degrees(data[:, -1]) > 1.0
    tilted = int(np.argmax(leaning)) if np.any(leaning) else len(t) - 1
    shown = t <= t[tilted]
    ax2.plot(t[shown], s[shown], label="kinematic S")
    ax2.plot(t[shown], data[shown, -2], label="S_phys (centre of pressure)", lw=0.8)
    tilt_deg = 1.0 + np.degrees(data[shown, -1])
    ax2.plot(t[shown], tilt_deg, color="0.5", lw=0.8, label="1 + tilt (deg)")
    ax2.axhline(1.0, color="tab:red", ls="--", lw=0.8)
    ax2.set_xlabel(f"t (s), until the base has tilted 1 deg ({t[tilted]:.1f} s)")
    fig.tight_layout()
    place_legend(ax1, fontsize=8)
    place_legend(ax2, fontsize=8)
    fig.tight_layout()
    fig.savefig(FIGURES / "physics_sideways_forces.png", dpi=110)
    plt.close(fig)
    first_unloaded = int(np.argmax(right_load < UNLOADED_FRACTION * weight))
    return (
        f"payload {payload:g} kg, th2 unfolding at {rate:g} rad/s: right-side load against "
        f"W (1 - 1/S) / 2 while S > 1.001: largest difference {worst:.3f} N (weight "
        f"{weight:.1f} N); right side first unloaded at S = {s[first_unloaded]:.4f} "
        f"(t = {t[first_unloaded]:.2f} s); tilt beyond {TIP_TILT_RAD:g} rad at "
        f"t = {t[fell]:.2f} s (S = {s[fell]:.4f})"
    )


def sideways_reach_runs(payloads=(3.0, 3.5, 4.0)) -> tuple[str, dict]:
    """Jacobian methods and qp on trajectories/sideways_reach.csv on the physics plant."""
    trajectory = load_trajectory("sideways_reach")
    methods = [("ats", {}), ("clrrmc-ts", {}), ("qp", {"stability_min": 1.25})]
    rows, runs = [], {}
    for payload in payloads:
        robot = Robot().with_payload(payload)
        q0 = robot.base_for_end_effector(trajectory.pose(0.0), 1.0, 1.6)
        for method, options in methods:
            result = simulate(robot, trajectory, method, plant="mujoco", q0=q0, dt=DT, **options)
            runs[payload, method] = result
            s = result.summary
            below = result.timeseries["t"][result.timeseries["stability"] < 1.0]
            kinematic = simulate(robot, trajectory, method, q0=q0, dt=DT, **options).summary
            rows.append(
                [
                    f"{payload:g}",
                    method,
                    f"{kinematic['min_stability']:.3f}",
                    f"{s['min_stability']:.3f}",
                    f"{below[0]:.2f}" if below.size else "-",
                    f"{s['min_physics_stability']:.3f}",
                    f"{s['min_edge_load_n']:.2f}",
                    f"{s['unloaded_time_s']:.2f}",
                    "yes" if s["tipped"] else "no",
                    f"{s['tip_time_s']:.2f}" if s["tipped"] else "-",
                    f"{1000 * kinematic['rms_position_error_m']:.2f}",
                    f"{1000 * s['rms_position_error_m']:.2f}",
                ]
            )
    header = [
        "payload (kg)",
        "method",
        "min S kinematic plant",
        "min S MuJoCo run",
        "first S<1 (s)",
        "min S_phys",
        "min edge load (N)",
        "unloaded (s)",
        "tipped",
        "tip time (s)",
        "RMS err kinematic (mm)",
        "RMS err MuJoCo (mm)",
    ]
    _plot_reach_runs(runs, payloads)
    return _table(header, rows), runs


#: Line widths of the sideways-reach runs (methods not listed: 1.4).
REACH_WIDTHS = {"ats": 3.0, "clrrmc-ts": 1.4}


def _plot_reach_runs(runs: dict, payloads) -> None:
    fig, axes = plt.subplots(
        2, len(payloads), figsize=(4.2 * len(payloads), 6), sharex=True, squeeze=False
    )
    for col, payload in enumerate(payloads):
        ax_s, ax_f = axes[0, col], axes[1, col]
        for (p, method), result in runs.items():
            if p != payload:
                continue
            ts = result.timeseries
            shown = np.ones(len(ts["t"]), dtype=bool)
            if result.summary["tipped"]:  # a fallen robot's margins mean nothing: cut
                shown = ts["t"] <= result.summary["tip_time_s"] + 0.3
            t = ts["t"][shown]
            # ats and clrrmc-ts coincide: the first drawn is wider, so both show.
            width = REACH_WIDTHS.get(method, 1.4)
            (line,) = ax_s.plot(t, ts["stability"][shown], lw=width, label=f"{method} S")
            colour = line.get_color()
            ax_s.plot(t, ts["physics_stability"][shown], ":", color=colour, lw=1)
            ax_f.plot(t, ts["min_edge_load_n"][shown], color=colour, lw=width, label=method)
            if result.summary["tipped"]:
                tip = result.summary["tip_time_s"]
                ax_s.axvline(
                    tip, color=colour, lw=0.8, ls="-.", label=f"{method} tipped {tip:.1f} s"
                )
        ax_s.axhline(1.0, color="tab:red", ls="--", lw=0.8)
        ax_s.axhline(1.25, color="k", lw=0.6)
        ax_s.set_ylim(bottom=min(0.8, ax_s.get_ylim()[0]))
        ax_s.set_title(f"payload {payload:g} kg (solid S, dotted S_phys)", fontsize=9)
        ax_f.set_xlabel("t (s)")
        ax_f.set_ylim(bottom=-1.0)
        if col == 0:
            ax_s.set_ylabel("stability margin")
            ax_f.set_ylabel("min edge load (N)")
    fig.tight_layout()
    for ax_s in axes[0]:
        place_legend(ax_s, fontsize=7)
    fig.savefig(FIGURES / "physics_sideways_runs.png", dpi=110)
    plt.close(fig)


def ellipse_run(plant: MujocoPlant, method: str = "clrrmc-ts"):
    """The default ellipse (40 s, dt 0.02 s, 3 cm start offset) on a physics plant."""
    robot = plant.robot
    trajectory = Ellipse()
    q0 = offset_configuration(robot, start_configuration(robot, trajectory), DEFAULT_INITIAL_OFFSET)
    return simulate(robot, trajectory, method, plant=plant, q0=q0, dt=DT)


def tracking_reasons() -> str:
    """Ellipse tracking on the kinematic plant and on MuJoCo, with one cause removed at a time."""
    robot = Robot().with_payload(3.0)
    strong = Robot(payload=3.0, wheel_torque_limit=1e3, joint_torque_limits=(1e4, 1e4))
    kinematic = simulate(robot, Ellipse(), "clrrmc-ts", dt=DT)
    held = simulate(robot, Ellipse(), "clrrmc-ts", dt=DT, integrator="euler")
    cases = [
        ("MuJoCo, default robot and floor", MujocoPlant(robot)),
        ("MuJoCo, friction 2 (more grip)", MujocoPlant(robot, friction=2.0)),
        ("MuJoCo, motors 500x stronger (no saturation)", MujocoPlant(strong)),
        (
            "MuJoCo, servo time constant 5 ms (less lag)",
            MujocoPlant(robot, servo_time_constant=0.005),
        ),
        ("MuJoCo, all three", MujocoPlant(strong, friction=2.0, servo_time_constant=0.005)),
    ]
    rows = [
        [
            "kinematic plant (RK4)",
            f"{1000 * kinematic.summary['rms_position_error_m']:.2f}",
            f"{1000 * kinematic.summary['final_position_error_m']:.2f}",
            "-",
            "-",
        ],
        [
            "kinematic plant (Euler: command held over dt, as on MuJoCo)",
            f"{1000 * held.summary['rms_position_error_m']:.2f}",
            f"{1000 * held.summary['final_position_error_m']:.2f}",
            "-",
            "-",
        ],
    ]
    results = {}
    for label, plant in cases:
        result = ellipse_run(plant)
        results[label] = result
        ts = result.timeseries
        lag = np.sqrt(np.mean((ts["v_measured"] - ts["v"]) ** 2))
        rows.append(
            [
                label,
                f"{1000 * result.summary['rms_position_error_m']:.2f}",
                f"{1000 * ts['position_error_m'][-1]:.2f}",
                f"{1000 * result.summary['max_wheel_slip_m_s']:.1f}",
                f"{1000 * lag:.1f}",
            ]
        )
    fig, ax = plt.subplots(figsize=(7.5, 4))
    floor = 1e-4  # the kinematic plant converges to 1e-12 m: floored, said in its label
    ax.semilogy(
        kinematic.timeseries["t"],
        np.maximum(kinematic.timeseries["position_error_m"], floor),
        "k",
        label=f"kinematic plant (floored at {1000 * floor:g} mm)",
    )
    # Wide to thin: runs that coincide (the default and stronger motors) stay visible.
    for width, (label, result) in zip(np.linspace(2.8, 0.9, len(results)), results.items()):
        ax.semilogy(
            result.timeseries["t"], result.timeseries["position_error_m"], lw=width, label=label
        )
    ax.set_xlabel("t (s)")
    ax.set_ylabel("end-effector position error (m)")
    ax.set_ylim(0.5 * floor, 0.1)
    ax.set_title("clrrmc-ts on the ellipse, payload 3 kg, dt 0.02 s", fontsize=10)
    fig.tight_layout()
    place_legend(ax, fontsize=7)
    fig.savefig(FIGURES / "physics_tracking.png", dpi=110)
    plt.close(fig)
    header = [
        "plant",
        "RMS error (mm)",
        "final error (mm)",
        "max wheel slip (mm/s)",
        "RMS v lag (mm/s)",
    ]
    return _table(header, rows)


def settings_study() -> str:
    """Engine timestep x contact stiffness: tipping agreement, tracking, run speed."""
    rows = []
    robot = Robot().with_payload(3.0)
    for timestep, contact in [
        (0.001, 0.005),
        (0.002, 0.005),
        (0.002, 0.01),
        (0.002, 0.02),
        (0.005, 0.01),
        (0.005, 0.02),
        (0.01, 0.02),
    ]:
        engine = {"timestep": timestep, "contact_time_constant": contact}
        s_tip = [tipping_payload(d, **engine)[1] for d in (0.0, 0.25 * math.pi, 0.5 * math.pi)]
        walls, result = [], None
        for _ in range(3):
            start = time.perf_counter()
            result = ellipse_run(MujocoPlant(robot, **engine))
            walls.append(time.perf_counter() - start)
        rows.append(
            [
                f"{1000 * timestep:g}",
                f"{1000 * contact:g}",
                *(f"{s - 1:+.4f}" for s in s_tip),
                f"{1000 * result.summary['rms_position_error_m']:.2f}",
                f"{result.summary['min_physics_stability']:.3f}",
                f"{result.summary['min_stability']:.3f}",
                f"{1000 * result.summary['max_wheel_slip_m_s']:.1f}",
                f"{40.0 / statistics.median(walls):.0f}",
            ]
        )
    header = [
        "timestep (ms)",
        "contact time constant (ms)",
        "S_tip - 1 forward",
        "front-left",
        "left",
        "ellipse RMS (mm)",
        "min S_phys",
        "min S",
        "max slip (mm/s)",
        "x real time",
    ]
    return _table(header, rows)


def speed(repeats: int = 7) -> str:
    """Simulated seconds per wall second: 40 s ellipse, dt 0.02 s, clrrmc-ts commands."""
    robot = Robot().with_payload(3.0)
    walls, engine_share = [], []
    for _ in range(repeats):
        plant = MujocoPlant(robot)
        start = time.perf_counter()
        ellipse_run(plant)
        walls.append(time.perf_counter() - start)
        probe = MujocoPlant(robot)
        probe.reset(np.array([0.0, 0.0, 0.0, -0.3, 0.6]), DT)
        tick = time.perf_counter()
        import mujoco

        mujoco.mj_step(probe.model, probe.data, 20000)  # the 40 s of engine steps alone
        engine_share.append(time.perf_counter() - tick)
    kinematic = []
    for _ in range(repeats):
        start = time.perf_counter()
        simulate(robot, Ellipse(), "clrrmc-ts", dt=DT)
        kinematic.append(time.perf_counter() - start)
    wall = statistics.median(walls)
    return (
        f"MuJoCo plant: {wall:.3f} s wall for 40 s simulated = {40.0 / wall:.0f}x real time "
        f"(median of {repeats}; min {min(walls):.3f} s, max {max(walls):.3f} s); "
        f"engine steps alone {statistics.median(engine_share):.3f} s; "
        f"kinematic plant (RK4) {statistics.median(kinematic):.3f} s"
    )


def animation(runs: dict) -> str:
    """GIF of the 4 kg clrrmc-ts sideways reach, the run that tips."""
    from ddwmmr.reports.physics_plots import save_physics_animation

    result = runs[4.0, "clrrmc-ts"]
    plant = MujocoPlant(result.robot)
    points = [s.point for s in plant.supports]
    path = save_physics_animation(result, points, plant.weight_n, FIGURES / "physics_tipping.gif")
    return f"wrote {path.relative_to(ROOT)}"


def render_snapshot() -> str:
    """MuJoCo's own offscreen render of the model (needs EGL; skipped where it fails)."""
    try:
        import mujoco

        plant = MujocoPlant(Robot().with_payload(3.0))
        plant.reset(np.array([0.0, 0.0, 0.0, 1.0, 0.5]), DT)
        renderer = mujoco.Renderer(plant.model, 360, 480)
        camera = mujoco.MjvCamera()
        camera.lookat[:] = (0.15, 0.25, 0.2)
        camera.distance, camera.azimuth, camera.elevation = 1.6, -130.0, -30.0
        renderer.update_scene(plant.data, camera)
        image = renderer.render()
        renderer.close()
    except Exception as exc:  # no OpenGL context here: the renderer is optional
        return f"offscreen render unavailable ({type(exc).__name__}: {exc})"
    fig, ax = plt.subplots(figsize=(4.8, 3.6))
    ax.imshow(image)
    ax.set_axis_off()
    fig.tight_layout(pad=0)
    fig.savefig(FIGURES / "physics_model.png", dpi=100)
    plt.close(fig)
    return f"rendered with MUJOCO_GL={os.environ.get('MUJOCO_GL')}"


def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def main(which: list[str]) -> None:
    FIGURES.mkdir(parents=True, exist_ok=True)
    jobs = {
        "render": render_snapshot,
        "static": static_agreement,
        "map": tipping_map,
        "slow": slow_sideways_reach,
        "tracking": tracking_reasons,
        "settings": settings_study,
        "speed": speed,
    }
    known = [*jobs, "runs"]
    unknown = [name for name in which if name not in known and name not in ("-h", "--help")]
    if unknown or not set(which).isdisjoint({"-h", "--help"}):
        print(f"usage: physics_figures.py [{' '.join(known)}] (none: all)", file=sys.stderr)
        raise SystemExit(0 if not unknown else 2)
    selected = which or known
    for name in selected:
        if name == "runs":
            table, runs = sideways_reach_runs()
            print(f"## sideways reach runs\n{table}\n{animation(runs)}\n", flush=True)
            continue
        print(f"## {name}\n{jobs[name]()}\n", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
