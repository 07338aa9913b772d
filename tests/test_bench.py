"""The benchmark: its statistics against hand-computed values, its state classes against
independent definitions, its report file and its command line."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Robot, available_methods, make_controller
from ddwmmr.bench import (
    EXTRA_CASES,
    NAIVE_LABEL,
    QP_CLASSES,
    REFERENCE_LABEL,
    TOOL,
    ExtraCase,
    NaivePseudoinverseController,
    benchmark_cases,
    format_comparison,
    format_table,
    record_class_states,
    record_states,
    run_benchmark,
    summarize_times,
    time_calls,
    timer_overhead_ns,
    write_report,
)
from ddwmmr.cli.bench import main
from footprint import outline_clearance
from in_process import call_main

TINY = {"repeats": 2, "calls": 20, "duration": 0.4}
ROBOT3 = Robot().with_payload(3.0)
#: Seed 0's scenarios with the shortest mpc runs, 74 and 60 (11.7 s and 12.1 s simulated;
#: the first two simulate 23.8 s and 20.2 s): the scenarios the bench's scenario sections
#: run in these tests.
SHORT_SCENARIOS = (74, 60)


def use_short_scenarios(patch: pytest.MonkeyPatch) -> tuple[list, list[tuple[int, int]]]:
    """``(batch, calls)``: through ``patch``, ``generate(n, seed)`` returns the first ``n``
    scenarios of ``batch`` (seed 0's :data:`SHORT_SCENARIOS`, in that order) and records
    ``(n, seed)`` in ``calls``."""
    from ddwmmr.scenarios import generator

    seed0 = generator.generate(max(SHORT_SCENARIOS), 0)
    batch = [seed0[number - 1] for number in SHORT_SCENARIOS]
    calls: list[tuple[int, int]] = []

    def generate(n, seed=0):
        calls.append((n, seed))
        return batch[:n]

    patch.setattr(generator, "generate", generate)
    return batch, calls


class FakeClock:
    """A clock (ns) that only moves when the code under test says so."""

    def __init__(self) -> None:
        self.now = 0

    def __call__(self) -> int:
        return self.now

    def spend(self, ns: int) -> None:
        self.now += ns


# -- statistics ---------------------------------------------------------------------------
def test_time_calls_measures_each_call_and_subtracts_the_clock_overhead():
    clock = FakeClock()
    costs = {0: 1000, 1: 5000, 2: 250_000}

    def command(i, repeat_noise):
        clock.spend(costs[i] + repeat_noise[0])

    noise = [0]
    calls = [(i, noise) for i in range(3)]

    def next_repeat():
        noise[0] += 100  # each repeat 100 ns slower than the last

    times = time_calls(command, calls, 3, clock=clock, overhead_ns=50, between=next_repeat)
    expected = np.array([[costs[i] + 100 * r - 50 for i in range(3)] for r in range(3)]) / 1000
    np.testing.assert_array_equal(times, expected)


def test_timer_overhead_is_the_median_gap_between_two_clock_reads():
    ticks = iter(range(0, 10**9, 37))  # every read advances 37 ns
    assert timer_overhead_ns(lambda: next(ticks), samples=101) == 37.0


def test_percentiles_are_over_states_of_each_states_median():
    """States cost 1..100 us; repeat 2 is disturbed on every state but the 50th, repeat 3
    on the 50th only: each state's median is its cost, so the percentiles over states are
    those of 1..100 (linear interpolation, by hand), untouched by the disturbances."""
    base = np.arange(1.0, 101.0)
    times = np.vstack([base, base + 1000.0, base.copy()])
    times[1, 49] = 50.0
    times[2, 49] = 5000.0
    stats = summarize_times(times)
    assert stats["median_us"] == 50.5
    assert stats["p90_us"] == pytest.approx(1 + 0.9 * 99)  # 90.1
    assert stats["p99_us"] == pytest.approx(1 + 0.99 * 99)  # 99.01
    assert stats["max_us"] == 100.0
    # Each repeat's own median: 1..100; 1001..1100 with 50 for 1050; 5000 for 50.
    assert stats["repeat_medians_us"] == [50.5, 1050.0, 51.5]


# -- the method table ---------------------------------------------------------------------
@pytest.fixture(scope="module")
def report() -> dict:
    extras = (
        *EXTRA_CASES,
        ExtraCase("naive-again", "ddwmmr.bench:NaivePseudoinverseController", pair="pi"),
        ExtraCase("missing", "ddwmmr.no_such_module:Thing", pair="pi"),
    )
    with pytest.MonkeyPatch.context() as patch:
        _, generated = use_short_scenarios(patch)  # the mpc floor's scenario: a short one
        report = run_benchmark(**TINY, extras=extras, floor_scenarios=1)
    assert generated == [(1, 0), (1, 0)]  # the solver's build, then the timed run
    return report


def test_rows_cover_baseline_and_every_registered_method(report: dict) -> None:
    rows = {row["label"]: row for row in report["rows"]}
    labels = list(rows)
    assert labels[0] == NAIVE_LABEL and rows[NAIVE_LABEL]["kind"] == "baseline"
    assert set(available_methods()) <= set(labels)  # every method measured exactly once
    assert len(labels) == len(set(labels))
    assert rows["naive-again"]["kind"] == "extra" and rows["qp-naive"]["kind"] == "extra"
    for row in report["rows"]:
        assert (row["meets_target"] is None) == (row["kind"] != "method")
    assert "ddwmmr.no_such_module" in report["skipped"]["missing"]
    assert (REFERENCE_LABEL in rows) != (REFERENCE_LABEL in report["skipped"])


def test_the_mpc_floor_is_measured_with_mpc_and_judged_against_its_targets(report: dict):
    from ddwmmr.bench.mpc_floor import FLOOR_TARGETS, floor_verdicts

    rows = report["mpc_floor"]
    assert [row["case"] for row in rows] == [
        "tracking rectangle (kinematic plant)",
        "tracking ellipse (kinematic plant)",
        "scenarios 1-1 (thesis plant)",
    ]
    assert report["mpc_floor_targets"] == FLOOR_TARGETS
    # 0.4 s at the trajectories' 0.02 s step; the scenario runs to its last waypoint
    assert rows[0]["steps"] == rows[1]["steps"] == 21 and rows[2]["steps"] > 500
    for row in rows:
        assert 0 < row["hpipm_median_us"] < row["median_us"] <= row["p99_us"] <= row["max_us"]
        assert row["p99_over_median"] == pytest.approx(row["p99_us"] / row["median_us"])
        assert row["step_over_hpipm"] > 1.0
    table = format_table(report).splitlines()
    start = next(i for i, line in enumerate(table) if line.startswith("mpc step against"))
    for row, line in zip(rows, table[start + 2 : start + 5], strict=True):
        verdicts = floor_verdicts(row)
        assert line.split()[-1] == ("ok" if verdicts["max_us"] else "MISS")
        assert line.count("MISS") == sum(met is False for met in verdicts.values())


def test_floor_verdicts_hold_at_each_limit_and_miss_just_past_it():
    from ddwmmr.bench.mpc_floor import FLOOR_TARGETS, floor_verdicts

    at_limits = dict(FLOOR_TARGETS)
    assert floor_verdicts(at_limits) == {key: True for key in FLOOR_TARGETS}
    for key in FLOOR_TARGETS:
        past = {**at_limits, key: at_limits[key] * (1 + 1e-9)}
        assert floor_verdicts(past) == {k: k != key for k in FLOOR_TARGETS}


def test_no_mpc_floor_without_mpc():
    report = run_benchmark(repeats=1, calls=5, duration=0.1, methods=["ats"])
    assert report["mpc_floor"] == [] and "mpc step against" not in format_table(report)


def test_numbers_are_ordered_and_ratios_consistent(report: dict) -> None:
    naive = report["rows"][0]
    assert naive["step_ratio"] == 1.0
    for row in report["rows"]:
        assert 0 < row["step_us"] <= row["step_p90_us"] <= row["step_p99_us"]
        assert row["steps_per_s"] > 0 and math.isfinite(row["steps_per_s"])
        assert row["step_ratio"] == pytest.approx(row["step_us"] / naive["step_us"], rel=1e-12)
        assert row["run_speedup"] == pytest.approx(
            row["steps_per_s"] / naive["steps_per_s"], rel=1e-12
        )
    steps = {row["label"]: row["step_us"] for row in report["rows"]}
    pairs = {pair["naive"]: pair for pair in report["pairs"]}
    assert pairs["naive-again"]["method"] == "pi"
    for pair in pairs.values():
        assert pair["step_ratio"] == pytest.approx(steps[pair["method"]] / steps[pair["naive"]])


def test_table_shows_the_reports_numbers(report: dict) -> None:
    table = format_table(report)
    for row in report["rows"]:
        line = next(x for x in table.splitlines() if x.startswith(row["label"] + " "))
        median, p90, p99, ratio, rate = (float(v) for v in line.split()[1:6])
        assert median == round(row["step_us"], 2) and p90 == round(row["step_p90_us"], 2)
        assert p99 == round(row["step_p99_us"], 2) and ratio == round(row["step_ratio"], 3)
        assert rate == round(row["steps_per_s"])
    assert "skipped missing: ddwmmr.no_such_module not importable" in table
    for entry in report["qp_classes"]:
        assert f"  {entry['name']} ({entry['states']} states" in table
    assert re.search(
        r"qp targets \(qp's own states by class, stricter than the table's 60 us budget\): "
        r"median <= 20 us and p99 <= 40 us in every class: (not judged|MISS) \(worst [\d.]+ / -\);"
        r" p99 needs >= 100 states, not judged in 4 of 4 classes",
        table,
    )


# -- qp state classes ----------------------------------------------------------------------
def test_qp_classes_report_rows_phases_and_ratios(report: dict) -> None:
    names = [entry["name"] for entry in report["qp_classes"]]
    assert names == [c.name for c in QP_CLASSES]
    for entry in report["qp_classes"]:
        rows = entry["rows"]
        assert {"qp", "qp (generic path)", "qp + user task, limit", "qp-naive"} <= set(rows)
        assert entry["states"] == TINY["calls"]
        for label, ratio in entry["ratios"].items():
            assert ratio["median"] == pytest.approx(
                rows[label]["median_us"] / rows["qp"]["median_us"]
            )
            assert ratio["min_over_repeats"] <= ratio["max_over_repeats"]
        assert set(entry["phases"]) == {"build", "solve", "check", "rest"}
        assert all(value >= 0.0 for value in entry["phases"].values())
        assert 0.0 <= entry["exact_check_fraction"] <= 1.0
        median_ok = rows["qp"]["median_us"] <= 20.0
        # TINY's 20 states are too few to judge a p99: None unless the median misses
        assert entry["meets_targets"] == (None if median_ok else False)


def _brute_clearance(robot: Robot, q, circle, n: int = 401) -> float:
    """Footprint-to-circle distance from points sampled on the footprint's outline."""
    half = (0.5 * robot.base_length, 0.5 * robot.base_width)
    return outline_clearance(*half, (q[0], q[1], q[2]), tuple(circle), n)


@pytest.mark.parametrize("name", [c.name for c in QP_CLASSES])
def test_each_class_holds_the_states_it_claims(name):
    """Checked with independent definitions: S from Robot.stability, the shoulder margin
    from th1, the obstacle clearance from sampled footprint points."""
    state_class = next(c for c in QP_CLASSES if c.name == name)
    _, calls = record_class_states(state_class, ROBOT3, 60)
    assert len(calls) >= 20
    for _, q, pose_d, velocity_d in calls:
        assert q.shape == (5,) and pose_d.shape == (3,) and velocity_d.shape == (3,)
        if name == "stability floor":
            assert ROBOT3.stability(q)[2] < 1.25 + 0.05
        elif name == "shoulder singularity":
            assert math.cos(q[3]) ** 2 - math.sin(0.25) ** 2 < 0.05
        elif name == "obstacles":
            (circle,) = state_class.options["obstacles"]
            assert _brute_clearance(ROBOT3, q, circle) < 0.6 + 1e-3


def test_tracking_class_replays_the_qp_run_in_order():
    """The tracking class is the run itself: times increase and the first call is the
    start (RK4: four calls per step, the first at the step's time)."""
    _, calls = record_class_states(QP_CLASSES[0], ROBOT3, 10**6)
    times = [c[0] for c in calls]
    assert times[0] == 0.0 and len(calls) == 4 * 2000 + 1
    assert all(b >= a for a, b in zip(times[::4], times[4::4]))


# -- the reference -------------------------------------------------------------------------
def test_reference_models_the_same_robot():
    pytest.importorskip("roboticstoolbox", reason="the bench extra is not installed")
    from ddwmmr.qp.rtb_reference import HolisticController, planar_pose

    reference = HolisticController(ROBOT3)
    model = reference.model
    controller = make_controller("qp", ROBOT3)
    rng = np.random.default_rng(3)
    for _ in range(10):
        q = rng.uniform(-2.0, 2.0, 5)
        model.base = planar_pose(*q[:3])
        model.q = np.array([0.0, 0.0, q[3], q[4]])
        pose = model.fkine(model.q).A
        fk = ROBOT3.fk(q)
        assert pose[:2, 3] == pytest.approx(fk[:2], abs=1e-12)
        assert math.atan2(pose[1, 0], pose[0, 0]) == pytest.approx(
            math.remainder(fk[2], 2 * math.pi), abs=1e-12
        )
        # Jacobian (toolbox: base-frame axes, columns yaw, drive, th1, th2) rotated by phi
        # against ours (world frame, u = (v, w, th1dot, th2dot)).
        jac = model.jacob0(model.q)[[0, 1, 5]][:, [1, 0, 2, 3]]
        c, s = math.cos(q[2]), math.sin(q[2])
        jac[:2] = np.array([[c, -s], [s, c]]) @ jac[:2]
        controller.ctx.update(0.0, q, fk, np.zeros(3))
        np.testing.assert_allclose(jac, controller.ctx.jac_e, atol=1e-12)
    u = reference.command(0.0, q, fk + np.array([0.1, 0.0, 0.0]), np.zeros(3))
    assert u.shape == (4,) and np.all(np.isfinite(u))


def test_missing_reference_is_skipped_with_the_install_hint(monkeypatch):
    monkeypatch.setitem(sys.modules, "roboticstoolbox", None)  # import now fails
    cases, skipped = benchmark_cases(methods=["qp"])
    assert REFERENCE_LABEL not in [c.label for c in cases]
    assert "pip install 'ddwmmr[bench]'" in skipped[REFERENCE_LABEL]


# -- report file and command line ----------------------------------------------------------
def test_report_file_is_written_atomically_and_guarded(tmp_path, report):
    out = tmp_path / "bench.json"
    write_report(report, out)
    data = json.loads(out.read_text())
    assert data["tool"] == TOOL and data["rows"] == report["rows"]
    assert [p.name for p in tmp_path.iterdir()] == ["bench.json"]  # no staging left
    write_report(report, out)  # our own report: replaced
    foreign = tmp_path / "notes.json"
    foreign.write_text('{"mine": 1}')
    with pytest.raises(ParameterError, match=r"is not a ddwmmr\.bench report"):
        write_report(report, foreign)
    assert foreign.read_text() == '{"mine": 1}'
    write_report(report, foreign, force=True)
    assert json.loads(foreign.read_text())["tool"] == TOOL


def test_comparison_lists_old_and_new_medians(report):
    previous = json.loads(json.dumps(report))
    for row in previous["rows"]:
        row["step_us"] *= 2.0
    text = format_comparison(report, previous)
    line = next(x for x in text.splitlines() if x.strip().startswith("pi "))
    assert line.strip().endswith("(0.50x)")


def test_cli_writes_the_report_and_compares(tmp_path, capsys):
    out = tmp_path / "b.json"
    args = ["--repeats", "1", "--calls", "10", "--duration", "0.2", "--method", "ats"]
    assert main([*args, "--out", str(out)]) == 0
    first = capsys.readouterr().out
    assert "ats" in first and out.is_file()
    assert main([*args, "--out", str(out), "--compare", str(out), "--json"]) == 0
    printed = capsys.readouterr().out
    data = json.loads(printed[: printed.rindex("}") + 1])
    assert [row["label"] for row in data["rows"]] == [NAIVE_LABEL, "ats"]
    assert data["qp_classes"] == []  # qp not selected
    assert "median step new / old" in printed


def _run_cli(*args: str, cwd) -> subprocess.CompletedProcess:
    """``python -m ddwmmr.bench`` as a process: the entry point, exit status and stderr
    of the real interpreter."""
    return subprocess.run(
        [sys.executable, "-m", "ddwmmr.bench", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


def _call_cli(capsys, monkeypatch, *args: str, cwd) -> tuple[int, str, str]:
    """``(status, stdout, stderr)`` of the tool's ``main`` run in this process from ``cwd``
    (argparse's refusals exit through SystemExit; its status is taken as the return)."""
    monkeypatch.chdir(cwd)
    return call_main(main, args, capsys)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--repeats", "abc"], "argument --repeats: must be an integer in [1, 1000] (got 'abc')"),
        (["--repeats", "0"], "argument --repeats: must be an integer in [1, 1000] (got '0')"),
        (["--calls", "-3"], "argument --calls: must be an integer in [1, 10000] (got '-3')"),
        (
            ["--duration", "nan"],
            "argument --duration: must be a number in [0.02, 20000] s (got 'nan')",
        ),
        (
            ["--duration", "inf"],
            "argument --duration: must be a number in [0.02, 20000] s (got 'inf')",
        ),
        (
            ["--duration", "1e"],
            "argument --duration: must be a number in [0.02, 20000] s (got '1e')",
        ),
        (["--method", "nope"], "unknown method 'nope' (choose from "),
        (["--method", "pi,nope"], "unknown method 'nope' (choose from "),
        (["--method", ","], "--method: no name given"),
        (["--method", "qp", "--method", ","], "--method: no name given (got ',')"),
        (["--frobnicate"], "unrecognized arguments: --frobnicate"),
    ],
)
def test_cli_bad_input_is_one_line_and_exit_2(tmp_path, capsys, monkeypatch, args, message):
    status, out, err = _call_cli(capsys, monkeypatch, *args, cwd=tmp_path)
    assert status == 2
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(("error: ", "python -m ddwmmr.bench: error: "))
    assert message in lines[0]
    assert list(tmp_path.iterdir()) == []  # nothing written


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--repeats", "abc"], "argument --repeats: must be an integer in [1, 1000] (got 'abc')"),
        (["--method", "nope"], "unknown method 'nope' (choose from "),
    ],
)
def test_the_module_refuses_bad_input_in_one_line_exit_2(tmp_path, args, message):
    """As a process (``python -m ddwmmr.bench``): an argparse refusal and the tool's own,
    exit status 2, one line on stderr, no traceback, nothing written."""
    result = _run_cli(*args, cwd=tmp_path)
    assert result.returncode == 2 and result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and message in lines[0] and "Traceback" not in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_cli_refuses_to_replace_a_foreign_file(tmp_path, capsys, monkeypatch):
    (tmp_path / "bench.json").write_text("my notes")
    args = ("--repeats", "1", "--calls", "5", "--method", "ats")
    status, _, err = _call_cli(capsys, monkeypatch, *args, cwd=tmp_path)
    assert status == 2 and len(err.splitlines()) == 1
    assert "is not a ddwmmr.bench report" in err
    assert (tmp_path / "bench.json").read_text() == "my notes"


