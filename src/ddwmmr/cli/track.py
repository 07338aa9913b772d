"""``python -m ddwmmr.track``: track one trajectory with one method and report.

Examples::

    python -m ddwmmr.track --method ats --traj ellipse
    python -m ddwmmr.track --method clrrmc-ts --traj rectangle --tau 0.3 --animate
    python -m ddwmmr.track --method qp --traj ellipse --payload 3 --stability-min 1.25
"""

from __future__ import annotations

import argparse
import datetime as dt
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ddwmmr.cli.common import (
    ArgumentParser,
    add_robot_arguments,
    atomic_output_dir,
    robot_from_arguments,
    run_main,
)
from ddwmmr.controllers.base import available_methods, make_controller, method_description
from ddwmmr.controllers.presets import PRESETS
from ddwmmr.errors import ParameterError
from ddwmmr.plants.kinematic import INTEGRATORS
from ddwmmr.progress import ProgressBar
from ddwmmr.resolution.reference import DEFAULT_INITIAL_OFFSET
from ddwmmr.sim.simulate import simulate
from ddwmmr.trajectories import available_trajectories, load_trajectory

#: Keys printed in the summary table, with their labels.
TABLE_KEYS = (
    ("rms_position_error_m", "RMS position error (m)"),
    ("max_position_error_m", "max position error (m)"),
    ("final_position_error_m", "final position error (m)"),
    ("rms_orientation_error_rad", "RMS orientation error (rad)"),
    ("max_nonholonomic_residual_m_s", "max nonholonomic residual (m/s)"),
    ("max_wheel_speed_rad_s", "max wheel speed (rad/s)"),
    ("min_manipulability", "min manipulability"),
    ("min_stability", "min stability S"),
    ("singular_steps", "singular (damped) steps"),
    ("saturated_steps", "saturated steps"),
    ("stability_violations", "steps with S < S_min"),
    ("qp_fallbacks", "QP fallbacks"),
    ("min_obstacle_clearance_m", "min obstacle clearance (m)"),
    ("steps", "steps"),
    ("median_step_us", "median controller step (us)"),
)

#: CLI option -> (controller keyword, methods it applies to; None = any method accepting it).
METHOD_OPTIONS = {
    "aux": "aux",
    "tau": "tau",
    "stability_min": "stability_min",
    "manipulability_weight": "manipulability_weight",
    "obstacles": "obstacles",
    "solver": "solver",
    "qp_mode": "mode",
}


def build_parser() -> ArgumentParser:
    """The argument parser (also used to render docs/cli.md)."""
    methods = available_methods()
    method_help = "; ".join(f"{m}: {method_description(m).rstrip('.')}" for m in methods)
    parser = ArgumentParser(
        prog="python -m ddwmmr.track",
        description=(
            "Simulate a differential-drive mobile manipulator tracking a desired end-effector "
            "trajectory with one redundancy-resolution / control method. Writes "
            "timeseries.csv, summary.json and figures into --out and prints a summary table."
        ),
        epilog=f"Methods - {method_help}.",
    )
    parser.add_argument("--method", required=True, choices=methods, help="control method")
    parser.add_argument(
        "--traj",
        required=True,
        metavar="NAME|FILE",
        help=f"trajectory name from trajectories/ ({', '.join(available_trajectories())}) "
        "or a .toml/.csv path",
    )
    parser.add_argument(
        "--aux",
        choices=("sum", "shoulder"),
        help="auxiliary row of the augmented Jacobian: sum (th1dot + th2dot = 0) or "
        "shoulder (th1dot = 0, default) [ats, clrrmc-ts, clrrmc-cs]",
    )
    parser.add_argument(
        "--tau",
        type=float,
        nargs="+",
        metavar="S",
        help="closed-loop time constant(s) in s, K = 1/tau: one value, or 3 (x, y, phi) for "
        "clrrmc-ts, 5 (x, y, phi, th1, th2) for clrrmc-cs; inf disables a channel "
        "(default 0.5)",
    )
    parser.add_argument(
        "--preset",
        choices=PRESETS,
        default="default",
        help="option values: default (the library's) or slides (the slides' settings: "
        "aux sum, no orientation feedback for clrrmc-ts); explicit options override it",
    )
    parser.add_argument("--dt", type=float, metavar="S", help="step in s (default T/N)")
    parser.add_argument(
        "--duration", type=float, metavar="S", help="simulated time in s (default one period)"
    )
    parser.add_argument(
        "--integrator", choices=INTEGRATORS, default="rk4", help="integrator (default rk4)"
    )
    parser.add_argument(
        "--offset",
        type=float,
        nargs=2,
        metavar=("DX", "DY"),
        default=DEFAULT_INITIAL_OFFSET,
        help="initial end-effector offset in m, applied with the arm (default "
        f"{DEFAULT_INITIAL_OFFSET[0]:.2f} {DEFAULT_INITIAL_OFFSET[1]:.2f})",
    )
    add_robot_arguments(parser)
    qp = parser.add_argument_group("QP controller options (--method qp)")
    qp.add_argument("--stability-min", type=float, metavar="S", help="hard floor on S")
    qp.add_argument(
        "--manipulability-weight",
        type=float,
        metavar="W",
        help="weight of the manipulability reward",
    )
    qp.add_argument(
        "--obstacles", metavar="FILE", help="TOML list of circles ([[obstacle]] x, y, radius)"
    )
    qp.add_argument(
        "--solver", help="qpsolvers backend (osqp, daqp, quadprog, proxqp, clarabel...)"
    )
    qp.add_argument("--qp-mode", choices=("weighted", "hierarchical"), help="priority handling")
    out = parser.add_argument_group("output")
    out.add_argument(
        "--out", metavar="DIR", help="output folder (default runs/<method>-<traj>-<time>/)"
    )
    out.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    out.add_argument("--animate", action="store_true", help="also write animation.gif")
    out.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser


