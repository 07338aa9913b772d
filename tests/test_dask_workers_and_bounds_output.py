"""The worker count a ``scenarios --executor dask --scheduler`` run reports and records
(the cluster's, not this machine's CPUs; ``--jobs`` refused there), the bounds tool's
refusal of another tool's ``--out`` (no ``--force`` offered, since it cannot help), and
its summary.json writing undefined means as ``null`` (``--bounds`` still reads files
that spell them ``"nan"``)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from ddwmmr.bounds import batch
from ddwmmr.cli import bounds as bounds_tool
from ddwmmr.cli import scenarios as scenarios_tool
from ddwmmr.outputs import list_in_manifest

FAST = ["--time-limit", "3", "--no-progress"]


def _strict_json(path: Path) -> dict:
    """``path`` parsed as standard JSON: NaN and Infinity literals are refused."""

    def refuse(name: str) -> None:
        raise AssertionError(f"{path} holds the non-standard {name}")

    return json.loads(path.read_text(encoding="utf-8"), parse_constant=refuse)


# -- scenarios --executor dask --scheduler ------------------------------------------------
def test_a_scheduler_run_reports_and_records_the_clusters_workers(tmp_path, capsys, monkeypatch):
    """A two-worker cluster on a machine that would give one worker: the closing line
    and run.workers say 2, run.jobs stays the option's null; the rows are those of a
    local one-process run, byte for byte."""
    pytest.importorskip("distributed")
    from test_cli_dask import local_cluster

    monkeypatch.setattr(scenarios_tool, "default_jobs", lambda: 1)
    with local_cluster(2) as cluster:
        argv = [*FAST, "--n", "3", "--executor", "dask", "--scheduler", cluster.scheduler_address]
        status = scenarios_tool.main([*argv, "--out", str(tmp_path / "dask")])
    err = capsys.readouterr().err
    assert status == 0, err
    assert "(2 dask workers)" in err
    run = _strict_json(tmp_path / "dask" / "summary.json")["run"]
    assert run["workers"] == 2 and run["jobs"] is None
    local = [*FAST, "--n", "3", "--jobs", "1", "--out", str(tmp_path / "local")]
    assert scenarios_tool.main(local) == 0
    assert "(1 local worker)" in capsys.readouterr().err
    assert _strict_json(tmp_path / "local" / "summary.json")["run"]["workers"] == 1
    rows = [(tmp_path / d / "scenarios.csv").read_bytes() for d in ("dask", "local")]
    assert rows[0] == rows[1]


def test_jobs_with_a_scheduler_is_refused_before_connecting(tmp_path, capsys):
    """Nothing listens at port 1: the refusal comes from the options, before any connect."""
    argv = [*FAST, "--executor", "dask", "--scheduler", "tcp://127.0.0.1:1", "--jobs", "4"]
    assert scenarios_tool.main([*argv, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "error: jobs: not used with --scheduler (the batch runs on the workers the "
        "scheduler has); leave --jobs out"
    )
    assert list(tmp_path.iterdir()) == []


def test_the_jobs_help_says_what_it_does_with_dask():
    text = " ".join(scenarios_tool.build_parser().format_help().split())
    assert "refused with --scheduler" in text and "the LocalCluster's workers" in text


# -- bounds --out: another tool's folder ----------------------------------------------------
@pytest.fixture
def scenarios_folder(tmp_path) -> Path:
    """A folder the scenarios tool wrote (its manifest lists its files)."""
    folder = tmp_path / "scen"
    folder.mkdir()
    (folder / "scenarios.csv").write_text("scenario\n1\n")
    list_in_manifest(folder, "scenarios", ["scenarios.csv"])
    return folder


@pytest.mark.parametrize("force", [[], ["--force"]])
def test_bounds_refuses_another_tools_folder_without_offering_force(
    scenarios_folder, capsys, force
):
    before = sorted(p.name for p in scenarios_folder.iterdir())
    argv = ["--scenarios", "1", "--no-progress", "--out", str(scenarios_folder), *force]
    assert bounds_tool.main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert f"out: {scenarios_folder} was written by ddwmmr scenarios, not bounds" in err
    assert "--force does not help" in err and "add --force" not in err
    assert sorted(p.name for p in scenarios_folder.iterdir()) == before


def test_bounds_refuses_a_user_folder_without_offering_force(tmp_path, capsys):
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("keep")
    assert bounds_tool.main(["--scenarios", "1", "--out", str(folder)]) == 2
    err = capsys.readouterr().err
    assert "holds files no ddwmmr bounds run wrote (notes.txt)" in err
    assert "add --force" not in err
    assert (folder / "notes.txt").read_text() == "keep"


def test_the_bounds_force_help_says_it_changes_nothing():
    text = " ".join(bounds_tool.build_parser().format_help().split())
    assert "changes nothing" in text


# -- bounds summary.json: undefined means ----------------------------------------------------
def _lower_only(job: batch.Job) -> dict:
    """batch.solve's result for a --lower-only job: a lower bound of 10 + scenario s."""
    index = job.scenario.index + 1
    wanted = batch.keys(job.scenario, job.payload, job.settings)
    return {"index": index, "lower": {"key": wanted["lower"], "lower_bound_s": 10.0 + index}}


@pytest.fixture
def lower_only_run(tmp_path, monkeypatch) -> Path:
    """A --lower-only bounds run of scenarios 1-2 (no best-known time: those means are
    undefined); its folder."""
    monkeypatch.setattr(batch, "solve", _lower_only)
    out = tmp_path / "b"
    argv = ["--scenarios", "1-2", "--jobs", "1", "--no-progress", "--lower-only"]
    assert bounds_tool.main([*argv, "--out", str(out)]) == 0
    return out


UNDEFINED = ("mean_best_known_s", "mean_width", "max_width", "min_width", "mean_spread_s")


def test_bounds_summary_writes_undefined_means_as_null(lower_only_run):
    text = (lower_only_run / "summary.json").read_text()
    summary = _strict_json(lower_only_run / "summary.json")
    assert all(summary[key] is None for key in UNDEFINED)
    assert summary["mean_lower_bound_s"] == pytest.approx(11.5, abs=1e-12)
    assert '"nan"' not in text and summary["replay_ok"] == 0


@pytest.mark.parametrize("spelling", ["nan", None])
def test_the_bounds_reader_takes_nan_strings_and_nulls(lower_only_run, spelling):
    """Files of earlier versions spell an undefined mean "nan", new ones null: both read."""
    record = lower_only_run / "summary.json"
    summary = json.loads(record.read_text())
    summary.update(dict.fromkeys(UNDEFINED, spelling))
    record.write_text(json.dumps(summary, indent=2))
    table = batch.read_bounds_file(lower_only_run / "bounds.csv", 0, 3.0)
    assert sorted(table) == [1, 2]
    assert table[1][0] == pytest.approx(11.0, abs=1e-12)
    assert table[2][0] == pytest.approx(12.0, abs=1e-12)
    assert math.isnan(table[1][1]) and math.isnan(table[2][1])
