"""Regenerate the theory figures of docs/theory.md into docs/figures/theory_*.png.

Run from anywhere: ``MPLBACKEND=Agg python docs/make_figures.py`` (or ``make docs``).
Every number drawn comes from the library (kinematics, stability, python-control loops,
simulations); the script writes only ``theory_*.png`` files and prints their names.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ddwmmr import Ellipse, Rectangle, Robot, simulate
from ddwmmr.model.kinematics import AUX_ROWS
from ddwmmr.resolution import kernels
from ddwmmr.sim.error_dynamics import closed_form_step, error_response, step_response

FIGURES = Path(__file__).resolve().parent / "figures"
GRID = np.linspace(-math.pi, math.pi, 241)  # joint-angle grid (rad)


def _save(fig: Figure, name: str) -> Path:
    path = FIGURES / f"theory_{name}.png"
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


def _angle_axes(ax: Axes) -> None:
    ticks = [-math.pi, -math.pi / 2, 0.0, math.pi / 2, math.pi]
    labels = ["-π", "-π/2", "0", "π/2", "π"]
    ax.set_xticks(ticks, labels)
    ax.set_yticks(ticks, labels)
    ax.set_xlabel("θ2 (rad)")
    ax.set_ylabel("θ1 (rad)")


def singularity_map(robot: Robot) -> Path:
    """|det J_aug| = L1 |cos θ1| and the SVD's smallest singular value of the 4x5 J."""
    th1, th2 = np.meshgrid(GRID, GRID, indexing="ij")
    # Each pose's 4x5 J once, its shoulder row appended: the 5x5 J_aug. The SVDs and
    # determinants run over the stack (numpy calls LAPACK per matrix, as one by one).
    jacobians = np.array(
        [
            [robot.jacobian([0.0, 0.0, 0.4, th1[i, j], th2[i, j]]) for j in range(len(GRID))]
            for i in range(len(GRID))
        ]
    )
    shoulder = np.broadcast_to(AUX_ROWS["shoulder"], (*th1.shape, 1, 5))
    sigma = np.linalg.svd(jacobians, compute_uv=False)[..., -1]
    det = np.abs(np.linalg.det(np.concatenate([jacobians, shoulder], axis=-2)))
    fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2), constrained_layout=True)
    panels = (
        (det, "|det J_aug| (m), both aux rows"),
        (sigma, "smallest singular value of the 4x5 J"),
    )
    # Where the damping starts (kernels docstring): sigma_min(M) = sigma0 for ats, the
    # pseudoinverse's measure 2 sqrt(2) L1 |cos th1| / trace(A A^T) = sigma0 for pi.
    ats_measure = np.vectorize(lambda c: kernels.smallest_singular_value_m(robot.L1, c))
    pi_measure = np.empty_like(th1)
    for i in range(len(GRID)):
        for j in range(len(GRID)):
            a = jacobians[i, j, :3] @ _input_matrix(0.4)
            pi_measure[i, j] = (
                2 * math.sqrt(2) * robot.L1 * abs(math.cos(th1[i, j])) / np.trace(a @ a.T)
            )
    for ax, (values, title) in zip(axes, panels):
        image = ax.pcolormesh(th2, th1, values, shading="auto", cmap="viridis")
        sigma0 = kernels.SINGULARITY_THRESHOLD
        ax.contour(th2, th1, ats_measure(np.cos(th1)), levels=[sigma0], colors="w", linewidths=1)
        ax.contour(th2, th1, pi_measure, levels=[sigma0], colors="w", linewidths=1, linestyles="--")
        fig.colorbar(image, ax=ax)
        ax.set_title(title)
        _angle_axes(ax)
    fig.suptitle(
        "Singular where cos θ1 = 0; damping bands: white solid ats (|cos θ1| < 0.15), dashed pi"
    )
    return _save(fig, "singularity")


def _input_matrix(phi: float) -> np.ndarray:
    from ddwmmr.model.kinematics import input_matrix

    return input_matrix(phi)


def damping_gain(robot: Robot) -> Path:
    """Largest |u| / |Xdot| of the ats and pi kernels across the singularity: the damping
    of the library against the earlier |cos θ1| < 0.05 band (re-implemented here)."""
    cos_values = np.geomspace(1e-4, 1.0, 400)
    th2 = 0.6
    curves: dict[str, list[float]] = {"ats (shoulder)": [], "pi": [], "ats, earlier band": []}
    for c in cos_values:
        q = [0.0, 0.0, 0.3, math.acos(c), th2]
        curves["ats (shoulder)"].append(
            _gain(lambda x, q=q: kernels.ats(robot.L1, robot.L2, *q[2:], *x)[0])
        )
        curves["pi"].append(
            _gain(lambda x, q=q: kernels.pseudoinverse(robot.L1, robot.L2, *q[2:], *x)[0])
        )
        curves["ats, earlier band"].append(_gain(lambda x, q=q: _earlier_ats(robot, q, x)))
    fig, ax = plt.subplots(figsize=(8, 4.6), constrained_layout=True)
    styles = {"ats (shoulder)": "C0-", "pi": "C1-", "ats, earlier band": "C3--"}
    for label, values in curves.items():
        ax.loglog(cos_values, values, styles[label], label=label, lw=1.4)
    ats_bound = kernels.ats_gain(robot.L1, robot.L2)
    ax.axhline(ats_bound, color="C0", ls=":", lw=1, label=f"documented ats bound {ats_bound:.1f}")
    ax.axhline(
        kernels.pi_gain(),
        color="C1",
        ls=":",
        lw=1,
        label=f"documented pi bound {kernels.pi_gain():.0f}",
    )
    ax.axvline(0.05, color="0.5", ls="-.", lw=0.8)
    ax.annotate("earlier band edge |cos θ1| = 0.05", (0.05, 1.2), fontsize=8, color="0.3")
    ax.set_xlabel("|cos θ1|  (θ2 = 0.6 rad, φ = 0.3 rad)")
    ax.set_ylabel("largest |u| / |Xdot|")
    ax.set_title("command gain near the singularity: continuous and bounded")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    return _save(fig, "damping")


