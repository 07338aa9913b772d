"""``python -m ddwmmr.bench`` reports bad input as every other tool does: a value the
library refuses is one line ``error: ...`` (run_main's), a malformed command line is
argparse's line prefixed with the tool's ``prog``; exit status 2, no usage, no traceback."""

from __future__ import annotations

import pytest

from ddwmmr.cli import bench, track
from in_process import call_main


def _stderr_of(main, argv, capsys) -> tuple[int, str]:
    status, _, err = call_main(main, argv, capsys)
    return status, err


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (["--out", ""], "error: out: give a report file (got an empty path)"),
        (["--method", "pi,,pi"], "error: --method: an empty name in the list (got 'pi,,pi')"),
        (["--method", "nope"], "error: method: unknown method 'nope' (choose from "),
        (["--compare", "/nonexistent/old.json"], "error: compare: cannot read "),
    ],
)
def test_a_value_bench_refuses_is_the_packages_one_line_form(argv, line, capsys):
    status, err = _stderr_of(bench.main, argv, capsys)
    assert status == 2
    assert err.count("\n") == 1 and err.startswith(line), err


def test_a_malformed_command_line_reads_as_tracks(capsys):
    status, err = _stderr_of(bench.main, ["--jbos", "2"], capsys)
    assert status == 2
    assert err == (
        "python -m ddwmmr.bench: error: unrecognized arguments: --jbos (did you mean --jobs?) 2\n"
    )
    # the same form as track's, for the same kind of mistake
    status, err = _stderr_of(track.main, ["--out", "x", "--jbos", "2"], capsys)
    assert status == 2 and err.startswith("python -m ddwmmr.track: error: unrecognized ")
