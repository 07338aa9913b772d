"""``python -m ddwmmr.track``: track one trajectory with one method and report.

Examples::

    python -m ddwmmr.track --method ats --traj ellipse
    python -m ddwmmr.track --method clrrmc-ts --traj rectangle --tau 0.3 --animate
    python -m ddwmmr.track --method qp --traj ellipse --payload 3 --stability-min 1.25
"""

from __future__ import annotations

import argparse
import json
import sys
import textwrap
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, TypeVar

from ddwmmr import provenance
from ddwmmr.cli.common import (
    ArgumentParser,
    add_force_argument,
    add_option_argument,
    add_plant_option_argument,
    add_robot_arguments,
    add_traj_scale_argument,
    built_plant,
    check_output_folder,
    check_plant_option_names,
    default_run_folder,
    given_text,
    horizon_defaults,
    horizon_range,
    method_options_text,
    number_type,
    offset_type,
    output_folder,
    output_target,
    parse_plant_options,
    robot_from_arguments,
    run_main,
    run_method_options,
    scaled_trajectory,
    seconds_type,
)
from ddwmmr.controllers.base import (
    available_methods,
    make_controller,
    method_description,
    method_options,
)
from ddwmmr.controllers.option_specs import parse_options
from ddwmmr.controllers.presets import PRESETS, preset_options
from ddwmmr.errors import (
    MAX_COST_WEIGHT,
    ParameterError,
    check_range,
    check_step_count,
    read_text_file,
    shown,
)
from ddwmmr.gains import GAIN_STEP_MARGIN, STABLE_GAIN_STEP, TAU_RANGE
from ddwmmr.model.stability import STABILITY_CAP
from ddwmmr.plants import available_plants, plant_description
from ddwmmr.plants.base import Plant
from ddwmmr.plants.kinematic import INTEGRATORS
from ddwmmr.progress import ProgressBar, phase
from ddwmmr.provenance import RunInputs, run_record
from ddwmmr.registry import PLANTS, check_recorded_plugins, unknown_hint
from ddwmmr.reports.metrics import METRICS
from ddwmmr.resolution.reference import (
    DEFAULT_INITIAL_OFFSET,
    default_offset,
    initial_configuration,
)
from ddwmmr.sim.simulate import (
    build_plant,
    check_start,
    check_tracks,
    default_step,
    plant_integrator,
    simulate,
)
from ddwmmr.trajectories import ScaledTrajectory, available_trajectories, load_trajectory
from ddwmmr.trajectories.files import find_obstacle_file, find_trajectory_file

PROG = provenance.TRACK_PROG
#: A recorded field's type (:func:`_field`).
_T = TypeVar("_T")
#: The default plant (``--plant``), and the plant of a record that names none.
PLANT = "kinematic"
#: ``--offset``'s default for the default robot, as written on the command line (m).
_DEFAULT_OFFSET_TEXT = f"{DEFAULT_INITIAL_OFFSET[0]:.2f} {DEFAULT_INITIAL_OFFSET[1]:.2f}"
#: What ``--tau`` and ``--dt`` say of the warning :func:`ddwmmr.gains.gain_step_warning`
#: prints before a run whose step is too coarse for its gains.
GAIN_STEP_WARNING_HELP = (
    f"a run whose largest K dt = dt/tau reaches {GAIN_STEP_MARGIN:g} of its loop's "
    f"stability limit ({STABLE_GAIN_STEP['hold']:g} with commands held over the step, "
    f"{STABLE_GAIN_STEP['rk4']:.4g} under rk4) is warned about "
    '(docs/theory.md, "Error dynamics and python-control")'
)
#: Tools whose summary.json records ``--rerun`` repeats: this one and the simulator's
#: data export (``python -m ddwmmr.gui``).
RERUN_TOOLS = ("track", "gui")
#: Options that fix what is simulated: they come from the record with --rerun.
RUN_OPTIONS = (
    "method", "traj", "traj_scale", "aux", "tau", "dt", "duration", "integrator", "offset",
    "robot", "plant", "payload", "stability_min", "manipulability_weight", "obstacles",
    "solver", "qp_mode", "preset", "horizon", "option", "plant_option",
)  # fmt: skip

