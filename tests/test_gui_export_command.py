"""The simulator's data export records a command that repeats the exported run: the
``python -m ddwmmr.track`` arguments of the window's settings, not the window's own."""

import json
import math
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from ddwmmr.gui import Settings
from test_gui_export import finished_app

#: Summary keys that hold wall-clock time (they differ from run to run).
TIMING = {"median_step_us", "max_step_us", "mean_step_us", "p95_step_us"}


def exported_summary(settings: Settings, root: Path) -> Path:
    """The summary.json of the window's data export of a run of ``settings``."""
    paths = finished_app(settings, root).export_data()
    (summary,) = [p for p in paths if p.name == "summary.json"]
    return summary


def run_recorded_command(record: dict, out: Path) -> dict:
    """The summary of the record's command run as written (its ``python`` this one)."""
    words = shlex.split(record["command"])
    assert words[:3] == ["python", "-m", "ddwmmr.track"]
    assert words[3:] == record["argv"]
    done = subprocess.run(
        [sys.executable, *words[1:], "--out", str(out), "--no-plots", "--no-progress"],
        cwd=record["cwd"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    return json.loads((out / "summary.json").read_text())


def same_numbers(exported: dict, repeated: dict, moved_samples: bool) -> None:
    exported, repeated = dict(exported), dict(repeated)
    exported.pop("run"), repeated.pop("run")
    if moved_samples:  # read back from trajectory.csv, which names it (as --rerun does)
        assert (exported.pop("trajectory"), repeated.pop("trajectory")) == ("figure8", "trajectory")
    for key in TIMING:
        exported.pop(key, None), repeated.pop(key, None)
    assert exported.keys() == repeated.keys()
    for key, value in exported.items():
        if isinstance(value, float) and math.isnan(value):
            assert math.isnan(repeated[key]), key
        else:
            assert repeated[key] == value, key  # bit for bit, labels included


SETTINGS = {
    # qp with the thesis's default trajectory moved, options, payload, euler, offset, dt
    "qp-moved-ellipse": Settings(
        trajectory="ellipse",
        geometry={"a": 2.2, "T": 30.0, "beta": 0.1},
        methods=("qp", None),
        options=({"tau": (0.4, 0.5, math.inf), "stability_min": 1.3}, {}),
        payload=2.0,
        integrator="euler",
        dt=0.025,
        duration=0.8,
        offset=(-0.1, 0.12),
    ),
    # a sampled trajectory moved by the geometry controls (written as trajectory.csv)
    "clrrmc-moved-figure8": Settings(
        trajectory="figure8",
        geometry={"a": 1.5},
        methods=("clrrmc-ts", None),
        options=({"aux": "sum"}, {}),
        duration=0.6,
    ),
}


@pytest.mark.parametrize("name", SETTINGS)
def test_the_recorded_command_repeats_the_exported_run(tmp_path: Path, name: str) -> None:
    summary_path = exported_summary(SETTINGS[name], tmp_path / "gui")
    exported = json.loads(summary_path.read_text())
    record = exported["run"]
    assert record["tool"] == "gui"
    assert "command_note" not in record  # every setting has a track argument
    repeated = run_recorded_command(record, tmp_path / "track")
    same_numbers(exported, repeated, moved_samples=name.endswith("figure8"))
    assert repeated["run"]["options"] == record["options"]
    assert repeated["run"]["robot"] == record["robot"]


def test_the_command_of_a_default_window_names_the_run(tmp_path: Path) -> None:
    record = json.loads(exported_summary(Settings(duration=0.5), tmp_path).read_text())["run"]
    argv = record["argv"]
    assert argv[:4] == ["--method", "clrrmc-ts", "--traj", "ellipse"]
    assert argv[argv.index("--duration") + 1] == "0.5"
    assert argv[argv.index("--dt") + 1] == "0.02"
    assert argv[argv.index("--plant") + 1] == "kinematic"


def test_a_setting_without_a_track_argument_is_named_not_claimed() -> None:
    from ddwmmr.gui.export import option_text

    assert option_text("qp", "tau", (0.4, 0.5, math.inf)) == "0.4,0.5,inf"
    assert option_text("qp", "stability_min", 1.3) == "1.3"
    assert option_text("clrrmc-ts", "aux", "sum") == "sum"
    # one tau in a tuple: --option reads "0.5" as the number, another option value
    assert option_text("qp", "tau", (0.5,)) is None
    assert option_text("qp", "no_such_option", 1.0) is None


def test_a_moved_parametric_trajectory_is_written_as_toml_that_reads_back_the_same(
    tmp_path: Path,
) -> None:
    from ddwmmr.gui.export import toml_text
    from ddwmmr.trajectories import Rectangle
    from ddwmmr.trajectories.files import read_toml

    moved = Rectangle(x0=0.1, a=1.0 / 3.0, T=12.5, N=77, orientation="constant", phi=0.2)
    path = tmp_path / "trajectory.toml"
    path.write_text(toml_text(moved))
    assert read_toml(path) == moved
