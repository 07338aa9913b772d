"""Quickstart: simulate a method on the default ellipse and print its summary.

Run: ``python examples/quickstart.py [method]`` (default ``clrrmc-ts``). Prints only.
"""

from __future__ import annotations

import sys
import textwrap
from typing import Any

import numpy as np

from ddwmmr import (
    Ellipse,
    Robot,
    available_methods,
    make_controller,
    simulate,
)
from ddwmmr.cli.common import run_script  # bad input: one line, status 2
from ddwmmr.errors import ParameterError

KEYS = (
    "rms_position_error_m",
    "max_position_error_m",
    "final_position_error_m",
    "rms_orientation_error_rad",
    "min_manipulability",
    "min_stability",
    "singular_steps",
    "steps",
    "median_step_us",
)


def main(method: str = "clrrmc-ts", *more: str) -> None:
    """Simulate ``method`` for one period (40 s, 2000 RK4 steps) and print the summary
    (``-h`` or ``--help``: the usage instead); one method per run."""
    if more:
        raise ParameterError(
            f"method: one METHOD per run (got {len(more) + 1}: {method} {' '.join(more)})"
        )
    if method in ("-h", "--help"):
        print(
            "usage: python examples/quickstart.py [METHOD]: one method on the default "
            f"ellipse (default clrrmc-ts; methods: {', '.join(available_methods())})"
        )
        return
    robot, trajectory = Robot(), Ellipse()
    result = simulate(robot, trajectory, method)
    print(f"{method} on {trajectory.name} (methods: {', '.join(available_methods())})")
    for key in KEYS:
        print(f"  {key:<26} {result.summary[key]:.6g}")
    # Whether it tracked, and if not what went wrong and why (simulate's verdict, from
    # ddwmmr.sim.verdict), as python -m ddwmmr.track prints it.
    print(textwrap.fill(f"verdict: {result.summary['verdict']}", 100, subsequent_indent="  "))

    # The same controller used directly, outside the simulator: one command u = (v, w,
    # th1dot, th2dot) in m/s and rad/s for the recorded start configuration.
    controller = make_controller(method, robot)
    controller.reset(trajectory, result.configurations()[0])
    # Any: a velocity method's command is an array; the Controller type also admits a
    # plug-in's list or a force method's WheelForces
    u: Any = controller.command(
        0.0, result.configurations()[0], trajectory.pose(0.0), trajectory.velocity(0.0)
    )
    print("  first command u =", np.array2string(u, precision=4))


if __name__ == "__main__":
    run_script(main, *sys.argv[1:])