#: Keys printed in the summary table, in order, each with its long label, unit and scale
#: (:data:`ddwmmr.reports.metrics.METRICS`; errors in mm, as in compare): every metric but
#: the mean manipulability, a column of compare's table only. A key the run's
#: summary lacks (or holds None) is left out: the support keys show on a plant that reports
#: them (MuJoCo), the predicted edge load where the controller's limit is on.
TABLE_KEYS = tuple(key for key in METRICS if key != "mean_manipulability")
#: Width of the table's label column: the longest label and a space, so the values align.
LABEL_WIDTH = 36

#: CLI option -> controller keyword; a method takes the option if its constructor has the
#: keyword (:func:`ddwmmr.controllers.base.method_options`), any other refuses it.
METHOD_OPTIONS = {
    "aux": "aux",
    "tau": "tau",
    "stability_min": "stability_min",
    "manipulability_weight": "manipulability_weight",
    "obstacles": "obstacles",
    "solver": "solver",
    "qp_mode": "mode",
    "horizon": "horizon",
}


#: Flags named for one method: only it takes them, whatever other controller (a plug-in's)
#: has a keyword of the same name (a plug-in's own ``mode`` is not the qp's).
FLAG_METHODS = {"qp_mode": ("qp",)}


def _methods_taking(keyword: str, attribute: str | None = None) -> list[str]:
    """Registered methods whose options include the controller keyword ``keyword`` (and,
    for a flag of :data:`FLAG_METHODS`, ``attribute``, only its methods)."""
    only = FLAG_METHODS.get(attribute or "")
    return [
        m
        for m in available_methods()
        if keyword in method_options(m) and (only is None or m in only)
    ]


def _either(names: Sequence[str]) -> str:
    """``a``, ``a or b``, ``a, b or c``."""
    return " or ".join([", ".join(names[:-1]), names[-1]] if len(names) > 1 else names)


def _option_help(
    text: str, keyword: str, default: str | None = None, attribute: str | None = None
) -> str:
    """``text`` with the default of each method taking ``keyword`` (or ``default``, for
    an option whose signature has None: chosen when the run starts) and those methods
    (``attribute``: the flag, for :data:`FLAG_METHODS`)."""
    defaults = {
        m: _default_text(method_options(m)[keyword]) for m in _methods_taking(keyword, attribute)
    }
    if default is not None:
        return f"{text} (default {default}) [{', '.join(defaults)}]"
    if len(set(defaults.values())) == 1:
        default = next(iter(defaults.values()))
    else:
        default = ", ".join(f"{value} for {m}" for m, value in defaults.items())
    return f"{text} (default {default}) [{', '.join(defaults)}]"


def _default_text(value: Any) -> str:
    """An option default as --help shows it (an empty sequence is none)."""
    if isinstance(value, list | tuple) and not value:
        return "none"
    return f"{value:g}" if isinstance(value, float) else str(value)


