"""Every method's every option from the command lines: ``--option NAME=VALUE`` on track,
compare and scenarios (parsed as the simulator's fields are), and the named flags."""

import json
import os
import subprocess
import sys

import pytest

from ddwmmr.cli.compare import build_parser as compare_parser
from ddwmmr.cli.compare import main as compare
from ddwmmr.cli.compare import parse_method_options
from ddwmmr.cli.gui import main as gui
from ddwmmr.cli.scenarios import build_parser as scenarios_parser
from ddwmmr.cli.scenarios import config_from_arguments
from ddwmmr.cli.scenarios import main as scenarios
from ddwmmr.cli.track import build_parser as track_parser
from ddwmmr.cli.track import controller_options
from ddwmmr.cli.track import main as track
from ddwmmr.controllers import available_methods, method_options
from ddwmmr.controllers.option_specs import option_names, option_specs
from ddwmmr.errors import ParameterError

#: Options only the API can set: Python objects no text stands for (stated here, so a
#: new option that the command line cannot reach fails the test below).
# route: a list of points, filled in by the scenario protocol (`--option lookahead=on`)
API_ONLY = {"qp": {"tasks", "limits"}, "mpc": {"fallback_options", "route"}}


@pytest.mark.parametrize("method", available_methods())
def test_every_option_of_every_method_is_reachable_from_track(method):
    """Each option's default, written as text, parses back to itself through --option."""
    assert set(method_options(method)) - set(option_names(method)) == API_ONLY.get(method, set())
    for spec in option_specs(method):
        text = spec.format(spec.default)
        if spec.default is None and spec.kind == "number":
            text = "auto"  # the automatic value's word: an empty value is refused
        if not text:  # a text option's empty default: said by leaving the option out
            continue
        argv = ["--method", method, "--traj", "ellipse", "--option", f"{spec.name}={text}"]
        options = controller_options(track_parser().parse_args(argv))
        assert options == {spec.name: spec.default}, spec.name


