"""Compare's report names one quantity per column and sentence: the settled-end RMS apart
from the error at the last sample, the steps the plant clipped apart from the limits a
method holds itself, the first-order time as the multiple of tau its column holds; a
default study the trajectories leave out is named; the advice table's text is left
aligned."""

from __future__ import annotations

import contextlib
import io
import math
import re
from pathlib import Path

import pytest

from ddwmmr import Robot, simulate
from ddwmmr.cli.compare import main
from ddwmmr.reports.compare.diagnosis import NOTHING_ADVERSE, held_limits_text
from ddwmmr.reports.compare.document import Document, mm
from ddwmmr.reports.compare.report import _rk4_finding, first_order
from ddwmmr.trajectories import load_trajectory


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> tuple[str, str]:
    """report.md and stderr of a 2 s comparison of ats, clrrmc-ts and mpc on the ellipse
    alone, with the default studies (corners among them)."""
    out = tmp_path_factory.mktemp("compare") / "cmp"
    argv = ["--methods", "ats,clrrmc-ts,mpc", "--only", "ellipse", "--duration", "2"]
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert main([*argv, "--jobs", "1", "--no-progress", "--out", str(out)]) == 0
    return (Path(out) / "report.md").read_text(), err.getvalue()


def _section(text: str, heading: str) -> str:
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return text[start : end if end >= 0 else None]


def _row(section: str, method: str) -> list[str]:
    line = next(x for x in section.splitlines() if x.startswith(f"| {method} |"))
    return [cell.strip() for cell in line.strip("|").split("|")]


def test_a_default_study_left_out_by_only_is_named(report) -> None:
    text, err = report
    assert (
        "note: study corners skipped: it needs the rectangle trajectory, which is not "
        "compared (trajectories: ellipse)\n" in err
    )
    assert (
        "(studies: tau, dt, integrator, init; corners skipped: it needs the rectangle "
        "trajectory, which is not compared)" in text
    )


def test_the_integrator_study_shows_the_error_at_the_end_in_text_and_table(report) -> None:
    section = _section(report[0], "## Study: Euler vs RK4")
    assert "| Euler at the end (mm) |" in section and "Euler final" not in section
    ats = simulate(
        Robot(),
        load_trajectory("ellipse"),
        "ats",
        integrator="euler",
        initial_offset=(0.0, 0.0),
        duration=2.0,
    ).summary
    end, settled = mm(ats["end_position_error_m"]), mm(ats["final_position_error_m"])
    assert (end, settled) == ("0.998", "0.978")  # the two differ: the table must pick one
    assert _row(section, "ats")[-1] == end
    said = re.search(r"mm half way, ([\d.e+-]+) mm at the end", section)
    assert said is not None and said.group(1) == end


def test_definitions_name_the_settled_end_and_the_clipped_steps(report) -> None:
    section = _section(report[0], "## Definitions and files")
    assert (
        'settled-end RMS position error (`final_position_error_m`; "final" in the verdict): '
        "RMS of the position error over the settled end of the run, the last 5 % of the "
        "samples outside the rectangle's corner windows; position error at the end "
        "(`end_position_error_m`): at the last sample" in section
    )
    assert "saturated steps: steps whose command the plant clipped" in section
    assert "speed limit was hit" not in section
    assert "within 0.1 % of its limit" in section


def test_mpc_shows_the_joint_rate_limit_it_holds_and_no_contradiction(report) -> None:
    text = report[0]
    table = _section(text, "## Trajectory: ellipse")
    header = [c.strip() for c in table.splitlines()[2].strip("|").split("|")]
    mpc = dict(zip(header, _row(table, "mpc")))
    assert "settled-end RMS pos (mm)" in header and "final pos (mm)" not in header
    assert (mpc["saturated steps"], mpc["wheel-limit steps"]) == ("0", "0")
    assert mpc["joint-rate-limit steps"] == "26"
    bullet = next(x for x in text.splitlines() if x.startswith("- **mpc**:"))
    assert (
        "it passes the shoulder singularity cos(th1) = 0 at t = 0.6 s without losing the "
        "path (largest error after it 10.3 mm; no step damped)" in bullet
    )
    assert "it held a joint at its rate limit on 26 steps (the plant clipped none)" in bullet
    assert "no singularity" not in bullet and bullet.endswith(NOTHING_ADVERSE + ".")


def test_held_limits_are_named_only_beyond_the_clipped_steps() -> None:
    assert held_limits_text({"saturated_steps": 5, "wheel_limit_steps": 5}) == ""
    assert held_limits_text({"saturated_steps": 3, "wheel_limit_steps": 40}) == (
        "it held a wheel at its speed limit on 40 steps (the plant clipped 3 steps in all)"
    )


def test_the_first_order_column_holds_the_multiple_its_header_names(report) -> None:
    theory = -math.log(0.05)
    assert first_order(theory) == "2.996 tau"
    section = _section(report[0], "## Study: time constant")
    assert "| 2.996 tau (s) |" in section and "3.00 tau" not in section
    assert "needs 2.996 tau" in section
    assert _row(section, "clrrmc-ts")[3] == "0.300"  # 0.2996 at tau = 0.1 s
    rows = [x for x in section.splitlines() if x.startswith("| clrrmc-ts | 0.300 |")]
    assert [c.strip() for c in rows[0].strip("|").split("|")][3] == "0.899"
    assert "saturated / wheel-limit / joint-rate-limit steps ellipse" in section


def test_rk4_finding_takes_the_measured_maxima() -> None:
    text = _rk4_finding({"ats": 2e-12, "clrrmc-ts": 1e-4}, {"ats": 4.44e-3, "clrrmc-ts": 2.4e-4})
    assert text == (
        "With RK4 the largest errors are 2.00e-09 mm for ats and 0.100 mm for clrrmc-ts: not "
        "below 0.1 x the method's Euler drift for clrrmc-ts."
    )


def test_the_advice_table_left_aligns_its_text_columns(report) -> None:
    section = _section(report[0], "## Which method should I use?")
    assert "|:---|:---|---:|:---|:---|:---|" in section
    doc = Document("t")
    doc.table(["a", "b", "c"], [["x", "y", "1"]], left=(0, 1))
    assert "|:---|:---|---:|" in doc.to_markdown()
    html = doc.to_html(Path("."))
    assert '<td>x</td><td style="text-align: left">y</td><td>1</td>' in html
    plain = Document("t")
    plain.table(["a", "b"], [["x", "1"]])
    assert "|:---|---:|" in plain.to_markdown()