class _Formatter(argparse.HelpFormatter):
    """Help as argparse wraps it, except the epilog's lines after the first paragraph (the
    options of each method), kept one method per line."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        first, _, rest = text.partition("\n\n")
        filled = super()._fill_text(first, width, indent)
        lines = [
            textwrap.fill(line, width, initial_indent=indent, subsequent_indent=indent + "    ")
            for line in rest.splitlines()
        ]
        return "\n\n".join([filled, "\n".join(lines)]) if rest else filled


def build_parser() -> ArgumentParser:
    """The argument parser; docs/cli.md documents each option (tests/test_cli_docs.py)."""
    methods = available_methods()
    method_help = "; ".join(f"{m}: {method_description(m).rstrip('.')}" for m in methods)
    parser = ArgumentParser(
        prog=PROG,
        description=(
            "Simulate a differential-drive mobile manipulator tracking a desired end-effector "
            "trajectory with one redundancy-resolution / control method. Writes "
            "timeseries.csv, summary.json and figures into --out and prints a summary table "
            "(errors in mm). summary.json records everything needed to repeat the run: "
            f"`{PROG} --rerun DIR/summary.json` reproduces it bit for bit on the same "
            "machine and library build (elsewhere to rounding)."
        ),
        epilog=f"Methods - {method_help}.\n\n{method_options_text(methods)}",
        formatter_class=_Formatter,
    )
    parser.add_argument(
        "--method", choices=methods, help="control method (required unless --rerun)"
    )
    parser.add_argument(
        "--traj",
        metavar="NAME|FILE",
        help=f"trajectory name ({', '.join(available_trajectories())}) or a .toml/.csv path "
        "(required unless --rerun)",
    )
    add_traj_scale_argument(parser, "the trajectory")
    parser.add_argument(
        "--rerun",
        metavar="SUMMARY",
        help="repeat the run a summary.json records (method, options, robot, trajectory, "
        "step...); only the output options may be given with it",
    )
    parser.add_argument(
        "--aux",
        choices=("sum", "shoulder"),
        help="auxiliary row of the augmented Jacobian: sum (th1dot + th2dot = 0) or "
        "shoulder (th1dot = 0, default) [ats, clrrmc-ts, clrrmc-cs]",
    )
    parser.add_argument(
        "--tau",
        type=number_type(TAU_RANGE),
        nargs="+",
        metavar="S",
        help="closed-loop time constant(s) in s, K = 1/tau: one value, or 3 (x, y, phi) for "
        "clrrmc-ts and qp (its tracking task), 5 (x, y, phi, th1, th2) for clrrmc-cs; inf "
        "disables a channel (default 0.5) [clrrmc-ts, clrrmc-cs, qp]; "
        f"{GAIN_STEP_WARNING_HELP}",
    )
    parser.add_argument(
        "--preset",
        choices=PRESETS,
        help="option values: default (the library's, the default) or slides (the slides' "
        "settings: aux sum, no orientation feedback for clrrmc-ts); explicit options "
        "override it",
    )
    parser.add_argument(
        "--dt",
        type=seconds_type,
        metavar="S",
        help="control and integration step in s (default: T/N of a parametric trajectory, "
        "0.02 s for the shipped ones; for a CSV the rows' spacing, made no coarser than "
        "0.02 s, as in the API; on mujoco a whole number of engine steps); "
        f"{GAIN_STEP_WARNING_HELP}",
    )
    parser.add_argument(
        "--duration",
        type=seconds_type,
        metavar="S",
        help="simulated time in s (default one period)",
    )
    parser.add_argument(
        "--plant",
        choices=available_plants(),
        help=f"what the commands drive (default {PLANT}): "
        + "; ".join(f"{p}: {plant_description(p).rstrip('.')}" for p in available_plants()),
    )
    parser.add_argument(
        "--integrator",
        choices=INTEGRATORS,
        help="integrator of the kinematic plant (default rk4; other plants integrate their "
        "own dynamics)",
    )
    add_plant_option_argument(parser)
    parser.add_argument(
        "--offset",
        type=offset_type,
        nargs=2,
        metavar=("DX", "DY"),
        help="initial end-effector offset in m, in the end effector's start frame (x along "
        f"its start orientation), applied with the arm (default {_DEFAULT_OFFSET_TEXT} times "
        f"the robot's length unit L1/0.35 m: {_DEFAULT_OFFSET_TEXT} for the default robot)",
    )
    add_robot_arguments(parser)
    qp = parser.add_argument_group(
        "QP and MPC controller options (in brackets: the methods taking each)"
    )
    qp.add_argument(
        "--stability-min",
        type=number_type(f"in (0, {STABILITY_CAP:g})"),
        metavar="S",
        help=_option_help(
            f"hard floor on the tip-over stability margin S (S <= 1 tips over), in (0, "
            f"{STABILITY_CAP:g})",
            "stability_min",
        ),
    )
    qp.add_argument(
        "--manipulability-weight",
        type=number_type(f"in [0, {MAX_COST_WEIGHT:g}]"),
        metavar="W",
        help=_option_help("weight of the manipulability reward", "manipulability_weight"),
    )
    qp.add_argument(
        "--obstacles",
        metavar="NAME|FILE",
        help=_option_help(
            "circles to avoid: a TOML file of [[obstacle]] tables x, y, radius (m), or the "
            "name of a shipped one (ellipse_post); drawn in path.png",
            "obstacles",
        ),
    )
    qp.add_argument(
        "--solver",
        help=_option_help(
            "qp: a qpsolvers backend (osqp, daqp, quadprog, proxqp, clarabel...); mpc: its "
            "NLP solver (rti, sqp, ipopt...)",
            "solver",
        ),
    )
    qp.add_argument(
        "--qp-mode",
        choices=("weighted", "hierarchical"),
        help=_option_help("priority handling", "mode", attribute="qp_mode"),
    )
    qp.add_argument(
        "--horizon",
        type=number_type(horizon_range()),
        metavar="S",
        help=_option_help(
            "prediction horizon in s (docs/mpc.md, Options)",
            "horizon",
            "{:g} s for tracking, {:g} s for waypoints".format(*horizon_defaults()),
        ),
    )
    add_option_argument(qp, "any option of --method, not only those with a flag")
    out = parser.add_argument_group("output")
    out.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default runs/<method>-<traj>-<time>/, never replacing anything: "
        "-2, -3... when taken)",
    )
    add_force_argument(out)
    out.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    out.add_argument("--animate", action="store_true", help="also write animation.gif")
    out.add_argument("--no-progress", action="store_true", help="no progress output on stderr")
    return parser


def controller_options(args: argparse.Namespace) -> dict[str, Any]:
    """Controller keyword arguments from the CLI options that were given: the named flags
    and ``--option [METHOD:]NAME=VALUE`` (METHOD: the run's, :func:`run_method_options`;
    one option may not be given both ways)."""
    options: dict[str, Any] = {}
    for attribute, keyword in METHOD_OPTIONS.items():
        value = getattr(args, attribute)
        if value is None:
            continue
        takers = _methods_taking(keyword, attribute)
        if args.method not in takers:
            flag = "--" + attribute.replace("_", "-")
            raise ParameterError(
                f"{flag[2:]}: {flag} is taken only by --method "
                f"{_either(takers) or '(none)'} (got --method {args.method})"
            )
        if attribute == "obstacles":
            given_text("obstacles", value, "a shipped obstacle name or a TOML file", "text")
        if attribute == "tau" and len(value) == 1:
            value = value[0]
        options[keyword] = value
    flags = {keyword: attribute for attribute, keyword in METHOD_OPTIONS.items()}
    texts = run_method_options(args.option, args.method, "--method")
    for name, value in parse_options(args.method, texts).items():
        if name in options:
            flag = "--" + flags[name].replace("_", "-")
            raise ParameterError(f"option: {name} is given both as {flag} and as --option")
        options[name] = value
    if isinstance(options.get("obstacles"), str):  # a name or a file: the circles
        from ddwmmr.qp.limits.obstacles import load_obstacles

        circles = load_obstacles(find_obstacle_file(options["obstacles"]))
        options["obstacles"] = [(c.x, c.y, c.radius) for c in circles]  # plain: recordable
    return options


def default_out(method: str, traj: str) -> Path:
    """``runs/<method>-<traj>-<YYYYmmdd-HHMMSS>`` (:func:`default_run_folder`)."""
    return default_run_folder(f"{method}-{Path(traj).stem}")


def format_table(summary: dict[str, Any]) -> str:
    """The summary as an aligned two-column text table (lengths in mm), then the run's
    verdict (:mod:`ddwmmr.sim.verdict`)."""
    plant = summary.get("plant", PLANT)
    lines = [f"{summary['method']} on {summary['trajectory']} ({plant} plant)"]
    for key in TABLE_KEYS:
        if summary.get(key) is not None:
            metric = METRICS[key]
            value = metric.shown(summary[key])
            text = f"{value:.6g}" if isinstance(value, float) else str(value)
            lines.append(f"  {metric.long_label:<{LABEL_WIDTH}} {text}")
    if "verdict" in summary:
        lines.append(textwrap.fill(f"verdict: {summary['verdict']}", 100, subsequent_indent="  "))
    return "\n".join(lines)


def inputs_from_arguments(args: argparse.Namespace) -> RunInputs:
    """Validated inputs from the command-line options."""
    missing = [
        flag for flag, given in (("--method", args.method), ("--traj", args.traj)) if given is None
    ]
    if missing:
        # both named at once: a newcomer should not learn them one refusal at a time
        verb = "is" if len(missing) == 1 else "are"
        raise ParameterError(
            f"{missing[0].lstrip('-')}: {' and '.join(missing)} {verb} required, e.g. "
            "--method ats --traj ellipse (or give --rerun)"
        )
    plant = args.plant or PLANT
    robot = robot_from_arguments(args, (plant,))
    source = find_trajectory_file(args.traj)
    trajectory = scaled_trajectory(load_trajectory(args.traj), args.traj_scale, robot)
    # The preset's values, then the explicit options (they win): the record keeps them all.
    options = {**preset_options(args.method, args.preset or "default"), **controller_options(args)}
    plant_options = parse_plant_options(plant, args.plant_option)
    duration = trajectory.duration if args.duration is None else args.duration
    step = default_step(trajectory, plant, robot, plant_options) if args.dt is None else args.dt
    if args.dt is None and 0 < duration < step:  # the user gave --duration, not --dt
        raise ParameterError(
            f"duration must be >= one step, {step:g} s (the trajectory's T/N; or give a "
            f"smaller --dt) (got {duration:g})"
        )
    offset = default_offset(robot) if args.offset is None else tuple(args.offset)
    inputs = RunInputs(
        args.method,
        options,
        robot,
        trajectory,
        source,
        step,
        duration,
        plant_integrator(plant, args.integrator),
        offset,
        args.traj,
        plant,
        plant_options=plant_options,
    )
    # a newcomer who gave no --offset must not read that theirs is wrong
    start = "--offset" if args.offset is not None else "the default --offset"
    return check_run(inputs, "payload" if args.payload is not None else "robot", start)


def check_run(inputs: RunInputs, holder: str, start: str) -> RunInputs:
    """``inputs`` if a run of them is within what the tool accepts, else a one-line
    :class:`ParameterError`: the checks every run passes, from options or from a record
    (``--rerun``), which is only as trustworthy as the file it was read from.

    The step count (duration, dt: finite, > 0, at most MAX_STEPS steps), the integrator
    for the plant, the plant's options (their values, in the plant's words), the offset
    within the arm's reach, obstacles within the command-line limits, and a start that
    neither tips the robot (S > 1) nor overlaps an obstacle.
    ``holder`` (what holds the payload) and ``start`` (what sets the start pose) word the
    tipping message; ``start`` also names the offset the arm cannot reach. The result
    carries ``dt`` and ``duration`` as the floats checked (a record may hold an integer)."""
    check_step_count(inputs.duration, inputs.dt)
    inputs = replace(inputs, dt=float(inputs.dt), duration=float(inputs.duration))
    plant_integrator(inputs.plant, inputs.integrator)
    if inputs.plant_options:  # a value the plant refuses: its own line, before the run
        built_plant(inputs.plant, inputs.robot, inputs.plant_options)
    if inputs.integrator is not None and inputs.integrator not in INTEGRATORS:
        raise ParameterError(
            f"integrator must be one of {', '.join(INTEGRATORS)} (got {shown(inputs.integrator)})"
        )
    robot = inputs.robot
    if len(inputs.offset) != 2:
        raise ParameterError(f"offset must be two numbers dx dy in m (got {shown(inputs.offset)})")
    for value in inputs.offset:
        check_range("offset", value, -robot.reach, robot.reach, "m (the arm's reach)")
    obstacles = inputs.options.get("obstacles") or ()
    if obstacles:
        from ddwmmr.qp.limits.obstacles import as_circles, within_limits

        obstacles = [within_limits(c.x, c.y, c.radius) for c in as_circles(obstacles)]
    # a start that tips the robot or sits in an obstacle is bad input
    q0 = initial_configuration(robot, inputs.trajectory, inputs.offset, name=start)
    check_start(robot, q0, obstacles, holder, start)
    return inputs


def inputs_from_record(args: argparse.Namespace) -> RunInputs:
    """The inputs a summary.json records (``--rerun``); simulation options are refused."""
    given = [name for name in RUN_OPTIONS if getattr(args, name) is not None]
    if given:
        option = "--" + given[0].replace("_", "-")
        raise ParameterError(
            f"rerun: {option} cannot be combined with --rerun (the record fixes it)"
        )
    given_text("rerun", args.rerun, "the path of a summary.json")
    record = load_run_record(args.rerun)
    try:
        check_recorded_plugins(record.get("plugins"))  # before "unknown method"
        plant_record = _field(record, "plant", dict, "plant")
        plant = _inside("plant", lambda: _field(plant_record, "name", str, "plant name"))
        if plant not in available_plants():
            raise ParameterError(
                f"plant {plant!r} is not supported by this version"
                + unknown_hint(plant, available_plants())
            )
        trajectory_record = _field(record, "trajectory", dict, "trajectory")
        trajectory, source, file_note = _inside(
            "trajectory", lambda: provenance.read_trajectory_record(trajectory_record)
        )
        base_record = provenance.base_trajectory_record(trajectory_record)
        offset = tuple(provenance.decode(_field(record, "initial_offset", list, "offset")))
        inputs = RunInputs(
            _field(record, "method", str, "method name"),
            provenance.decode(_field(record, "options", dict, "options")),
            provenance.robot_from_record(_field(record, "robot", dict, "robot")),
            trajectory,
            source,
            record["dt"],  # checked by check_run, as --dt and --duration are
            record["duration"],
            _integrator(record, plant),
            offset,
            str(base_record.get("name") or "rerun"),
            plant,
            _recorded_digest(base_record, base_record.get("file")),
            _plant_options(plant_record, plant),
        )
        checked = check_run(inputs, "payload", "the recorded initial_offset")
    except ParameterError as exc:  # one line naming what is wrong: say where it was read
        raise _in_record(args.rerun, exc) from None
    except KeyError as exc:
        raise ParameterError(
            f"rerun: {args.rerun} is not a complete run record (field run.{exc.args[0]} is missing)"
        ) from None
    except (TypeError, AttributeError, ValueError) as exc:
        raise ParameterError(f"rerun: {args.rerun} lacks a complete run record ({exc})") from None
    if file_note is not None:
        print(f"note: {file_note}", file=sys.stderr)
    _note_other_software(record)
    return checked


def _note_other_software(record: dict[str, Any]) -> None:
    """Say so (one line, stderr) when the record was written by other software or on another
    CPU than this rerun runs on (:func:`~ddwmmr.provenance.software_differences`): the rerun
    still runs, but its numbers may then differ from the record's in the last bits."""
    differences = provenance.software_differences(record)
    if differences:
        print(
            f"note: the record was written with other software or on another CPU "
            f"({', '.join(differences)}): the rerun's numbers may differ from the recorded "
            "run's in the last bits",
            file=sys.stderr,
        )


