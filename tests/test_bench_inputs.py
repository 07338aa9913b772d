"""Bad input to ``python -m ddwmmr.bench``: one line naming the option, exit status 2, no
traceback, nothing written, and every check done before the benchmark runs."""

from __future__ import annotations

import errno
import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from ddwmmr import ParameterError
from ddwmmr.bench import (
    MAX_CALLS,
    MAX_REPEATS,
    SCENARIO_KEYS,
    TOOL,
    benchmark_cases,
    format_comparison,
    read_report,
    run_benchmark,
    scenario_workers,
    time_scenarios,
)
from ddwmmr.bench import report as bench_report
from ddwmmr.bench import run as bench_run
from ddwmmr.cli import bench as bench_cli
from ddwmmr.cli.bench import build_parser, main
from ddwmmr.errors import MAX_JOBS
from in_process import call_main

#: The smallest run: one method, one repeat, five states, 1 s runs, no scenarios.
SMALL = ["--method", "pi", "--repeats", "1", "--calls", "5", "--duration", "1", "--scenarios", "0"]
VALID = {"tool": TOOL, "config": {}, "rows": [{"label": "pi", "step_us": 2.0}]}


def tree(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.fixture
def workdir(tmp_path, monkeypatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


def run_main(args: list[str], capsys) -> tuple[int, str, str]:
    """``main(args)`` in this process: status, stdout, stderr (argparse exits too)."""
    return call_main(main, args, capsys)


def refused(args: list[str], workdir: Path, capsys, monkeypatch) -> str:
    """Run SMALL + ``args`` (--out out.json unless given), which must be refused before
    the benchmark starts: status 2, one line on stderr, nothing new in the folder."""

    def no_run(*_, **__):
        raise AssertionError("the benchmark ran before the input was checked")

    monkeypatch.setattr(bench_cli, "run_benchmark", no_run)
    extra = [] if "--out" in args else ["--out", "out.json"]
    given = {arg.split("=")[0] for arg in args if arg.startswith("--")}
    base = [  # SMALL without the options ``args`` gives itself: a tool refuses one twice
        word
        for name, value in zip(SMALL[::2], SMALL[1::2])
        if name not in given
        for word in (name, value)
    ]
    before = tree(workdir)
    status, out, err = run_main([*base, *args, *extra], capsys)
    assert status == 2, err
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(("error: ", "python -m ddwmmr.bench: error: ")), err
    assert tree(workdir) == before  # no --out file, no staging file, no folder
    return lines[0]


# -- numbers -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--jobs", "100000"], "argument --jobs: must be an integer in [1, 256] (got '100000')"),
        (["--jobs", "257"], "argument --jobs: must be an integer in [1, 256] (got '257')"),
        (["--jobs", "0"], "argument --jobs: must be an integer in [1, 256] (got '0')"),
        (["--jobs", "two"], "argument --jobs: must be an integer in [1, 256] (got 'two')"),
        (
            ["--calls", "1000000000000000"],
            "argument --calls: must be an integer in [1, 10000] (got '1000000000000000')",
        ),
        (["--calls", "10001"], "argument --calls: must be an integer in [1, 10000]"),
        (["--calls", "1e3"], "argument --calls: must be an integer in [1, 10000] (got '1e3')"),
        (
            ["--repeats", "1000000000000000"],
            "argument --repeats: must be an integer in [1, 1000] (got '1000000000000000')",
        ),
        (["--repeats", "1001"], "argument --repeats: must be an integer in [1, 1000]"),
        (["--repeats", "9" * 5000], "argument --repeats: must be an integer in [1, 1000]"),
        (["--scenarios", "100001"], "argument --scenarios: must be an integer in [0, 100000]"),
        (["--scenarios", "-1"], "argument --scenarios: must be an integer in [0, 100000]"),
        (["--duration", "1e12"], "duration must be in [0.02, 20000] s (got 1e+12)"),
        (["--duration", "1e-9"], "duration must be in [0.02, 20000] s (got 1e-09)"),
        (["--duration", "20001"], "duration must be in [0.02, 20000] s"),
        (["--duration", "-1"], "duration must be in [0.02, 20000] s (got -1)"),
        (["--duration=-inf"], "argument --duration: must be a number in [0.02, 20000] s"),
    ],
)
def test_out_of_range_numbers_are_refused_before_the_run(
    args, message, workdir, capsys, monkeypatch
):
    assert message in refused(args, workdir, capsys, monkeypatch)


def test_caps_are_the_documented_ones():
    assert MAX_JOBS == 256  # docs/cli.md, "Limits": every tool's --jobs
    assert (MAX_REPEATS, MAX_CALLS) == (1000, 10_000)
    text = build_parser().format_help()
    for words in ("at most 1000", "at most 10000", "at most 256", "0.02 to 20000"):
        assert words in " ".join(text.split())
    assert "--no-progress" in text