def _gain(kernel) -> float:
    """Operator 2-norm of the (linear) kernel Xdot -> u, from its columns."""
    matrix = np.column_stack([kernel(e) for e in np.eye(3)])
    return float(np.linalg.svd(matrix, compute_uv=False)[0])


def _earlier_ats(robot: Robot, q, xdot) -> np.ndarray:
    """The earlier ats (shoulder) kernel: damping on |cos θ1| < 0.05 with lambda = 0.05."""
    c = abs(math.cos(q[3]))
    lam2 = 0.0 if c >= 0.05 else 0.05**2 * (1 - (c / 0.05) ** 2)
    a = robot.jacobian(q)[:3] @ _input_matrix(q[2])
    columns = np.array([[1, 0], [0, 1], [0, 0], [0, -1]], dtype=float)
    known = np.array([0, 0, 0, xdot[2]])
    m = (a @ columns)[:2]
    r = (np.asarray(xdot) - a @ known)[:2]
    z = np.linalg.solve(m.T @ m + lam2 * np.eye(2), m.T @ r)
    return columns @ z + known


def step_responses(robot: Robot) -> Path:
    """python-control step responses K/(s+K) and the simulated clrrmc-ts error decay."""
    taus = (0.25, 0.5, 1.0, 2.0)
    fig, (left, right) = plt.subplots(1, 2, figsize=(10.5, 4.0), constrained_layout=True)
    times = np.linspace(0.0, 6.0, 601)
    for tau in taus:
        (line,) = left.plot(times, step_response(tau, times), label=f"τ = {tau:g} s")
        left.plot(times, closed_form_step(tau, times), "k:", linewidth=0.8)
        left.plot([tau], [1 - math.exp(-1)], "o", color=line.get_color())
        result = simulate(robot, Ellipse(), "clrrmc-ts", tau=tau, duration=4.0 * tau)
        ts = result.timeseries
        ratio = ts["position_error_m"] / ts["position_error_m"][0]
        right.semilogy(ts["t"], ratio, color=line.get_color(), label=f"simulated, τ = {tau:g} s")
        right.semilogy(ts["t"], error_response(tau, ts["t"]), "k:", linewidth=0.8)
    left.axhline(1 - math.exp(-1), color="0.6", linewidth=0.6)
    left.set(xlabel="t (s)", ylabel="y(t)", title="Step response of K/(s+K), K = 1/τ")
    left.legend(title="python-control (dotted: 1 - exp(-t/τ))", fontsize=8)
    right.set(
        xlabel="t (s)",
        ylabel="|e(t)| / |e(0)|",
        title="clrrmc-ts, ellipse: end-effector position error",
    )
    right.legend(title="dotted: exp(-t/τ)", fontsize=8)
    return _save(fig, "step_responses")


def stability_maps(robot: Robot) -> Path:
    """Tip-over stability S over (θ1, θ2) for the 1.25 kg and 3.0 kg payloads."""
    th1, th2 = np.meshgrid(GRID, GRID, indexing="ij")
    fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2), constrained_layout=True)
    for ax, payload in zip(axes, (1.25, 3.0)):
        loaded = robot.with_payload(payload)
        values = np.vectorize(lambda a, b, r=loaded: r.stability([0, 0, 0, a, b])[2])(th1, th2)
        image = ax.pcolormesh(th2, th1, values, shading="auto", cmap="RdYlGn", vmin=0.8, vmax=3)
        contours = ax.contour(th2, th1, values, levels=[1.0, 1.25, 1.6], colors="k")
        ax.clabel(contours, fmt="S=%.2f", fontsize=7)
        fig.colorbar(image, ax=ax, label="S (capped display 0.8..3)")
        ax.set_title(f"payload {payload:g} kg: min S = {values.min():.3f}")
        _angle_axes(ax)
    fig.suptitle("Static tip-over stability S = min(S_lon, S_lat); S <= 1 tips")
    return _save(fig, "stability")


