"""Benchmark: control-step latency of every method, the qp step by state class and phase,
full-run throughput; the report goes to ``bench.json``.

Three parts (docs/api.md, "Benchmark", explains the method):

* **methods**: the naive baseline ``naive-pinv``, every registered method and the extra
  rows of :data:`EXTRA_CASES`, each timed call by call over states recorded from a
  ``clrrmc-ts`` run of the default ellipse (median, 90th and 99th percentile over states of
  each state's median over the repeats), and the steps per second of a full
  :func:`ddwmmr.simulate` run;
* **qp by state class**: ``qp`` (3 kg payload) over states recorded from its own runs in
  four situations (:data:`QP_CLASSES`: tracking, at the stability floor, at the shoulder
  singularity, beside an obstacle), next to the same controller through the generic
  path, with a user task and limit, its naive twin ``qp-naive`` and the reference a user
  would otherwise pick, roboticstoolbox-python's holistic QP step (``rtb-holistic``,
  skipped with the reason when the ``bench`` extra is not installed); plus the cost of
  each phase of a qp step (build, solve, check) and how often the exact look-ahead ran;
* **scenarios**: simulated seconds per wall-clock second of the thesis benchmark's
  scenarios with the thesis controller and with ``qp`` (:func:`time_scenarios`, on by
  default in the command-line run without ``--method``).

Targets (docs/api.md, "Benchmark"): qp median <= 20 us and p99 <= 40 us in every class; rtb-holistic
at least 40x slower than qp. Timing thresholds are never unit tests: they are reported.

The package, by concern: :mod:`~ddwmmr.bench.baseline` (the naive row),
:mod:`~ddwmmr.bench.timing`, :mod:`~ddwmmr.bench.methods` (the method table),
:mod:`~ddwmmr.bench.qp_classes`, :mod:`~ddwmmr.bench.scenarios`, :mod:`~ddwmmr.bench.run`
(:func:`run_benchmark`) and :mod:`~ddwmmr.bench.report` (tables, the report file); the
command line is :mod:`ddwmmr.cli.bench`.
"""

from ddwmmr.bench.baseline import NAIVE_LABEL, NaivePseudoinverseController
from ddwmmr.bench.methods import (
    EXTRA_CASES,
    REFERENCE_FACTORY,
    REFERENCE_LABEL,
    STATE_SOURCE_METHOD,
    STEP_BUDGETS_US,
    TARGET_RATIO,
    BenchCase,
    BenchStates,
    ExtraCase,
    benchmark_cases,
    record_states,
    time_run,
    time_steps,
)
from ddwmmr.bench.qp_classes import (
    PHASES,
    QP_CLASSES,
    QP_TARGETS,
    StateClass,
    qp_class_cases,
    record_class_states,
    time_qp_phases,
)
from ddwmmr.bench.report import (
    REPORT_VERSION,
    TOOL,
    check_out,
    format_comparison,
    format_table,
    probe_out,
    read_report,
    write_report,
)
from ddwmmr.bench.run import MAX_CALLS, MAX_REPEATS, check_duration, run_benchmark
from ddwmmr.bench.scenarios import (
    SCENARIO_CONTROLLERS,
    SCENARIO_COUNT,
    SCENARIO_KEYS,
    scenario_workers,
    time_scenarios,
)
from ddwmmr.bench.timing import summarize_times, time_calls, timer_overhead_ns

__all__ = [
    "EXTRA_CASES",
    "MAX_CALLS",
    "MAX_REPEATS",
    "NAIVE_LABEL",
    "PHASES",
    "QP_CLASSES",
    "QP_TARGETS",
    "REFERENCE_FACTORY",
    "REFERENCE_LABEL",
    "REPORT_VERSION",
    "SCENARIO_CONTROLLERS",
    "SCENARIO_COUNT",
    "SCENARIO_KEYS",
    "STATE_SOURCE_METHOD",
    "STEP_BUDGETS_US",
    "TARGET_RATIO",
    "TOOL",
    "BenchCase",
    "BenchStates",
    "ExtraCase",
    "NaivePseudoinverseController",
    "StateClass",
    "benchmark_cases",
    "check_duration",
    "check_out",
    "format_comparison",
    "format_table",
    "probe_out",
    "qp_class_cases",
    "read_report",
    "record_class_states",
    "record_states",
    "run_benchmark",
    "scenario_workers",
    "summarize_times",
    "time_calls",
    "time_qp_phases",
    "time_run",
    "time_scenarios",
    "time_steps",
    "timer_overhead_ns",
    "write_report",
]