def test_run_benchmark_checks_its_arguments_before_running(monkeypatch):
    def no_states(*_, **__):
        raise AssertionError("states recorded before the arguments were checked")

    monkeypatch.setattr(bench_run, "record_states", no_states)
    cases = [
        ({"repeats": 0}, r"repeats must be an integer in \[1, 1000\]"),
        ({"repeats": 10**15}, r"repeats must be an integer in \[1, 1000\]"),
        ({"calls": 10**15}, r"calls must be an integer in \[1, 10000\]"),
        ({"scenarios": -1}, r"scenarios must be an integer in \[0, 100000\]"),
        ({"floor_scenarios": -1}, r"floor_scenarios must be an integer in \[0, 100000\]"),
        ({"scenarios": 2, "scenario_jobs": 100_000}, r"jobs must be an integer in \[1, 256\]"),
        ({"duration": 1e12}, r"duration must be in \[0.02, 20000\] s"),
    ]
    for kwargs, message in cases:
        with pytest.raises(ParameterError, match=message):
            run_benchmark(**kwargs)


def test_never_more_workers_than_scenarios(monkeypatch):
    import ddwmmr.scenarios.executors as executors
    import ddwmmr.scenarios.report as scenario_report

    started = []

    def fake_run_many(batch, config, jobs):
        started.append((len(batch), jobs))
        return []

    monkeypatch.setattr(executors, "run_many", fake_run_many)
    monkeypatch.setattr(scenario_report, "summarize", lambda o, w: dict.fromkeys(SCENARIO_KEYS, 0))
    rows = time_scenarios(2, jobs=200)
    assert started == [(2, 2), (2, 2), (2, 2)]  # thesis, qp and mpc, two workers each
    assert [row["jobs"] for row in rows] == [2, 2, 2]
    assert scenario_workers(100, 3) == 3
    assert 1 <= scenario_workers(1) == 1
    with pytest.raises(ParameterError, match=r"jobs must be an integer in \[1, 256\]"):
        scenario_workers(2, 257)


def test_a_repeated_method_is_measured_once():
    cases, _ = benchmark_cases(methods=["pi", "pi"], extras=())
    assert [c.label for c in cases] == ["naive-pinv", "pi"]


# -- --compare -------------------------------------------------------------------------------
def _report(**changes) -> str:
    data = {**VALID, **changes}
    return json.dumps({k: v for k, v in data.items() if v is not ...})


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (_report(rows="x"), '"rows" must be a list (got a string)'),
        (_report(rows=...), 'no "rows"'),
        (_report(rows=[1]), '"rows"[1] must be an object (got a number)'),
        (_report(rows=[{"label": "pi"}]), '"rows"[1].step_us must be a number > 0 (got null)'),
        (_report(rows=[{"label": "pi", "step_us": 0}]), '"rows"[1].step_us must be a number > 0'),
        (_report(rows=[{"label": 3, "step_us": 1}]), '"rows"[1].label must be a string'),
        (_report(scenarios="x"), '"scenarios" must be a list (got a string)'),
        (_report(scenarios=[{"controller": "qp"}]), "sim_seconds_per_wall_second must be"),
        (_report(qp_classes=["rows"]), '"qp_classes"[1] must be an object (got a string)'),
        (_report(qp_classes=[{"name": "a", "rows": {}}]), "rows.qp.median_us must be"),
        (_report(config=...), '"config" must be an object (got null)'),
        (_report(config="x"), '"config" must be an object (got a string)'),
        ('{"tool": "ddwmmr.bench", "config": {}, "rows": [{"label": "pi", "step_us": 1e400}]}',
         '"rows"[1].step_us must be a number > 0 (got inf)'),
        ("[" * 100_000 + "]" * 100_000, "is not valid JSON (nested too deeply)"),
        (f'{{"tool": "{TOOL}", "x": {"[" * 100_000 + "]" * 100_000}}}', "nested too deeply"),
        ("not json", "is not valid JSON (Expecting value"),
        ('{"mine": 1}', 'is not a ddwmmr.bench report (no "tool": "ddwmmr.bench")'),
        ("[1, 2]", "is not a ddwmmr.bench report"),
    ],
)  # fmt: skip
def test_a_malformed_comparison_report_is_refused_before_the_run(
    text, message, workdir, capsys, monkeypatch
):
    (workdir / "old.json").write_text(text)
    line = refused(["--compare", "old.json"], workdir, capsys, monkeypatch)
    assert line.startswith("error: compare: old.json ") and message in line


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda d: "missing.json", "compare: cannot read missing.json (No such file or directory)"),
        (lambda d: str(d), "is not a regular file"),
        (lambda d: "", "compare: no file name given"),
        (lambda d: os.mkfifo(d / "fifo") or "fifo", "compare: fifo is not a regular file"),
        (lambda d: (d / "l.json").write_bytes(b"\xff{}") and "l.json", "is not UTF-8 text"),
    ],
)
def test_an_unreadable_comparison_file_says_why(make, message, workdir, capsys, monkeypatch):
    target = make(workdir)
    assert message in refused(["--compare", target], workdir, capsys, monkeypatch)


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads any file")
def test_an_unreadable_comparison_file_says_permission_denied(workdir, capsys, monkeypatch):
    secret = workdir / "old.json"
    secret.write_text(json.dumps(VALID))
    secret.chmod(0)
    try:
        line = refused(["--compare", "old.json"], workdir, capsys, monkeypatch)
    finally:
        secret.chmod(0o644)
    assert "compare: cannot read old.json (Permission denied)" in line


