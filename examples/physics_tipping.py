"""Tipping on the physics plant: what the MPC needs to stay on its wheels.

Runs benchmark scenario 7 (seed 0: five waypoints in an 8 m square, 3 kg payload) on the
MuJoCo plant, where tipping is judged by the contact forces, with the ``mpc`` three ways:

1. the static stability floor alone (``S >= 1.25`` on the centre of mass, no arm lag, no
   braking step): turning fast with the payload out moves the centre of pressure onto one
   edge and the base pivots, while the static S is still 1.23 (near its floor: the plan's
   arm model is not the servos');
2. the same floor, with the arm's servo lag, its motors' acceleration limit and the braking
   step (what a physics plant gives the mpc by itself), but without the edge-load rows;
3. the default on this plant: also every edge of the support polygon keeps at least 10 %
   of the weight while moving (``min_edge_load``, the force model's edge loads).

Prints only; about 25 s of CPU. The 100-scenario study is
``python -m ddwmmr.scenarios --controller mpc --plant mujoco`` (docs/mpc.md).
"""

from __future__ import annotations

from typing import Any

from ddwmmr.cli.common import run_script  # bad input: one line, status 2
from ddwmmr.scenarios import RunConfig, generate, run_scenario

#: (label, mpc options) of each run, from the bare static floor to the default.
VARIANTS: tuple[tuple[str, dict[str, Any]], ...] = (
    ("static floor only", {"dynamic_stability": False, "arm_time_constant": 0.0}),
    ("+ arm lag, braking step", {"dynamic_stability": False}),
    ("+ every edge loaded (default)", {}),
)


def main() -> None:
    """Run scenario 7 with each variant and print the physics verdict."""
    scenario = generate(7, seed=0)[6]
    print(f"scenario {scenario.index + 1} (seed 0) on MuJoCo, 3 kg payload, 5 waypoints")
    for label, options in VARIANTS:
        config = RunConfig(
            controller="mpc", plant="mujoco", controller_options=tuple(options.items())
        )
        metrics = run_scenario(scenario, config).metrics
        verdict = "TIPPED" if "tipped" in metrics["reason"] else metrics["reason"]
        print(
            f"  {label:<29} {verdict:<7} at {metrics['time_s']:6.2f} s, "
            f"waypoints {metrics['waypoints_reached']}/5, "
            f"static S >= {metrics['min_stability']:.3f}, "
            f"an edge unloaded {metrics['unloaded_time_s']:.2f} s"
        )


if __name__ == "__main__":
    run_script(main)
