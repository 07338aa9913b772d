"""What decides a run's last bits is recorded, a rerun on other software says so, and a
relative ``--option plan=DIR`` means the folder it names where the command was given."""

import json
import os
import subprocess
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np
import scipy

from ddwmmr import provenance
from ddwmmr.cli.scenarios import build_parser as scenarios_parser
from ddwmmr.cli.scenarios import config_from_arguments
from ddwmmr.cli.track import main as track
from ddwmmr.mpc.min_time import PLAN_FOLDER, PLAN_NAME, plan_path

#: Keys every record has held since records began: kept, not renamed.
FIRST_KEYS = {
    "record_version", "tool", "version", "git", "python", "numpy", "command", "argv", "cwd",
}  # fmt: skip
RUN = ["--method", "clrrmc-ts", "--traj", "rectangle", "--duration", "0.4", "--no-plots"]


def test_the_record_holds_the_libraries_blas_and_cpu_that_decide_the_last_bits():
    record = provenance.header("track", "python -m ddwmmr.track", [])
    assert set(record) >= FIRST_KEYS
    assert record["numpy"] == np.__version__
    assert record["libraries"]["scipy"] == scipy.__version__
    assert set(record["libraries"]) <= set(provenance.NUMERIC_LIBRARIES)
    assert {"casadi", "control", "daqp", "qpsolvers", "osqp"} <= set(record["libraries"])
    # this build's BLAS, as numpy's own configuration names it
    blas = np.__config__.CONFIG["Build Dependencies"]["blas"]
    assert blas["version"] in record["blas"]["numpy"]
    assert record["blas"]["scipy"]  # scipy links its own BLAS (dlqr's Riccati solve)
    machine = record["machine"]
    assert machine["machine"] and machine["system"] and machine["cpu"]
    json.dumps(record, allow_nan=False)  # plain JSON


def test_a_blas_kernel_chosen_by_the_environment_is_recorded():
    code = "from ddwmmr import provenance; print(provenance.header('t', 'p', [])['blas'])"
    env = {**os.environ, "OPENBLAS_CORETYPE": "Sandybridge"}
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    ).stdout
    assert "'OPENBLAS_CORETYPE': 'Sandybridge'" in out


def _rerun(tmp_path, capsys, edit) -> tuple[str, Path, Path]:
    """Run, edit the record with ``edit(run)``, rerun: (stderr of the rerun, both runs)."""
    first, second = tmp_path / "a", tmp_path / "b"
    assert track([*RUN, "--no-progress", "--out", str(first)]) == 0
    summary = json.loads((first / "summary.json").read_text())
    edit(summary["run"])
    (first / "summary.json").write_text(json.dumps(summary))
    capsys.readouterr()
    argv = ["--rerun", str(first / "summary.json"), "--no-plots", "--no-progress"]
    assert track([*argv, "--out", str(second)]) == 0
    return capsys.readouterr().err, first, second


def _rows(folder: Path) -> list[str]:
    """timeseries.csv without its wall-clock column (the last, step_us)."""
    lines = (folder / "timeseries.csv").read_text().splitlines()
    assert lines[0].split(",")[-1] == "step_us"
    return [line.rsplit(",", 1)[0] for line in lines]


def test_a_rerun_of_a_record_from_other_software_says_so_in_one_line_and_reruns(tmp_path, capsys):
    def older(run):
        run.update(version="0.0.9", numpy="1.26.4", python="3.9.18")
        run["git"] = {"commit": "0" * 40, "dirty": False}
        run["libraries"]["casadi"] = "3.6.0"
        run["machine"]["cpu"] = "Intel(R) Xeon(R) CPU E5-2680"

    err, first, second = _rerun(tmp_path, capsys, older)
    assert err.count("\n") == 1 and err.startswith("note: the record was written ")
    named = ["version 0.0.9 -> ", "numpy 1.26.4 -> ", "python 3.9.18 -> ", "casadi 3.6.0 -> "]
    for text in [*named, f"commit {'0' * 40} -> ", "cpu Intel(R) Xeon(R) CPU E5-2680 -> "]:
        assert text in err, text
    assert "may differ" in err and "last bits" in err
    assert "scipy" not in err  # what agrees is not named
    assert _rows(first) == _rows(second)  # the same machine: still bit for bit


def test_a_rerun_of_a_record_from_this_software_says_nothing(tmp_path, capsys):
    err, first, second = _rerun(tmp_path, capsys, lambda run: None)
    assert err == ""
    assert _rows(first) == _rows(second)


def test_a_rerun_of_a_record_written_before_the_libraries_were_recorded_compares_the_rest(
    tmp_path, capsys
):
    def old_layout(run):
        for key in ("libraries", "blas", "machine"):
            del run[key]

    err, _, _ = _rerun(tmp_path, capsys, old_layout)
    assert err == ""  # nothing recorded to compare is no difference
    err, _, _ = _rerun(tmp_path / "again", capsys, lambda run: run.update(numpy="1.26.4"))
    assert err.count("\n") == 1 and "numpy 1.26.4 -> " + np.__version__ in err


def test_a_relative_plan_folder_is_the_one_where_the_command_was_given(tmp_path, monkeypatch):
    here, worker = tmp_path / "here", tmp_path / "worker"
    for folder in (here, worker):  # a worker's own bQ must not be taken instead
        (folder / "bQ" / PLAN_FOLDER).mkdir(parents=True)
        (folder / "bQ" / PLAN_FOLDER / PLAN_NAME.format(1)).write_bytes(b"")
    monkeypatch.chdir(here)
    argv = ["--controller", "mpc", "--n", "1", "--option", "plan=bQ"]
    config = config_from_arguments(scenarios_parser().parse_args(argv))
    plan = dict(config.controller_options)["plan"]
    assert plan == str(here / "bQ")
    assert provenance.encode(asdict(config))["controller_options"] == [["plan", str(here / "bQ")]]
    monkeypatch.chdir(worker)  # where a Dask worker may run the scenario
    assert plan_path(plan, 1) == here / "bQ" / PLAN_FOLDER / PLAN_NAME.format(1)
