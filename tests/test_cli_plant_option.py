"""``track --plant-option NAME=VALUE``: a plant's constructor options from the command line,
checked against the plant, recorded in summary.json and repeated by ``--rerun``."""

import json
import subprocess
import sys

import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.cli.track import build_parser
from ddwmmr.cli.track import main as run

#: A robot whose wheel drive is not the thesis robot's (its motors give 20 N per wheel).
BIG_ROBOT = "wheel_radius = 0.1\nwheel_torque_limit = 2.0\n"
BASE = ["--method", "ats", "--traj", "ellipse", "--duration", "4", "--no-plots", "--no-progress"]
THESIS = [*BASE, "--plant", "thesis"]
OPTIONS = ["--plant-option", "force_limit=20", "--plant-option", "c2=2"]


@pytest.fixture
def big_robot(tmp_path):
    path = tmp_path / "big.toml"
    path.write_text(BIG_ROBOT)
    return str(path)


def _summary(folder):
    return json.loads((folder / "summary.json").read_text())


def test_plant_options_reach_the_plant_as_the_api_sets_them(tmp_path, big_robot):
    out = tmp_path / "run"
    assert run([*THESIS, "--robot", big_robot, *OPTIONS, "--out", str(out)]) == 0
    summary = _summary(out)
    api = simulate(
        Robot.from_toml(big_robot),
        load_trajectory("ellipse"),
        "ats",
        duration=4.0,
        plant="thesis",
        plant_options={"force_limit": 20.0, "c2": 2.0},
    )
    # the 20 N limit lets a wheel push past the thesis's 10 N (19.03 N at the start)
    assert summary["max_wheel_force_n"] == pytest.approx(19.034, abs=1e-3)
    assert summary["max_wheel_force_n"] == api.summary["max_wheel_force_n"]
    assert summary["rms_position_error_m"] == api.summary["rms_position_error_m"]
    assert summary["rms_position_error_m"] == pytest.approx(0.05879, abs=1e-5)
    assert summary["run"]["plant"] == {
        "name": "thesis",
        "options": {"force_limit": 20.0, "c2": 2.0},
    }


def test_a_run_without_plant_options_is_recorded_as_before(tmp_path, big_robot, capsys):
    out = tmp_path / "run"
    assert run([*THESIS, "--robot", big_robot, "--out", str(out)]) == 0
    summary = _summary(out)
    assert summary["run"]["plant"] == {"name": "thesis"}
    # its own force limit: the thesis's 10 N of 20.5 N motors, of its 20 N motors
    assert summary["max_wheel_force_n"] == pytest.approx(9.75, abs=1e-9)
    err = capsys.readouterr().err  # the thesis plant's warning names the option to set
    assert "force_limit = 9.75 N" in err and "--plant-option force_limit=" in err


@pytest.mark.parametrize("options", [OPTIONS, []])
def test_rerun_repeats_the_plant_options(tmp_path, big_robot, options, capsys):
    first, second = tmp_path / "a", tmp_path / "b"
    assert run([*THESIS, "--robot", big_robot, *options, "--out", str(first)]) == 0
    summary = str(first / "summary.json")
    assert run(["--rerun", summary, "--no-plots", "--no-progress", "--out", str(second)]) == 0
    before, after = _summary(first), _summary(second)
    assert after["run"]["plant"] == before["run"]["plant"]
    for key in ("max_wheel_force_n", "rms_position_error_m", "final_position_error_m"):
        assert after[key] == before[key]
    assert after["max_wheel_force_n"] == pytest.approx(19.034 if options else 9.75, abs=1e-3)


def test_rerun_refuses_plant_options_given_with_it(tmp_path, capsys):
    first = tmp_path / "a"
    assert run([*THESIS, "--out", str(first)]) == 0
    capsys.readouterr()
    summary = str(first / "summary.json")
    status = run(["--rerun", summary, "--plant-option", "c1=3", "--out", str(tmp_path / "b")])
    assert status == 2
    assert capsys.readouterr().err == (
        "error: rerun: --plant-option cannot be combined with --rerun (the record fixes it)\n"
    )


