"""Metrics and ranking: ``metrics.csv`` rows, the score, ties, the :class:`Ranking`, and
the check of the slides' ranking (:func:`check_slides`).

**Ranking score**: the RMS end-effector position error over the whole run (m), per
trajectory; lower is better. Every method starts from the same configuration with the
same initial offset, so the score rewards removing the offset quickly and penalises
drift. Scores within 5 % plus 0.1 mm of a better one count as a tie, which is what the
slides' ``>=`` allows. The overall score is the geometric mean over trajectories (errors
span orders of magnitude, so the mean of their logarithms is the fair summary).
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ddwmmr.reports.compare.constants import SLIDES_ORDER, TIE_ABSOLUTE_M, TIE_RELATIVE
from ddwmmr.reports.compare.diagnosis import diagnose
from ddwmmr.reports.compare.plan import CompareConfig, Plan, RunOutput, RunSpec
from ddwmmr.sim.result import json_safe
from ddwmmr.sim.verdict import reasons

# -- metrics and ranking ------------------------------------------------------------------


def metrics_rows(
    plan: Plan,
    outputs: Mapping[RunSpec, RunOutput],
    shown: Callable[[str], str] = str,
    specs: Sequence[RunSpec] | None = None,
) -> list[dict[str, Any]]:
    """One row per main run (or per run of ``specs``: :func:`plant_metrics_rows`):
    ``method``, ``trajectory`` and every summary field, where ``trajectory`` is the name
    the report shows for the trajectory (``shown`` of its key,
    :meth:`CompareConfig.shown`: unique, ``loop`` and ``loop-2`` for two trajectories of
    that name), as its tables name it, not the summary's name of the run's trajectory."""
    rows = []
    for spec in plan.main if specs is None else specs:
        summary = outputs[spec].summary
        name = shown(spec.trajectory)
        row = {"method": spec.method, "trajectory": name, **summary}
        row["trajectory"] = name  # over the summary's, in the same column
        rows.append(row)
    return rows


def plant_metrics_rows(
    plan: Plan, outputs: Mapping[RunSpec, RunOutput], shown: Callable[[str], str] = str
) -> list[dict[str, Any]]:
    """The rows of ``plant_metrics.csv``: one per main run repeated on an extra plant
    (``--plant``), plant by plant in the plan's order, as :func:`metrics_rows` writes them
    with the run's ``plant`` third."""
    specs = [spec for specs in plan.plants.values() for spec in specs]
    rows = metrics_rows(plan, outputs, shown, specs)
    return [
        {"method": r["method"], "trajectory": r["trajectory"], "plant": r["plant"], **r}
        for r in rows
    ]


def metrics_csv(rows: Sequence[Mapping[str, Any]]) -> str:
    """CSV text of ``rows``: union of their keys, floats written exactly (repr)."""
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_csv_value(row.get(c, "")) for c in columns])
    return buffer.getvalue()


def _csv_value(value: Any) -> str:
    """Exact text of a summary value: floats by repr (round-trips), None as empty, a list
    of names (``verdict_reasons``) space separated, a dict (``mpc_options``) as compact
    JSON with sorted keys (``json.loads`` reads it back; its non-finite floats are
    ``"nan"``/``"inf"`` strings, as in ``summary.json``)."""
    value = json_safe(value)
    if value is None:
        return ""
    if isinstance(value, dict):
        return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)
    if isinstance(value, list | tuple):
        return " ".join(str(item) for item in value)
    return repr(value) if isinstance(value, float) else str(value)


def score(summary: Mapping[str, Any]) -> float:
    """Ranking score (m): RMS end-effector position error over the run; NaN counts as inf."""
    value = float(summary["rms_position_error_m"])
    return math.inf if math.isnan(value) else value


def did_not_track(summary: Mapping[str, Any]) -> bool:
    """The run did not track: its verdict found a reason (:func:`ddwmmr.sim.verdict.reasons`,
    the codes the console's "Did not track" list and the tables' "tracked?" column give)."""
    return bool(reasons(summary))


#: The mark of a score whose run did not track (:func:`did_not_track`), and its footnote.
NOT_TRACKED_MARK = "\u2020"  # a dagger
NOT_TRACKED_NOTE = f'{NOT_TRACKED_MARK} did not track (docs/cli.md, "Verdict")'


def at_least_as_good(a: float, b: float) -> bool:
    """Score ``a`` is better than or tied with ``b`` (see :data:`TIE_RELATIVE`)."""
    return a <= b * (1.0 + TIE_RELATIVE) + TIE_ABSOLUTE_M


