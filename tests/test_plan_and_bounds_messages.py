"""One home for the qp's obstacle influence, and the one-line errors of a plan or bounds
file that is not where the tools look: a ``--lower-only`` bounds folder given as
``plan=DIR``, a folder given as a plan file or as ``--bounds``, a missing or foreign
summary.json beside a bounds.csv."""

from __future__ import annotations

import inspect
import json
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import ParameterError
from ddwmmr.bounds.batch import read_bounds_file
from ddwmmr.cli.scenarios import main as scenarios_main
from ddwmmr.mpc.min_time import PLAN_FOLDER, PLAN_NAME, Guess, plan_path
from ddwmmr.qp.limits import obstacles
from ddwmmr.qp.tasks.avoidance import ObstacleSteeringTask
from ddwmmr.sim import verdict

BOUNDS_CSV = (
    "scenario,lower_bound_s,best_known_s,starts,spread_s,replay_ok\n1,13.8,nan,0,nan,False\n"
)


# -- one home for the influence distance ----------------------------------------------------
def test_the_verdict_and_both_qp_obstacle_pieces_share_one_influence_constant():
    assert abs(obstacles.INFLUENCE_M - 0.6) < 1e-12
    assert verdict.OBSTACLE_NEAR_M is obstacles.INFLUENCE_M
    for owner in (obstacles.ObstacleLimit, ObstacleSteeringTask):
        default = inspect.signature(owner).parameters["influence"].default
        assert default is obstacles.INFLUENCE_M, owner


def test_the_detour_cause_switches_at_the_influence_distance():
    off_track = {"steps": 2000, "rms_position_error_m": 0.2, "final_position_error_m": 0.2}
    near = verdict.verdict({**off_track, "min_obstacle_clearance_m": 0.599})["verdict"]
    far = verdict.verdict({**off_track, "min_obstacle_clearance_m": 0.601})["verdict"]
    assert "under the 600 mm within which the qp steers" in near
    assert "went round an obstacle" not in far


# -- plan=DIR without the scenario's plan -------------------------------------------------
def _lower_only_folder(root: Path) -> Path:
    """A folder as ``python -m ddwmmr.bounds --scenarios 1 --lower-only`` leaves it."""
    (root / PLAN_FOLDER).mkdir(parents=True)
    (root / PLAN_FOLDER / "scenario-001-lower.json").write_text('{"lower_bound_s": 13.8}\n')
    (root / "bounds.csv").write_text(BOUNDS_CSV)
    return root


def test_a_lower_only_folder_says_it_holds_no_plan_and_how_to_get_one(tmp_path):
    folder = _lower_only_folder(tmp_path / "lo")
    expected = folder / PLAN_FOLDER / PLAN_NAME.format(1)
    with pytest.raises(ParameterError) as error:
        plan_path(folder, 1)
    text = str(error.value)
    assert text.startswith(f"plan {folder}: {expected} is missing: the folder holds no best")
    assert "lower bounds only, as a --lower-only run leaves it" in text
    assert f"--out {folder} again without --lower-only" in text
    assert "--scenarios including 1 " in text and "\n" not in text
    assert "no such file" not in text


def test_a_folder_with_other_scenarios_plans_names_the_missing_scenario(tmp_path):
    folder = _lower_only_folder(tmp_path / "some")
    np.savez(folder / PLAN_FOLDER / PLAN_NAME.format(2), times=np.zeros(2))
    with pytest.raises(
        ParameterError, match=r"trajectories of other scenarios, not of scenario 1;"
    ):
        plan_path(folder, 1)
    assert plan_path(folder, 2) == folder / PLAN_FOLDER / PLAN_NAME.format(2)


def test_a_search_that_found_no_trajectory_says_so(tmp_path):
    folder = _lower_only_folder(tmp_path / "failed")
    (folder / PLAN_FOLDER / "scenario-003-best.json").write_text('{"best_known_s": null}\n')
    with pytest.raises(ParameterError, match=r"found no trajectory for scenario 3 \(its search"):
        plan_path(folder / PLAN_FOLDER, 3)  # the cache folder itself


def test_a_folder_that_is_no_bounds_output_says_what_plan_dir_takes(tmp_path):
    with pytest.raises(ParameterError, match=r"plan=DIR takes the output folder of python -m"):
        plan_path(tmp_path, 1)