def test_the_mpc_horizon_from_a_flag_and_from_option_is_the_same_run(tmp_path):
    runs = {}
    for label, extra in (("flag", ["--horizon", "2"]), ("option", ["--option", "horizon=2"])):
        out = tmp_path / label
        argv = ["--method", "mpc", "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
        assert track([*argv, "--no-progress", "--out", str(out), *extra]) == 0
        runs[label] = json.loads((out / "summary.json").read_text())
    assert runs["flag"]["mpc_horizon_s"] == runs["option"]["mpc_horizon_s"] == 2.0
    assert runs["flag"]["run"]["options"]["horizon"] == 2.0
    assert runs["flag"]["rms_position_error_m"] == runs["option"]["rms_position_error_m"]


def test_a_tuple_option_matches_its_flag():
    base = ["--method", "clrrmc-ts", "--traj", "rectangle"]
    by_flag = controller_options(track_parser().parse_args([*base, "--tau", "0.5", "0.5", "inf"]))
    by_text = controller_options(track_parser().parse_args([*base, "--option", "tau=0.5,0.5,inf"]))
    assert by_flag == {"tau": [0.5, 0.5, float("inf")]}
    assert tuple(by_flag["tau"]) == by_text["tau"] == (0.5, 0.5, float("inf"))


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (
            ["--option", "horizn=2"],
            "error: option: mpc has no option 'horizn' (did you mean horizon?) (options: model, ",
        ),
        (["--option", "horizon"], "error: option must be NAME=VALUE (got 'horizon')"),
        (
            ["--option", "horizon=soon"],
            "error: horizon must be a finite number in [0.0001, 100] s (got 'soon')",
        ),
        (
            ["--horizon", "2", "--option", "horizon=3"],
            "error: option: horizon is given both as --horizon and as --option",
        ),
    ],
)
def test_a_wrong_option_is_one_line_naming_the_accepted_ones(tmp_path, capsys, extra, message):
    out = tmp_path / "out"
    argv = ["--method", "mpc", "--traj", "ellipse", "--no-plots", "--out", str(out), *extra]
    assert track(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and err.count("\n") == 1 and not out.exists()


def test_the_horizon_flag_is_refused_by_a_method_without_one(tmp_path, capsys):
    assert track(["--method", "ats", "--traj", "ellipse", "--horizon", "2"]) == 2
    assert "horizon: --horizon is taken only by --method mpc" in capsys.readouterr().err


@pytest.mark.parametrize("parser", [track_parser, compare_parser, scenarios_parser])
def test_help_lists_the_options_of_each_method(parser):
    text = parser().format_help()
    assert "--option NAME=VALUE" in text and "--horizon S" in text
    assert "options of each method (--option NAME=VALUE" in text
    assert "  mpc: model, stability_min, manipulability_weight" in text
    if parser is not scenarios_parser:
        assert "  ats: aux, singularity_threshold, damping" in text


def test_track_and_scenarios_take_method_colon_name_for_their_method():
    """``METHOD:NAME=VALUE``, which compare takes, was refused by track ("mpc has no option
    'mpc:horizon'"): it now means NAME=VALUE when METHOD is the run's, and names the run's
    method when it is another's. A value's colon does not mark a method."""
    base = ["--method", "mpc", "--traj", "ellipse"]
    args = track_parser().parse_args([*base, "--option", "mpc:horizon=2", "--option", "aux=sum"])
    with pytest.raises(ParameterError, match=r"^option: mpc has no option 'aux'"):
        controller_options(args)  # NAME=VALUE alone stays as it was
    args = track_parser().parse_args([*base, "--option", "mpc:horizon=2"])
    assert controller_options(args) == {"horizon": 2.0}
    args = track_parser().parse_args([*base, "--option", "qp:tau=0.3"])
    with pytest.raises(ParameterError) as error:
        controller_options(args)
    assert str(error.value) == (
        "option: 'qp' is not the method of this run (--method mpc); METHOD:NAME=VALUE takes "
        "mpc:NAME=VALUE or NAME=VALUE (got 'qp:tau=0.3')"
    )
    argv = ["--controller", "thesis", "--option", "thesis:adjust=0.3"]
    config = config_from_arguments(scenarios_parser().parse_args(argv))
    assert config.controller_options == (("adjust", 0.3),)
    argv = ["--controller", "thesis", "--option", "qp:tau=0.3"]
    with pytest.raises(ParameterError, match=r"^option: 'qp' is not the method of this run \(--c"):
        config_from_arguments(scenarios_parser().parse_args(argv))


def test_the_method_prefix_of_an_option_is_read_in_one_place():
    from ddwmmr.cli.common import option_target

    assert option_target("mpc:horizon=2") == ("mpc", "horizon=2")
    assert option_target("plan=C:/runs") == (None, "plan=C:/runs")
    assert option_target("horizon=2") == (None, "horizon=2")


def test_compare_options_go_to_the_methods_that_take_them():
    methods = ("pi", "clrrmc-ts", "mpc")
    options = parse_method_options(["tau=0.3", "pi:damping=0.1"], methods, horizon=2.0)
    assert options == {"pi": {"damping": 0.1}, "clrrmc-ts": {"tau": 0.3}, "mpc": {"horizon": 2.0}}
    with pytest.raises(ParameterError, match=r"^option: no compared method takes 'tua' \(did yo"):
        parse_method_options(["tua=0.3"], methods)
    with pytest.raises(ParameterError, match=r"^option: 'qp' is not a compared method"):
        parse_method_options(["qp:tau=0.3"], methods)
    with pytest.raises(ParameterError, match=r"^option: pi has no option 'tau'"):
        parse_method_options(["pi:tau=0.3"], methods)


def test_compare_runs_carry_the_options_except_where_a_study_sets_its_own():
    from ddwmmr.reports.compare.plan import CompareConfig, plan_runs
    from ddwmmr.trajectories import load_trajectory

    config = CompareConfig(
        methods=("clrrmc-ts",),
        trajectories={"ellipse": load_trajectory("ellipse")},
        studies=("tau",),
        options={"clrrmc-ts": {"tau": 0.3, "damping": 0.1}},
    )
    plan = plan_runs(config)
    assert dict(plan.main[0].options) == {"tau": 0.3, "damping": 0.1}
    swept = {dict(spec.options)["tau"] for spec in plan.studies["tau"]}
    assert 0.3 not in swept or len(swept) > 1  # the study's own values win there
    assert all(dict(spec.options)["damping"] == 0.1 for spec in plan.studies["tau"])


def test_compare_records_the_options(tmp_path):
    from ddwmmr.cli.compare import main as compare

    out = tmp_path / "report"
    argv = ["--methods", "pi", "clrrmc-ts", "--study", "none", "--duration", "0.5", "--jobs", "1"]
    argv += ["--only", "ellipse"]  # the options are recorded per method, not per trajectory
    argv += ["--option", "tau=0.3", "--option", "pi:damping=0.1", "--no-progress"]
    assert compare([*argv, "--out", str(out)]) == 0
    record = json.loads((out / "run.json").read_text())
    assert record["options"]["clrrmc-ts"]["tau"] == 0.3
    assert record["options"]["pi"]["damping"] == 0.1


def test_scenarios_pass_options_to_the_controller_and_refuse_the_protocol_s():
    config = config_from_arguments(scenarios_parser().parse_args(["--option", "adjust=0.3"]))
    assert config.controller_options == (("adjust", 0.3),)
    argv = ["--controller", "mpc", "--plant", "kinematic", "--horizon", "1.5"]
    assert config_from_arguments(scenarios_parser().parse_args(argv)).controller_options == (
        ("horizon", 1.5),
    )
    with pytest.raises(ParameterError, match=r"^option: the scenarios set dt themselves \(it is"):
        argv = ["--controller", "qp", "--option", "dt=0.02"]
        config_from_arguments(scenarios_parser().parse_args(argv))
    with pytest.raises(
        ParameterError, match=r"^horizon: --horizon is taken only by --controller mpc"
    ):
        config_from_arguments(scenarios_parser().parse_args(["--horizon", "2"]))


def test_the_thesis_controller_takes_the_batch_s_options():
    from ddwmmr.cli.scenarios import config_from_arguments as configure
    from ddwmmr.model import Robot
    from ddwmmr.scenarios.generator import generate
    from ddwmmr.scenarios.protocol import make_scenario_controller, make_scenario_plant

    config = configure(scenarios_parser().parse_args(["--option", "adjust=0.3"]))
    scenario = generate(1, seed=0)[0]
    robot = Robot().with_payload(config.payload)
    plant = make_scenario_plant(robot, config)
    controller = make_scenario_controller(robot, scenario, config, plant)
    assert controller.behaviours["stability"].adjust == 0.3


@pytest.mark.parametrize(
    ("method", "option", "message"),
    [
        ("pi", "damping=nan", "error: damping must be a finite number in [1e-06, 1000] (got nan)"),
        ("ats", "damping=nan", "error: damping must be a finite number in [1e-06, 1000] (got nan)"),
        ("qp", "speed_budget=nan", "error: speed_budget must be two numbers > 0, (v_top m/s"),
        ("qp", "obstacle_margin=nan", "error: obstacle_margin must be a finite number >= 0"),
        (
            "qp",
            "stability_min=nan",
            "error: stability_min must be a finite number in (0, 10) (got nan)",
        ),
        ("mpc", "intervals=nan", "error: intervals must be an integer in [2, 200] (got nan)"),
    ],
)
def test_a_nan_option_names_the_allowed_range(tmp_path, capsys, method, option, message):
    """Audit: ``--option damping=nan`` said only "must be a number (got 'nan')"."""
    out = tmp_path / "out"
    argv = ["--method", method, "--traj", "ellipse", "--duration", "0.2", "--no-plots"]
    assert track([*argv, "--out", str(out), "--option", option]) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and err.count("\n") == 1 and not out.exists()


def _run_with_option(tool, method, option, tmp_path, capsys) -> tuple[int, str, bool]:
    """Exit status and stderr of ``tool`` run in-process with ``--option option`` for
    ``method``, and whether it left its output (folder, or the simulator's snapshot)."""
    out = tmp_path / ("shot.png" if tool == "gui" else "out")
    argv = {
        "track": [track, "--method", method, "--traj", "ellipse", "--duration", "0.2",
                  "--no-plots", "--no-progress", "--out", str(out)],
        "compare": [compare, "--methods", method, "--only", "ellipse", "--study", "none",
                    "--jobs", "1", "--out", str(out)],
        "scenarios": [scenarios, "--controller", method, "--n", "1", "--time-limit", "0.2",
                      "--jobs", "1", "--no-progress", "--out", str(out)],
        "gui": [gui, "--method", method, "--traj", "ellipse", "--duration", "0.2",
                "--snapshot", str(out)],
    }[tool]  # fmt: skip
    status = argv[0]([*argv[1:], "--option", option])
    return status, capsys.readouterr().err, out.exists()


#: The time constants' range, as gains.TAU_RANGE words it.
TAU_RANGE = "> 0 s (at least 0.0001 s), or inf to disable a channel"


@pytest.mark.parametrize(
    ("tool", "method", "option", "allowed"),
    [
        ("track", "ats", "damping=abc", "a finite number in [1e-06, 1000]"),
        ("track", "ats", "damping=1,2", "a finite number in [1e-06, 1000]"),  # one number expected
        ("track", "clrrmc-ts", "tau=", TAU_RANGE),  # an empty value names the range too
        ("track", "pi", "singularity_threshold=x", "a finite number in [1e-06, 1000]"),
        ("track", "clrrmc-ts", "tau=0.5,fast,0.5", TAU_RANGE),
        ("track", "mpc", "intervals=ten", "an integer in [2, 200]"),
        ("track", "mpc", "horizon=2s", "a finite number in [0.0001, 100] s"),
        ("compare", "pi", "damping=abc", "a finite number in [1e-06, 1000]"),
        (
            "compare",
            "clrrmc-cs",
            "clrrmc-cs:reference_step=abc",
            "a finite number in [0.0001, 1] s",
        ),
        ("scenarios", "qp", "manipulability_weight=abc", "a finite number in [0, 1e+06]"),
        ("scenarios", "thesis", "adjust=abc", "a finite number in [0.01, 5] m"),
        ("gui", "ap", "K1=abc", "a finite number >= 0"),
        ("gui", "qp", "max_speed=fast", "a finite number > 0"),
        # An empty value is never "not given", even for an option whose blank field in
        # the simulator means automatic (a shell variable that is not set).
        ("track", "pi", "damping=", "a finite number in [1e-06, 1000]"),
        ("compare", "pi", "pi:damping=", "a finite number in [1e-06, 1000]"),
        ("scenarios", "qp", "singularity_margin=", "a finite number > 0"),
        ("gui", "pi", "damping=", "a finite number in [1e-06, 1000]"),
        # Python reads 0_5 as 5 and full-width digits as digits: a typo, refused.
        ("track", "clrrmc-ts", "tau=0_5", TAU_RANGE),
        ("gui", "ap", "K1=1_0", "a finite number >= 0"),
        ("track", "pi", "damping=\uff10.\uff15", "a finite number in [1e-06, 1000]"),
    ],
)
def test_a_non_numeric_option_names_the_allowed_range(
    tmp_path, capsys, tool, method, option, allowed
):
    """Audit: ``--option damping=abc`` said only "damping must be a number (got 'abc')"
    (``damping=1,2`` "takes one number", ``damping=`` "needs a number").
    Each tool now refuses it (exit 2, one line, nothing written) in the words of the nan
    message, which the method's own check writes: the range is named in that one place."""
    name, _, text = option.rpartition("=")
    message = f"error: {name.rpartition(':')[2]} must be {allowed} (got {text!r})\n"
    assert _run_with_option(tool, method, option, tmp_path, capsys) == (2, message, False)
    status, refused_nan, _ = _run_with_option(tool, method, f"{name}=nan", tmp_path, capsys)
    assert status == 2 and refused_nan == message.replace(f"(got {text!r})", "(got nan)")


def test_an_empty_text_option_is_refused_not_taken_as_its_default(tmp_path, capsys):
    status, err, written = _run_with_option("track", "qp", "obstacles=", tmp_path, capsys)
    assert (status, written) == (2, False)
    assert err == (
        "error: option: obstacles has an empty value (got 'obstacles='); "
        "give one or leave the option out\n"
    )


@pytest.mark.parametrize(
    ("option", "message"),
    [
        ("c1=", "error: c1 must be a finite number in [1e-20, 1e+13] N s/m (got '')\n"),
        (
            "c1=1_5",
            "error: c1 must be a finite number in [1e-20, 1e+13] N s/m (got '1_5')\n",
        ),
    ],
)
def test_a_plant_option_empty_or_with_underscores_is_refused(tmp_path, capsys, option, message):
    out = tmp_path / "out"
    argv = ["--method", "pi", "--traj", "ellipse", "--plant", "thesis", "--duration", "0.2"]
    status = track([*argv, "--no-plots", "--out", str(out), "--plant-option", option])
    assert (status, capsys.readouterr().err, out.exists()) == (2, message, False)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--dt", "0_02"], "argument --dt: must be a number > 0 s (got '0_02')"),
        (
            ["--dt", "\uff10.\uff10\uff12"],
            "argument --dt: must be a number > 0 s (got '\uff10.\uff10\uff12')",
        ),
        (["--payload", "1_5"], "argument --payload: must be a number in [0, "),
    ],
)
def test_a_command_line_number_with_underscores_or_other_digits_is_refused(
    tmp_path, capsys, argv, message
):
    """``float`` reads ``0_02`` as 2.0: a mistyped step 100 times the intended one ran."""
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as stop:
        track(["--method", "pi", "--traj", "ellipse", *argv, "--out", str(out)])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and message in err and err.count("\n") == 1
    assert not out.exists()


