"""Method comparison: run plan, parallel execution, analysis and the report.

``python -m ddwmmr.compare`` (see :mod:`ddwmmr.cli.compare`) runs every registered method on
the same trajectories with the same robot, start configuration, integrator and step, then
writes ``report.md``, a self-contained ``report.html``, ``metrics.csv`` and PNG figures.

Library use::

    config = CompareConfig(methods=("ats", "clrrmc-ts"), trajectories={"ellipse": Ellipse()})
    plan = plan_runs(config)
    outputs = execute(config, plan.all_specs(), jobs=2)
    info = write_report(config, plan, outputs, Path("report"))

**Ranking score** (documented in the report): the RMS end-effector position error over the
whole run (m), per trajectory; lower is better. Every method starts from the same
configuration with the same initial offset, so the score rewards removing the offset quickly
and penalises drift. Scores within 5 % plus 0.1 mm of a better one count as a tie, which is
what the slides' ``>=`` allows. The overall score is the geometric mean over trajectories
(errors span orders of magnitude, so the mean of their logarithms is the fair summary).

Layout (each module imports only the ones listed above it):

- :mod:`.constants`: the slides' ranking, study sweeps, tie and diagnosis thresholds.
- :mod:`.plan`: configuration, run specs, the plan of runs, (parallel) execution.
- :mod:`.document`: number formatting, the Markdown/HTML document, the console table.
- :mod:`.diagnosis`: why a run scored as it did; measurements shared by the studies.
- :mod:`.ranking`: ``metrics.csv``, score, ties, ranking (with the runs that did not
  track), the slides' ranking check.
- :mod:`.report`: :func:`write_report` and one builder per report section.

Figures are drawn by :mod:`ddwmmr.reports.compare_plots`. Every public name of the modules
is re-exported here, so ``from ddwmmr.reports.compare import ...`` keeps working.
"""

from ddwmmr.reports.compare.constants import (
    CONVERGED_FRACTION,
    CORNER_TRAJECTORY,
    DEFAULT_TRAJECTORIES,
    MARKER,
    OFFSET_SCALES,
    SINGULAR_COS,
    SINGULAR_LOSS_M,
    SLIDES_NAMES,
    SLIDES_ORDER,
    STEP_SIZES,
    STUDIES,
    STUDY_TRAJECTORY,
    TAUS,
    TIE_ABSOLUTE_M,
    TIE_RELATIVE,
    TIMING_KEYS,
    VARIANTS,
    is_timing,
    slides_name,
)
from ddwmmr.reports.compare.diagnosis import (
    Finding,
    at_joint_limit,
    convergence_time,
    corner_times,
    diagnose,
    keeps_offset,
    observed_order,
    orientation_jumps,
    saturated_after_jumps,
    saturation_span,
    singularity_onset,
)
from ddwmmr.reports.compare.document import (
    Document,
    fmt,
    mm,
    text_table,
)
from ddwmmr.reports.compare.plan import (
    CompareConfig,
    Plan,
    RunOutput,
    RunSpec,
    accepts_option,
    default_step,
    estimated_cost,
    execute,
    main_spec,
    plan_runs,
    run_duration,
    run_one,
    study_offsets,
    study_steps,
    tau_methods,
)
from ddwmmr.reports.compare.ranking import (
    NOT_TRACKED_MARK,
    NOT_TRACKED_NOTE,
    Ranking,
    SlidesCheck,
    Violation,
    at_least_as_good,
    build_ranking,
    check_slides,
    did_not_track,
    geometric_mean,
    metrics_csv,
    metrics_rows,
    plant_metrics_rows,
    rank_with_ties,
    score,
)
from ddwmmr.reports.compare.report import (
    METRIC_COLUMNS,
    ReportInfo,
    corner_peaks,
    drift_kind,
    output_names,
    ranking_footnote,
    ranking_table,
    slides_verdict,
    write_report,
)

__all__ = [
    "CONVERGED_FRACTION",
    "CORNER_TRAJECTORY",
    "DEFAULT_TRAJECTORIES",
    "MARKER",
    "METRIC_COLUMNS",
    "NOT_TRACKED_MARK",
    "NOT_TRACKED_NOTE",
    "OFFSET_SCALES",
    "SINGULAR_COS",
    "SINGULAR_LOSS_M",
    "SLIDES_NAMES",
    "SLIDES_ORDER",
    "STEP_SIZES",
    "STUDIES",
    "STUDY_TRAJECTORY",
    "TAUS",
    "TIE_ABSOLUTE_M",
    "TIE_RELATIVE",
    "TIMING_KEYS",
    "VARIANTS",
    "CompareConfig",
    "Document",
    "Finding",
    "Plan",
    "Ranking",
    "ReportInfo",
    "RunOutput",
    "RunSpec",
    "SlidesCheck",
    "Violation",
    "accepts_option",
    "at_joint_limit",
    "at_least_as_good",
    "build_ranking",
    "check_slides",
    "convergence_time",
    "corner_peaks",
    "corner_times",
    "default_step",
    "diagnose",
    "did_not_track",
    "drift_kind",
    "estimated_cost",
    "execute",
    "fmt",
    "geometric_mean",
    "is_timing",
    "keeps_offset",
    "main_spec",
    "metrics_csv",
    "metrics_rows",
    "mm",
    "observed_order",
    "orientation_jumps",
    "output_names",
    "plan_runs",
    "plant_metrics_rows",
    "rank_with_ties",
    "ranking_footnote",
    "ranking_table",
    "run_duration",
    "run_one",
    "saturated_after_jumps",
    "saturation_span",
    "score",
    "singularity_onset",
    "slides_name",
    "slides_verdict",
    "study_offsets",
    "study_steps",
    "tau_methods",
    "text_table",
    "write_report",
]
