"""``python -m ddwmmr.bounds``: bad input refused before any scenario is solved (one line,
status 2, nothing written), as the other tools refuse it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import ddwmmr.cli.bounds as tool
from ddwmmr.cli.scenarios import main as scenarios


@pytest.fixture
def nothing_solved(monkeypatch):
    """Fail the test if the tool gets as far as solving a scenario."""

    def solve(*args, **kwargs):
        raise AssertionError("a scenario was solved")

    monkeypatch.setattr(tool, "_solve_all", solve)


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc")
def test_an_out_no_file_can_be_created_in_is_refused_first(nothing_solved, capsys):
    """/proc looks writable to os.access (as root) but takes no file: it used to fail with
    status 1 only when the first scenario's result was cached, after seconds of work."""
    status = tool.main(["--scenarios", "1", "--lower-only", "--jobs", "1", "--out", "/proc/x"])
    assert status == 2
    err = capsys.readouterr().err
    assert err == (
        "error: out: cannot write in /proc: /proc takes no new files or folders; "
        "choose a folder elsewhere\n"
    )


def test_a_payload_that_tips_the_start_pose_is_refused_as_scenarios_refuses_it(
    nothing_solved, tmp_path, capsys
):
    out = tmp_path / "b"
    argv = ["--scenarios", "1", "--lower-only", "--payload", "20", "--out", str(out)]
    assert tool.main(argv) == 2
    err = capsys.readouterr().err
    assert err == (
        "error: payload: 20 kg tips the robot over in the start pose (S = 0.741 <= 1); the "
        "start pose holds at most 9.338 kg\n"
    )
    assert scenarios(["--payload", "20", "--out", str(tmp_path / "s")]) == 2
    assert capsys.readouterr().err == err  # the same check, the same line
    assert list(tmp_path.iterdir()) == []


def test_the_summary_line_counts_one_scenario_in_the_singular():
    from ddwmmr.cli.bounds import summary_line

    summary = {"mean_lower_bound_s": 11.0, "replay_ok": 0, "mean_best_known_s": math.nan}
    assert summary_line(1, summary).startswith("1 scenario: lower bound 11.00 s, no best-known")
    assert summary_line(2, summary).startswith("2 scenarios: lower bound 11.00 s")