def test_a_non_numeric_option_as_a_module_is_one_line_without_traceback(tmp_path):
    out = tmp_path / "out"
    argv = ["--method", "ats", "--traj", "ellipse", "--option", "damping=abc", "--out", str(out)]
    done = subprocess.run(
        [sys.executable, "-m", "ddwmmr.track", *argv],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert done.returncode == 2 and "Traceback" not in done.stderr and not out.exists()
    assert done.stderr == "error: damping must be a finite number in [1e-06, 1000] (got 'abc')\n"


@pytest.mark.parametrize("value", ["-1", "0", "0.001", "1e9", "nan", "inf"])
def test_scenarios_refuse_an_adjust_outside_its_range(tmp_path, capsys, value):
    """Audit: the thesis controller took ``adjust=-1`` (drives away from the end effector)
    and ``adjust=1e9`` (a drive target across the world)."""
    from ddwmmr.cli.scenarios import main as scenarios

    out = tmp_path / "out"
    argv = ["--n", "1", "--no-progress", "--out", str(out), "--option", f"adjust={value}"]
    assert scenarios(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and not out.exists()
    assert err.startswith("error: adjust must be ") and "in [0.01, 5] m" in err


def test_the_thesis_controller_takes_adjust_at_the_ends_of_its_range():
    from ddwmmr.controllers import make_controller
    from ddwmmr.thesis_controller import ADJUST_RANGE_M

    assert ADJUST_RANGE_M == (0.01, 5.0)
    for adjust in ADJUST_RANGE_M:
        controller = make_controller("thesis", adjust=adjust)
        assert controller.behaviours["manipulability"].adjust == adjust
        assert controller.behaviours["stability"].adjust == adjust


@pytest.mark.parametrize("main", [track, compare, scenarios])
def test_help_says_what_the_dt_option_of_qp_and_mpc_is(main, capsys):
    """--help listed the qp's and mpc's option dt without a word: it reads as the run's
    step (--dt), but is the step the controller plans each command for."""
    with pytest.raises(SystemExit) as stop:
        main(["--help"])
    assert stop.value.code == 0
    text = " ".join(capsys.readouterr().out.split())  # unwrapped
    assert (
        "dt (qp, mpc): the step the controller plans each command for, s (qp: its stability "
        "check's look-ahead and its acceleration limits' step; mpc: its plan's first "
        "interval); default: the run's control step (--dt), which the option does not "
        "change" in text
    )


def test_scenarios_refuse_dt_as_the_controller_s_step_not_the_simulation_s(tmp_path, capsys):
    """--option dt=0.05 was refused as "the scenarios set dt themselves (--dt ...)", as if
    the option were the scenario step; the line now says what it is, and --dt sets both."""
    out = tmp_path / "x"
    argv = ["--controller", "qp", "--option", "dt=0.05", "--out", str(out)]
    assert scenarios(argv) == 2
    assert capsys.readouterr().err == (
        "error: option: the scenarios set dt themselves (it is the controller's planning "
        "step, not the simulation step; the protocol holds it at the scenario step: set --dt "
        "for both; got 'dt=0.05')\n"
    )
    assert not out.exists()
