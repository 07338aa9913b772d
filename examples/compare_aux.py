"""Augmented task space: auxiliary row ``sum`` (th1dot + th2dot = 0) vs ``shoulder`` (th1dot = 0).

With ``aux="sum"`` the base must yaw at the end effector's rate (w = phiEdot). On the
rectangle's edges phiEdot = 0, so the base cannot turn there and the arm is dragged towards
the cos(th1) = 0 singularity; ``aux="shoulder"`` lets the base turn freely. Prints only.
"""

from __future__ import annotations

from ddwmmr import Ellipse, Rectangle, Robot, simulate
from ddwmmr.cli.common import run_script  # bad input: one line, status 2


def main() -> None:
    """Print tracking error, damped (singular) steps and saturated steps for each choice."""
    print(
        f"{'trajectory':<10} {'aux':<9} {'rms (m)':>9} {'max (m)':>9} {'singular':>9} "
        f"{'saturated':>10}"
    )
    for trajectory in (Ellipse(), Rectangle()):
        for aux in ("shoulder", "sum"):
            s = simulate(Robot(), trajectory, "ats", aux=aux).summary
            print(
                f"{trajectory.name:<10} {aux:<9} {s['rms_position_error_m']:9.4f} "
                f"{s['max_position_error_m']:9.4f} {s['singular_steps']:9d} "
                f"{s['saturated_steps']:10d}"
            )


if __name__ == "__main__":
    run_script(main)
