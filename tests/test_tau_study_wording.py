"""The tau study's sentence on convergence: a tau the run is too short to settle for (the
run ends before the 2.996 tau a first-order decay needs to fall below 5 %) is said to be
that, not a steady error above 5 %; with a long enough run the text is as before."""

from __future__ import annotations

import math
import re

from ddwmmr.cli.compare import main
from ddwmmr.reports.compare.report import _tau_finding

THEORY = -math.log(0.05)  # 2.996: exp(-t/tau) falls below 5 % after this many tau


def test_a_run_shorter_than_three_tau_is_said_to_be_too_short() -> None:
    convergence = {"clrrmc-ts": {0.1: 0.3, 0.3: 0.9, 1.0: 3.0, 3.0: math.nan}}
    assert _tau_finding(convergence, 5.0, THEORY) == (
        "Convergence time: 0.300 s at tau = 0.1 s to 3.00 s at tau = 1 s for clrrmc-ts (the "
        "5 s run is too short to settle for tau = 3 s: it ends before 2.996 tau). Larger tau "
        "is more sluggish."
    )


def test_a_long_enough_run_keeps_the_steady_error_text() -> None:
    convergence = {"qp": {0.1: 0.3, 0.3: 0.9, 1.0: 3.0, 3.0: math.nan}}
    assert _tau_finding(convergence, 20.0, THEORY) == (
        "Convergence time: 0.300 s at tau = 0.1 s to 3.00 s at tau = 1 s for qp (not settled "
        "for tau = 3 s: its steady error exceeds 5 % of the offset). Larger tau is more "
        "sluggish."
    )
    never = {"ap": dict.fromkeys((0.1, 0.3, 1.0, 3.0), math.nan)}
    assert _tau_finding(never, 20.0, THEORY) == (
        "Convergence time: ap never gets below 5 % of the offset. Larger tau is more sluggish."
    )


def test_both_causes_and_a_run_too_short_for_any_tau() -> None:
    convergence = {"qp": {0.1: 0.3, 0.3: math.nan, 1.0: math.nan, 3.0: math.nan}}
    assert _tau_finding(convergence, 2.0, THEORY) == (
        "Convergence time: 0.300 s at tau = 0.1 s for qp (not "
        "settled for tau = 0.3 s: its steady error exceeds 5 % of the offset; the 2 s run is "
        "too short to settle for tau = 1, 3 s: it ends before 2.996 tau). Larger tau is more "
        "sluggish."
    )
    never = {"qp": dict.fromkeys((0.1, 0.3, 1.0, 3.0), math.nan)}
    assert _tau_finding(never, 0.2, THEORY) == (
        "Convergence time: qp does not get below 5 % of the offset (the 0.2 s run is too "
        "short to settle for tau = 0.1, 0.3, 1, 3 s: it ends before 2.996 tau). Larger tau is "
        "more sluggish."
    )


def test_the_report_of_a_5_s_tau_study(tmp_path) -> None:
    out = tmp_path / "cmp"
    argv = ["--methods", "clrrmc-ts", "--study", "tau", "--duration", "5", "--jobs", "1"]
    argv += ["--only", "ellipse"]  # the study runs on the ellipse; the rectangle adds nothing
    assert main([*argv, "--no-progress", "--out", str(out)]) == 0
    text = (out / "report.md").read_text()
    found = re.search(r"Convergence time: [^\n]*sluggish\.", text)
    assert found is not None
    assert found.group(0) == (
        "Convergence time: 0.300 s at tau = 0.1 s to 3.00 s at tau = 1 s for clrrmc-ts (the "
        "5 s run is too short to settle for tau = 3 s: it ends before 2.996 tau). Larger tau "
        "is more sluggish."
    )