@pytest.mark.parametrize(
    ("recorded", "message"),
    [
        ({"force_limt": 20.0}, "plant-option: the thesis plant has no option 'force_limt'"),
        ({"c2": -1.0}, "c2 must be in [1e-20, 1e+13] N m s/rad (got -1)"),
        ([1, 2], "the plant options must be a dict"),
    ],
)
def test_rerun_of_recorded_plant_options_checks_them(tmp_path, capsys, recorded, message):
    first = tmp_path / "a"
    assert run([*THESIS, *OPTIONS, "--out", str(first)]) == 0
    capsys.readouterr()
    summary = _summary(first)
    summary["run"]["plant"]["options"] = recorded
    path = tmp_path / "damaged.json"
    path.write_text(json.dumps(summary))
    assert run(["--rerun", str(path), "--no-progress", "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: rerun: {path}") and message in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("arguments", "line"),
    [
        (
            ["--plant", "thesis", "--plant-option", "force_limt=3"],
            "plant-option: the thesis plant has no option 'force_limt' (did you mean "
            "force_limit?) (options: c1, c2, force_limit, joint_speed, velocity_bandwidth)",
        ),
        (
            ["--plant", "thesis", "--plant-option", "c2=-1"],
            "c2 must be in [1e-20, 1e+13] N m s/rad (got -1)",
        ),
        (
            ["--plant", "thesis", "--plant-option", "c1=abc"],
            "c1 must be a finite number in [1e-20, 1e+13] N s/m (got 'abc')",
        ),
        (
            ["--plant", "thesis", "--plant-option", "c1"],
            "plant-option must be NAME=VALUE (got 'c1')",
        ),
        (
            ["--plant", "thesis", "--plant-option", "c1=2", "--plant-option", "c1=3"],
            "plant-option: c1 given twice (got 'c1=3')",
        ),
        (
            ["--plant-option", "c2=2"],
            "plant-option: the kinematic plant has no options (got 'c2'; --integrator sets "
            "its integrator)",
        ),
        (
            ["--plant", "kinematic", "--plant-option", "integrator=euler"],
            "plant-option: the kinematic plant has no options (got 'integrator'; "
            "--integrator sets its integrator)",
        ),
        (
            ["--plant", "mujoco", "--plant-option", "timestep=1"],
            "timestep must be in [1e-05, 0.01] s (got 1)",
        ),
    ],
)
def test_bad_plant_options_are_one_line(tmp_path, capsys, arguments, line):
    out = tmp_path / "run"
    assert run([*BASE, *arguments, "--out", str(out)]) == 2
    assert capsys.readouterr().err == f"error: {line}\n"
    assert not out.exists()


def test_a_mujoco_timestep_sets_the_default_step(tmp_path, capsys):
    out = tmp_path / "run"
    arguments = [*BASE[:4], "--duration", "0.105", "--no-plots", "--no-progress"]
    options = ["--plant-option", "timestep=0.003", "--plant-option", "base_damping=1,2"]
    assert run([*arguments, "--plant", "mujoco", *options, "--out", str(out)]) == 0
    summary = _summary(out)
    assert summary["run"]["dt"] == pytest.approx(0.021, abs=1e-12)  # 7 engine steps of 3 ms
    assert summary["mujoco_timestep_s"] == pytest.approx(0.003, abs=1e-12)
    assert summary["steps"] == 5
    assert summary["run"]["plant"]["options"] == {"timestep": 0.003, "base_damping": [1.0, 2.0]}


def test_help_lists_each_plants_options():
    text = " ".join(build_parser().format_help().split())
    assert "--plant-option NAME=VALUE" in text
    assert "thesis: c1, c2, force_limit, joint_speed, velocity_bandwidth" in text
    assert "mujoco: timestep, friction, servo_time_constant, cone," in text
    assert "kinematic: none" in text


def test_building_the_parser_does_not_import_the_physics_engine():
    code = (
        "import sys; from ddwmmr.cli.track import build_parser; build_parser(); "
        "print('mujoco' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False"


@pytest.mark.parametrize(
    ("module", "tool"), [("ddwmmr.cli.compare", "compare"), ("ddwmmr.cli.gui", "the simulator")]
)
def test_tools_that_run_plants_on_their_defaults_refuse_plant_options(module, tool, capsys):
    main = __import__(module, fromlist=["main"]).main
    with pytest.raises(SystemExit) as stop:
        main(["--plant", "thesis", "--plant-option", "c1=3"])
    assert stop.value.code == 2
    prog = "python -m " + module.replace(".cli", "")
    assert capsys.readouterr().err == (
        f"{prog}: error: --plant-option: {tool} runs each plant with its default options; "
        "python -m ddwmmr.track --plant-option NAME=VALUE sets them\n"
    )
