"""Where a scenario step's cost goes, and the floor under the throughput target.

The target asks the thesis benchmark's scenarios to run at twice the simulated seconds per
wall second of commit 1145cc2, for the thesis controller and for ``qp``. This script
measures how much of a scenario step is the controller and the plant themselves, so the
target can be judged against what any loop would have to pay. It runs the first N
scenarios (seed 0, 3 kg payload, thesis plant) two ways in one process:

* ``library``: :func:`ddwmmr.scenarios.protocol.run_scenario`, the benchmark as it runs
  (the simulation loop, the waypoint task, observations, the stability and collision
  checks, the timing of each controller call);
* ``bare``: only what every step must do, written out with nothing around it: the
  controller's own entry (the thesis controller's ``act``, the ``qp``'s ``command``), the
  plant's own step (the thesis plant's ``advance`` for wheel forces, ``step`` for a
  velocity command, which includes its velocity servo) and the waypoint bookkeeping; no
  observation objects, no checks, no timing;
* ``checked``: ``bare`` plus the protocol's stability and collision check of the state
  after every step (``_Tally.check``), the least a loop that judges the run must add.

Both must take the same number of steps in every scenario (same commands, same states):
the script stops if they do not. It prints the cost per simulated step as wall time (median
of interleaved repeats; this machine class is noisy, so read the ratios) and, with
``--instructions``, as instructions counted by valgrind (deterministic to about 1 %, what
the docs quote). ``--reference-src`` adds the library row of another checkout's ``src``
(for example ``git worktree add /tmp/ref 1145cc2`` and ``--reference-src /tmp/ref/src``),
so the 2x budget can be read off the same run:

    .venv/bin/python benchmarks/scenario_floor.py --instructions --reference-src /tmp/ref/src

The numbers and what they mean are in docs/thesis.md ("Speed and scale-out").
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

CONTROLLERS = ("thesis", "qp")
DT = 0.01


def _scenarios(count: int):
    from ddwmmr.scenarios.generator import generate

    return generate(count, 0)


def run_library(controller: str, scenarios, time_limit: float | None = None) -> list[int]:
    """Steps of ``run_scenario`` per scenario (the benchmark as it runs)."""
    from ddwmmr.scenarios.protocol import RunConfig, run_scenario

    config = RunConfig(controller=controller, time_limit=time_limit)
    return [run_scenario(s, config).metrics["sim_steps"] for s in scenarios]


def _scenario_controller_factory():
    """``make(robot, scenario, config, plant)``: the protocol's controller of a run, from
    this checkout or from a ``--reference-src`` one that predates
    ``make_scenario_controller`` (one builder per controller there)."""
    from ddwmmr.scenarios import protocol

    if hasattr(protocol, "make_scenario_controller"):
        return protocol.make_scenario_controller

    def make(robot, scenario, config, plant):
        if config.controller == "thesis":
            return protocol.make_thesis_controller(robot, scenario, config)
        return protocol.make_qp(robot, scenario, config, protocol._envelope(plant))

    return make


def run_bare(
    controller: str, scenarios, time_limit: float | None = None, checked: bool = False
) -> list[int]:
    """Steps of the bare loop (controller entry + plant step + waypoints) per scenario;
    ``checked`` adds the protocol's stability and collision check after every step."""
    import numpy as np

    from ddwmmr.behaviours.objective import default_pose
    from ddwmmr.model import Robot
    from ddwmmr.scenarios.protocol import RunConfig, _Tally, make_scenario_plant

    make_controller = _scenario_controller_factory()

    config = RunConfig(controller=controller, time_limit=time_limit)
    robot = Robot().with_payload(config.payload)
    L1, L2 = robot.L1, robot.L2
    steps_per_run = []
    for scenario in scenarios:
        plant = make_scenario_plant(robot, config)
        q0 = np.array([0.0, 0.0, 0.0, *default_pose(robot)])
        plant.reset(q0, DT)
        agent = make_controller(robot, scenario, config, plant)
        if controller != "thesis":
            agent.adopt_control_step(DT)
        agent.reset(None, q0)
        tally = _Tally(robot, scenario, config)
        state, waypoints, index = plant.state, scenario.waypoints, 0
        limit = round(config.limit_for(scenario) / DT)
        velocity_d = np.zeros(3)
        pose_d = np.array([*waypoints[0], 0.0])
        for k in range(limit + 1):
            x, y, phi, th1, th2 = state.x, state.y, state.phi, state.th1, state.th2
            a1 = phi + th1
            xe = x + L1 * math.cos(a1) + L2 * math.cos(a1 + th2)
            ye = y + L1 * math.sin(a1) + L2 * math.sin(a1 + th2)
            while index < len(waypoints) and (
                math.hypot(xe - waypoints[index][0], ye - waypoints[index][1]) <= config.tolerance
            ):
                index += 1
                if index < len(waypoints):
                    pose_d = np.array([*waypoints[index], 0.0])
            if index == len(waypoints) or k == limit:
                break
            if controller == "thesis":
                agent.target = waypoints[index]
                left, right, t1, t2 = agent.act(k * DT, (x, y, phi, th1, th2), state.v, state.w)
                plant.advance(state, left, right, (t1, t2), DT)
            else:
                u = agent.command(k * DT, np.array((x, y, phi, th1, th2)), pose_d, velocity_d)
                plant.step(k * DT, u, DT)
            if checked and tally.check((state.x, state.y, state.phi, state.th1, state.th2)):
                k += 1  # the run ends after the step, as the loop's after_step does
                break
        steps_per_run.append(k)
    return steps_per_run