def controller_options(args: argparse.Namespace) -> dict[str, Any]:
    """Controller keyword arguments from the CLI options that were given."""
    options: dict[str, Any] = {}
    for attribute, keyword in METHOD_OPTIONS.items():
        value = getattr(args, attribute)
        if value is None:
            continue
        if attribute == "tau" and len(value) == 1:
            value = value[0]
        if attribute == "obstacles":
            from ddwmmr.qp.limits.obstacles import load_obstacles

            value = load_obstacles(value)
        options[keyword] = value
    return options


def default_out(method: str, traj: str) -> Path:
    """``runs/<method>-<traj>-<YYYYmmdd-HHMMSS>``."""
    stamp = dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    return Path("runs") / f"{method}-{Path(traj).stem}-{stamp}"


def format_table(summary: dict[str, Any]) -> str:
    """The summary as an aligned two-column text table."""
    lines = [f"{summary['method']} on {summary['trajectory']}"]
    for key, label in TABLE_KEYS:
        if key in summary and summary[key] is not None:
            value = summary[key]
            text = f"{value:.6g}" if isinstance(value, float) else str(value)
            lines.append(f"  {label:<36} {text}")
    return "\n".join(lines)


def _main(argv: Sequence[str] | None = None) -> int:
    """Run the tool; bad input raises :class:`ParameterError`."""
    args = build_parser().parse_args(argv)
    robot = robot_from_arguments(args)
    trajectory = load_trajectory(args.traj)
    options = controller_options(args)
    controller = make_controller(args.method, robot, preset=args.preset, **options)
    out = Path(args.out) if args.out else default_out(args.method, args.traj)
    with atomic_output_dir(out, marker="summary.json") as staging:
        steps_hint = _steps_hint(trajectory, args)
        with ProgressBar(steps_hint, "track", enabled=not args.no_progress) as bar:
            result = simulate(
                robot,
                trajectory,
                controller,
                dt=args.dt,
                duration=args.duration,
                integrator=args.integrator,
                initial_offset=tuple(args.offset),
                progress=lambda k, n: bar.advance(),
            )
        result.write_csv(staging / "timeseries.csv")
        result.write_summary(staging / "summary.json")
        if not args.no_plots:
            from ddwmmr.reports.plots import save_run_figures

            save_run_figures(result, staging)
        if args.animate:
            from ddwmmr.reports.plots import save_animation

            save_animation(result, staging / "animation.gif")
    print(format_table(result.summary))
    print(f"wrote {out}/")
    return 0


def _steps_hint(trajectory, args: argparse.Namespace) -> int:
    duration = args.duration or trajectory.duration
    step = args.dt or trajectory.duration / getattr(trajectory, "samples", 1000)
    if not (step and step > 0 and duration and duration > 0):
        raise ParameterError(f"dt must be > 0 s (got {args.dt})")
    return max(1, round(duration / step))


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; bad input prints one line on stderr and returns 2."""
    return run_main(_main, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
