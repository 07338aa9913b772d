"""The docs scripts' one CSV writer (:func:`ddwmmr.outputs.csv_text` with the file's own
:func:`ddwmmr.outputs.line_ending`, written by ``write_atomic``): the committed data of
docs/bounds comes out byte for byte when rewritten from its rows."""

from __future__ import annotations

import csv
import importlib.util
import shutil
import sys
from pathlib import Path

import pytest

from ddwmmr.outputs import csv_text, line_ending

DOCS = Path(__file__).resolve().parent.parent / "docs"
COMMITTED = sorted((DOCS / "bounds").glob("*.csv"))


def read(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    with open(path, newline="") as handle:
        reader = csv.DictReader(handle)
        return list(reader.fieldnames or []), list(reader)


@pytest.mark.parametrize("path", COMMITTED, ids=lambda p: p.name)
def test_committed_bounds_csvs_rewrite_byte_identical(path):
    header, rows = read(path)
    assert len(rows) >= 100
    assert csv_text(header, rows, line_ending(path)).encode() == path.read_bytes()


def test_line_endings_of_the_committed_files_and_of_a_new_one(tmp_path):
    assert line_ending(DOCS / "bounds" / "bounds_seed0.csv") == "\r\n"
    assert line_ending(DOCS / "bounds" / "accounting_seed0.csv") == "\n"
    assert line_ending(tmp_path / "absent.csv") == "\n"
    assert line_ending(tmp_path / "absent.csv", default="\r\n") == "\r\n"


def test_csv_text_quotes_and_fills_like_dictwriter():
    text = csv_text(["a", "b"], [{"a": "x,y", "b": 1.5}, {"a": 2}], "\r\n")
    assert text == 'a,b\r\n"x,y",1.5\r\n2,\r\n'
    with pytest.raises(ValueError):
        csv_text(["a"], [{"a": 1, "c": 2}])


def test_bounds_stops_rewrites_the_committed_lower_bounds_byte_identical(tmp_path, monkeypatch):
    """docs/bounds_stops.py: the committed stops rows (as floats, as computed) set every
    ``lower_bound_s`` of bounds_seed{S}.csv to the same bytes, and stops_seed{S}.csv too."""
    spec = importlib.util.spec_from_file_location("docs_bounds_stops_h72", DOCS / "bounds_stops.py")
    script = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, script)
    spec.loader.exec_module(script)
    monkeypatch.setattr(script, "DATA", tmp_path)
    for seed in script.SEEDS:
        for name in (f"bounds_seed{seed}.csv", f"stops_seed{seed}.csv"):
            shutil.copyfile(DOCS / "bounds" / name, tmp_path / name)
        header, text_rows = read(DOCS / "bounds" / f"stops_seed{seed}.csv")
        rows = [
            {k: int(v) if k == "scenario" else float(v) for k, v in r.items()} for r in text_rows
        ]
        script.write_csv(tmp_path / f"stops_seed{seed}.csv", header, rows)
        script.set_lower_bounds(seed, rows)
        for name in (f"bounds_seed{seed}.csv", f"stops_seed{seed}.csv"):
            assert (tmp_path / name).read_bytes() == (DOCS / "bounds" / name).read_bytes()


def test_bounds_stops_keeps_the_line_ending_of_a_fresh_bounds_csv(tmp_path, monkeypatch):
    """A bounds.csv as ``python -m ddwmmr.bounds`` writes it (LF) stays LF when
    docs/bounds_stops.py sets its lower bounds, as docs/bounds_figures.py keeps it."""
    spec = importlib.util.spec_from_file_location("docs_bounds_stops_h72", DOCS / "bounds_stops.py")
    script = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, script)
    spec.loader.exec_module(script)
    monkeypatch.setattr(script, "DATA", tmp_path)
    header = "scenario,lower_bound_s,best_known_s,starts,spread_s,replay_ok\n"
    (tmp_path / "bounds_seed0.csv").write_bytes(
        (header + "1,nan,10.0,59,1.0,True\n2,nan,9.0,59,1.0,True\n").encode()
    )
    script.set_lower_bounds(0, [{"scenario": 1, "a": 4.5, "b": 5.25}, {"scenario": 2, "a": 6.0}])
    assert (tmp_path / "bounds_seed0.csv").read_bytes() == (
        header + "1,5.25,10.0,59,1.0,True\n2,6.0,9.0,59,1.0,True\n"
    ).encode()