def test_cli_help_is_plain_text(tmp_path):
    result = _run_cli("--help", cwd=tmp_path)
    assert result.returncode == 0
    assert result.stdout.startswith("usage: python -m ddwmmr.bench")
    assert "Time every control method" in result.stdout
    assert "``" not in result.stdout and ":func:" not in result.stdout  # no docstring dump
    for option in ("--repeats", "--calls", "--duration", "--method", "--out", "--compare"):
        assert option in result.stdout


def test_extra_case_replaces_the_registered_method_of_the_same_name() -> None:
    extra = ExtraCase("ats", "ddwmmr.bench:NaivePseudoinverseController", pair="pi")
    cases, skipped = benchmark_cases(methods=["pi", "ats"], extras=(extra,))
    assert [(c.label, c.kind) for c in cases] == [
        (NAIVE_LABEL, "baseline"),
        ("pi", "method"),
        ("ats", "extra"),
    ]
    assert skipped == {}
    assert isinstance(cases[-1].make(Robot()), NaivePseudoinverseController)


def test_selected_methods_keep_only_their_extra_cases() -> None:
    extras = (
        ExtraCase("pi-twin", "ddwmmr.bench:NaivePseudoinverseController", pair="pi"),
        ExtraCase("ats-twin", "ddwmmr.bench:NaivePseudoinverseController", pair="ats"),
    )
    cases, _ = benchmark_cases(methods=["pi"], extras=extras)
    assert [c.label for c in cases] == [NAIVE_LABEL, "pi", "pi-twin"]