def _recorded_digest(trajectory_record: dict[str, Any], source: Any) -> str | None:
    """The SHA-256 the record gives its trajectory file (a record naming a file must)."""
    if not (isinstance(source, str) and source):
        return None
    digest: str | None = _inside(
        "trajectory", lambda: provenance.recorded_sha256(trajectory_record)
    )
    return digest


def _in_record(path: str, exc: ParameterError) -> ParameterError:
    """``exc``, a refusal of what the record at ``path`` holds, naming that file
    (``rerun: FILE: ...``) unless it already does."""
    text = str(exc)
    return ParameterError(text if text.startswith("rerun:") else f"rerun: {path}: {text}")


def _inside(section: str, read: Callable[[], Any]) -> Any:
    """``read()``; a field it misses is named inside ``section`` (``trajectory.type``)."""
    try:
        return read()
    except KeyError as exc:
        raise KeyError(f"{section}.{exc.args[0]}") from None


def _field(record: dict[str, Any], key: str, kind: type[_T], what: str) -> _T:
    """``record[key]`` if it is a ``kind`` (KeyError when missing, TypeError otherwise)."""
    value = record[key]
    if not isinstance(value, kind) or isinstance(value, bool):
        raise TypeError(f"{key}: the {what} must be a {kind.__name__}, got {shown(value)}")
    return value