def _draw_robot(ax: Axes, robot: Robot, q, color: str = "0.3", labels: bool = False) -> None:
    x, y, phi, th1, _ = (float(v) for v in q)
    c, s = math.cos(phi), math.sin(phi)
    rotation = np.array([[c, -s], [s, c]])
    hl, hw = robot.base_length / 2, robot.base_width / 2
    corners = np.array([[hl, hw], [-hl, hw], [-hl, -hw], [hl, -hw], [hl, hw]])
    base = corners @ rotation.T + [x, y]
    ax.plot(base[:, 0], base[:, 1], color=color, linewidth=1.2)
    for side in (-1, 1):  # wheels on the axle through (x, y)
        centre = np.array([x, y]) + rotation @ [0.0, side * robot.track_width / 2]
        along = rotation @ [robot.wheel_radius, 0.0]
        tread = np.array([centre - along, centre + along])
        ax.plot(tread[:, 0], tread[:, 1], color="k", linewidth=4, solid_capstyle="butt")
    elbow = np.array([x + robot.L1 * math.cos(phi + th1), y + robot.L1 * math.sin(phi + th1)])
    tip = robot.fk(q)[:2]
    arm = np.array([[x, y], elbow, tip])
    ax.plot(arm[:, 0], arm[:, 1], "-o", color="tab:blue", markersize=3, linewidth=2)
    if not labels:
        return
    ax.annotate("", xy=(x + 0.45 * c, y + 0.45 * s), xytext=(x, y), arrowprops={"arrowstyle": "->"})
    ax.text(x + 0.47 * c, y + 0.47 * s, "heading φ", fontsize=8)
    # Left of the first link, inside the footprint, clear of the link and the base edge.
    ax.text(*(0.5 * (np.array([x, y]) + elbow) - [0.05, 0.03]), "L1, θ1", fontsize=8, ha="right")
    ax.text(*(0.5 * (elbow + tip) + [0.02, 0.0]), "L2, θ2", fontsize=8)
    ax.text(*(tip + np.array([0.02, 0.02])), "E (xE, yE, φE)", fontsize=8)
    ax.text(x - 0.1, y - 0.08, "(x, y)", fontsize=8)
    reach = plt.Circle((x, y), robot.reach, fill=False, linestyle="--", color="0.6")
    ax.add_patch(reach)


def robot_and_workspace(robot: Robot) -> Path:
    """Robot sketch with its variables, and the default trajectories tracked by clrrmc-ts."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.6), constrained_layout=True)
    _draw_robot(left, robot, [0.0, 0.0, 0.35, 0.6, 0.7], labels=True)
    left.set(aspect="equal", xlim=(-0.8, 0.9), ylim=(-0.7, 0.9), xlabel="x (m)", ylabel="y (m)")
    left.set_title(f"model: reach L1 + L2 = {robot.reach:.2f} m (dashed)")
    for trajectory, style in ((Ellipse(), "tab:green"), (Rectangle(), "tab:purple")):
        result = simulate(robot, trajectory, "clrrmc-ts")
        ts = result.timeseries
        right.plot(ts["xE_d"], ts["yE_d"], color=style, label=f"{trajectory.name}: desired")
        right.plot(ts["x"], ts["y"], "--", color=style, linewidth=0.9, label="base path")
        if trajectory.name == "ellipse":
            q = result.configurations()
            for k in range(0, len(q), len(q) // 8):
                _draw_robot(right, robot, q[k])
    right.set(aspect="equal", xlabel="x (m)", ylabel="y (m)")
    right.set_title("default trajectories (2.0 m x 1.5 m, T = 40 s), clrrmc-ts")
    right.legend(fontsize=7, loc="center")
    return _save(fig, "robot")


def method_drift(robot: Robot) -> Path:
    """θ1 over one ellipse period: which methods stay away from cos θ1 = 0."""
    cases = (
        ("pi", {}),
        ("ap", {"K3": 0.66}),
        ("ap", {"K3": 0.0}),
        ("ats", {"aux": "sum"}),
        ("ats", {"aux": "shoulder"}),
        ("clrrmc-ts", {}),
    )
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), sharex=True, constrained_layout=True)
    for method, options in cases:
        result = simulate(robot, Ellipse(), method, **options)
        ts = result.timeseries
        label = method + "".join(
            f" {k}={v:g}" if k != "aux" else f" {v}" for k, v in options.items()
        )
        top.plot(ts["t"], ts["th1"], label=label)
        bottom.semilogy(ts["t"], np.maximum(ts["position_error_m"], 1e-10), label=label)
    for level in (-math.pi / 2, math.pi / 2):
        top.axhline(level, color="k", linestyle=":", linewidth=0.8)
    top.set(ylabel="θ1 (rad)", title="ellipse, default robot: θ1 (dotted: cos θ1 = 0)")
    bottom.set(xlabel="t (s)", ylabel="position error (m)")
    top.legend(fontsize=7, ncol=3)
    return _save(fig, "methods")


def main() -> int:
    """Write every figure and print its path."""
    FIGURES.mkdir(parents=True, exist_ok=True)
    robot = Robot()
    for make in (singularity_map, step_responses, stability_maps, robot_and_workspace):
        print(make(robot))
    print(method_drift(robot))
    print(damping_gain(robot))
    return 0


if __name__ == "__main__":
    sys.exit(main())