def rank_with_ties(scores: Mapping[str, float]) -> dict[str, int]:
    """Competition ranks (1 = best); a score tied with its group's best shares its rank."""
    ranks: dict[str, int] = {}
    leader = math.nan
    rank = 0
    for position, (method, value) in enumerate(sorted(scores.items(), key=lambda x: (x[1], x[0]))):
        if position == 0 or not at_least_as_good(value, leader):
            leader, rank = value, position + 1
        ranks[method] = rank
    return ranks


def geometric_mean(values: Iterable[float]) -> float:
    """Geometric mean of positive values (zeros are floored at 1e-15 m)."""
    logs = [math.log(max(v, 1e-15)) for v in values]
    return math.exp(sum(logs) / len(logs)) if logs else math.nan


@dataclass
class Ranking:
    """Scores (m) and ranks per trajectory and overall (see the module docstring);
    ``untracked``: trajectory -> the methods whose run there did not track
    (:func:`did_not_track`; ranked by their score all the same)."""

    scores: dict[str, dict[str, float]]
    ranks: dict[str, dict[str, int]]
    overall: dict[str, float]
    overall_rank: dict[str, int]
    untracked: dict[str, frozenset[str]] = field(default_factory=dict)

    def tracked(self, name: str, method: str) -> bool:
        """``method``'s run on the trajectory ``name`` tracked (or was not judged)."""
        return method not in self.untracked.get(name, frozenset())

    @property
    def order(self) -> list[str]:
        """Methods, best first."""
        return sorted(self.overall, key=lambda m: (self.overall_rank[m], self.overall[m], m))


def build_ranking(
    plan: Plan, outputs: Mapping[RunSpec, RunOutput], specs: Sequence[RunSpec] | None = None
) -> Ranking:
    """Rank the main runs (or ``specs``, e.g. ``plan.alternative``) by :func:`score`, per
    trajectory and by geometric mean."""
    scores: dict[str, dict[str, float]] = {}
    untracked: dict[str, set[str]] = {}
    for spec in plan.main if specs is None else specs:
        summary = outputs[spec].summary
        scores.setdefault(spec.trajectory, {})[spec.method] = score(summary)
        failed = untracked.setdefault(spec.trajectory, set())
        if did_not_track(summary):
            failed.add(spec.method)
    methods = list(next(iter(scores.values())))
    overall = {m: geometric_mean(scores[n][m] for n in scores) for m in methods}
    return Ranking(
        scores=scores,
        ranks={n: rank_with_ties(s) for n, s in scores.items()},
        overall=overall,
        overall_rank=rank_with_ties(overall),
        untracked={n: frozenset(m) for n, m in untracked.items()},
    )


# -- the slides' ranking (the reasons it fails come from diagnosis.diagnose) --------------


@dataclass
class Violation:
    """On ``trajectory``, ``expected_better`` scored worse than ``expected_worse``."""

    trajectory: str
    expected_better: str
    expected_worse: str
    better_score: float
    worse_score: float


@dataclass
class SlidesCheck:
    """Whether CLRRMC-TS >= CLRRMC-CS >= RR-AP >= RR-ATS >= RR-PI holds, per trajectory."""

    chain: list[str]
    holds: dict[str, bool]
    violations: list[Violation]
    reasons: dict[tuple[str, str], list[str]]  # (trajectory, method) -> explanations

    @property
    def holds_everywhere(self) -> bool:
        """True when the chain holds on every trajectory."""
        return all(self.holds.values())


def check_slides(
    config: CompareConfig,
    plan: Plan,
    outputs: Mapping[RunSpec, RunOutput],
    ranking: Ranking,
    specs: Sequence[RunSpec] | None = None,
) -> SlidesCheck:
    """Test every pair the slides' chain implies (a before b: a at least as good as b) on
    the runs ``specs`` that ``ranking`` ranked (default: the main runs)."""
    chain = [m for m in SLIDES_ORDER if m in config.methods]
    holds: dict[str, bool] = {}
    violations: list[Violation] = []
    reasons: dict[tuple[str, str], list[str]] = {}
    by_key = {(s.method, s.trajectory): s for s in (plan.main if specs is None else specs)}
    for name, scores in ranking.scores.items():
        found = [
            Violation(name, a, b, scores[a], scores[b])
            for i, a in enumerate(chain)
            for b in chain[i + 1 :]
            if not at_least_as_good(scores[a], scores[b])
        ]
        holds[name] = not found
        violations += found
        for method in dict.fromkeys(v.expected_better for v in found):
            spec = by_key[(method, name)]
            findings = diagnose(config, plan, outputs, spec)
            reasons[(name, method)] = [f.text for f in findings if f.adverse]
    return SlidesCheck(chain, holds, violations, reasons)