def _plant_options(plant_record: dict[str, Any], plant: str) -> dict[str, Any]:
    """The plant's options the record gives (``plant.options``; none in a record of a run
    on the plant's defaults), their names checked as ``--plant-option``'s are (the values
    by the plant, :func:`check_run`)."""
    if "options" not in plant_record:
        return {}
    options: dict[str, Any] = provenance.decode(
        _field(plant_record, "options", dict, "plant options")
    )
    check_plant_option_names(plant, options)
    return options


def _integrator(record: dict[str, Any], plant: str) -> str | None:
    """The recorded integrator: a name on the kinematic plant, null on the others."""
    if plant != "kinematic" and record["integrator"] is None:
        return None
    return _field(record, "integrator", str, "integrator name")


def load_run_record(path: str) -> dict[str, Any]:
    """The ``run`` record of a track summary.json."""
    text = read_text_file(path, "rerun")
    try:
        summary = json.loads(text)
    except ValueError as exc:
        raise ParameterError(f"rerun: {path} is not valid JSON ({exc})") from None
    except RecursionError:
        raise ParameterError(f"rerun: {path} is not a run record (nested too deeply)") from None
    record = summary.get("run") if isinstance(summary, dict) else None
    if not isinstance(record, dict) or record.get("tool") not in RERUN_TOOLS:
        raise ParameterError(
            f"rerun: {path} is not a summary.json written by {PROG} or exported by the simulator"
        )
    version = record.get("record_version")
    if type(version) is not int or version != provenance.RECORD_VERSION:
        raise ParameterError(
            f"rerun: {path} holds a run record of version {shown(version)}; this version of "
            f"ddwmmr reruns version {provenance.RECORD_VERSION}"
        )
    return record


