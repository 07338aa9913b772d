"""``python -m ddwmmr.bounds`` and ``scenarios --bounds``: means that say which scenarios
they are over, a cache that is checked before it is trusted (the ends' values, the
best-known trajectory beside its record), messages that say what happened (a cache
folder given as --out, the part of a scenario's cache removed, an interrupt, settings the
cache holds), ASCII scenario numbers only, and the plant and floor a bracket is for. The
solves are replaced by records with known numbers (a real scenario takes minutes)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import ddwmmr.cli.bounds as tool
from ddwmmr import ParameterError
from ddwmmr.bounds import batch
from ddwmmr.cli.scenarios import main as scenarios_main
from ddwmmr.model.symbolic import NU_FORCE, NX_FORCE
from ddwmmr.mpc.min_time import Guess

#: Times of the fake solves (s): scenario i's lower bound and best-known time.
LOWER, BEST = 10.0, 12.5


def _plan() -> dict[str, np.ndarray]:
    """A trajectory ``--option plan=DIR`` reads (3 steps of 1 s, 2 legs)."""
    return {
        "times": np.arange(4.0),
        "states": np.zeros((4, NX_FORCE)),
        "inputs": np.zeros((3, NU_FORCE)),
        "legs": np.array([1.0, 2.0]),
    }


def _solved(job: batch.Job, lower: float | None = None) -> dict:
    """What :func:`batch.solve` returns for a search that kept a trajectory."""
    index = job.scenario.index + 1
    wanted = batch.keys(job.scenario, job.payload, job.settings)
    out: dict = {"index": index}
    if job.need_lower:
        value = LOWER + index if lower is None else lower
        out["lower"] = {"key": wanted["lower"], "lower_bound_s": value}
    if job.need_best:
        out["best"] = {
            "key": wanted["best"],
            "best_known_s": BEST + index,
            "replay_ok": True,
            "start": "fbfbf-sssss-up-start",
            "starts": 3,
            "spread_s": 0.25,
        }
        out["trajectory"] = _plan()
    return out


@pytest.fixture
def solved(monkeypatch) -> list[tuple[int, bool, bool]]:
    """The jobs solved, in order: (scenario, best searched, lower bound computed)."""
    calls: list[tuple[int, bool, bool]] = []

    def solve(job: batch.Job) -> dict:
        calls.append((job.scenario.index + 1, job.need_best, job.need_lower))
        return _solved(job)

    monkeypatch.setattr(batch, "solve", solve)
    return calls


def _run(out: Path, scenarios: str, *extra: str) -> int:
    argv = ["--scenarios", scenarios, "--jobs", "1", "--no-progress", "--out", str(out)]
    return tool.main([*argv, *extra])


def _rows(out: Path) -> list[list[str]]:
    return [line.split(",") for line in (out / "bounds.csv").read_text().splitlines()[1:]]


def _cache(out: Path, index: int, part: str) -> Path:
    return out / batch.cache_names(index)[part]


# -- 1. each mean over its own scenarios --------------------------------------------------
def test_the_means_say_which_scenarios_they_are_over(tmp_path, solved, capsys):
    """Scenarios 1-2 searched, 3-4 lower bounds only: the best known's mean is over 2, the
    lower bound's over 4; the lower bound over those 2 is given beside it."""
    out = tmp_path / "b"
    assert _run(out, "1-2", "--quick") == 0
    assert _run(out, "1-4", "--quick", "--lower-only") == 0
    line = capsys.readouterr().out.splitlines()[-2]  # the last: wrote DIR/
    assert line == (
        "4 scenarios: lower bound 12.50 s (mean of all 4); over the 2 with a replayed "
        "best-known time: lower bound 11.50 s, best known 14.00 s, bracket width 1.218 "
        "(mean of best known / lower bound)"
    )
    summary = json.loads((out / "summary.json").read_text())
    assert summary["mean_lower_bound_s"] == pytest.approx(12.5, abs=1e-12)
    assert summary["mean_best_known_s"] == pytest.approx(14.0, abs=1e-12)
    assert summary["bracketed"] == 2 and summary["replay_ok"] == 2
    assert summary["mean_lower_bound_bracketed_s"] == pytest.approx(11.5, abs=1e-12)
    assert summary["mean_width"] == pytest.approx((13.5 / 11 + 14.5 / 12) / 2, abs=1e-12)