def test_naive_baseline_equals_closed_form_pseudoinverse() -> None:
    """Away from cos(th1) = 0 the SVD pseudoinverse and the closed-form kernel agree."""
    robot, trajectory = Robot(), Ellipse()
    states = record_states(robot, trajectory, 25)
    naive = NaivePseudoinverseController(robot)
    closed = make_controller("pi", robot)
    for t, q, pose, velocity in states.calls():
        assert abs(math.cos(q[3])) > 0.1
        np.testing.assert_allclose(
            naive.command(t, q, pose, velocity), closed.command(t, q, pose, velocity), atol=1e-10
        )
        assert abs(naive.last.nonholonomic_residual) < 1e-12


def _bench_docs():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_docs.py"
    spec = importlib.util.spec_from_file_location("bench_docs", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_docs_tables_are_regenerated_between_their_markers(report, tmp_path):
    bench_docs = _bench_docs()
    docs = tmp_path / "docs"
    docs.mkdir()
    for name, page in (("api-table", "api.md"), ("qp-classes", "qp.md")):
        (docs / page).write_text(
            f"intro\n<!-- bench:{name} begin -->\nold\n<!-- bench:{name} end -->\noutro\n"
        )
    out = tmp_path / "bench.json"
    write_report(report, out)
    assert bench_docs.main([str(out), "--docs", str(docs)]) == 0
    api = (docs / "api.md").read_text()
    assert api.startswith("intro\n<!-- bench:api-table begin -->\nMeasured ")
    assert format_table(report) in api and "old" not in api and api.endswith("outro\n")
    qp = (docs / "qp.md").read_text()
    for entry in report["qp_classes"]:
        median = entry["rows"]["qp"]["median_us"]
        assert f"| {entry['name']} | {entry['states']} | {median:.1f} / " in qp
        assert f"| {entry['name']} | {entry['phases']['build']:.2f} | " in qp
    assert bench_docs.main([str(out), "--docs", str(docs)]) == 0  # idempotent
    figure = docs / "figures" / "bench.png"
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and figure.stat().st_size > 10_000
    assert (docs / "qp.md").read_text() == qp


def test_committed_reference_report_matches_the_docs():
    """docs/api.md and docs/qp.md show benchmarks/bench.json as bench_docs renders it."""
    from pathlib import Path

    bench_docs = _bench_docs()
    root = Path(__file__).resolve().parents[1]
    report = json.loads((root / "benchmarks" / "bench.json").read_text())
    assert report["tool"] == TOOL
    assert bench_docs.api_table(report) in (root / "docs" / "api.md").read_text()
    assert bench_docs.qp_tables(report) in (root / "docs" / "qp.md").read_text()


@pytest.mark.parametrize("case", ["under a file", "a folder"])
def test_cli_refuses_an_unusable_out_path_before_running(tmp_path, capsys, monkeypatch, case):
    (tmp_path / "plain").write_text("x")
    out = tmp_path / "plain" / "b.json" if case == "under a file" else tmp_path
    args = ("--out", str(out), "--method", "ats", "--force")
    status, _, err = _call_cli(capsys, monkeypatch, *args, cwd=tmp_path)
    assert status == 2 and len(err.splitlines()) == 1
    assert err.startswith("error: out: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain"]


# -- scenario throughput --------------------------------------------------------------------
#: Outcomes of the scenario runs made in this process, by (scenario, config): both frozen.
SCENARIO_OUTCOMES: dict[tuple, object] = {}


@pytest.fixture
def short_batch(monkeypatch) -> tuple[list, list[tuple[int, int]]]:
    """:func:`use_short_scenarios`, and ``run_scenario`` run once per (scenario, config)
    in this process (an outcome depends on nothing else; the throughput and command-line
    tests time the same first scenario with the same configs). The tests count the calls
    time_scenarios makes, whether run or replayed."""
    from ddwmmr.scenarios import executors

    batch, calls = use_short_scenarios(monkeypatch)
    run = executors.run_scenario

    def once(scenario, config):
        key = (scenario, config)
        if key not in SCENARIO_OUTCOMES:
            SCENARIO_OUTCOMES[key] = run(scenario, config)
        return SCENARIO_OUTCOMES[key]

    monkeypatch.setattr(executors, "run_scenario", once)
    return batch, calls


def test_scenario_throughput_counts_the_simulated_time_of_every_scenario(monkeypatch, short_batch):
    """Each controller's row sums the simulated time of every one of the scenarios, each
    run with that controller's default config: the runs time_scenarios makes are recorded
    (one run per scenario, not a second run of each) and their times summed here. The
    scenarios are those generate(count, 0) returns (a batch of two short ones here)."""
    from ddwmmr.bench import SCENARIO_CONTROLLERS, time_scenarios
    from ddwmmr.scenarios import executors
    from ddwmmr.scenarios.protocol import RunConfig

    runs: list[tuple] = []

    def recorded(scenario, config):
        outcome = run_scenario(scenario, config)
        runs.append((config, scenario, outcome.metrics["time_s"]))
        return outcome

    run_scenario = executors.run_scenario
    monkeypatch.setattr(executors, "run_scenario", recorded)
    rows = time_scenarios(2, jobs=1)
    assert [row["controller"] for row in rows] == list(SCENARIO_CONTROLLERS)
    scenarios, generated = short_batch
    assert generated == [(2, 0)]  # the first two scenarios of seed 0
    assert len(runs) == len(rows) * len(scenarios)
    for row in rows:
        config = RunConfig(controller=row["controller"])
        times = [time for c, _, time in runs if c == config]
        assert [s for c, s, _ in runs if c == config] == scenarios
        assert row["sim_time_s"] == pytest.approx(sum(times), rel=1e-12)
        assert row["wall_time_s"] > 0 and row["failed"] == 0
        assert row["sim_seconds_per_wall_second"] == pytest.approx(
            row["sim_time_s"] / row["wall_time_s"]
        )


def test_cli_times_scenarios_only_when_asked_with_a_method(tmp_path, capsys, short_batch):
    from ddwmmr.bench import SCENARIO_CONTROLLERS

    out = tmp_path / "b.json"
    args = ["--repeats", "1", "--calls", "5", "--duration", "0.1", "--method", "ats"]
    assert main([*args, "--out", str(out), "--scenarios", "1", "--jobs", "1"]) == 0
    printed = capsys.readouterr().out
    data = json.loads(out.read_text())
    assert [row["scenarios"] for row in data["scenarios"]] == [1] * len(SCENARIO_CONTROLLERS)
    assert "scenario benchmark (1 scenario, seed 0, 1 worker" in printed
    assert short_batch[1] == [(1, 0)]
    assert main([*args, "--out", str(out)]) == 0  # --method alone: no scenarios
    assert json.loads(out.read_text())["scenarios"] == []
    with pytest.raises(SystemExit) as stop:
        main([*args, "--out", str(out), "--scenarios", "-1"])
    assert stop.value.code == 2
    assert "--scenarios: must be an integer in [0, 100000]" in capsys.readouterr().err