def run_checked(controller: str, scenarios, time_limit: float | None = None) -> list[int]:
    """Steps of the bare loop with the protocol's check after every step."""
    return run_bare(controller, scenarios, time_limit, checked=True)


VARIANTS = {"library": run_library, "bare": run_bare, "checked": run_checked}


def wall_times(controller: str, count: int, repeats: int) -> dict[str, float]:
    """Median wall time per step (us) of each variant, repeats interleaved."""
    scenarios = _scenarios(count)
    steps = {name: run(controller, scenarios) for name, run in VARIANTS.items()}
    if len({tuple(counts) for counts in steps.values()}) != 1:
        raise SystemExit(f"{controller}: the variants took other steps: {steps}")
    total = sum(steps["library"])
    samples: dict[str, list[float]] = {name: [] for name in VARIANTS}
    for _ in range(repeats):
        for name, run in VARIANTS.items():
            start = time.perf_counter()
            run(controller, scenarios)
            samples[name].append((time.perf_counter() - start) / total * 1e6)
    return {name: statistics.median(values) for name, values in samples.items()}


def instructions(controller: str, variant: str, count: int, src: str | None) -> float:
    """Instructions per step of ``variant`` (valgrind; ``count`` scenarios minus none)."""
    env = dict(os.environ, PYTHONHASHSEED="0")
    if src is not None:
        env["PYTHONPATH"] = src
    totals = []
    for n in (0, count):
        command = [
            "setarch",
            "-R",
            "valgrind",
            "--tool=cachegrind",
            "--cache-sim=no",
            "--cachegrind-out-file=/dev/null",
            sys.executable,
            __file__,
            "--count-only",
            controller,
            variant,
            str(n),
        ]
        done = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
        refs = [line for line in done.stderr.splitlines() if "I   refs:" in line]
        steps = int(done.stdout.split()[-1])
        totals.append((int(refs[-1].split()[-1].replace(",", "")), steps))
    (base, _), (total, steps) = totals
    return (total - base) / steps


def count_only(controller: str, variant: str, count: int) -> None:
    """Run ``count`` scenarios of one variant and print the steps (for valgrind)."""
    scenarios = _scenarios(max(count, 1))
    # The same imports and first-use set-up with count 0 (two steps of one scenario), so
    # that only the steps of the counted scenarios differ.
    VARIANTS[variant](controller, scenarios[:1], 0.02)
    print(sum(VARIANTS[variant](controller, scenarios[:count])) if count else 0)


def _src_folder(text: str) -> str:
    """An argparse type: a checkout's ``src`` folder (it holds the ddwmmr package)."""
    if not (Path(text) / "ddwmmr" / "__init__.py").is_file():
        raise argparse.ArgumentTypeError(f"must be a src folder holding ddwmmr/ (got {text!r})")
    return text


def main() -> None:
    try:
        from ddwmmr.cli.bench import _integer
    except ImportError:  # a --reference-src checkout from before ddwmmr.cli.bench
        from ddwmmr.bench import _integer
    from ddwmmr.cli.common import ArgumentParser

    parser = ArgumentParser(prog="scenario_floor", description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--scenarios", type=_integer(1, 100), default=20, help="scenarios timed, 1-100 (20)"
    )
    parser.add_argument(
        "--repeats", type=_integer(1, 100), default=5, help="interleaved repeats, 1-100 (5)"
    )
    parser.add_argument(
        "--instructions",
        action="store_true",
        help="also count instructions per step with valgrind (3 thesis, 2 qp scenarios)",
    )
    parser.add_argument(
        "--reference-src", type=_src_folder, help="src folder of another checkout to compare"
    )
    parser.add_argument("--count-only", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.count_only:
        controller, variant, count = args.count_only
        count_only(controller, variant, int(count))
        return
    if args.reference_src and not args.instructions:
        parser.error("--reference-src is used only with --instructions")
    missing = [tool for tool in ("valgrind", "setarch") if shutil.which(tool) is None]
    if args.instructions and missing:
        parser.error(f"--instructions needs {' and '.join(missing)} on PATH")
    for controller in CONTROLLERS:
        times = wall_times(controller, args.scenarios, args.repeats)
        row = ", ".join(f"{name} {value:.2f} us" for name, value in times.items())
        print(f"{controller}: wall time per step (median of {args.repeats}): {row}")
        if args.instructions:
            count = 3 if controller == "thesis" else 2
            counts = {v: instructions(controller, v, count, None) for v in VARIANTS}
            if args.reference_src:
                reference = instructions(controller, "library", count, args.reference_src)
                counts[f"library at {Path(args.reference_src).parent.name}"] = reference
                counts["2x budget"] = reference / 2.0
            row = ", ".join(f"{name} {value / 1000:.1f}k" for name, value in counts.items())
            print(f"{controller}: instructions per step: {row}")


if __name__ == "__main__":
    main()
