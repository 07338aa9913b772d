"""Names in compare reports: a trajectory name becomes part of file names and of the
Markdown; neither may escape the output folder, exceed a file name's length, or inject
HTML or break a table (report.md inserted them raw, report.html escaped them)."""

from __future__ import annotations

from pathlib import Path

import pytest

from ddwmmr.cli.compare import main as compare_main
from ddwmmr.errors import ParameterError
from ddwmmr.reports.compare import CompareConfig
from ddwmmr.reports.compare.document import Document
from ddwmmr.reports.compare.plan import MAX_REPORT_NAME, check_report_name, report_name
from ddwmmr.trajectories import Ellipse


@pytest.mark.parametrize(
    ("name", "safe"),
    [
        ("ellipse", "ellipse"),
        ("figure8.v2", "figure8.v2"),
        ("sub/../../escape", "sub_______escape"),
        ("..", "__"),
        (".hidden", "_hidden"),
        ("-dash", "_dash"),
        ("<img src=x onerror=alert(1)>", "_img_src_x_onerror_alert_1__"),
        ("two\nlines", "two_lines"),
        ("", "_"),
        ("n" * 300, "n" * MAX_REPORT_NAME),
    ],
)
def test_report_name_is_a_plain_file_name(name, safe):
    assert report_name(name) == safe
    assert check_report_name(report_name(name)) == safe


@pytest.mark.parametrize("name", ["sub/../../escape", "n" * 251, "a\nb", "<b>", "..", 3])
def test_a_config_with_an_unsafe_name_is_refused_before_any_run(name):
    with pytest.raises(ParameterError, match="cannot name the report's files") as error:
        CompareConfig(methods=("pi",), trajectories={name: Ellipse()})
    assert "\n" not in str(error.value) and len(str(error.value)) < 300


def test_markdown_shows_html_and_line_breaks_in_names_as_text():
    doc = Document("Method comparison")
    name = "<img src=x onerror=alert(1)>"
    doc.heading(f"trajectory {name}\n# not a heading")
    doc.paragraph(f"file {name}.csv, `code <b> kept`, S < 1.25")
    doc.bullets([f"a\nb {name}"])
    doc.table(["method", f"{name} RMS"], [["pi\n| x |", "1.0"]])
    text = doc.to_markdown()
    assert "<img" not in text.replace("`code <b> kept`", "")
    assert "&lt;img src=x onerror=alert(1)>" in text
    assert "`code <b> kept`" in text and "S < 1.25" in text  # code spans and comparisons
    lines = text.splitlines()
    assert "## trajectory &lt;img src=x onerror=alert(1)> # not a heading" in lines
    assert "| pi \\| x \\| | 1.0 |" in lines  # one row, its bars escaped
    assert "- a b &lt;img src=x onerror=alert(1)>" in lines


def test_compare_with_unsafe_trajectory_names_writes_inside_its_folder(tmp_path, monkeypatch):
    # before: every simulation ran, then exit 1 at the figure stage
    monkeypatch.chdir(tmp_path)
    Path("escape.toml").write_text('[trajectory]\nshape = "ellipse"\nname = "sub/../../escape"\n')
    Path("long.toml").write_text(f'[trajectory]\nshape = "ellipse"\nname = "{"n" * 260}"\n')
    args = ["--methods", "pi", "--only", "escape.toml,long.toml", "--study", "none"]
    assert compare_main([*args, "--jobs", "1", "--duration", "0.2", "--out", "out"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["escape.toml", "long.toml", "out"]
    files = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert "paths_sub_______escape.png" in files
    assert f"paths_{'n' * MAX_REPORT_NAME}.png" in files
    text = (tmp_path / "out" / "report.md").read_text()
    # the name is shown as written, as text; every link points at a file-safe name
    assert (
        "sub/../../escape" in text
        and "](sub/" not in text
        and "](paths_sub_______escape.png)" in text
    )