def test_an_older_report_without_qp_classes_or_scenarios_is_compared(tmp_path):
    old = tmp_path / "old.json"
    old.write_text(json.dumps(VALID))
    previous = read_report(old)
    text = format_comparison({"rows": [{"label": "pi", "step_us": 1.0}]}, previous)
    assert text.splitlines()[1].split() == ["pi", "2.00", "->", "1.00", "us", "(0.50x)"]


# -- --out -----------------------------------------------------------------------------------
@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs /proc")
def test_an_out_file_in_proc_is_refused_before_the_run(workdir, capsys, monkeypatch):
    line = refused(["--out", "/proc/b.json"], workdir, capsys, monkeypatch)
    assert "out: " in line and "/proc" in line


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda d: (d / "folder").mkdir() or "folder", "out: folder is a folder"),
        (lambda d: (d / "f").write_text("x") and "f/b.json", "is not a folder"),
        (lambda d: (d / "n.json").write_text("[" * 100_000) and "n.json", "is not a ddwmmr"),
    ],
)
def test_an_unwritable_out_is_refused_before_the_run(make, message, workdir, capsys, monkeypatch):
    target = make(workdir)
    assert message in refused(["--out", target], workdir, capsys, monkeypatch)


@pytest.mark.parametrize("force", [[], ["--force"]])
def test_a_device_as_out_is_refused_without_suggesting_force(force, workdir, capsys, monkeypatch):
    """--force cannot replace a device: the message without it does not offer it."""
    line = refused(["--out", os.devnull, *force], workdir, capsys, monkeypatch)
    message = (
        f"out: {os.devnull} exists and is not a regular file (a character device); give a file name"
    )
    assert line == f"error: {message}" and "--force" not in line


def test_method_help_lists_every_valid_name():
    text = " ".join(build_parser().format_help().split())
    names = "ap, ats, clrrmc-cs, clrrmc-ts, mpc, pi, qp, qp-naive, rtb-holistic"
    assert f"one of {names} (default: all)" in text
    assert "the naive-pinv baseline is always measured" in text


@pytest.mark.parametrize("force", [[], ["--force"]])
def test_a_fifo_as_out_is_never_read_nor_replaced(force, tmp_path):
    """In a subprocess with a timeout: reading a FIFO would block."""
    fifo = tmp_path / "fifo.json"
    os.mkfifo(fifo)
    result = subprocess.run(
        [sys.executable, "-m", "ddwmmr.bench", *SMALL, "--out", str(fifo), *force],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=60,
    )
    assert result.returncode == 2 and result.stdout == ""
    (line,) = result.stderr.splitlines()
    assert line.startswith("error: out: ") and "Traceback" not in result.stderr
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert [p.name for p in tmp_path.iterdir()] == ["fifo.json"]


def test_a_deeply_nested_comparison_file_gives_no_traceback(tmp_path, monkeypatch, capsys):
    """In-process: a RecursionError ``main`` let out would fail the test."""
    (tmp_path / "old.json").write_text("[" * 100_000 + "]" * 100_000)
    monkeypatch.chdir(tmp_path)
    status = main([*SMALL, "--compare", "old.json"])
    captured = capsys.readouterr()
    assert status == 2 and captured.out == ""
    expected = "error: compare: old.json is not valid JSON (nested too deeply)\n"
    assert captured.err == expected
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.json"]  # no bench.json


# -- progress and late errors ---------------------------------------------------------------
def test_no_progress_silences_stderr(workdir, capsys):
    status, out, err = run_main([*SMALL, "--no-progress", "--out", "new/sub/b.json"], capsys)
    assert status == 0 and err == ""
    assert "pi" in out
    assert json.loads((workdir / "new" / "sub" / "b.json").read_text())["tool"] == TOOL


def test_a_failed_write_leaves_nothing_and_says_one_line(workdir, capsys, monkeypatch):
    def disk_full(path, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(bench_report, "write_atomic", disk_full)
    status, out, err = run_main([*SMALL, "--out", "b.json"], capsys)
    line = "error: out: cannot write b.json (No space left on device)"
    assert status == 2 and out == ""
    assert err.splitlines()[-1] == line
    assert len(err.splitlines()) == 2  # the progress line came first
    status, out, err = run_main([*SMALL, "--out", "b.json", "--no-progress"], capsys)
    assert status == 2 and out == ""
    assert err == line + "\n"
    assert tree(workdir) == []


def test_an_extra_row_that_cannot_load_is_skipped_not_an_unknown_method():
    # bench --method rtb-holistic said "unknown method" when roboticstoolbox was missing,
    # though --help lists the name
    from ddwmmr.bench.methods import ExtraCase, benchmark_cases

    missing = ExtraCase("extra-row", "ddwmmr_no_such_module:Controller", pair="qp")
    cases, skipped = benchmark_cases(["extra-row"], (missing,))
    assert [case.label for case in cases] == ["naive-pinv"]
    assert "not importable" in skipped["extra-row"]
