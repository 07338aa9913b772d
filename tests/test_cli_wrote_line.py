"""Every tool's last line on stdout is ``wrote <path>``: its output folder (with a
trailing ``/``) or file, as given with ``--out`` (a relative path stays relative), so a
script finds where any tool wrote the same way (docs/cli.md, "Where the output went")."""

from __future__ import annotations

import json

import pytest

from ddwmmr.bounds import batch
from ddwmmr.cli import bench, bounds, compare, scenarios, track


def _lower_bound_only(job: batch.Job) -> dict:
    """Stand-in for batch.solve (a --lower-only job): the tool's plumbing, no optimisation."""
    wanted = batch.keys(job.scenario, job.payload, job.settings)
    lower = {"key": wanted["lower"], "lower_bound_s": 10.0}
    return {"index": job.scenario.index + 1, "lower": lower}


#: tool: (main, arguments besides --out, --out as given, the path the line names).
CASES = {
    "track": (
        track.main,
        ["--method", "pi", "--traj", "ellipse", "--duration", "0.2", "--no-plots"],
        "runs/t",
        "runs/t/",
    ),
    "compare": (
        compare.main,
        ["--methods", "pi", "--only", "ellipse", "--study", "none", "--duration", "0.2"],
        "runs/c",
        "runs/c/",
    ),
    "scenarios": (
        scenarios.main,
        ["--n", "1", "--time-limit", "0.3", "--jobs", "1"],
        "runs/s",
        "runs/s/",
    ),
    "bounds": (bounds.main, ["--scenarios", "1", "--lower-only"], "runs/b", "runs/b/"),
    "bench": (
        bench.main,
        ["--repeats", "1", "--calls", "10", "--duration", "0.2", "--method", "ats"],
        "bench-ats.json",
        "bench-ats.json",
    ),
}


@pytest.mark.parametrize("tool", CASES)
def test_the_last_stdout_line_names_the_output_as_given(tool, tmp_path, monkeypatch, capsys):
    """Before, only track ended stdout with it: scenarios and bounds (the latter with the
    absolute path) said it on stderr, compare only in its Report line, bench nothing."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(batch, "solve", _lower_bound_only)  # bounds, in this process
    main, arguments, given, named = CASES[tool]
    jobs = [] if tool in ("track", "scenarios", "bench") else ["--jobs", "1"]
    assert main([*arguments, *jobs, "--out", given, "--no-progress"]) == 0
    said = capsys.readouterr()
    assert said.out.splitlines()[-1] == f"wrote {named}"
    assert "wrote" not in said.err
    assert (tmp_path / named).exists()


def test_bench_json_keeps_stdout_one_json_document(tmp_path, monkeypatch, capsys):
    """With --json the line goes to stderr: `bench --json > copy.json` stays JSON."""
    monkeypatch.chdir(tmp_path)
    main, arguments, given, named = CASES["bench"]
    assert main([*arguments, "--out", given, "--json", "--no-progress"]) == 0
    said = capsys.readouterr()
    assert json.loads(said.out) == json.loads((tmp_path / named).read_text())
    assert said.err.splitlines()[-1] == f"wrote {named}"
