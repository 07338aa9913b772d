"""A run on the MuJoCo plant that unloaded an edge of its support polygon (a wheel off the
ground) says so where a researcher looks: ``track``'s table and the verdict's warning
clause, ``compare``'s plant table, plant section and ``plant_metrics.csv``; and the
console's run counts agree."""

from __future__ import annotations

import csv
import warnings
from types import SimpleNamespace

import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.cli.compare import not_tracked, runs_text
from ddwmmr.cli.track import format_table
from ddwmmr.reports.compare import CompareConfig, execute, plan_runs, write_report
from ddwmmr.sim.verdict import TRACKED, short_verdict, support_warning, verdict

#: A robot whose long arm lightens an edge: qp on the ellipse on MuJoCo lifts a wheel.
LONG_ARM = {"L1": 0.7, "L2": 0.6}
#: Short enough for a test; the edge is unloaded for 0.08 s within the first 2 s.
DURATION = 2.0
#: The start offset of these runs (m): half the long-arm robot's own default.
OFFSET = (-0.03, -0.03)


def _run(duration: float = DURATION, **options: float) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = simulate(
            Robot(**LONG_ARM),
            Ellipse(),
            "qp",
            plant="mujoco",
            duration=duration,
            initial_offset=OFFSET,
            **options,
        )
    return result.summary


@pytest.fixture(scope="module")
def lifted() -> dict:
    return _run()


def test_a_run_that_lost_support_tracks_with_a_warning(lifted: dict) -> None:
    assert lifted["support_lost"] and not lifted["tipped"]
    assert lifted["unloaded_time_s"] == pytest.approx(0.08, abs=1e-9)
    assert lifted["verdict_reasons"] == [] and short_verdict(lifted) == TRACKED
    assert lifted["verdict"].startswith(
        "tracked; warning: an edge of the support polygon was unloaded for 0.08 of 2 s "
        "(support_lost: a wheel off the ground"
    )
    # the edge rows gave way on the first six steps (they conflicted with the other
    # limits): the prediction fell below the floor there, and the verdict says so
    assert lifted["edge_load_relaxed_steps"] == 6
    assert lifted["min_predicted_edge_load_n"] == pytest.approx(6.494, abs=0.01)
    assert (
        "the controller predicted an edge load of 6.49 N, below its 13 N floor"
        in (lifted["verdict"])
    )


def test_a_failed_run_names_the_lost_support_and_the_broken_floor() -> None:
    summary = _run(3.0, stability_min=1.1)
    assert summary["unloaded_time_s"] == pytest.approx(0.12, abs=1e-9)
    assert summary["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert summary["verdict"].startswith("did not track: settled-end RMS position error")
    assert (
        "; warning: an edge of the support polygon was unloaded for 0.12 of 3 s"
        in summary["verdict"]
    )
    assert (
        "the controller predicted an edge load of -363 N, below its 13 N floor"
        in (summary["verdict"])
    )


def test_no_warning_without_support_loss_or_with_a_tip_over(lifted: dict) -> None:
    kinematic = {k: v for k, v in lifted.items() if k not in ("support_lost", "tipped")}
    # the long-arm run starts below its floor: that warning, and no support warning
    below_floor = (
        f"{TRACKED}; warning: the run started below its stability floor "
        "(start S = 1.06821 < stability_min 1.25;"
    )
    for summary in (kinematic, {**lifted, "support_lost": False}):
        text = verdict(summary)["verdict"]
        assert text.startswith(below_floor) and "unloaded" not in text
    tipped = verdict({**lifted, "tipped": True, "tip_time_s": 1.0})
    assert tipped["verdict_reasons"] == ["tipped_over"] and "unloaded" not in tipped["verdict"]
    assert support_warning({**lifted, "support_lost": False}) == ""


def test_track_table_shows_the_support_keys_only_where_reported(lifted: dict) -> None:
    lines = format_table(lifted).splitlines()
    assert "  support lost (an edge unloaded)      True" in lines
    assert "  time with an edge unloaded (s)       0.08" in lines
    assert "  min predicted edge load (N)          6.49376" in lines
    kinematic = simulate(Robot(), Ellipse(), "ats", duration=1.0).summary
    assert "unloaded" not in format_table(kinematic)


def test_compare_writes_the_plant_runs_and_their_support(tmp_path) -> None:
    config = CompareConfig(
        methods=("qp",),
        trajectories={"ellipse": Ellipse()},
        robot=Robot(**LONG_ARM),
        duration=DURATION,
        studies=(),
        plants=("mujoco",),
    )
    plan = plan_runs(config)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outputs = execute(config, plan.all_specs())
    info = write_report(config, plan, outputs, tmp_path)
    assert "plant_metrics.csv" in info.files
    with open(tmp_path / "plant_metrics.csv", newline="") as handle:
        (row,) = list(csv.DictReader(handle))
    assert list(row)[:3] == ["method", "trajectory", "plant"]
    assert (row["method"], row["plant"], row["support_lost"]) == ("qp", "mujoco", "True")
    # compare starts at the robot's own default offset, twice these runs' OFFSET
    assert float(row["unloaded_time_s"]) == pytest.approx(0.12, abs=1e-9)
    text = (tmp_path / "report.md").read_text()
    header = next(line for line in text.splitlines() if "| RMS mujoco (mm) |" in line)
    assert "| edge unloaded (s) | min predicted edge load / floor (N) |" in header
    row_line = next(line for line in text.splitlines() if line.startswith("| ellipse | qp |"))
    cells = [c.strip() for c in row_line.strip("|").split("|")]
    assert cells[12:14] == ["0.120", "8.94 / 13.0"]
    assert "Lost support on the mujoco plant, tracked or not (1 of 1 runs" in text
    kinematic = CompareConfig(
        methods=("ats",), trajectories={"ellipse": Ellipse()}, duration=1.0, studies=()
    )
    assert (
        "plant_metrics.csv"
        not in write_report(
            kinematic,
            plan_runs(kinematic),
            execute(kinematic, plan_runs(kinematic).all_specs()),
            tmp_path / "k",
        ).files
    )


def test_console_counts_agree() -> None:
    """3 methods x 2 trajectories x (kinematic + mujoco) = 12 judged runs of 14 run: the
    first line says which 12 the 'of 12 runs' counts."""
    main = [SimpleNamespace(method=f"m{i}", trajectory="t") for i in range(6)]
    plan = SimpleNamespace(main=main, plants={"mujoco": list(main)})
    assert runs_text(plan, 14) == (
        "14 runs (the 12 main runs on the kinematic and mujoco plants, judged below, and 2 "
        "for the report's other sections)"
    )
    assert runs_text(SimpleNamespace(main=main, plants={}), 6) == "6 runs"
    bad = {"rms_position_error_m": 1.0, "steps": 10}
    outputs = {id(s): SimpleNamespace(summary=bad) for s in main}

    class _ById(dict):
        def __getitem__(self, spec):
            return outputs[id(spec)]

    assert not_tracked(plan, _ById())[0].startswith("Did not track (12 of 12 runs")
