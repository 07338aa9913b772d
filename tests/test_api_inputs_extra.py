"""More bad input to the public API, each one ParameterError line naming the parameter:
the result writers' target paths, the scenario API's steps, counts and seeds, the
rectangle's corner durations and the nested table of Robot.from_dict.

Before, a writer renamed its file over a device or FIFO (``/dev/null`` became a regular
file when running as root), run_scenario looped for ever on a tiny dt, generate(10**12)
ran out of memory and corner_windows(1e12) never returned. No test here touches /dev: a
FIFO lives in tmp_path and a device is simulated by a patched ``os.stat``.
"""

import math
import os
import stat
import tempfile
import warnings

import pytest

import ddwmmr.outputs.atomic as atomic_module
from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.scenarios import RunConfig, Scenario, generate, run_scenario
from ddwmmr.trajectories import Rectangle


def _refused(call, message: str) -> None:
    with pytest.raises(ParameterError) as error:
        call()
    assert str(error.value) == message


@pytest.fixture(scope="module")
def result():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(Robot(), Ellipse(), "ats", duration=0.1)


@pytest.fixture
def no_temp_file(monkeypatch):
    """Fails the test if a temporary file is made (the refusal must come first)."""
    made = []
    real = tempfile.mkstemp

    def spy(*args, **kwargs):
        made.append(kwargs.get("dir"))
        return real(*args, **kwargs)

    monkeypatch.setattr(tempfile, "mkstemp", spy)
    return made


# -- SimulationResult.write_csv / write_summary (write_atomic) -----------------------------
@pytest.mark.parametrize("writer", ["write_csv", "write_summary"])
def test_a_fifo_is_never_replaced_and_no_temp_file_is_made(result, tmp_path, writer, no_temp_file):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    _refused(
        lambda: getattr(result, writer)(fifo),
        f"path: {fifo} exists and is not a regular file (a FIFO); give a file name",
    )
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert no_temp_file == [] and sorted(os.listdir(tmp_path)) == ["pipe"]


def test_a_folder_is_refused_before_a_temp_file_is_made(result, tmp_path, no_temp_file):
    folder = tmp_path / "out"
    folder.mkdir()
    _refused(
        lambda: result.write_summary(folder),
        f"path: {folder} exists and is not a regular file (a folder); give a file name",
    )
    assert no_temp_file == [] and sorted(os.listdir(tmp_path)) == ["out"]
    assert os.listdir(folder) == []


def test_a_device_is_never_replaced(result, tmp_path, monkeypatch, no_temp_file):
    device = tmp_path / "null"  # never created: os.stat says it is a character device
    real_stat = os.stat

    def fake_stat(path, *args, **kwargs):
        if os.fspath(path) == str(device):
            return os.stat_result((stat.S_IFCHR | 0o666, 0, 0, 1, 0, 0, 0, 0, 0, 0))
        return real_stat(path, *args, **kwargs)

    monkeypatch.setattr(os, "stat", fake_stat)
    _refused(
        lambda: result.write_csv(device),
        f"path: {device} exists and is not a regular file (a character device); give a file name",
    )
    assert no_temp_file == [] and os.listdir(tmp_path) == []


def test_a_fifo_made_during_the_write_is_not_replaced(result, tmp_path, monkeypatch):
    target = tmp_path / "summary.json"
    real_mode = atomic_module.file_mode

    def mode_and_fifo():  # called while the temporary file is being written
        os.mkfifo(target)
        return real_mode()

    monkeypatch.setattr(atomic_module, "file_mode", mode_and_fifo)
    _refused(
        lambda: result.write_summary(target),
        f"path: {target} exists and is not a regular file (a FIFO); give a file name",
    )
    assert stat.S_ISFIFO(os.lstat(target).st_mode)
    assert os.listdir(tmp_path) == ["summary.json"]  # the temporary file is gone


