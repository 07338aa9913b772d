"""Figures and numbers of docs/mpc.md (run by hand: ~10 min on one core).

    python docs/mpc_figures.py [--quick]

* ``mpc_step_responses.png``: the python-control designs (CLRRMC error loops for tau, the
  thesis plant's velocity loop linear and force-limited, the LQR terminal law);
* ``mpc_rectangle.png``: position error on the default rectangle, mpc beside clrrmc-ts
  and qp (the corners);
* ``mpc_horizon.png``: the horizon study (tracking error and step time against the
  horizon on the rectangle; scenario time against the horizon on the thesis plant);
* ``mpc_physics_tipping.png``: scenario 7 on the MuJoCo plant, mpc with its static floor
  only and with the dynamic margin and the lagged arm (``--physics`` makes only this one).

Prints every number it plots (medians over the runs; the machine may be shared).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import control
import matplotlib.pyplot as plt
import numpy as np

from ddwmmr import Rectangle, Robot, simulate
from ddwmmr.behaviours.objective import default_pose
from ddwmmr.model import symbolic as sym
from ddwmmr.mpc import terminal
from ddwmmr.mpc.models import KinematicPrediction, ThesisPrediction
from ddwmmr.mpc.ocp import OCPConfig
from ddwmmr.plants.thesis import ThesisPlant
from ddwmmr.scenarios import RunConfig, generate, run_scenario
from ddwmmr.scenarios.protocol import (
    WaypointTask,
    _Tally,
    make_scenario_controller,
    make_scenario_plant,
)
from ddwmmr.sim.error_dynamics import saturated_velocity_step, step_response, velocity_loop
from ddwmmr.sim.loop import run_loop

FIGURES = Path(__file__).parent / "figures"


def step_responses() -> None:
    robot = Robot().with_payload(3.0)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    times = np.linspace(0.0, 3.0, 301)
    for tau in (0.2, 0.5, 1.0):
        axes[0].plot(times, step_response(tau, times), label=f"tau = {tau:g} s")
    axes[0].set(title="CLRRMC error loop K/(s+K), K = 1/tau", xlabel="t (s)", ylabel="pose / step")
    plant = ThesisPlant(robot)
    for k in (2.0, 5.0, 10.0):
        linear = control.step_response(velocity_loop(plant.mass, plant.c1, k), times)
        line = axes[1].plot(times, np.ravel(linear.outputs), "--", lw=1)[0]
        limited = saturated_velocity_step(plant.mass, plant.c1, k, 20.0, 1.0, times)
        axes[1].plot(times, limited, color=line.get_color(), label=f"k = {k:g} 1/s")
        print(
            f"velocity loop k={k:g}: linear 63 % at {1 / (1 + k):.3f} s, limited "
            f"63 % at {times[np.argmax(limited >= 0.632)]:.2f} s (1 m/s step)"
        )
    axes[1].set(
        title="thesis velocity loop, 1 m/s step\n(dashed linear, solid |F| <= 20 N)",
        xlabel="t (s)",
        ylabel="v (m/s)",
    )
    config = OCPConfig(
        intervals=10,
        control_interval=0.02,
        first_interval=0.05,
        horizon=1.0,
        track_orientation=False,
    )
    for name, model in (
        ("kinematic", KinematicPrediction(robot)),
        ("thesis", ThesisPrediction(robot, sym.ThesisDynamics.from_robot(robot))),
    ):
        design = terminal.design(robot, model, config, default_pose(robot))
        closed = control.ss(
            design.A - design.B @ design.K,
            np.zeros((design.A.shape[0], 1)),
            np.eye(design.A.shape[0]),
            0,
            dt=True,
        )
        x0 = np.zeros(design.A.shape[0])
        x0[0] = 0.05
        response = control.initial_response(closed, np.arange(40), x0)
        h = float(config.interval_lengths()[-1])
        axes[2].plot(
            np.arange(40) * h,
            np.ravel(response.outputs[0]) * 1e3,
            "o-",
            ms=3,
            label=f"{name} model",
        )
        print(f"LQR terminal ({name}): |poles| {np.round(np.abs(design.poles), 3)}")
    axes[2].set(
        title="LQR terminal law: 5 cm end-effector offset", xlabel="t (s)", ylabel="error (mm)"
    )
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(FIGURES / "mpc_step_responses.png", dpi=120)


def rectangle() -> None:
    robot = Robot()
    trajectory = Rectangle()
    fig, ax = plt.subplots(figsize=(9, 3.6))
    for method in ("clrrmc-ts", "qp", "mpc"):
        integrator = "euler" if method == "mpc" else "rk4"
        result = simulate(robot, trajectory, method, integrator=integrator)
        ts, summary = result.timeseries, result.summary
        ax.semilogy(
            ts["t"],
            np.maximum(ts["position_error_m"], 1e-6) * 1e3,
            lw=1,
            label=f"{method}: RMS {1e3 * summary['rms_position_error_m']:.2f} mm",
        )
        corners = [np.max(ts["position_error_m"][np.abs(ts["t"] - c) < 2.0]) for c in (10, 20, 30)]
        print(
            f"rectangle {method} ({integrator}): RMS {1e3 * summary['rms_position_error_m']:.2f} "
            f"mm, max {1e3 * summary['max_position_error_m']:.1f} mm, corner peaks "
            f"{np.round(np.array(corners) * 1e3, 1)} mm, orientation RMS "
            f"{summary['rms_orientation_error_rad']:.3f} rad, median step "
            f"{summary['median_step_us']:.0f} us"
        )
    for corner in (10, 20, 30):
        ax.axvline(corner, color="grey", lw=0.5)
    ax.set(
        xlabel="t (s)",
        ylabel="position error (mm)",
        title="default rectangle (corners at 10, 20, 30 s)",
    )
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(FIGURES / "mpc_rectangle.png", dpi=120)


def scenario_time(options: dict, scenarios) -> tuple[float, float]:
    """Mean scenario time (s) and median step (ms) of mpc on the thesis plant (the
    scenario protocol, ``python -m ddwmmr.scenarios --controller mpc``)."""
    config = RunConfig(controller="mpc", plant="thesis", controller_options=tuple(options.items()))
    outcomes = [run_scenario(scenario, config) for scenario in scenarios]
    totals = [o.metrics["time_s"] for o in outcomes]
    steps = [o.median_step_us for o in outcomes]
    return float(np.mean(totals)), 1e-3 * float(np.median(steps))


def horizon_study(quick: bool) -> None:
    robot = Robot()
    trajectory = Rectangle()
    horizons = (0.2, 0.4, 0.7, 1.0, 1.5, 2.0, 3.0)
    rms, step = [], []
    for horizon in horizons:
        intervals = max(3, min(20, round(horizon / 0.1)))
        summary = simulate(
            robot, trajectory, "mpc", integrator="euler", horizon=horizon, intervals=intervals
        ).summary
        rms.append(1e3 * summary["rms_position_error_m"])
        step.append(summary["median_step_us"] / 1e3)
        print(
            f"tracking horizon {horizon:g} s ({intervals} intervals): RMS {rms[-1]:.2f} mm, "
            f"median step {step[-1]:.2f} ms"
        )
    scenarios = generate(4 if quick else 8, 0)
    reach = (2.0, 3.0, 5.0, 7.0)
    mean_time, reach_step = [], []
    for horizon in reach:
        mean, median = scenario_time({"horizon": horizon}, scenarios)
        mean_time.append(mean)
        reach_step.append(median)
        print(
            f"waypoint horizon {horizon:g} s: mean time {mean:.2f} s over {len(scenarios)} "
            f"scenarios, median step {median:.2f} ms"
        )
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.6))
    axes[0].plot(horizons, rms, "o-", color="C0")
    axes[0].set(
        xlabel="horizon (s)",
        ylabel="RMS position error (mm)",
        yscale="log",
        title="tracking, default rectangle (kinematic model)",
    )
    twin = axes[0].twinx()
    twin.plot(horizons, step, "s--", color="C1")
    twin.set_ylabel("median step (ms)", color="C1")
    axes[1].plot(reach, mean_time, "o-", color="C0")
    axes[1].set(
        xlabel="horizon (s)",
        ylabel="mean scenario time (s)",
        title=f"waypoints, thesis plant ({len(scenarios)} scenarios, 12 intervals)",
    )
    twin = axes[1].twinx()
    twin.plot(reach, reach_step, "s--", color="C1")
    twin.set_ylabel("median step (ms)", color="C1")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(FIGURES / "mpc_horizon.png", dpi=120)


def physics_run(options: tuple, duration: float = 1.5) -> tuple[np.ndarray, float | None]:
    """Scenario 7 (seed 0) on MuJoCo for ``duration`` s, not stopped when it tips: per step
    t, static S, S_phys (the centre of pressure's margin), the smallest edge load (N), tilt
    (rad); and the tip time."""
    scenario, robot = generate(7, 0)[6], Robot().with_payload(3.0)
    config = RunConfig(
        controller="mpc", plant="mujoco", time_limit=duration, controller_options=options
    )
    plant = make_scenario_plant(robot, config)
    controller = make_scenario_controller(robot, scenario, config, plant)
    tally = _Tally(robot, scenario, config)
    task = WaypointTask(tally, controller, False, plant)
    judge, rows = task.after_step, []
    column = plant.extra_columns.index
    physics, edge, tilt = (
        column(n) for n in ("physics_stability", "min_edge_load_n", "base_tilt_rad")
    )

    def record(k, t, obs, applied):
        judge(k, t, obs, applied)  # keeps the tallies; the run goes on after a tip
        values = plant.extra_values()
        rows.append(
            (t + config.dt, robot.stability(obs.q)[2], values[physics], values[edge], values[tilt])
        )
        return False

    task.after_step = record
    q0 = np.array([0.0, 0.0, 0.0, *default_pose(robot)])
    run_loop(plant, controller, task, q0, config.dt, tally.steps)
    return np.array(rows), plant.tip_time


def physics_tipping() -> None:
    """Scenario 7 on MuJoCo: the static floor lets the base pivot; the dynamic margin does not."""
    runs = {
        "static floor only": physics_run(
            (("dynamic_stability", False), ("arm_time_constant", 0.0))
        ),
        "dynamic margin + lagged arm, bounded accelerations (the protocol's)": physics_run(()),
    }
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for (label, (rows, tip)), color in zip(runs.items(), ("tab:red", "tab:blue")):
        t = rows[:, 0]
        axes[0].plot(t, rows[:, 1], color=color, label=label)
        axes[1].plot(t, rows[:, 3], color=color, label=label)
        axes[2].plot(t, np.degrees(rows[:, 4]), color=color, label=label)
        if tip is not None:
            for ax in axes:
                ax.axvline(tip, color=color, lw=0.8, ls="--")
            # left of the tip line, above the tilt that is still small before it
            axes[2].annotate(
                f"tipped (physics) at {tip:.2f} s ",
                (tip, 2.5),
                color=color,
                fontsize=8,
                ha="right",
            )
        print(
            f"{label}: tip {tip}, max tilt {np.degrees(rows[:, 4].max()):.2f} deg, "
            f"min edge load {rows[:, 3].min():.1f} N, min static S {rows[:, 1].min():.3f}"
        )
    axes[0].axhline(1.25, color="k", lw=0.7)
    axes[0].axhline(1.0, color="0.5", lw=0.7, ls="--")
    axes[0].set_ylim(1.0, 2.2)
    axes[0].set_ylabel("static S (floor 1.25)")
    axes[1].set_ylabel("smallest edge load (N)")
    axes[2].set_ylabel("base tilt (deg)")
    axes[2].set_xlabel("t (s)")
    axes[0].set_title("Scenario 7 on MuJoCo, mpc turning with the 3 kg payload out", fontsize=10)
    # one legend under the panels: inside them it would cover the curves
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(FIGURES / "mpc_physics_tipping.png", dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer scenarios in the study")
    parser.add_argument("--physics", action="store_true", help="only mpc_physics_tipping.png")
    args = parser.parse_args()
    FIGURES.mkdir(exist_ok=True)
    physics_tipping()
    if args.physics:
        return
    step_responses()
    rectangle()
    horizon_study(args.quick)


if __name__ == "__main__":
    main()