def output_names(plots: bool, animate: bool, physics: bool = False) -> tuple[str, ...]:
    """The files a run writes (checked against a user's files before the run, --force);
    ``physics``: on a plant that judges tipping by its contact forces (support_loads.png)."""
    names = ("timeseries.csv", "summary.json", *(("animation.gif",) if animate else ()))
    if not plots:
        return names
    from ddwmmr.reports.physics_plots import SUPPORT_LOADS_FIGURE
    from ddwmmr.reports.plots import FIGURE_NAMES  # matplotlib: only for runs that plot

    return (*names, *FIGURE_NAMES, *((SUPPORT_LOADS_FIGURE,) if physics else ()))


def run_plant(inputs: RunInputs) -> Plant:
    """The plant of ``inputs``, built once as ``simulate`` builds it
    (:func:`~ddwmmr.sim.simulate.build_plant`) and passed to it; a control step it will
    refuse when the run starts (MuJoCo: not a whole number of engine steps) is refused now,
    in its own words: before the duration note and the output folder, so bad input is one
    line."""
    plant = build_plant(inputs.plant, inputs.robot, inputs.integrator, inputs.plant_options)
    check_control_step = getattr(plant, "check_control_step", None)
    if check_control_step is not None:
        check_control_step(inputs.dt)
    return plant