@pytest.mark.parametrize(
    ("path", "message"),
    [
        (None, "path must be a file name, a non-empty str or os.PathLike (got None)"),
        (5, "path must be a file name, a non-empty str or os.PathLike (got 5)"),
        (["x.csv"], "path must be a file name, a non-empty str or os.PathLike (got ['x.csv'])"),
        ("", "path must be a file name, a non-empty str or os.PathLike (got '')"),
        (b"x.csv", "path must be a file name, a non-empty str or os.PathLike (got b'x.csv')"),
        ("a\0b.csv", "path: the file name contains a NUL byte ('a\\x00b.csv')"),
    ],
)
def test_path_must_be_a_file_name(result, path, message):
    _refused(lambda: result.write_csv(path), message)
    _refused(lambda: result.write_summary(path), message)


def test_files_and_missing_parents_are_written_but_not_through_a_file(result, tmp_path):
    target = tmp_path / "a" / "b" / "timeseries.csv"
    result.write_csv(target)  # documented: missing parent folders are created
    assert target.read_text().startswith("t,")
    summary = tmp_path / "summary.json"
    summary.write_text("old")
    result.write_summary(str(summary), run={"tool": "test"})  # a regular file: replaced
    assert '"tool": "test"' in summary.read_text()
    _refused(lambda: result.write_csv(summary / "x.csv"), f"path: {summary} is not a folder")
    assert '"tool": "test"' in summary.read_text()


# -- ddwmmr.scenarios: steps, count, seed --------------------------------------------------
@pytest.mark.parametrize(
    ("options", "message"),
    [
        (
            {"dt": 1e-9, "time_limit": 60.0},
            "time_limit / dt must be <= 1000000 steps per run (got 60 s / 1e-09 s = 6e+10); "
            "use a larger dt or a shorter time_limit",
        ),
        ({"dt": 1e200, "time_limit": 1e300}, "dt must be in (0, 0.1] s (got 1e+200)"),
        ({"dt": 1.0, "time_limit": 0.5}, "dt must be in (0, 0.1] s (got 1)"),
        ({"dt": 100.0}, "dt must be in (0, 0.1] s (got 100)"),
        ({"dt": 0.1, "time_limit": 0.05}, "dt must be <= time_limit (0.05 s) (got 0.1)"),
        (
            {"dt": 1e-5},
            "time_limit / dt must be <= 1000000 steps per run (got 60 s / 1e-05 s = 6e+06); "
            "use a larger dt or a shorter time_limit",
        ),
    ],
)
def test_run_config_keeps_the_step_cap(options, message):
    _refused(lambda: RunConfig(**options), message)


def test_run_config_steps_round_as_simulate_does():
    scenario = generate(1, 0)[0]
    assert RunConfig(dt=0.01, time_limit=0.5).steps_for(scenario) == 50
    assert RunConfig(dt=0.01).steps_for(scenario) == 6000
    with_obstacles = Scenario(0, scenario.waypoints, ((1.0, 0.0, 0.3),))
    assert RunConfig(dt=0.01).steps_for(with_obstacles) == 12000


def test_the_obstacle_time_limit_is_checked_when_the_scenario_runs():
    # 60 s / 1e-4 s is within the cap; the 120 s of a scenario with obstacles is not.
    config = RunConfig(dt=1e-4)
    scenario = Scenario(0, generate(1, 0)[0].waypoints, ((1.0, 0.0, 0.3),))
    _refused(
        lambda: run_scenario(scenario, config),
        "time_limit / dt must be <= 1000000 steps per run (got 120 s / 0.0001 s = 1.2e+06); "
        "use a larger dt or a shorter time_limit",
    )


@pytest.mark.parametrize(
    ("n", "message"),
    [
        (10**12, "n must be an integer in [1, 100000] (got 1000000000000)"),
        (100_001, "n must be an integer in [1, 100000] (got 100001)"),
    ],
)
def test_generate_caps_the_scenario_count(n, message):
    _refused(lambda: generate(n), message)


@pytest.mark.parametrize("seed", [-1, math.nan, 1.5, "a", None, True])
def test_generate_seed_is_an_integer(seed):
    _refused(lambda: generate(1, seed), f"seed must be an integer >= 0 (got {seed!r})")


def test_generate_accepts_integral_seeds():
    assert generate(2, 7.0) == generate(2, 7)
    assert len(generate(100_000, 0)) == 100_000