def test_a_fully_bracketed_run_prints_the_line_it_always_printed():
    rows = [batch.row(i, {"best_known_s": 12.0 + i, "replay_ok": True}, {"lower_bound_s": 10.0 + i})
            for i in (1, 2)]  # fmt: skip
    assert tool.summary_line(2, batch.summarize(rows)) == (
        "2 scenarios: lower bound 11.50 s, best known 13.50 s (replayed 2), bracket width "
        "1.174 (mean of best known / lower bound)"
    )


# -- 2. the ends checked where the cache is read, and where a row is written ----------------
@pytest.mark.parametrize("value", [20.0, 0.0, -1.0, "nan", None])
def test_a_cached_lower_bound_no_bracket_has_is_computed_again(tmp_path, solved, value):
    """20 s is above scenario 1's best known 13.5 s: it gave "bracket width 0.662" and a
    bounds.csv the scenario tool refuses."""
    out = tmp_path / "b"
    assert _run(out, "1", "--quick") == 0
    path = _cache(out, 1, "lower")
    record = json.loads(path.read_text())
    path.write_text(json.dumps({**record, "lower_bound_s": value}))
    assert _run(out, "1", "--quick", "--lower-only") == 0
    assert solved == [(1, True, True), (1, False, True)]
    assert _rows(out) == [["1", "11.0", "13.5", "3", "0.25", "True"]]
    assert json.loads(path.read_text())["lower_bound_s"] == 11.0


def test_a_best_known_time_below_a_fresh_lower_bound_is_refused_in_one_line(
    tmp_path, monkeypatch, capsys
):
    monkeypatch.setattr(batch, "solve", lambda job: _solved(job, lower=20.0))
    out = tmp_path / "b"
    assert _run(out, "1", "--quick") == 2
    err = capsys.readouterr().err
    assert err == (
        "error: bounds: scenario 1's best-known time 13.5 s is below its lower bound 20 s "
        "(no achieved time is below its lower bound): one of cache/scenario-001-best.json, "
        "cache/scenario-001-lower.json is wrong; delete both and run again\n"
    )
    assert not (out / "bounds.csv").exists()


# -- 3. the best-known trajectory checked with its record ---------------------------------
@pytest.mark.parametrize("damage", ["missing", "truncated"])
def test_a_lost_trajectory_makes_its_record_stale_and_is_searched_again(
    tmp_path, solved, capsys, damage
):
    out = tmp_path / "b"
    assert _run(out, "1", "--quick") == 0
    plan = _cache(out, 1, "trajectory")
    if damage == "missing":
        plan.unlink()
    else:
        plan.write_bytes(plan.read_bytes()[:100])
    assert _run(out, "1", "--quick") == 0
    assert solved == [(1, True, True), (1, True, False)]  # searched again, lower cached
    assert _rows(out) == [["1", "11.0", "13.5", "3", "0.25", "True"]]
    Guess.load(plan)  # what plan=DIR reads is whole again


def test_a_lower_only_run_drops_a_record_whose_trajectory_is_lost(tmp_path, solved, capsys):
    """plan=DIR then says the folder holds no plan and how to get one, instead of failing
    on the damaged file or saying the search found none."""
    out = tmp_path / "b"
    assert _run(out, "1", "--quick") == 0
    _cache(out, 1, "trajectory").unlink()
    assert _run(out, "1", "--quick", "--lower-only") == 0
    assert sorted(p.name for p in (out / "cache").iterdir()) == ["scenario-001-lower.json"]
    assert _rows(out) == [["1", "11.0", "nan", "0", "nan", "False"]]
    err = capsys.readouterr().err
    assert (
        f"note: removed the best-known record and trajectory of 1 scenario (1) from "
        f"{out / 'cache'}, keeping the lower bound: " in err
    )
    assert "or its trajectory missing or damaged; a run of it without --lower-only " in err


