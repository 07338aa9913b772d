"""``bench --compare FILE`` with an edited report: an entry named twice was read as the
last of them, silently; a tiny or huge number (> 0, so accepted) printed ``(infx)``."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from ddwmmr import ParameterError
from ddwmmr.bench.report import format_comparison, read_report

REPORT = Path(__file__).resolve().parents[1] / "benchmarks" / "bench.json"


def edited(tmp_path: Path, edit) -> Path:
    data = json.loads(REPORT.read_text())
    edit(data)
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    ("key", "field"), [("rows", "label"), ("qp_classes", "name"), ("scenarios", "controller")]
)
def test_an_entry_named_twice_is_refused(tmp_path, key, field):
    def twice(data):
        data[key].append(copy.deepcopy(data[key][0]))

    name = json.loads(REPORT.read_text())[key][0][field]
    with pytest.raises(ParameterError, match=rf'"{key}"\[\d+\]\.{field} .*{name}.* is given twice'):
        read_report(edited(tmp_path, twice))


def test_a_ratio_beyond_floats_is_said_so_not_printed_as_inf(tmp_path):
    def tiny(data):
        data["rows"][0]["step_us"] = 1e-320

    previous = read_report(edited(tmp_path, tiny))  # > 0: a report may hold it
    report = read_report(REPORT)
    lines = format_comparison(report, previous).splitlines()
    label = report["rows"][0]["label"]
    (line,) = [text for text in lines if text.strip().startswith(label + " ")]
    assert line.endswith("(>1e308x)") and "inf" not in line
    previous["rows"][0]["step_us"] = 1e308
    report = copy.deepcopy(report)
    report["rows"][0]["step_us"] = 1e-300
    (line,) = [t for t in format_comparison(report, previous).splitlines() if label + " " in t]
    assert line.endswith("(<1e-308x)")
    assert "(1.00x)" in format_comparison(read_report(REPORT), read_report(REPORT))


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda config: config.update(timestamp="2026-12-07\nfake: line"), "timestamp"),
        (lambda config: config.update(timestamp=20261207), "timestamp"),
        (lambda config: config.update(package_version="0.1.0\nx"), "package_version"),
        (lambda config: config["git"].update(commit="f2da\r\n"), "git.commit"),
    ],
)
def test_a_header_field_off_one_line_is_refused(tmp_path, edit, field):
    # printed in the comparison's header line as it was, a newline split the line
    with pytest.raises(ParameterError, match=rf'^compare: .* "config"\.{field} must be') as info:
        read_report(edited(tmp_path, lambda data: edit(data["config"])))
    assert "\n" not in str(info.value)


def test_a_date_only_timestamp_and_a_null_commit_are_read(tmp_path):
    def edit(data):
        data["config"]["timestamp"] = "2026-12-07"
        data["config"]["git"]["commit"] = None

    header = format_comparison(read_report(REPORT), read_report(edited(tmp_path, edit)))
    assert header.splitlines()[0].startswith("against 2026-12-07 (ddwmmr 0.1.0, no commit)")
