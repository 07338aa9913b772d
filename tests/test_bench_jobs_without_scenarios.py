"""``python -m ddwmmr.bench --jobs N`` is refused when no scenario is timed."""

from __future__ import annotations

import pytest

from ddwmmr.cli import bench as bench_cli
from in_process import call_main


@pytest.mark.parametrize(
    ("args", "given"),
    [
        (["--scenarios", "0", "--jobs", "4"], "got 0"),
        (["--method", "pi", "--jobs", "2"], "0 by default with --method"),
    ],
)
def test_bench_refuses_jobs_when_no_scenario_runs(args, given, tmp_path, monkeypatch, capsys):
    """--jobs was ignored without a word when no scenario was timed."""

    def no_run(*_, **__):
        raise AssertionError("the benchmark ran")

    monkeypatch.setattr(bench_cli, "run_benchmark", no_run)
    monkeypatch.chdir(tmp_path)
    status, out, err = call_main(bench_cli.main, [*args, "--out", "b.json"], capsys)
    assert (status, out) == (2, "")
    assert err == f"error: --jobs: only used with --scenarios N >= 1 ({given})\n"
    assert list(tmp_path.iterdir()) == []
    assert "only with --scenarios N >= 1" in " ".join(
        bench_cli.build_parser().format_help().split()
    )
