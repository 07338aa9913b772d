"""A summary metric reads the same in ``track``'s printed table, ``compare``'s report and the
simulator's summary line: the short label (compare's column, the simulator's line) is one
string, and track's long label spells out its words (an abbreviation is the start of its
word) in the same order; track's values stay aligned."""

from __future__ import annotations

import re
from types import SimpleNamespace

import pytest

from ddwmmr import Ellipse
from ddwmmr.cli.track import TABLE_KEYS, format_table
from ddwmmr.gui.app import SUMMARY_METRICS, _summary_line
from ddwmmr.reports.compare import CompareConfig, execute, plan_runs, write_report
from ddwmmr.reports.compare.report import METRIC_COLUMNS
from ddwmmr.sim.verdict import STEP_COUNT_KEYS

#: Flags of the summary (False here) and its text (``joint_limit_held``).
FLAGS = ("diverged", "tipped", "support_lost")


def full_summary() -> dict[str, object]:
    """A summary holding every key the three outputs show, each a different value: step
    counts are ints below ``steps``, flags False, the rest floats."""
    keys = {*TABLE_KEYS, *SUMMARY_METRICS, *(key for _, key, _ in METRIC_COLUMNS)}
    summary: dict[str, object] = {"method": "qp", "trajectory": "ellipse", "plant": "thesis"}
    for i, key in enumerate(sorted(keys)):
        summary[key] = i + 1 if key in STEP_COUNT_KEYS else 0.25 * (i + 1)
    summary.update(dict.fromkeys(FLAGS, False), joint_limit_held="th2 = -3.142 rad")
    summary.update(steps=1000, verdict_reasons=[], fallback_steps=0, duration=10.0, dt=0.02)
    return summary


def track_labels() -> dict[str, str]:
    """Track's label of each key, read off its printed table (one line per key, in order)."""
    lines = format_table(full_summary()).splitlines()[1 : 1 + len(TABLE_KEYS)]
    return {key: line[2:38].rstrip() for key, line in zip(TABLE_KEYS, lines, strict=True)}


def gui_labels() -> dict[str, str]:
    """The simulator's label of each key, ``name (unit)`` as compare heads its column,
    read off its summary line (``name value unit``, comma-separated after the verdict)."""
    line = _summary_line("qp", SimpleNamespace(summary=full_summary()))
    items = line.split("; ", 1)[1].split(", ")[: len(SUMMARY_METRICS)]
    labels = {}
    for key, item in zip(SUMMARY_METRICS, items, strict=True):
        name, _, unit = re.fullmatch(r"(.+) [-+0-9.e]+( (\S+))?", item).group(1, 2, 3)
        labels[key] = f"{name} ({unit})" if unit else name
    return labels


def words(label: str) -> list[str]:
    return [w.rstrip(".") for w in re.split(r"[\s\-()]+", label.lower()) if w]


def unit(label: str) -> str:
    """A label's trailing ``(unit)``, '' for none."""
    found = re.search(r"\(([^ ()]+)\)$", label)
    return found.group(1) if found else ""


def spells_out(short: str, long: str) -> bool:
    """Each word of ``short`` starts a word of ``long``, in order (``long`` may add words)."""
    rest = iter(words(long))
    return all(any(w.startswith(s) for w in rest) for s in words(short))


def test_the_simulator_names_each_metric_as_compare_heads_its_column() -> None:
    compare = {key: header for header, key, _ in METRIC_COLUMNS}
    assert gui_labels() == {key: compare[key] for key in SUMMARY_METRICS}


def test_track_spells_out_compare_s_label_of_each_shared_metric() -> None:
    compare = {key: header for header, key, _ in METRIC_COLUMNS}
    track = track_labels()
    shared = sorted(set(compare) & set(track))
    assert len(shared) == 13  # every column but the mean manipulability and the verdict
    assert [k for k in shared if not spells_out(compare[k], track[k])] == []
    # where compare gives a unit, track gives the same one
    assert [k for k in shared if unit(compare[k]) not in ("", unit(track[k]))] == []