# -- Rectangle.corner_times / corner_windows -----------------------------------------------
@pytest.mark.parametrize("method", ["corner_times", "corner_windows"])
@pytest.mark.parametrize(
    ("duration", "message"),
    [
        (math.nan, "duration must be a finite number > 0 (got nan)"),
        (math.inf, "duration must be a finite number > 0 (got inf)"),
        (None, "duration must be a finite number > 0 (got None)"),
        ("20", "duration must be a finite number > 0 (got '20')"),
        (0.0, "duration must be > 0 (got 0)"),
        (-1.0, "duration must be > 0 (got -1)"),
        (
            1e12,
            "duration must be in (0, 1e+07] s for T = 40 s (at most 1e+09 s and 1000000 "
            "corners, one every T / 4) (got 1e+12)",
        ),
    ],
)
def test_corner_duration_is_checked(method, duration, message):
    _refused(lambda: getattr(Rectangle(), method)(duration), message)


def test_corner_count_and_duration_caps():
    fast = Rectangle(T=1e-6)  # 20 s would be 8e7 corners
    _refused(
        lambda: fast.corner_windows(20.0),
        "duration must be in (0, 0.25] s for T = 1e-06 s (at most 1e+09 s and 1000000 "
        "corners, one every T / 4) (got 20)",
    )
    slow = Rectangle(T=1e9)
    _refused(
        lambda: slow.corner_times(1e12),
        "duration must be in (0, 1e+09] s for T = 1e+09 s (at most 1e+09 s and 1000000 "
        "corners, one every T / 4) (got 1e+12)",
    )
    assert len(Rectangle().corner_times(1e7)) == 1_000_000
    assert Rectangle(T=20.0).corner_times(20.0) == [5.0, 10.0, 15.0, 20.0]


def test_simulate_refuses_a_duration_with_too_many_corners_before_the_run():
    """The rectangle's corner windows were computed for the summary, after the run: 1e5
    steps of 1e7 s were simulated, then refused. Now no step runs."""
    steps = []
    with pytest.raises(ParameterError) as info:
        simulate(
            Robot(),
            Rectangle(),
            "ats",
            duration=1e12,
            dt=1e7,
            progress=lambda k, n: steps.append(k),
        )
    assert str(info.value) == (
        "duration must be in (0, 1e+07] s for T = 40 s (at most 1e+09 s and 1000000 "
        "corners, one every T / 4) (got 1e+12)"
    )
    assert steps == []


# -- Robot.from_dict with a [robot] table ---------------------------------------------------
def test_from_dict_reads_a_robot_table_as_from_toml_does(tmp_path):
    nested = Robot.from_dict({"robot": {"L1": 0.4, "payload": 2.0}})
    assert nested == Robot.from_dict({"L1": 0.4, "payload": 2.0}) == Robot(L1=0.4, payload=2.0)
    path = tmp_path / "robot.toml"
    path.write_text("[robot]\nL1 = 0.4\npayload = 2.0\n")
    assert Robot.from_toml(path) == nested


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (
            {"robot": {"L1": 0.4}, "x": 1},
            "robot: unknown key 'x' (Robot fields go at the top or all under one [robot] table)",
        ),
        (
            {"robot": {"L1": 0.4}, "other": {}},
            "robot: unknown table [other] (Robot fields go at the top or all under one "
            "[robot] table)",
        ),
        ({"robot": None}, "robot: [robot] must be one table of Robot fields (got None)"),
        (
            {"robot": [{"L1": 0.4}]},
            "robot: [robot] must be one table of Robot fields (got an array of tables [[robot]])",
        ),
        ({"robot": {"L1": "0.4"}}, "robot: L1 must be a number in [1e-06, 1000] m (got '0.4')"),
    ],
)
def test_from_dict_robot_table_errors(data, message):
    _refused(lambda: Robot.from_dict(data), message)


def test_from_toml_messages_still_name_the_file(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text("[robot]\nL1 = 0.3\n[other]\nx = 1\n")
    _refused(
        lambda: Robot.from_toml(path),
        f"robot: {path}: unknown table [other] (Robot fields go at the top or all under one "
        "[robot] table)",
    )
