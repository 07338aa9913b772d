"""``python -m ddwmmr.scenarios``: the thesis's 100-scenario benchmark (thesis ch. 5).

Examples::

    python -m ddwmmr.scenarios --out runs/thesis                  # thesis controller, 100
    python -m ddwmmr.scenarios --controller qp --plant kinematic --out runs/qp
    python -m ddwmmr.scenarios --stability 1.4 1.7 --out runs/high-stability
    python -m ddwmmr.scenarios --study thresholds --out runs/thresholds
    python -m ddwmmr.scenarios --study obstacles --out runs/obstacles
    python -m ddwmmr.scenarios --arbiter competitive --out runs/competitive
    python -m ddwmmr.scenarios --study arbiters --out runs/arbiters
    python -m ddwmmr.scenarios --executor dask --scheduler tcp://10.0.0.5:8786 --out runs/d
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import sys
import textwrap
import time
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import asdict, astuple, replace
from pathlib import Path
from typing import Any

from ddwmmr import provenance
from ddwmmr.arbiters import DEFAULT_ARBITER, arbiter_description, available_arbiters
from ddwmmr.arbiters.state_machine import THESIS_MANIPULABILITY, THESIS_STABILITY
from ddwmmr.behaviours.obstacle import base_bubble
from ddwmmr.cli.common import (
    ArgumentParser,
    RefusedOption,
    add_force_argument,
    add_option_argument,
    check_output_folder,
    default_run_folder,
    given_text,
    horizon_defaults,
    horizon_range,
    integer_type,
    method_options_text,
    number_type,
    output_folder,
    output_target,
    parse_named_options,
    payload_type,
    run_main,
    run_method_options,
)
from ddwmmr.commands import traits_of
from ddwmmr.controllers import controller_traits, method_description, method_options
from ddwmmr.controllers.option_specs import option_names, parse_options
from ddwmmr.errors import (
    MAX_JOBS,
    MAX_SCENARIOS,
    MAX_STEPS,
    ParameterError,
    check_int_at_least,
    shown,
)
from ddwmmr.model import Robot
from ddwmmr.model.stability import STABILITY_CAP, STABILITY_FLOOR
from ddwmmr.outputs import write_atomic
from ddwmmr.plants import available_plants, plant_class, plant_description
from ddwmmr.progress import ProgressBar, phase
from ddwmmr.registry import used_plugins
from ddwmmr.scenarios import report, studies
from ddwmmr.scenarios.executors import (
    CONNECT_TIMEOUT,
    EXECUTORS,
    MAX_CONNECT_TIMEOUT,
    DaskWorkers,
    check_connect_timeout,
    default_jobs,
    run_many,
)
from ddwmmr.scenarios.generator import Scenario, generate
from ddwmmr.scenarios.protocol import (
    MAX_DT,
    MAX_QP_SPEED,
    OBSTACLE_TIME_LIMIT_S,
    THRESHOLD_RANGES,
    TIME_LIMIT_S,
    Outcome,
    RunConfig,
    check_dt,
    check_payload,
    check_thresholds,
    check_time_limit,
    config_robot,
    controller_options_record,
    make_scenario_controller,
    make_scenario_plant,
    plants_for,
    run_scenario,
    scenario_controllers,
    step_count,
)

#: The batch summary (holds the run record: everything needed to repeat the batch).
MARKER = "summary.json"
#: A batch's figures (in --out), named after what they show, whichever controller ran:
#: time per state, speed, paths of a few scenarios, state timeline of one; per-scenario
#: time in each fix state (a controller with an arbiter), the competitive arbiter's
#: weights; and with --study obstacles every obstacle scenario's path.
TIMES_FIGURE, SPEED_FIGURE = "times.png", "speed.png"
PATHS_FIGURE, TIMELINE_FIGURE = "paths.png", "timeline.png"
FIX_STATE_FIGURES = {"stability": "stability.png", "manipulability": "manipulability.png"}
WEIGHTS_FIGURE, OBSTACLE_PATHS_FIGURE = "weights.png", "obstacle_paths.png"
STUDIES = ("thresholds", "obstacles", "arbiters")
PROG = "python -m ddwmmr.scenarios"
#: --qp-* options (``RunConfig`` fields, which check their values): the controllers that
#: use them.
QP_OPTIONS = {"qp_stability_min": ("qp", "mpc"), "qp_max_speed": ("qp",)}
#: ``RunConfig`` fields only a controller with an arbiter (the thesis controller) reads:
#: its fix states' thresholds and its arbiter.
ARBITER_FIELDS = ("stability", "manipulability", "arbiter", "arbiter_seed", "arbiter_options")
#: ``RunConfig`` fields whose option is spelt otherwise, for its messages.
OPTION_SPELLING = {
    field: field.replace("_", "-")
    for field in ("time_limit", "arbiter_seed", "qp_stability_min", "qp_max_speed")
}
OPTION_SPELLING["arbiter_options"] = "arbiter-option"
#: Controller options the protocol sets itself, and what sets them instead of --option.
PROTOCOL_OPTIONS = {
    "obstacles": "each scenario's own, --obstacles",
    # The controller's planning step (the qp's stability look-ahead, the mpc's first
    # interval), not the simulation's: the protocol holds it at the scenario step, so that
    # each command is planned for as long as it is held (the qp's S floor is exact then).
    "dt": "it is the controller's planning step, not the simulation step; the protocol "
    "holds it at the scenario step: set --dt for both",
    "stability_min": "--qp-stability-min",
    "max_speed": "--qp-max-speed",
    "arbiter": "--arbiter",
    "route": "each scenario's own waypoints, with --option lookahead=on or plan=DIR",
}
#: The thesis's thresholds (enter, exit), the defaults of --stability and --manipulability.
DEFAULT_THRESHOLDS = {
    "stability": astuple(THESIS_STABILITY),
    "manipulability": astuple(THESIS_MANIPULABILITY),
}

DESCRIPTION = f"""\
Run the thesis's scenario benchmark: N scenarios of 5 waypoints drawn uniformly (seeded) in
an 8 m x 8 m square; the end effector must reach them in order within 0.01 m in {TIME_LIMIT_S:g} s
({OBSTACLE_TIME_LIMIT_S:g} s with obstacles) while the tip-over stability S stays above 1.
Writes scenarios.csv (one row per scenario), summary.json, table.txt (thesis Table 5.2
format) and figures into --out: times.png and speed.png (and with the thesis controller
stability.png and manipulability.png), per-scenario bars as thesis Figs 5.3-5.9;
paths.png, a few scenarios' paths; timeline.png, one scenario's states over time. It
prints the table. The controllers are the registered ones that do this
waypoint task, the plants the registered ones; --help lists both, each controller with the
plants it can command."""

EPILOG = f"""\
The default payload is 3.0 kg: with the {Robot.payload:g} kg of the thesis's experiments
(the Robot default) the planar arm can never tip (S >= 1.56), so the stability behaviour
could never be needed. Results are identical for any --executor and --jobs. Bad input
prints one line and exits with status 2, leaving no output behind."""


def _options_epilog() -> str:
    """The options of each scenario controller, one per line (wrapped)."""
    text = method_options_text(scenario_controllers())
    return "\n".join(
        textwrap.fill(line, 88, subsequent_indent="    ") for line in text.splitlines()
    )


#: Why ``--robot`` is refused here: the protocol runs the thesis robot
#: (:mod:`ddwmmr.scenarios.protocol`), whose payload alone can be chosen.
THESIS_ROBOT_ONLY = (
    'the scenario benchmark runs the thesis robot only (docs/thesis.md, "What is simulated")'
)


def build_parser() -> ArgumentParser:
    """The ``python -m ddwmmr.scenarios`` argument parser."""
    parser = ArgumentParser(
        prog=PROG,
        description=DESCRIPTION,
        epilog=f"{EPILOG}\n\n{_options_epilog()}",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--controller",
        choices=scenario_controllers(),
        default="thesis",
        help="controller to benchmark (default: thesis): "
        + "; ".join(
            f"{name}: {method_description(name).rstrip('.')} (plants: "
            f"{', '.join(plants_for(name))})"
            for name in scenario_controllers()
        ),
    )
    parser.add_argument(
        "--arbiter",
        choices=available_arbiters(),
        default=None,
        help=f"thesis controller's arbiter (default: {DEFAULT_ARBITER}; the same thresholds "
        "options for each): "
        + "; ".join(f"{a}: {arbiter_description(a).rstrip('.')}" for a in available_arbiters()),
    )
    parser.add_argument(
        "--arbiter-seed",
        type=integer_type(0, checked_later=True),
        default=None,
        metavar="N",
        help="noise seed of the competitive arbiter, an integer >= 0 (--arbiter competitive "
        "or --study arbiters; default: 0)",
    )
    parser.add_argument(
        "--arbiter-option",
        action="append",
        metavar="NAME=VALUE",
        help="an option of a plug-in --arbiter (repeatable): a keyword parameter of its "
        "constructor but the thresholds and seed, read as --option reads a method's (the "
        "built-in arbiters have none)",
    )
    parser.add_argument(
        "--plant",
        choices=available_plants(),
        default="thesis",
        help="plant (default: thesis): "
        + "; ".join(f"{p}: {plant_description(p).rstrip('.')}" for p in available_plants())
        + "; a physics plant judges tipping from its contact forces",
    )
    parser.add_argument(
        "--n",
        type=integer_type(1, MAX_SCENARIOS, checked_later=True),
        default=100,
        metavar="N",
        help=f"number of scenarios (default: 100, at most {MAX_SCENARIOS}; --study obstacles "
        "always runs the thesis's scenarios 1, 3, 7 and 10)",
    )
    parser.add_argument(
        "--seed",
        type=integer_type(0, checked_later=True),
        default=0,
        help="generator seed, an integer >= 0 (default: 0)",
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default: runs/scenarios-<time>/, never replacing anything: "
        "-2, -3... when taken; a folder given here is replaced only if it holds nothing but "
        "a previous scenarios run)",
    )
    add_force_argument(parser)
    parser.add_argument(
        "--payload",
        type=payload_type,
        default=3.0,
        metavar="KG",
        help="end-effector payload in kg, >= 0 and light enough that the start pose stands "
        f"(S > 1) (default: 3.0; the thesis's own experiments carried {Robot.payload:g} kg, "
        "the Robot default that track and compare run: see below)",
    )
    parser.add_argument(
        "--robot", action=RefusedOption, reason=f"{THESIS_ROBOT_ONLY}; use --payload"
    )
    parser.add_argument(
        "--stability",
        nargs=2,
        type=number_type(f"in (0, {THRESHOLD_RANGES['stability']:g}]"),
        default=None,
        metavar=("ENTER", "EXIT"),
        help="thesis controller's stability thresholds: enter below ENTER, leave at EXIT, "
        f"ENTER <= EXIT, both in (0, {THRESHOLD_RANGES['stability']:g}] "
        f"(default: {THESIS_STABILITY.enter:.2f} {THESIS_STABILITY.exit:.2f})",
    )
    parser.add_argument(
        "--manipulability",
        nargs=2,
        type=number_type(f"in (0, {THRESHOLD_RANGES['manipulability']:g}]"),
        default=None,
        metavar=("ENTER", "EXIT"),
        help="thesis controller's manipulability thresholds, ENTER <= EXIT, both in "
        f"(0, {THRESHOLD_RANGES['manipulability']:g}] "
        f"(default: {THESIS_MANIPULABILITY.enter:.2f} {THESIS_MANIPULABILITY.exit:.2f})",
    )
    parser.add_argument(
        "--no-hysteresis",
        action="append",
        default=[],
        choices=("stability", "manipulability"),
        help="leave that fix state as soon as the metric is back above ENTER (repeatable; "
        "refused with an EXIT other than ENTER in --stability or --manipulability)",
    )
    parser.add_argument(
        "--obstacles",
        action="store_true",
        help="run thesis scenarios 1, 3, 7, 10 (those up to --n) with two obstacles (r 0.3 m) "
        f"each, {OBSTACLE_TIME_LIMIT_S:g} s limit",
    )
    parser.add_argument(
        "--time-limit",
        type=number_type("> 0 s"),
        metavar="S",
        help=f"time limit per scenario in s, > 0, at most {MAX_STEPS:,} steps of --dt (default: "
        f"{TIME_LIMIT_S:g}, {OBSTACLE_TIME_LIMIT_S:g} with obstacles)",
    )
    parser.add_argument(
        "--dt",
        type=number_type(f"in (0, {MAX_DT:g}] s"),
        default=0.01,
        metavar="S",
        help=f"control and integration step in s, in (0, {MAX_DT:g}] (default: 0.01, the thesis "
        "controller's sample time); with --plant mujoco a whole multiple of its 0.002 s "
        "engine step",
    )
    parser.add_argument(
        "--jobs",
        type=integer_type(1, MAX_JOBS, checked_later=True),
        metavar="N",
        help=f"worker processes, 1 to {MAX_JOBS} (default: the CPUs available); with "
        "--executor dask the LocalCluster's workers; refused with --scheduler (the batch "
        "runs on the workers the scheduler has)",
    )
    parser.add_argument(
        "--executor",
        choices=EXECUTORS,
        default="local",
        help="'local' process pool (default) or 'dask'",
    )
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="Dask scheduler address (with --executor dask; default: start a LocalCluster)",
    )
    parser.add_argument(
        "--connect-timeout",
        type=number_type(f"in (0, {MAX_CONNECT_TIMEOUT:g}] s", finite=True),
        metavar="S",
        help=f"with --scheduler: seconds the scheduler has to answer, and then to have a "
        f"worker, in (0, {MAX_CONNECT_TIMEOUT:g}] (default: {CONNECT_TIMEOUT:g}); checked "
        "before anything is written",
    )
    parser.add_argument(
        "--study",
        choices=STUDIES,
        help="'thresholds': rerun thesis Tables 5.5-5.20 threshold variations; "
        "'obstacles': thesis Table 5.21; 'arbiters': state machine vs competitive arbiter "
        "(Table 5.2 and threshold variants side by side, weights, noise seeds and levels)",
    )
    parser.add_argument(
        "--qp-stability-min",
        type=number_type(f"in (0, {STABILITY_CAP:g})"),
        default=None,
        metavar="S",
        help=f"hard stability bound of the qp and mpc controllers, in (0, {STABILITY_CAP:g}) "
        f"(default: {STABILITY_FLOOR:g})",
    )
    parser.add_argument(
        "--qp-max-speed",
        type=number_type(f"in (0, {MAX_QP_SPEED:g}] m/s"),
        default=None,
        metavar="M_S",
        help=f"qp controller's end-effector speed limit, in (0, {MAX_QP_SPEED:g}] m/s "
        "(default: 1.0)",
    )
    add_option_argument(
        parser,
        "an option of --controller, except those the protocol sets: "
        + ", ".join(f"{k} ({v})" for k, v in PROTOCOL_OPTIONS.items()),
        "adjust=0.3 (thesis), tau=0.3 (qp), intervals=8 (mpc)",
    )
    parser.add_argument(
        "--horizon",
        type=number_type(horizon_range()),
        metavar="S",
        help="mpc's prediction horizon in s (docs/mpc.md); the same as --option horizon=S "
        f"(default {horizon_defaults()[1]:g} s, its waypoint one)",
    )
    parser.add_argument(
        "--bounds",
        metavar="FILE",
        help="a bounds.csv of python -m ddwmmr.bounds (same seed and payload; only with "
        "--plant thesis, without --study or --obstacles): the summary gives the mean ratio "
        "of each scenario's time to its lower bound and best-known time",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser  # fmt: skip


def default_out() -> Path:
    """``runs/scenarios-<YYYYmmdd-HHMMSS>`` (:func:`default_run_folder`, as track's)."""
    return default_run_folder("scenarios")


def _qp_options(args: argparse.Namespace) -> dict[str, float]:
    """The given ``--qp-*`` options, refused for a controller without them (their values
    are ``RunConfig``'s to check)."""
    options = {}
    for name, controllers in QP_OPTIONS.items():
        value = getattr(args, name)
        if value is None:
            continue
        if args.controller not in controllers:
            raise ParameterError(
                f"{OPTION_SPELLING[name]}: only used with --controller {' or '.join(controllers)}"
            )
        options[name] = value
    return options


@contextlib.contextmanager
def _option_names() -> Iterator[None]:
    """Re-raise a :class:`ParameterError` of the protocol's checks naming the options
    (``time-limit``), not the ``RunConfig`` fields (``time_limit``)."""
    try:
        yield
    except ParameterError as exc:
        message = str(exc)
        for field, option in OPTION_SPELLING.items():
            message = re.sub(rf"\b{field}\b", option, message)
        raise ParameterError(message) from None


def scenario_controller_options(args: argparse.Namespace) -> tuple[tuple[str, Any], ...]:
    """``--option NAME=VALUE`` and ``--horizon`` as ``RunConfig.controller_options``:
    parsed and checked as the simulator's fields are; the options the protocol sets
    (:data:`PROTOCOL_OPTIONS`, those of them the controller takes) are refused, naming what
    sets them; one it does not take is refused as any unknown option. A relative
    ``plan=DIR`` becomes absolute here, against this process's working folder: the
    scenarios may run in workers with another one (a Dask worker's)."""
    if args.horizon is not None and "horizon" not in option_names(args.controller):
        takers = [c for c in scenario_controllers() if "horizon" in option_names(c)]
        raise ParameterError(  # worded as track's flags are
            f"horizon: --horizon is taken only by --controller {' or '.join(takers) or '(none)'}"
            f" (got --controller {args.controller})"
        )
    texts = [
        *run_method_options(args.option, args.controller, "--controller"),
        *(() if args.horizon is None else (f"horizon={args.horizon!r}",)),
    ]
    taken = method_options(args.controller)
    for text in texts:
        name = text.partition("=")[0].strip()
        if name in PROTOCOL_OPTIONS and name in taken:
            raise ParameterError(
                f"option: the scenarios set {name} themselves ({PROTOCOL_OPTIONS[name]}; got "
                f"{text!r})"
            )
    options = parse_options(args.controller, texts, unlisted=PROTOCOL_OPTIONS)
    if isinstance(options.get("plan"), str) and options["plan"]:  # "" is refused later
        options["plan"] = os.path.abspath(options["plan"])
    return tuple((name, tuple(v) if isinstance(v, list) else v) for name, v in options.items())


def config_from_arguments(args: argparse.Namespace) -> RunConfig:
    """Validate the options and build the run configuration (before any output exists)."""
    check_int_at_least("n", args.n, 1, MAX_SCENARIOS)
    check_int_at_least("seed", args.seed, 0)
    if args.jobs is not None:
        check_int_at_least("jobs", args.jobs, 1, MAX_JOBS)
    given_text("scheduler", args.scheduler, "a Dask scheduler address", "address")
    if args.scheduler is not None and args.executor != "dask":
        raise ParameterError("scheduler: only used with --executor dask")
    if args.scheduler is not None and args.jobs is not None:
        raise ParameterError(
            "jobs: not used with --scheduler (the batch runs on the workers the scheduler "
            "has); leave --jobs out"
        )
    if args.connect_timeout is not None:
        if args.scheduler is None:
            raise ParameterError("connect-timeout: only used with --scheduler")
        check_connect_timeout(args.connect_timeout)
    if args.study == "thresholds" and args.controller != "thesis":
        raise ParameterError("study: the threshold study needs --controller thesis")
    if args.study == "arbiters" and args.controller != "thesis":
        raise ParameterError("study: the arbiter study needs --controller thesis")
    _check_thesis_options(args)
    if args.study and args.obstacles:
        raise ParameterError("study: --obstacles is implied by --study obstacles")
    check_dt(args.dt)
    if args.time_limit is not None:
        with _option_names():
            check_time_limit(args.time_limit)
    qp_options = _qp_options(args)
    check_payload(args.payload)
    obstacles = args.obstacles or args.study == "obstacles"
    longest = (
        args.time_limit
        if args.time_limit is not None
        else (OBSTACLE_TIME_LIMIT_S if obstacles else TIME_LIMIT_S)
    )
    with _option_names():
        step_count(longest, args.dt)  # 120 s with obstacles, which RunConfig cannot know
    thresholds = {name: _thresholds(args, name) for name in ("stability", "manipulability")}
    controller_options = scenario_controller_options(args)
    with _option_names():
        return RunConfig(
            controller=args.controller,
            plant=args.plant,
            payload=args.payload,
            stability=thresholds["stability"],
            manipulability=thresholds["manipulability"],
            dt=args.dt,
            time_limit=args.time_limit,
            # ignore: qp_options holds only the float qp_* fields, not the bool or int ones
            **qp_options,  # type: ignore[arg-type]
            arbiter=args.arbiter or DEFAULT_ARBITER,
            arbiter_seed=0 if args.arbiter_seed is None else args.arbiter_seed,
            controller_options=controller_options,
            arbiter_options=_arbiter_options(args),
        )


def _arbiter_options(args: argparse.Namespace) -> tuple[tuple[str, Any], ...]:
    """``--arbiter-option NAME=VALUE`` as ``RunConfig.arbiter_options``: each name one the
    arbiter takes (:func:`~ddwmmr.arbiters.factory.check_arbiter_options`, which
    ``RunConfig`` calls again), its value read as ``--plant-option`` reads one
    (:func:`~ddwmmr.cli.common.parse_named_options`); a number option's text that is no
    number is refused here (the plug-in's constructor may not check)."""
    from ddwmmr.arbiters.factory import arbiter_option_specs, check_arbiter_options
    from ddwmmr.controllers.base import NumberText

    if not args.arbiter_option:
        return ()
    if args.study == "arbiters":
        raise ParameterError("--arbiter-option: the arbiter study runs the built-in arbiters")
    arbiter = args.arbiter or DEFAULT_ARBITER

    def specs_for(names: list[str]) -> dict[str, Any]:
        with _option_names():
            check_arbiter_options([(name, None) for name in names], arbiter, args.controller)
        return arbiter_option_specs(arbiter)

    options = parse_named_options(args.arbiter_option, "arbiter-option", specs_for)
    for name, value in options.items():
        if isinstance(value, NumberText):
            raise ParameterError(
                f"arbiter-option: {name} must be {value.expected} (got {shown(value)})"
            )
    return tuple((n, tuple(v) if isinstance(v, list) else v) for n, v in options.items())


def _check_engine_step(config: RunConfig) -> None:
    """With a physics plant (``--plant mujoco``): ``--dt`` a whole multiple of its engine
    step, refused naming this tool's range of dt, (0, :data:`MAX_DT`] s (the plant's own
    message would give the longer steps the plant alone allows)."""
    if not hasattr(plant_class(config.plant), "check_control_step"):
        return
    plant = make_scenario_plant(config_robot(config), config)
    # ignore: a physics plant has these (its class checked above); the Plant protocol does not
    try:
        plant.check_control_step(config.dt)  # type: ignore[attr-defined]
    except ParameterError:
        h = plant.timestep  # type: ignore[attr-defined]
        raise ParameterError(
            f"dt must be a whole multiple of the {config.plant} plant's engine step {h:g} s in "
            f"(0, {MAX_DT:g}] s ({', '.join(f'{k * h:g}' for k in (1, 2, 3))}, ...) "
            f"(got {config.dt:g})"
        ) from None


def _thresholds(args: argparse.Namespace, name: str) -> tuple[float, float]:
    """``--stability`` or ``--manipulability`` (``name``) as (enter, exit), checked as
    ``RunConfig`` checks them; ``--no-hysteresis name`` makes exit enter, and is refused
    with a given EXIT other than ENTER (which it would silently drop)."""
    given = getattr(args, name)
    enter, exit_ = check_thresholds(name, DEFAULT_THRESHOLDS[name] if given is None else given)
    if name not in args.no_hysteresis:
        return enter, exit_
    if given is not None and exit_ != enter:
        raise ParameterError(
            f"no-hysteresis: --no-hysteresis {name} leaves the state at ENTER, so --{name} "
            f"{enter:g} {exit_:g} gives an EXIT it would ignore; give EXIT = ENTER "
            f"(--{name} {enter:g} {enter:g})"
        )
    return enter, enter


def _check_thesis_options(args: argparse.Namespace) -> None:
    """Refuse the thesis controller's options where nothing would read them."""
    given = [f"--{n}" for n in ("stability", "manipulability") if getattr(args, n) is not None]
    given += ["--no-hysteresis"] if args.no_hysteresis else []
    arbitrated = controller_traits(args.controller)["arbiter"]  # thresholds are its arbiter's
    if given and not arbitrated:
        raise ParameterError(
            f"{given[0]}: only used with --controller thesis (the qp and mpc hold "
            "--qp-stability-min)"
        )
    if given and args.study in ("thresholds", "arbiters"):
        raise ParameterError(
            f"{given[0]}: the {args.study[:-1]} study runs its own thresholds (thesis Table 5.2 "
            "and Tables 5.5-5.20); leave it out"
        )
    if args.arbiter is not None and not arbitrated:
        raise ParameterError("--arbiter: only the thesis controller has an arbiter")
    if args.arbiter is not None and args.study == "arbiters":
        raise ParameterError("--arbiter: the arbiter study runs both arbiters; leave it out")
    if args.arbiter_seed is not None and args.arbiter != "competitive" and args.study != "arbiters":
        raise ParameterError(
            "--arbiter-seed: only used with --arbiter competitive or --study arbiters"
        )


class Runner:
    """Runs batches with the chosen executor, a progress bar and timing.

    A context manager: with ``--executor dask`` the ``with`` block holds one client for
    every batch, connected (or its LocalCluster started) on entry, before any output
    exists, so a scheduler that is not there fails with one line and leaves nothing.

    ``jobs`` is the local parallelism (the process pool, the LocalCluster's workers, the
    arbiter study's statistics); ``workers`` the workers the batches run on: ``jobs``,
    except with ``--scheduler``, where it is the scheduler's worker count once connected.
    """

    def __init__(self, args: argparse.Namespace) -> None:
        # never more workers than the largest batch has scenarios
        self.jobs = min(args.jobs or default_jobs(), largest_batch(args))
        self.workers = self.jobs
        self.executor = args.executor
        self.scheduler = args.scheduler
        self.connect_timeout = args.connect_timeout or CONNECT_TIMEOUT
        self.progress = not args.no_progress
        self._client: Any = None
        self._held = contextlib.ExitStack()

    def __enter__(self) -> Runner:
        if self.executor == "dask":
            workers = DaskWorkers(self.jobs, self.scheduler, self.connect_timeout)
            label = "connecting to Dask" if self.scheduler else "starting Dask workers"
            with phase(label, enabled=self.progress):
                self._client = self._held.enter_context(workers)
            if self.scheduler:  # the cluster's own count, not this machine's CPUs
                self.workers = cluster_workers(self._client)
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._client = None
        self._held.close()

    def run(
        self, scenarios: list[Scenario], config: RunConfig, label: str
    ) -> tuple[list[Outcome], float]:
        """Outcomes in scenario order and the wall time (s)."""
        start = time.perf_counter()
        with ProgressBar(len(scenarios), label, enabled=self.progress) as bar:
            outcomes = run_many(
                scenarios,
                config,
                jobs=min(self.workers, MAX_JOBS),  # the chunking's cap, not the cluster's
                executor=self.executor,
                client=self._client,
                on_done=bar.advance,
            )
        return outcomes, time.perf_counter() - start


def cluster_workers(client: Any) -> int:
    """Workers the Dask scheduler of ``client`` has now (at least 1: connecting waited for
    one)."""
    return max(1, len(client.nthreads()))


def largest_batch(args: argparse.Namespace) -> int:
    """Scenarios in the largest batch a run of ``args`` sends to the workers."""
    largest: int = max(args.n, 10) if args.study == "obstacles" else args.n
    return largest


def output_names(args: argparse.Namespace, config: RunConfig) -> tuple[str, ...]:
    """The files a run of ``args`` writes (checked against a user's files before the run,
    with --force)."""
    if args.study == "thresholds":
        return (MARKER, "thresholds.md", *(f"{v.key}.csv" for v in studies.THRESHOLD_VARIANTS))
    if args.study == "arbiters":
        from ddwmmr.scenarios import arbiter_study

        return (MARKER, *arbiter_study.output_names())
    figures = [TIMES_FIGURE, SPEED_FIGURE, PATHS_FIGURE, TIMELINE_FIGURE]
    if controller_traits(config.controller)["arbiter"]:  # time in its fix states
        figures += FIX_STATE_FIGURES.values()
    if config.arbiter == "competitive":
        figures.append(WEIGHTS_FIGURE)
    if args.study == "obstacles":
        figures += ["obstacles.md", OBSTACLE_PATHS_FIGURE]
    return (MARKER, "scenarios.csv", "table.txt", *figures)


def _title(config: RunConfig) -> str:
    """What the table's batch ran: controller, plant, payload and the settings that
    controller uses: an arbiter's thresholds (S and eta, enter/exit) and arbiter, or the
    ``qp``/``mpc``'s stability floor ``S_min`` and the ``qp``'s end-effector speed limit."""
    title = f"{config.controller} controller, {config.plant} plant, payload {config.payload:g} kg"
    if controller_traits(config.controller)["arbiter"]:
        s, m = config.stability, config.manipulability
        title += f", S {s[0]:g}/{s[1]:g}, eta {m[0]:g}/{m[1]:g}"
    uses = {name for name, takers in QP_OPTIONS.items() if config.controller in takers}
    if "qp_stability_min" in uses:
        title += f", S_min {config.qp_stability_min:g}"
    if "qp_max_speed" in uses:
        title += f", max speed {config.qp_max_speed:g} m/s"
    if config.arbiter != "state-machine":
        title += f", {config.arbiter} arbiter"
    return title


def write_batch(
    folder: Path,
    scenarios: list[Scenario],
    outcomes: list[Outcome],
    config: RunConfig,
    wall: float,
    extra: dict[str, Any],
    progress: bool = True,
) -> dict[str, Any]:
    """scenarios.csv, summary.json, table.txt and the figures of one batch."""
    summary = report.summarize(outcomes, wall)
    summary.update(extra)
    summary["config"] = config_record(config)
    title = _title(config)
    write_atomic(folder / "scenarios.csv", report.metrics_csv(outcomes))
    table = report.format_table(summary, f"Table 5.2 format: {title}")
    write_atomic(folder / "table.txt", table)
    _figures(folder, scenarios, outcomes, config, progress)
    write_atomic(folder / MARKER, report.summary_json(summary))
    print(table, end="")
    failures = failure_line(summary)
    if failures:
        print(failures)
    return summary


def failure_line(summary: dict[str, Any]) -> str:
    """One line counting why scenarios did not finish (the table's means would otherwise
    hide, say, a controller that raised in every one); empty if every one finished."""
    reasons = Counter(str(f["reason"]) for f in summary.get("failures", ()))
    if not reasons:
        return ""
    listed = ", ".join(f"{shown(reason, 80)} x{count}" for reason, count in reasons.most_common(3))
    more = f" and {len(reasons) - 3} more" if len(reasons) > 3 else ""
    return (
        f"scenarios: {summary['failed']} of {summary['n']} did not finish: {listed}{more} "
        "(each in scenarios.csv)"
    )


def _figures(
    folder: Path,
    scenarios: list[Scenario],
    outcomes: list[Outcome],
    config: RunConfig,
    progress: bool,
) -> None:
    with phase("scenarios: figures", enabled=progress):
        _draw_figures(folder, scenarios, outcomes, config)


def _draw_figures(
    folder: Path, scenarios: list[Scenario], outcomes: list[Outcome], config: RunConfig
) -> None:
    short = f"{config.controller} controller, {config.plant} plant"
    report.plot_state_times(outcomes, folder / TIMES_FIGURE, short)
    report.plot_speeds(outcomes, folder / SPEED_FIGURE, short)
    if controller_traits(config.controller)["arbiter"]:
        for key, name in FIX_STATE_FIGURES.items():
            report.plot_fix_state(outcomes, key, folder / name, short)
    if config.arbiter == "competitive":
        from ddwmmr.scenarios import arbiter_study

        focus_scenario = scenarios[highlight(outcomes)]
        arbiter_study.plot_weights(focus_scenario, config, folder / WEIGHTS_FIGURE, short)
    # Re-run (deterministically) the scenarios to draw, with a trace: the first two and
    # the one to look at (the first failure, else the most fix-state transitions).
    focus = highlight(outcomes)
    chosen = sorted({0, min(1, len(scenarios) - 1), focus})
    traced = replace(config, record=True)
    items = [(scenarios[i], run_scenario(scenarios[i], traced)) for i in chosen]
    report.plot_paths(items, folder / PATHS_FIGURE, paths_title(short, outcomes, chosen, focus))
    scenario, timeline = next((s, o) for (s, o) in items if s.index == scenarios[focus].index)
    report.plot_timeline(
        timeline, folder / TIMELINE_FIGURE, short, scenario, **timeline_thresholds(config)
    )


def paths_title(short: str, outcomes: list[Outcome], chosen: list[int], focus: int) -> str:
    """The title of :data:`PATHS_FIGURE`: which of how many scenarios it shows, and why (the
    first two, and the :func:`highlight` one: the first failure, else the busiest in fix
    states), e.g. "thesis controller, thesis plant: paths of scenarios 1, 2 (the first
    two) and 5 (the first failure) of 6 scenarios run", or "... 1, 2 (the first two; 1: the
    first failure) of 6 scenarios run"."""
    number = [o.metrics["scenario"] for o in outcomes]
    firsts = [i for i in chosen if i < 2]
    m = outcomes[focus].metrics
    entries = _count(m["transitions_stability"]) + _count(m["transitions_manipulability"])
    why = "the first failure" if not m["success"] else "the most fix-state entries"
    note = "the first two" if len(firsts) == 2 else "the first"
    if focus in firsts and (not m["success"] or entries > 0):  # the one to look at
        note += f"; {number[focus]}: {why}"
    shown = ", ".join(str(number[i]) for i in firsts) + f" ({note})"
    if focus not in firsts:
        shown += f" and {number[focus]} ({why})"
    plural = "s" * (len(chosen) > 1)
    ran = f"{len(outcomes)} scenario" + "s" * (len(outcomes) > 1)
    return f"{short}: paths of scenario{plural} {shown} of {ran} run"


def _state_lines(
    state: str, symbol: str, thresholds: tuple[float, float]
) -> list[tuple[float, str]]:
    """Enter and exit lines of a fix state; one line where they coincide (no hysteresis)."""
    enter, leave = thresholds
    if enter == leave:
        return [(enter, f"{state} state below, left above {symbol} = {enter:g}")]
    return [
        (enter, f"enter {state} state, {symbol} < {enter:g}"),
        (leave, f"leave it, {symbol} >= {leave:g}"),
    ]


def timeline_thresholds(config: RunConfig) -> dict[str, list[tuple[float, str]]]:
    """The thresholds the timeline's S and eta panels draw (:func:`report.plot_timeline`):
    an arbiter's enter/exit thresholds (the competitive arbiter grades stability in below
    its enter threshold, with no exit switch), or the ``qp``/``mpc`` stability floor
    ``S_min``; none for an arbiter of one's own."""
    if controller_traits(config.controller)["arbiter"]:
        manipulability = _state_lines("manipulability", "eta", config.manipulability)
        if config.arbiter == "competitive":
            enter = config.stability[0]
            graded = [(enter, f"stability weighs in below S = {enter:g} (graded)")]
            return {"stability_lines": graded, "manipulability_lines": manipulability}
        if config.arbiter != "state-machine":
            return {}
        return {
            "stability_lines": _state_lines("stability", "S", config.stability),
            "manipulability_lines": manipulability,
        }
    uses = {name for name, takers in QP_OPTIONS.items() if config.controller in takers}
    if "qp_stability_min" in uses:
        floor = config.qp_stability_min
        return {"stability_lines": [(floor, f"floor S_min = {floor:g}")]}
    return {}


def highlight(outcomes: list[Outcome]) -> int:
    """Position of the scenario to draw in detail: first failure, else busiest in fix states."""
    for i, o in enumerate(outcomes):
        if not o.metrics["success"]:
            return i
    return max(
        range(len(outcomes)),
        key=lambda i: (
            _count(outcomes[i].metrics["transitions_stability"])
            + _count(outcomes[i].metrics["transitions_manipulability"]),
            -i,
        ),
    )


def _count(value: Any) -> float:
    return 0.0 if isinstance(value, float) and math.isnan(value) else float(value)


def _run_benchmark(
    args: argparse.Namespace, config: RunConfig, runner: Runner, folder: Path
) -> None:
    scenarios = generate(args.n, args.seed)
    if args.obstacles:
        scenarios = studies.obstacle_scenarios(scenarios)
        print(obstacles_note(args.n, [s.index + 1 for s in scenarios]), file=sys.stderr)
    outcomes, wall = runner.run(scenarios, config, "scenarios")
    extra = {"seed": args.seed, "run": _record(args, config, runner.workers)}
    beaten: list[tuple[int, float, float]] = []
    if args.bounds_table is not None:
        beaten = report.below_lower_bound(outcomes, args.bounds_table)
        extra["bracket"] = {"bounds": args.bounds, **report.bracket(outcomes, args.bounds_table)}
    extra["controller_options"] = controller_options_record(config, scenarios[0])
    summary = write_batch(folder, scenarios, outcomes, config, wall, extra, runner.progress)
    if args.bounds_table is not None:
        print(_bracket_line(summary["bracket"], args.bounds, len(outcomes)))
        if beaten:
            print(_beaten_line(beaten, args.bounds), file=sys.stderr)
    print(
        f"wall time {wall:.2f} s, {summary['sim_time_s']:.0f} simulated s, "
        f"{summary['sim_seconds_per_wall_second']:.0f} simulated s per wall s "
        f"({runner.workers} {args.executor} worker{'s' * (runner.workers != 1)})",
        file=sys.stderr,
    )


def obstacles_note(n: int, numbers: Sequence[int]) -> str:
    """The stderr line of ``--obstacles``: which of the thesis's obstacle scenarios run
    (those up to ``--n``, here ``numbers``), since ``--n`` alone does not say it."""
    listed = ", ".join(map(str, studies.OBSTACLE_SCENARIOS))
    which = f"scenario{'s' * (len(numbers) != 1)} {', '.join(map(str, numbers))}"
    return f"note: --obstacles runs the thesis's obstacle scenarios {listed} up to --n {n}: {which}"


def _bracket_line(b: dict[str, Any], bounds: str, n: int) -> str:
    """The printed line of ``--bounds``: both mean ratios, each with how many of the ``n``
    scenarios it covers when not all (failed ones, or ones the file lacks), or why it is
    missing (no successful scenario with that end of its bracket) instead of a bare nan."""
    parts = []
    for end, key, count in (
        ("lower bound", "mean_ratio_to_lower_bound", "scenarios_with_lower_bound"),
        ("best-known time", "mean_ratio_to_best_known", "scenarios_with_best_known"),
    ):
        ratio, covered = b[key], b[count]
        if covered and math.isfinite(ratio):
            parts.append(f"{ratio:.3f}" + (f" (over {covered} of {n})" if covered < n else ""))
        else:
            parts.append(f"none (no successful scenario has a {end} in the file)")
    return f"mean ratio to the lower bound {parts[0]}, to the best-known time {parts[1]} ({bounds})"


def _beaten_line(beaten: list[tuple[int, float, float]], bounds: str) -> str:
    """The warning of ``--bounds`` when scenarios beat their lower bounds: which, and by
    how much the first did."""
    numbers = [str(number) for number, _, _ in beaten]
    listed = ", ".join(numbers[:10]) + (
        f" and {len(numbers) - 10} more" if len(numbers) > 10 else ""
    )
    number, time_s, lower = beaten[0]
    first = f"scenario {number}: " if len(beaten) > 1 else ""
    return (
        f"warning: {bounds} gives lower bounds above the times achieved in "
        f"scenario{'s' * (len(beaten) > 1)} {listed} ({first}{time_s:g} s < {lower:g} s); "
        "a lower bound holds for every run of its scenario, so the file is "
        "not for these scenarios (other waypoints, robot or limits) or is wrong, and the "
        "ratios to its lower bounds mean nothing"
    )


def _run_thresholds(
    args: argparse.Namespace, config: RunConfig, runner: Runner, folder: Path
) -> None:
    scenarios = generate(args.n, args.seed)
    results = []
    rows = []
    for variant in studies.THRESHOLD_VARIANTS:
        cfg = replace(config, stability=variant.stability, manipulability=variant.manipulability)
        outcomes, wall = runner.run(scenarios, cfg, variant.key)
        summary = report.summarize(outcomes, wall)
        results.append((variant, summary))
        rows.append({"variant": variant.key, **{k: summary[k] for k in summary if k != "failures"}})
        write_atomic(folder / f"{variant.key}.csv", report.metrics_csv(outcomes))
    context = studies.context_line(len(scenarios), args.seed, config)
    table = studies.threshold_table(results, context)
    write_atomic(folder / "thresholds.md", table)
    total = {
        "study": "thresholds",
        "n": len(scenarios),
        "seed": args.seed,
        "config": config_record(config),
        "variants": rows,
        "wall_time_s": sum(s["wall_time_s"] for _, s in results),
        "run": _record(args, config, runner.workers),
    }
    write_atomic(folder / MARKER, report.summary_json(total))
    print(table, end="")


def _run_obstacles(
    args: argparse.Namespace, config: RunConfig, runner: Runner, folder: Path
) -> None:
    scenarios = studies.obstacle_scenarios(generate(max(args.n, 10), args.seed))
    outcomes, wall = runner.run(scenarios, config, "obstacles")
    extra = {"seed": args.seed, "study": "obstacles", "run": _record(args, config, runner.workers)}
    extra["controller_options"] = controller_options_record(config, scenarios[0])
    write_batch(folder, scenarios, outcomes, config, wall, extra, runner.progress)
    table = studies.obstacle_table([o.metrics for o in outcomes], _title(config))
    write_atomic(folder / "obstacles.md", table)
    report.plot_paths(
        [(s, run_scenario(s, replace(config, record=True))) for s in scenarios],
        folder / OBSTACLE_PATHS_FIGURE,
        f"obstacle study, {config.controller} controller, {config.plant} plant: paths",
        clearance=base_bubble(config_robot(config)),
    )
    print()
    print(table, end="")


def _run_arbiters(
    args: argparse.Namespace, config: RunConfig, runner: Runner, folder: Path
) -> None:
    """State machine vs competitive arbiter (scenarios/arbiter_study.py)."""
    from ddwmmr.scenarios import arbiter_study

    scenarios = generate(args.n, args.seed)
    study = arbiter_study.write_study(
        folder, scenarios, config, runner.run, runner.jobs, seed=args.seed
    )
    study.update(
        seed=args.seed, config=config_record(config), run=_record(args, config, runner.workers)
    )
    write_atomic(folder / MARKER, report.summary_json(study))
    print(study["table"], end="")


def config_record(config: RunConfig) -> dict[str, Any]:
    """``config`` as a batch's summary.json records it (``config``, and ``run.config``):
    its fields (``asdict``) without those its controller does not read, the thresholds
    and arbiter of :data:`ARBITER_FIELDS` for a controller with no arbiter (``qp``,
    ``mpc``) and a ``qp_*`` option for a controller that does not take it
    (:data:`QP_OPTIONS`). ``RunConfig(**record)`` runs the same batch: a field left out
    takes its default, which the controller ignores as it ignored the recorded value."""
    record = asdict(config)
    unused = [] if controller_traits(config.controller)["arbiter"] else list(ARBITER_FIELDS)
    if not config.arbiter_options and "arbiter_options" not in unused:
        unused.append("arbiter_options")  # a batch without them: recorded as before them
    unused += [name for name, takers in QP_OPTIONS.items() if config.controller not in takers]
    for name in unused:
        del record[name]
    return record


def batch_plugins(config: RunConfig) -> dict[str, dict[str, str]]:
    """The plug-ins a batch runs (:func:`ddwmmr.registry.used_plugins`): its controller,
    plant and, for a controller with an arbiter, the arbiter."""
    arbitrated = controller_traits(config.controller)["arbiter"]
    arbiters = [config.arbiter] if arbitrated and isinstance(config.arbiter, str) else []
    return used_plugins(method=[config.controller], plant=[config.plant], arbiter=arbiters)


def _record(args: argparse.Namespace, config: RunConfig, workers: int) -> dict[str, Any]:
    """summary.json["run"]: everything needed to repeat the batch, and how it ran: ``jobs``
    is the ``--jobs`` given (None: the default), ``workers`` the workers the batch ran on
    (:attr:`Runner.workers`)."""
    record = provenance.header("scenarios", PROG, args.argv, batch_plugins(config))
    record.update(
        config=provenance.encode(config_record(config)),
        n=args.n,
        seed=args.seed,
        study=args.study,
        obstacles=bool(args.obstacles),
        robot=provenance.robot_record(config_robot(config)),
        plant={"name": config.plant},
        executor=args.executor,
        jobs=args.jobs,
        workers=workers,
    )
    return record


def _bounds_table(
    args: argparse.Namespace, config: RunConfig
) -> dict[int, tuple[float, float]] | None:
    """``--bounds``: the file's ``{scenario: (lower, best)}``, checked against the run.

    Refused (one line) on another plant than the thesis plant: the lower bound prices the
    thesis plant's model, its wheels' force budget (docs/mpc.md, "The physical limit,
    bracketed"), which the kinematic plant does not have and MuJoCo's physics is not. A
    ``qp`` or ``mpc`` run whose floor on S (``--qp-stability-min``) is not the bounds
    run's gets a one-line note: its best-known times are for that floor (the lower bound
    holds for any)."""
    if args.bounds is None:
        return None
    given_text("bounds", args.bounds, "the path of a bounds run's bounds.csv")
    from ddwmmr.bounds.batch import bounds_floor, read_bounds_file

    if args.study or args.obstacles:
        raise ParameterError("bounds: only for the benchmark without a study or obstacles")
    if config.plant != "thesis":
        raise ParameterError(
            f"bounds: only with --plant thesis (got {config.plant}): the lower bound prices "
            "the thesis plant's wheel forces, so no other plant's time is bracketed by it"
        )
    table = read_bounds_file(args.bounds, args.seed, config.payload)
    if not set(table) & set(range(1, args.n + 1)):  # scenarios are numbered from 1
        span = "1" if args.n == 1 else f"1-{args.n}"
        run = f"scenario{'s' * (args.n > 1)} {span}"
        held = f"scenarios {_span(table)}" if table else "no scenario rows"
        raise ParameterError(
            f"bounds: {args.bounds} covers none of the run's {run} (it has {held}); "
            f"python -m ddwmmr.bounds --scenarios {span} makes them"
        )
    floor = bounds_floor(args.bounds)
    own = config.qp_stability_min if config.controller in QP_OPTIONS["qp_stability_min"] else None
    if None not in (floor, own) and floor != own:
        print(
            f"note: the best-known times of {args.bounds} hold S >= {floor:g}, "
            f"this run S >= {own:g} (--qp-stability-min): its ratios to them compare "
            "different problems (the lower bounds hold for any floor)",
            file=sys.stderr,
        )
    return table


def _span(table: dict[int, Any]) -> str:
    """``first-last`` of the scenario numbers of a bounds table (``n`` if only one)."""
    first, last = min(table), max(table)
    return str(first) if first == last else f"{first}-{last}"


def _main(argv: Sequence[str] | None = None) -> int:
    """Run the tool; bad input raises :class:`ParameterError`."""
    args = build_parser().parse_args(argv)
    args.argv = argv  # recorded in the summary
    config = config_from_arguments(args)
    _check_engine_step(config)
    args.bounds_table = _bounds_table(args, config)
    base, out, fresh = output_target(args.out, default_out)
    check_output_folder(out, "scenarios", args.force, output_names(args, config))
    if config.controller in ("qp", "mpc"):
        # their options are checked by building one for the plant, before any output or
        # worker: a bad one is one line and status 2, not an error in every scenario
        robot = config_robot(config)
        plant = make_scenario_plant(robot, config)
        controller = make_scenario_controller(robot, generate(1, args.seed)[0], config, plant)
        controller.adopt_plant(traits_of(plant))
    writer = output_folder(base, "scenarios", args.force, fresh)  # numbers from base if fresh
    with Runner(args) as runner, writer as folder:  # workers first, then the output
        if args.study == "thresholds":
            _run_thresholds(args, config, runner, folder)
        elif args.study == "obstacles":
            _run_obstacles(args, config, runner, folder)
        elif args.study == "arbiters":
            _run_arbiters(args, config, runner, folder)
        else:
            _run_benchmark(args, config, runner, folder)
    print(f"wrote {out.with_name(writer.path.name)}/")  # last on stdout, as every tool
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; bad input prints one line on stderr and returns 2."""
    return run_main(_main, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
