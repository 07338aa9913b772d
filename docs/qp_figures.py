"""Figures and numbers of docs/qp.md (the QP task-priority controller).

Run from the repository root::

    MPLBACKEND=Agg .venv/bin/python docs/qp_figures.py

Writes ``docs/figures/qp_*.png`` and prints the tables quoted in docs/qp.md (markdown).
Every run uses the 3 kg payload (docs/theory.md, "Tip-over stability": a full sideways
stretch is then exactly S = 1).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker
import numpy as np
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Polygon

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.plants.kinematic import KinematicPlant
from ddwmmr.qp.controller import QPController
from ddwmmr.qp.limits import footprint_clearances, load_obstacles
from ddwmmr.qp.naive import NaiveQPController
from ddwmmr.qp.tasks import PostureTask
from ddwmmr.reports.legends import legend_beside

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
ROBOT = Robot().with_payload(3.0)
FLOOR = 1.25


def wide_to_thin(count: int) -> list[float]:
    """Line widths from wide to thin: runs that coincide (ats and clrrmc-ts, qp's two
    modes) stay visible, each a thinner stroke on the previous one."""
    return list(np.linspace(3.6, 1.0, count))


def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def _row(label: str, summary: dict, steps: np.ndarray) -> list[str]:
    return [
        label,
        f"{summary['min_stability']:.3f}",
        str(int(np.sum(steps < FLOOR))),
        str(summary.get("qp_fallbacks", "-")),
        f"{1000 * summary['rms_position_error_m']:.2f}",
        f"{summary['mean_manipulability']:.3f}",
    ]


HEADER = ["method", "min S", "steps S<1.25", "fallbacks", "RMS pos. error (mm)", "mean eta"]


def sideways_reach() -> str:
    """S(t) and tracking error of every method on the sideways reach."""
    trajectory = load_trajectory("sideways_reach")
    q0 = ROBOT.base_for_end_effector(trajectory.pose(0.0), 1.0, 1.6)
    runs = [
        ("pi", "pi", {}),
        ("ap", "ap", {}),
        ("ats", "ats", {}),
        ("clrrmc-ts", "clrrmc-ts", {}),
        ("clrrmc-cs", "clrrmc-cs", {}),
        ("qp (weighted)", "qp", {}),
        ("qp (hierarchical)", "qp", {"mode": "hierarchical"}),
    ]
    fig, (ax_s, ax_e) = plt.subplots(2, 1, figsize=(9.5, 6.5), sharex=True)
    rows = []
    for width, (label, method, options) in zip(wide_to_thin(len(runs)), runs):
        result = simulate(ROBOT, trajectory, method, q0=q0, **options)
        ts = result.timeseries
        rows.append(_row(label, result.summary, ts["stability"]))
        style = "-" if method == "qp" else "--"
        ax_s.plot(ts["t"], ts["stability"], style, lw=width, label=label)
        error = np.maximum(ts["position_error_m"], 1e-7)
        ax_e.semilogy(ts["t"], error, style, lw=width, label=label)
    ax_s.axhline(FLOOR, color="k", lw=0.8)
    ax_s.axhline(1.0, color="r", lw=0.8)
    ax_s.set_ylabel("stability margin S")
    ax_s.set_title("Sideways reach, 3 kg payload: floor S_min = 1.25 (black), tipping (red)")
    ax_e.set_ylabel("position error (m)")
    ax_e.set_xlabel("t (s)")
    legend_beside(ax_s, fontsize=8)
    fig.tight_layout()
    fig.savefig(FIGURES / "qp_sideways_reach.png", dpi=110)
    plt.close(fig)
    return _table(HEADER, rows)


def ellipse_manipulability() -> str:
    """eta(t) on the default ellipse: clrrmc-ts against qp at three weights."""
    trajectory = load_trajectory("ellipse")
    runs = [("clrrmc-ts", "clrrmc-ts", {})] + [
        (f"qp, weight {w:g}", "qp", {"manipulability_weight": w}) for w in (0.1, 0.5, 1.0)
    ]
    runs.append(
        ("qp hierarchical, weight 1", "qp", {"mode": "hierarchical", "manipulability_weight": 1.0})
    )
    fig, (ax_m, ax_e) = plt.subplots(2, 1, figsize=(9.5, 6.5), sharex=True)
    rows = []
    for width, (label, method, options) in zip(wide_to_thin(len(runs)), runs):
        result = simulate(ROBOT, trajectory, method, **options)
        ts = result.timeseries
        rows.append(_row(label, result.summary, ts["stability"]))
        ax_m.plot(ts["t"], ts["manipulability"], lw=width, label=label)
        ax_e.semilogy(ts["t"], np.maximum(ts["position_error_m"], 1e-7), lw=width, label=label)
    ax_m.set_ylabel("manipulability eta = |sin th2|")
    legend_beside(ax_m, fontsize=8)
    ax_m.set_title("Default ellipse, 3 kg payload, 3 cm initial offset")
    ax_e.set_ylabel("position error (m)")
    ax_e.set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(FIGURES / "qp_ellipse_manipulability.png", dpi=110)
    plt.close(fig)
    return _table(HEADER, rows)


def _footprint(ax, x, y, phi, color) -> None:
    hl, hw = 0.5 * ROBOT.base_length, 0.5 * ROBOT.base_width
    c, s = math.cos(phi), math.sin(phi)
    corners = [(hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw)]
    points = [(x + c * a - s * b, y + s * a + c * b) for a, b in corners]
    ax.add_patch(Polygon(points, closed=True, fill=False, ec=color, lw=0.8))


def obstacle() -> str:
    """Base paths past the post on the ellipse: clrrmc-ts drives through, qp around."""
    trajectory = load_trajectory("ellipse")
    circles = load_obstacles(ROOT / "trajectories" / "obstacles" / "ellipse_post.toml")
    free = simulate(ROBOT, trajectory, "clrrmc-ts")
    rows, results = [], {}
    for mode in ("weighted", "hierarchical"):
        results[mode] = simulate(ROBOT, trajectory, "qp", obstacles=circles, mode=mode)
    fig, ax = plt.subplots(figsize=(8, 6.5))
    ts = free.timeseries
    # Over qp's end-effector path, which lies on it.
    ax.plot(ts["xE_d"], ts["yE_d"], "k:", lw=0.9, label="desired end effector", zorder=3)
    ax.plot(ts["x"], ts["y"], "C1--", label="clrrmc-ts base")
    qp = results["weighted"].timeseries
    ax.plot(qp["x"], qp["y"], "C0-", label="qp base")
    ax.plot(qp["xE"], qp["yE"], "C2-", lw=0.8, label="qp end effector")
    for k in range(350, 800, 25):  # around the post
        _footprint(ax, ts["x"][k], ts["y"][k], ts["phi"][k], "C1")
        _footprint(ax, qp["x"][k], qp["y"][k], qp["phi"][k], "C0")
    for circle in circles:
        ax.add_patch(CirclePatch((circle.x, circle.y), circle.radius, color="r", alpha=0.5))
    ax.set_aspect("equal")  # limits from everything drawn (matplotlib's autoscale)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(fontsize=8, loc="center")
    ax.set_title("Post on the base's path (footprints every 0.5 s near it)")
    fig.tight_layout()
    fig.savefig(FIGURES / "qp_obstacle.png", dpi=110)
    plt.close(fig)
    header = ["method", "min clearance (m)", "RMS pos. error (mm)", "max pos. error (mm)"]
    for label, result in [("clrrmc-ts (no limit)", free)] + [
        (f"qp ({mode})", r) for mode, r in results.items()
    ]:
        summary = result.summary
        clearance = summary.get("min_obstacle_clearance_m")
        if clearance is None:
            t = result.timeseries
            clearance = float(
                footprint_clearances(0.225, 0.175, t["x"], t["y"], t["phi"], circles).min()
            )
        rows.append(
            [
                label,
                f"{clearance:.3f}",
                f"{1000 * summary['rms_position_error_m']:.1f}",
                f"{1000 * summary['max_position_error_m']:.1f}",
            ]
        )
    return _table(header, rows)


def modes() -> str:
    """Weighted against hierarchical when a secondary task fights tracking (ellipse).

    The ap potential V = th1^2 + 0.25 th2^2 + 0.66 phi^2 added as a user task: its th2
    row can only be met by moving the end effector, so its weight sets how much tracking
    the weighted mode gives up; the hierarchical mode gives up none.
    """
    trajectory = load_trajectory("ellipse")
    weights = (0.01, 0.1, 1.0, 10.0, 100.0)
    fig, (ax_e, ax_m) = plt.subplots(1, 2, figsize=(9, 3.8))
    rows = []
    for mode, marker in (("weighted", "o-"), ("hierarchical", "s--")):
        errors, etas = [], []
        for weight in weights:
            potential = PostureTask(weight, K1=1.0, K2=0.25, K3=0.66)
            summary = simulate(ROBOT, trajectory, "qp", mode=mode, tasks=[potential]).summary
            errors.append(1000 * summary["rms_position_error_m"])
            etas.append(summary["mean_manipulability"])
            rows.append([mode, f"{weight:g}", f"{errors[-1]:.2f}", f"{etas[-1]:.3f}"])
        ax_e.loglog(weights, errors, marker, label=mode)
        ax_m.semilogx(weights, etas, marker, label=mode)
    ax_e.set_xlabel("weight of the ap potential task")
    ax_e.set_ylabel("RMS position error (mm)")
    ax_m.set_xlabel("weight of the ap potential task")
    ax_m.set_ylabel("mean eta")
    ax_e.legend()
    fig.tight_layout()
    fig.savefig(FIGURES / "qp_modes.png", dpi=110)
    plt.close(fig)
    return _table(["mode", "potential weight", "RMS pos. error (mm)", "mean eta"], rows)


SOLVERS = [
    ("daqp, direct (default)", "qp", {}),
    ("daqp, direct, warm start", "qp", {"warm_start": True}),
    ("daqp via qpsolvers", "qp", {"solver": "qpsolvers-daqp"}),
    ("quadprog", "qp", {"solver": "quadprog"}),
    ("proxqp", "qp", {"solver": "proxqp"}),
    ("clarabel", "qp", {"solver": "clarabel"}),
    ("osqp (warm start)", "qp", {"solver": "osqp"}),
    ("naive: fresh arrays + OSQP setup", NaiveQPController(ROBOT), {}),
    ("daqp, hierarchical (2 QPs)", "qp", {"mode": "hierarchical"}),
]


def solvers(repeats: int = 3) -> str:
    """Median controller step (first call of each step, as simulate records it)."""
    trajectory = load_trajectory("ellipse")
    rows, labels, medians = [], [], []
    for label, method, options in SOLVERS:
        samples = []
        for _ in range(repeats):
            result = simulate(ROBOT, trajectory, method, duration=10.0, **options)
            samples.append(result.timeseries["step_us"][:-1])
        steps = np.concatenate(samples)
        median = float(np.median(steps))
        labels.append(label)
        medians.append(median)
        rows.append(
            [
                label,
                f"{median:.1f}",
                f"{np.percentile(steps, 90):.1f}",
                f"{1000 * result.summary['rms_position_error_m']:.3f}",
            ]
        )
    solvers_figure(labels, medians)
    header = ["backend", "median step (us)", "p90 (us)", "RMS pos. error (mm)"]
    return _table(header, rows)


def solvers_figure(labels: list[str], medians: list[float]) -> None:
    """``qp_solvers.png``: each backend's median step (us) against the qp's targets
    (docs/api.md, "Benchmark")."""
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.barh(labels[::-1], medians[::-1], color="C0")
    ax.axvline(20.0, color="C1", lw=0.8)
    ax.axvline(60.0, color="r", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlim(1.0, 2.0 * max(medians))
    ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("median step (us), log scale; orange: 20 us target, red: 60 us budget")
    fig.tight_layout()
    fig.savefig(FIGURES / "qp_solvers.png", dpi=110)
    plt.close(fig)


def waypoints(scenarios: int = 10, seed: int = 0) -> str:
    """Far waypoints (velocity_d = 0, position only, max_speed = 1 m/s), as the scenario
    benchmark drives qp; 5 uniform waypoints in 8 m x 8 m, 0.01 m to reach, 60 s limit."""
    rng = np.random.default_rng(seed)
    plant = KinematicPlant(ROBOT, "euler")
    dt = 0.02
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
    done, times, min_s, peak = 0, [], math.inf, 0.0
    for index in range(scenarios):
        goals = rng.uniform(-4.0, 4.0, size=(5, 2))
        controller = QPController(ROBOT, track_orientation=False, max_speed=1.0, dt=dt)
        q = np.array([0.0, 0.0, 0.0, *ROBOT.home_pose])
        controller.reset(None, q)
        t, path, ok = 0.0, [q[:2].copy()], True
        for goal in goals:
            target = np.array([goal[0], goal[1], 0.0])
            while math.dist(ROBOT.fk(q)[:2], goal) > 0.01:
                if t > 60.0:
                    ok = False
                    break
                u = controller.command(t, q, target, np.zeros(3))
                peak = max(peak, *(abs(w) for w in ROBOT.wheel_speeds_from_u(u[0], u[1])))
                q = plant.integrate(t, q, dt, None, first_command=u)[0]
                min_s = min(min_s, ROBOT.stability(q)[2])
                t += dt
                path.append(q[:2].copy())
            if not ok:
                break
        done += ok
        times.append(t)
        if index < 3:
            path = np.array(path)
            ax.plot(path[:, 0], path[:, 1], lw=0.8, label=f"scenario {index}")
            ax.plot(goals[:, 0], goals[:, 1], "x", color=ax.lines[-1].get_color())
    ax.set_aspect("equal")
    ax.legend(fontsize=8)
    ax.set_title("qp driving to far waypoints (base paths)")
    fig.tight_layout()
    fig.savefig(FIGURES / "qp_waypoints.png", dpi=110)
    plt.close(fig)
    header = ["scenarios", "completed", "mean time (s)", "min S", "peak wheel speed (rad/s)"]
    row = [str(scenarios), str(done), f"{np.mean(times):.1f}", f"{min_s:.3f}", f"{peak:.1f}"]
    return _table(header, [row])


#: Sections whose figure shows wall-clock timings: they differ on every run, so `make docs`
#: (byte-identical figures) skips them; `--timings` (`make docs-timings`) draws them.
TIMED = {"Solvers"}


def main() -> None:
    """Make every figure and print every table (timed sections only with --timings)."""
    FIGURES.mkdir(parents=True, exist_ok=True)
    timings = "--timings" in sys.argv[1:]
    for name, make in [
        ("Sideways reach", sideways_reach),
        ("Ellipse manipulability", ellipse_manipulability),
        ("Obstacle", obstacle),
        ("Modes", modes),
        ("Waypoints", waypoints),
        ("Solvers", solvers),
    ]:
        if name in TIMED and not timings:
            continue
        start = time.perf_counter()
        table = make()
        print(f"\n### {name} ({time.perf_counter() - start:.1f} s)\n\n{table}")


if __name__ == "__main__":
    main()