def _note_uneven_duration(duration: float, dt: float, steps: int) -> None:
    """Say so (stderr) when the run does not last the duration asked for: ``duration`` (s)
    is not a whole number of steps ``dt`` (s), and the run takes the nearest, ``steps``."""
    covered = steps * dt
    if abs(covered - duration) > 1e-9 * duration:
        print(
            f"note: duration {duration:g} s is not a whole number of steps of dt "
            f"{dt:g} s; the run lasts {steps} steps, {covered:.6g} s",
            file=sys.stderr,
        )


def _note_unscaled_obstacles(options: dict[str, Any]) -> None:
    """Say so (stderr) when a scaled trajectory's run has obstacles: they are circles in
    world metres, which ``--traj-scale`` does not move or resize."""
    if options.get("obstacles"):
        print(
            "note: --traj-scale scales the trajectory only; the obstacles stay as given, in "
            "world metres",
            file=sys.stderr,
        )


def _main(argv: Sequence[str] | None = None) -> int:
    """Run the tool; bad input raises :class:`ParameterError`."""
    args = build_parser().parse_args(argv)
    inputs = inputs_from_record(args) if args.rerun is not None else inputs_from_arguments(args)
    steps = check_step_count(inputs.duration, inputs.dt)  # before anything is allocated
    try:
        check_tracks(inputs.method)  # a recorded method must track, too
        controller = make_controller(inputs.method, inputs.robot, **inputs.options)
    except ParameterError as exc:  # a recorded method or option: name the record
        if args.rerun is None:
            raise
        raise _in_record(args.rerun, exc) from None
    plant = run_plant(inputs)
    base, out, fresh = output_target(args.out, lambda: default_out(inputs.method, inputs.label))
    physics = hasattr(PLANTS.load(inputs.plant), "tip_time")  # judges tipping: support loads
    names = output_names(not args.no_plots, args.animate, physics)
    check_output_folder(out, "track", args.force, names)
    record = run_record(inputs, argv, args.rerun, tool="track", prog=PROG)
    if isinstance(inputs.trajectory, ScaledTrajectory):
        _note_unscaled_obstacles(inputs.options)
    progress = not args.no_progress
    _note_uneven_duration(inputs.duration, inputs.dt, steps)
    writer = output_folder(base, "track", args.force, fresh)  # numbers from base if fresh
    with writer as staging:
        with ProgressBar(steps, "track: steps", enabled=progress, unit="step") as bar:
            result = simulate(
                inputs.robot,
                inputs.trajectory,
                controller,
                dt=inputs.dt,
                duration=inputs.duration,
                plant=plant,
                initial_offset=inputs.offset,
                progress=lambda k, n: bar.advance(),
            )
        with phase("track: writing timeseries.csv, summary.json", enabled=progress):
            result.write_csv(staging / "timeseries.csv")
            result.write_summary(staging / "summary.json", run=record)
        if not args.no_plots:
            from ddwmmr.reports.plots import save_run_figures

            with phase("track: figures", enabled=progress):
                save_run_figures(result, staging, obstacles=inputs.options.get("obstacles"))
                from ddwmmr.reports import physics_plots

                if physics_plots.is_physics_run(result):
                    figure = staging / physics_plots.SUPPORT_LOADS_FIGURE
                    physics_plots.save_support_loads(result, figure)
        if args.animate:
            from ddwmmr.reports.plots import save_animation

            save_animation(
                result,
                staging / "animation.gif",
                obstacles=inputs.options.get("obstacles"),
                progress=progress,
            )
    print(format_table(result.summary))
    print(f"wrote {out.with_name(writer.path.name)}/")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; bad input prints one line on stderr and returns 2."""
    return run_main(_main, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