def test_the_labels_that_disagreed_now_read_alike() -> None:
    """peak wheel / max wheel speed, step latency / median controller step, and track's
    joint rate "at speed limit", which the verdict calls a joint at its rate limit."""
    compare = {key: header for header, key, _ in METRIC_COLUMNS}
    track, gui = track_labels(), gui_labels()
    assert compare["max_wheel_speed_rad_s"] == gui["max_wheel_speed_rad_s"]
    assert compare["max_wheel_speed_rad_s"] == track["max_wheel_speed_rad_s"]
    assert compare["max_wheel_speed_rad_s"] == "max wheel speed (rad/s)"
    assert compare["median_step_us"] == "median step (us)"
    assert track["median_step_us"] == "median controller step (us)"
    assert track["joint_rate_limit_steps"] == "joint at rate limit (steps)"
    assert track["wheel_limit_steps"] == "wheel at speed limit (steps)"
    assert compare["min_stability"] == track["min_stability"] == gui["min_stability"]


def test_the_verdict_names_the_settled_end_error_as_track_s_table_does() -> None:
    """The verdict quoted the settled-end RMS as "final error"; it uses track's name."""
    from ddwmmr import Robot, load_trajectory, simulate
    from ddwmmr.reports.metrics import METRICS
    from ddwmmr.sim.verdict import REASONS, SETTLED_END_ERROR

    label = METRICS["final_position_error_m"]
    assert SETTLED_END_ERROR == label.long == "settled-end RMS position error"
    assert track_labels()["final_position_error_m"] == f"{SETTLED_END_ERROR} (mm)"
    assert REASONS["final_error_above_limit"].startswith(f"{SETTLED_END_ERROR} {{final_mm")
    rectangle = load_trajectory("rectangle")  # ends 361 mm off (tests/test_verdict.py)
    run = simulate(Robot(), rectangle, "clrrmc-cs", tau=0.3, integrator="euler", dt=0.05)
    summary = run.summary
    assert "final_error_above_limit" in summary["verdict_reasons"]
    assert "settled-end RMS position error 361 mm (limit 84.85 mm)" in summary["verdict"]
    assert "final error" not in summary["verdict"]


def test_the_words_rule_refuses_a_synonym() -> None:
    assert spells_out("RMS pos (mm)", "RMS position error (mm)")
    assert spells_out("min manip.", "min manipulability")
    assert not spells_out("peak wheel (rad/s)", "max wheel speed (rad/s)")
    assert not spells_out("joint-rate-limit steps", "joint rate at speed (steps)")


def test_track_s_values_stay_aligned_with_every_row() -> None:
    lines = format_table(full_summary()).splitlines()[1 : 1 + len(TABLE_KEYS)]
    assert len(lines) == len(TABLE_KEYS) == 34
    # two spaces, the label padded to 36 characters, a space, then every value at column 39
    assert all(line[:2] == "  " and line[2] != " " for line in lines)
    assert all(line[38] == " " and line[39] != " " for line in lines)
    assert max(len(label) for label in track_labels().values()) == 35


@pytest.fixture(scope="module")
def report_text(tmp_path_factory) -> str:
    """ats on 2 s of the ellipse, kinematic and thesis plant, no studies."""
    config = CompareConfig(
        methods=("ats",),
        trajectories={"ellipse": Ellipse()},
        duration=2.0,
        studies=(),
        plants=("thesis",),
    )
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs())
    folder = tmp_path_factory.mktemp("report")
    write_report(config, plan, outputs, folder)
    return (folder / "report.md").read_text()


def header_after(text: str, heading: str) -> list[str]:
    lines = text[text.index(heading) :].splitlines()
    row = next(x for x in lines if x.startswith("| "))
    return [c.strip() for c in row.strip("|").split("|")]


def test_the_report_heads_its_tables_with_the_shared_labels(report_text: str) -> None:
    metrics = header_after(report_text, "## Trajectory: ellipse")
    assert metrics[1:15] == [header for header, _, _ in METRIC_COLUMNS][:14]
    assert "max wheel speed (rad/s)" in metrics and "median step (us)" in metrics
    plant = header_after(report_text, "## Plant: thesis")
    assert "min stability S" in plant and "min S" not in plant
    assert "- median step: median wall-clock time of one controller call (us)" in report_text