def test_the_scenario_tool_prints_the_lower_only_message_and_exits_2(tmp_path, capsys):
    folder = _lower_only_folder(tmp_path / "lo")
    argv = ["--controller", "mpc", "--plant", "thesis", "--n", "1", "--jobs", "1"]
    argv += ["--option", "lookahead=on", "--option", f"plan={folder}"]
    argv += ["--out", str(tmp_path / "out"), "--no-progress"]
    assert scenarios_main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: plan {folder}: ") and "\n" not in err
    assert "(lower bounds only, as a --lower-only run leaves it)" in err


def test_a_folder_given_as_a_plan_file_is_named_a_folder(tmp_path):
    with pytest.raises(ParameterError) as error:
        Guess.load(tmp_path)
    text = str(error.value)
    assert text.startswith(f"plan {tmp_path} must be a .npz file, not a folder")
    assert "IsADirectoryError" not in text and "cache/scenario-NNN-best.npz" in text


# -- --bounds beside its summary ------------------------------------------------------------
def test_a_bounds_folder_is_refused_naming_the_file_to_give(tmp_path):
    (tmp_path / "bounds.csv").write_text(BOUNDS_CSV)
    with pytest.raises(ParameterError) as error:
        read_bounds_file(tmp_path, 0, 3.0)
    assert str(error.value) == (
        f"bounds must be the bounds.csv file of a bounds run, not its folder (got {tmp_path}; "
        f"give {tmp_path / 'bounds.csv'})"
    )


def test_a_missing_summary_is_named_alone(tmp_path):
    path = tmp_path / "bounds.csv"
    path.write_text(BOUNDS_CSV)
    with pytest.raises(ParameterError) as error:
        read_bounds_file(path, 0, 3.0)
    text = str(error.value)
    assert text == (
        f"bounds: cannot read {tmp_path / 'summary.json'} (No such file or directory); it is "
        "the bounds run's record of the seed and payload bounds.csv is for, which must be "
        "beside it"
    )


def test_a_summary_that_is_not_utf8_is_named_once(tmp_path):
    """The reading's own line, once: it was quoted inside 'cannot read ... (...)'."""
    path = tmp_path / "bounds.csv"
    path.write_text(BOUNDS_CSV)
    (tmp_path / "summary.json").write_bytes(b'\xff{"seed": 0}')
    with pytest.raises(ParameterError) as error:
        read_bounds_file(path, 0, 3.0)
    text = str(error.value)
    assert text.startswith(
        f"bounds: {tmp_path / 'summary.json'} is not UTF-8 text (byte 0xff at offset 0); it is "
        "the bounds run's record of the seed and payload bounds.csv is for"
    )
    assert text.count(str(tmp_path / "summary.json")) == 1


@pytest.mark.parametrize("record", [[1, 2], {"seed": 0}, "text"])
def test_a_summary_without_seed_and_payload_is_one_line(tmp_path, record):
    """A list raised AttributeError (a traceback); a dict without the keys read 'is for
    seed None, payload None kg'."""
    path = tmp_path / "bounds.csv"
    path.write_text(BOUNDS_CSV)
    (tmp_path / "summary.json").write_text(json.dumps(record))
    with pytest.raises(ParameterError, match=r"summary\.json records no seed and payload"):
        read_bounds_file(path, 0, 3.0)


@pytest.mark.parametrize(
    ("record", "seed", "recorded"),
    [
        ({"seed": "0", "payload": 3.0}, 0, "seed '0', payload 3.0 kg"),
        ({"seed": True, "payload": 3.0}, 1, "seed True, payload 3.0 kg"),
    ],
)
def test_a_summary_recording_no_number_is_refused_quoting_it(tmp_path, record, seed, recorded):
    """A seed "0" read 'is for seed 0, payload 3.0 kg, not seed 0, payload 3 kg'; a seed
    true was taken for seed 1."""
    path = tmp_path / "bounds.csv"
    path.write_text(BOUNDS_CSV)
    (tmp_path / "summary.json").write_text(json.dumps(record))
    with pytest.raises(ParameterError) as error:
        read_bounds_file(path, seed, 3.0)
    assert str(error.value) == (f"bounds: {path} is for {recorded}, not seed {seed}, payload 3 kg")


def test_a_matching_lower_only_bounds_file_still_reads(tmp_path):
    path = tmp_path / "bounds.csv"
    path.write_text(BOUNDS_CSV)
    (tmp_path / "summary.json").write_text(json.dumps({"seed": 0, "payload": 3.0}))
    lower, best = read_bounds_file(path, 0, 3.0)[1]
    assert lower == pytest.approx(13.8, abs=1e-12) and np.isnan(best)