# -- 4. --lower-only names the settings the cache holds best-known times for ---------------
def test_lower_only_says_the_cache_holds_quick_results(tmp_path, solved, capsys):
    out = tmp_path / "b"
    assert _run(out, "1", "--quick") == 0
    assert _run(out, "1", "--lower-only") == 0
    line = capsys.readouterr().out.splitlines()[-2]  # the last: wrote DIR/
    assert line == (
        "1 scenario: lower bound 11.00 s, no best-known time with these settings (the cache "
        "holds ones of other settings: --quick; run with those to use them, or without "
        "--lower-only to search)"
    )
    assert _run(out, "1", "--lower-only", "--quick", "--stability-min", "1.5") == 0
    assert "other settings: --stability-min 1.25;" in capsys.readouterr().out


def test_lower_only_without_any_best_known_record_says_none_yet(tmp_path, solved, capsys):
    assert _run(tmp_path / "b", "1", "--lower-only") == 0
    assert capsys.readouterr().out.endswith(
        f"no best-known time yet (run without --lower-only for them)\nwrote {tmp_path / 'b'}/\n"
    )


# -- 5. scenarios --bounds: the thesis plant, and the floor of the best-known times --------
@pytest.fixture
def bounds_csv(tmp_path, solved) -> Path:
    out = tmp_path / "b"
    assert _run(out, "1", "--quick", "--stability-min", "1.3") == 0
    return out / "bounds.csv"


@pytest.mark.parametrize("plant", ["kinematic", "mujoco"])
def test_bounds_is_refused_on_a_plant_it_does_not_bound(tmp_path, bounds_csv, capsys, plant):
    argv = ["--n", "1", "--controller", "mpc", "--plant", plant, "--no-progress"]
    argv += ["--out", str(tmp_path / "s")]
    assert scenarios_main([*argv, "--bounds", str(bounds_csv)]) == 2
    assert capsys.readouterr().err == (
        f"error: bounds: only with --plant thesis (got {plant}): the lower bound prices the "
        "thesis plant's wheel forces, so no other plant's time is bracketed by it\n"
    )
    assert not (tmp_path / "s").exists()


def test_a_floor_other_than_the_bounds_runs_is_noted(bounds_csv, tmp_path, monkeypatch, capsys):
    """The note comes as the file is read, before any scenario runs."""
    import ddwmmr.cli.scenarios as scenarios_tool

    argv = ["--n", "1", "--controller", "qp", "--no-progress", "--out", str(tmp_path / "s")]
    config = scenarios_tool.config_from_arguments(scenarios_tool.build_parser().parse_args(argv))
    args = scenarios_tool.build_parser().parse_args([*argv, "--bounds", str(bounds_csv)])
    table = scenarios_tool._bounds_table(args, config)
    assert table[1] == (11.0, 13.5)
    assert capsys.readouterr().err == (
        f"note: the best-known times of {bounds_csv} hold S >= 1.3, this run "
        "S >= 1.25 (--qp-stability-min): its ratios to them compare different problems "
        "(the lower bounds hold for any floor)\n"
    )
    same = scenarios_tool.build_parser().parse_args(
        [*argv, "--qp-stability-min", "1.3", "--bounds", str(bounds_csv)]
    )
    scenarios_tool._bounds_table(same, scenarios_tool.config_from_arguments(same))
    assert capsys.readouterr().err == ""


# -- 6. messages --------------------------------------------------------------------------
def test_the_cache_folder_given_as_out_is_named_so(tmp_path, solved, capsys):
    out = tmp_path / "b"
    assert _run(out, "1", "--quick", "--lower-only") == 0
    capsys.readouterr()
    assert _run(out / "cache", "1", "--lower-only") == 2
    assert capsys.readouterr().err == (
        f"error: out: {out / 'cache'} is the cache folder of the bounds run in {out}, not a "
        f"run's folder: give --out {out} to resume or extend that run\n"
    )


def test_an_unreadable_best_record_is_named_as_the_part_removed(tmp_path, solved, capsys):
    out = tmp_path / "b"
    assert _run(out, "1", "--quick") == 0
    _cache(out, 1, "best").write_text("{")
    assert _run(out, "1", "--quick", "--lower-only") == 0
    err = capsys.readouterr().err
    assert "note: removed the best-known record and trajectory of 1 scenario (1) from " in err
    assert "note: removed the cache of" not in err
    assert _cache(out, 1, "lower").exists() and not _cache(out, 1, "trajectory").exists()


def test_an_interrupt_says_the_cache_is_kept_and_the_command_resumes(tmp_path, monkeypatch, capsys):
    done: list[int] = []

    def solve(job: batch.Job) -> dict:
        if done:
            raise KeyboardInterrupt
        done.append(job.scenario.index + 1)
        return _solved(job)

    monkeypatch.setattr(batch, "solve", solve)
    out = tmp_path / "b"
    assert _run(out, "1-2", "--quick", "--lower-only") == 130
    assert capsys.readouterr().err.splitlines() == [
        f"bounds: the cache of the scenarios finished so far is kept in {out / 'cache'}; the "
        "same command resumes from it",
        "interrupted (Ctrl-C): stopped; unfinished output removed",
    ]
    assert _cache(out, 1, "lower").exists() and not (out / "bounds.csv").exists()


def test_an_interrupt_before_any_scenario_finished_promises_no_cache(tmp_path, monkeypatch, capsys):
    def solve(job: batch.Job) -> dict:
        raise KeyboardInterrupt

    monkeypatch.setattr(batch, "solve", solve)
    out = tmp_path / "b"
    assert _run(out, "1-2", "--quick", "--lower-only") == 130
    assert capsys.readouterr().err.splitlines() == [
        "interrupted (Ctrl-C): stopped; unfinished output removed"
    ]
    assert not out.exists()


# -- 7. --scenarios in ASCII digits only -------------------------------------------------
@pytest.mark.parametrize("text", ["1_0", "+3", "\u0663", "1 - 3", "1-", "-3", "1,,2", "3.0"])
def test_scenarios_takes_ascii_digits_only(text):
    with pytest.raises(ParameterError, match=r"^scenarios must be numbers or ranges like"):
        tool.parse_scenarios(text)


def test_scenarios_takes_numbers_ranges_and_spaces_around_items():
    assert tool.parse_scenarios(" 3 ") == [3]
    assert tool.parse_scenarios("1, 3,7-9") == [1, 3, 7, 8, 9]
    assert tool.parse_scenarios("10") == [10]


# -- 8. the help's timings are docs/mpc.md's ---------------------------------------------
def test_the_help_gives_the_measured_times():
    text = " ".join(tool.build_parser().format_help().split())
    assert "about 55 s of CPU on average, 34 s with --quick, 19 s with --lower-only" in text
    assert "46 starts instead of 59-60" in text
    assert "lower bounds (about 19 s of CPU per scenario)" in text  # the option says it too
    assert "1-3 minutes" not in text and "half" not in text and "25 s" not in text
    cli = (Path(__file__).parents[1] / "docs" / "cli.md").read_text()
    assert "bounds (about 19 s of CPU each;" in cli
    docs = (Path(__file__).parents[1] / "docs" / "mpc.md").read_text()
    assert "About 55 s of CPU per scenario" in docs and "`--quick` (46 starts) about 34 s" in docs
    assert "59-60 starts each" in docs and "About 19 s of CPU per scenario (" in docs
