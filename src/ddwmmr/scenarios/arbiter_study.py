"""Side-by-side study: the thesis's state machine against the competitive-dynamics arbiter.

Same scenarios, same behaviours, same plant; only the arbiter differs (docs/thesis.md,
"Results: state machine and competitive arbiter side by side").
Three parts, each a function the CLI (``--study arbiters``) and ``docs/competitive_figures.py``
call:

* :func:`compare_variants`: both arbiters over threshold variants of thesis Tables
  5.5-5.20 (those where a fix state is used) -> :func:`table_52` (thesis Table 5.2 with a
  column per arbiter) and :func:`variants_table`.
* :func:`weight_statistics`: per scenario, from the competitive arbiter's own weight
  history (``record=True``): dominance switches, fast reversals, the largest weight and
  share rates, the hand-over time -> the numbers behind "smooth transitions, no
  chattering" (:func:`claims_table`).
* :func:`noise_study`: failures and times across noise seeds and noise levels ->
  "robust to noise".

"Switches" are counted the same way for both arbiters: entries into a fix state
(manipulability, stability, obstacle avoidance), i.e. the state machine's transitions and
the competitive arbiter's changes of dominant behaviour into a fix behaviour.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ddwmmr.arbiters.competitive import (
    BEHAVIOURS,
    CompetitiveDynamicsArbiter,
    CompetitiveParameters,
)
from ddwmmr.arbiters.state_machine import STATES, Hysteresis
from ddwmmr.outputs import write_atomic
from ddwmmr.scenarios import report, studies
from ddwmmr.scenarios.generator import Scenario
from ddwmmr.scenarios.protocol import (
    TRACE_INTERVAL,
    Outcome,
    RunConfig,
    run_scenario,
)
from ddwmmr.scenarios.studies import table_number
from ddwmmr.workers import process_pool

if TYPE_CHECKING:
    import os

#: The two arbiters, in column order, with their labels.
ARBITER_COLUMNS = (("state-machine", "state machine"), ("competitive", "competitive"))
#: Threshold variants (keys of ``studies.THRESHOLD_VARIANTS``) where a fix state is used
#: on the planar robot (the others give the baseline's numbers for both arbiters).
VARIANT_KEYS = (
    "baseline",
    "high-stability",
    "stab-nohyst-1.40",
    "stab-nohyst-1.50",
    "stab-1.50-1.70",
    "high-manipulability",
    "manip-nohyst-0.99",
)
#: Noise study: seeds at the default level, and levels (multiples of the default noise).
NOISE_SEEDS = (0, 1, 2, 3, 4)
NOISE_LEVELS = (0.0, 1.0, 5.0, 25.0)
#: Two dominance changes A -> B -> A within this time (s) count as a fast reversal.
REVERSAL_WINDOW = 0.5
FIX_KEYS = ("manipulability", "stability", "obstacle")
#: Sampling interval of a recorded trace (s).
TRACE_STEP = TRACE_INTERVAL

#: The CLI's batch runner: (scenarios, configuration, label) -> (outcomes, wall time s).
Runner = Callable[[list[Scenario], RunConfig, str], tuple[list[Outcome], float]]


#: Variants whose competitive weights are drawn (``competitive_weights_<key>.png``).
WEIGHT_FIGURE_KEYS = ("baseline", "stab-1.50-1.70", "stab-nohyst-1.50")


def output_names() -> tuple[str, ...]:
    """The files :func:`write_study` writes (the CLI adds ``summary.json``)."""
    runs = [f"{v.key}-{arbiter}.csv" for v in variants() for arbiter, _ in ARBITER_COLUMNS]
    figures = [f"competitive_weights_{key}.png" for key in WEIGHT_FIGURE_KEYS]
    return ("arbiters.md", *runs, *figures)


def variants(keys: Sequence[str] = VARIANT_KEYS) -> list[studies.Variant]:
    """The threshold variants of the study, in the given order."""
    by_key = {v.key: v for v in studies.THRESHOLD_VARIANTS}
    return [by_key[k] for k in keys]


def fix_entries(outcome: Outcome) -> float:
    """Entries into fix states in one scenario (the "switches" of both arbiters)."""
    return float(sum(outcome.metrics[f"transitions_{k}"] for k in FIX_KEYS))


def summarize(
    outcomes: Sequence[Outcome], wall: float, enter: float | None = None
) -> dict[str, Any]:
    """The report's batch summary plus switches per scenario (mean, sd, max) and, for
    recorded outcomes and a stability enter threshold, how well it was kept:
    ``median_min_stability`` (median over scenarios of the run's minimum S) and
    ``time_below_enter_s`` (mean time per scenario with S below ``enter``, from the trace).
    """
    summary = report.summarize(outcomes, wall)
    entries = np.array([fix_entries(o) for o in outcomes])
    summary["fix_entries"] = float(np.mean(entries))
    summary["sd_fix_entries"] = float(np.std(entries, ddof=1)) if entries.size > 1 else math.nan
    summary["max_fix_entries"] = float(np.max(entries))
    minima = [o.metrics["min_stability"] for o in outcomes]
    summary["median_min_stability"] = float(np.median(minima))
    if enter is not None and all(o.trace is not None for o in outcomes):
        # ignore: the all() above rules a missing trace out
        below = [TRACE_STEP * float(np.sum(np.asarray(o.trace["s"]) < enter)) for o in outcomes]  # type: ignore[index]
        summary["time_below_enter_s"] = float(np.mean(below))
    else:
        summary["time_below_enter_s"] = math.nan
    return summary


@dataclass
class VariantResult:
    """One threshold variant run under both arbiters."""

    variant: studies.Variant
    summaries: dict[str, dict[str, Any]]
    outcomes: dict[str, list[Outcome]]


def compare_variants(
    scenarios: list[Scenario],
    config: RunConfig,
    run: Runner,
    chosen: Sequence[studies.Variant] | None = None,
) -> list[VariantResult]:
    """Run every variant under both arbiters (``run`` is the CLI's batch runner)."""
    results = []
    for variant in chosen if chosen is not None else variants():
        summaries, outcomes = {}, {}
        for arbiter, _ in ARBITER_COLUMNS:
            cfg = replace(
                config,
                arbiter=arbiter,
                stability=variant.stability,
                manipulability=variant.manipulability,
                record=True,
            )
            batch, wall = run(scenarios, cfg, f"{variant.key} {arbiter}")
            summaries[arbiter] = summarize(batch, wall, variant.stability[0])
            outcomes[arbiter] = [Outcome(o.metrics) for o in batch]  # traces: not kept
        results.append(VariantResult(variant, summaries, outcomes))
    return results


def table_52(summaries: Sequence[tuple[str, dict[str, Any]]]) -> str:
    """Thesis Table 5.2 with one column per (label, summary), plus min S and switches."""
    columns = [report.table_rows(s) for _, s in summaries]
    lines = ["| | " + " | ".join(label for label, _ in summaries) + " |"]
    lines.append("|---|" + "---|" * len(summaries))
    for i, (label, _) in enumerate(columns[0]):
        lines.append(f"| {label} | " + " | ".join(col[i][1] for col in columns) + " |")
    extra: tuple[tuple[str, Callable[[dict[str, Any]], str]], ...] = (
        ("Minimum stability S", lambda s: table_number(s["min_stability"])),
        (
            "Median over scenarios of the minimum S",
            lambda s: table_number(s["median_min_stability"]),
        ),
        (
            "Time with S below the enter threshold (s)",
            lambda s: table_number(s["time_below_enter_s"]),
        ),
        (
            "Fix-state entries per scenario (sd) [max]",
            lambda s: (
                f"{table_number(s['fix_entries'])} ({table_number(s['sd_fix_entries'])}) "
                f"[{table_number(s['max_fix_entries'])}]"
            ),
        ),
    )
    for label, cell in extra:
        lines.append(f"| {label} | " + " | ".join(cell(s) for _, s in summaries) + " |")
    return "\n".join(lines) + "\n"


VARIANT_COLUMNS = (
    ("failed", "failed"),
    ("mean_time_s", "time (s)"),
    ("min_stability", "min S"),
    ("median_min_stability", "median min S"),
    ("time_below_enter_s", "S < enter (s)"),
    ("time_stability_s", "stab. (s)"),
    ("transitions_stability", "stab. entries"),
    ("time_manipulability_s", "manip. (s)"),
    ("fix_entries", "fix entries"),
)


def variants_table(results: Sequence[VariantResult]) -> str:
    """Markdown: one row per variant, cells "state machine / competitive"."""
    head = "| variant (thesis table) | S enter/exit | eta enter/exit | "
    head += " | ".join(label for _, label in VARIANT_COLUMNS) + " |"
    lines = [head, "|" + "---|" * (3 + len(VARIANT_COLUMNS))]
    for result in results:
        v = result.variant
        cells = [
            f"{v.label} ({v.table})",
            f"{v.stability[0]:g}/{v.stability[1]:g}",
            f"{v.manipulability[0]:g}/{v.manipulability[1]:g}",
        ]
        for key, _ in VARIANT_COLUMNS:
            sm, comp = (result.summaries[a][key] for a, _ in ARBITER_COLUMNS)
            cells.append(f"{table_number(sm)} / {table_number(comp)}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


# -- weights: smoothness and chattering ------------------------------------------------------
def recorded_run(
    scenario: Scenario, config: RunConfig, parameters: CompetitiveParameters | None = None
) -> tuple[Outcome, dict[str, list[float | str]]]:
    """One competitive run with the arbiter's weight history (and the protocol's trace)."""
    arbiter = CompetitiveDynamicsArbiter(
        Hysteresis(*config.stability),
        Hysteresis(*config.manipulability),
        parameters=parameters,
        seed=config.arbiter_seed,
        record=True,
    )
    outcome = run_scenario(scenario, replace(config, arbiter=arbiter))
    return outcome, arbiter.history


def _behaviour_of(state: str) -> str:
    return "objective" if state in STATES[:2] else state


def history_statistics(history: dict[str, list[float | str]]) -> dict[str, float]:
    """Smoothness numbers of one weight history.

    Returns: ``switches`` (changes of dominant behaviour), ``reversals`` (A -> B -> A within
    ``REVERSAL_WINDOW``), ``max_weight_rate`` (largest |dw/dt| of any behaviour, 1/s)
    and ``max_share_rate`` (largest |d share/dt|, share = w^2 / max(1, sum w^2); a full
    hand-over from one behaviour to another takes at least 1 / max_share_rate).
    """
    t = np.asarray(history["t"])
    w = np.array([history[f"w_{b}"] for b in BEHAVIOURS])
    if t.size < 2:
        return dict.fromkeys(
            ("switches", "reversals", "max_weight_rate", "max_share_rate"),
            math.nan,
        )
    dt = np.diff(t)
    squares = w**2
    shares = squares / np.maximum(1.0, squares.sum(axis=0))
    # ignore: the history's state column holds the states' names (the others floats)
    owners = [_behaviour_of(s) for s in history["state"]]  # type: ignore[arg-type]
    changes = [i for i in range(1, len(owners)) if owners[i] != owners[i - 1]]
    reversals = sum(
        1
        for a, b in itertools.pairwise(changes)
        if owners[b] == owners[a - 1] and t[b] - t[a] < REVERSAL_WINDOW
    )
    return {
        "switches": float(len(changes)),
        "reversals": float(reversals),
        "max_weight_rate": float(np.max(np.abs(np.diff(w, axis=1)) / dt)),
        "max_share_rate": float(np.max(np.abs(np.diff(shares, axis=1)) / dt)),
    }


def _statistics_of(args: tuple[Scenario, RunConfig]) -> dict[str, float]:
    scenario, config = args
    outcome, history = recorded_run(scenario, config)
    stats = history_statistics(history)
    stats["success"] = float(outcome.metrics["success"])
    return stats


def weight_statistics(
    scenarios: Sequence[Scenario], config: RunConfig, jobs: int = 1
) -> list[dict[str, float]]:
    """:func:`history_statistics` of every scenario (competitive arbiter), in order."""
    items = [(s, config) for s in scenarios]
    if jobs <= 1:
        return [_statistics_of(item) for item in items]
    with process_pool(jobs) as pool:
        return list(pool.map(_statistics_of, items, chunksize=max(1, len(items) // (4 * jobs))))


def claims_table(
    rows: Sequence[tuple[str, list[dict[str, float]], dict[str, dict[str, Any]]]],
) -> str:
    """Markdown: per variant, the switching and smoothness numbers of both arbiters.

    ``rows``: (variant label, :func:`weight_statistics` of the competitive runs, summaries
    by arbiter). The state machine's shares jump from 0 to 1 within one step: its share
    rate is 1 / dt (100 /s at 0.01 s).
    """
    lines = [
        "| variant | fix-state entries per scenario (max), state machine / competitive | "
        "competitive: dominance changes per scenario | of which fast reversals (< 0.5 s) | "
        "max weight rate (1/s) | max share rate (1/s) |",
        "|---|---|---|---|---|---|",
    ]
    for label, stats, summaries in rows:
        col = {k: np.array([row[k] for row in stats]) for k in stats[0]}
        sm, comp = summaries["state-machine"], summaries["competitive"]
        cells = (
            f"{table_number(sm['fix_entries'])} ({table_number(sm['max_fix_entries'])}) / "
            f"{table_number(comp['fix_entries'])} ({table_number(comp['max_fix_entries'])})",
            table_number(float(np.mean(col["switches"]))),
            table_number(float(np.mean(col["reversals"]))),
            table_number(float(np.max(col["max_weight_rate"]))),
            table_number(float(np.max(col["max_share_rate"]))),
        )
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


# -- noise ---------------------------------------------------------------------------------
def noisy_config(config: RunConfig, level: float, seed: int) -> RunConfig:
    """``config`` with a competitive arbiter at ``level`` x the default noise and ``seed``."""
    base = CompetitiveParameters()
    arbiter = CompetitiveDynamicsArbiter(
        Hysteresis(*config.stability),
        Hysteresis(*config.manipulability),
        parameters=replace(base, noise=base.noise * level),
        seed=seed,
    )
    return replace(config, arbiter=arbiter, arbiter_seed=seed)


def noise_study(
    scenarios: list[Scenario],
    config: RunConfig,
    run: Runner,
    chosen: Sequence[studies.Variant],
    seeds: Sequence[int] = NOISE_SEEDS,
    levels: Sequence[float] = NOISE_LEVELS,
) -> list[dict[str, Any]]:
    """Failures, mean time, min S and fix entries across noise seeds and levels."""
    rows = []
    cases = [(1.0, s) for s in seeds] + [(lv, seeds[0]) for lv in levels if lv != 1.0]
    for variant in chosen:
        base = replace(config, stability=variant.stability, manipulability=variant.manipulability)
        for level, seed in cases:
            outcomes, wall = run(
                scenarios, noisy_config(base, level, seed), f"{variant.key} noise x{level:g}"
            )
            summary = summarize(outcomes, wall)
            rows.append(
                {
                    "variant": variant.key,
                    "label": variant.label,
                    "level": level,
                    "noise": CompetitiveParameters().noise * level,
                    "seed": seed,
                    **{k: summary[k] for k in ("failed", "mean_time_s", "min_stability")},
                    "fix_entries": summary["fix_entries"],
                }
            )
    return rows


def noise_table(rows: Sequence[dict[str, Any]]) -> str:
    """Markdown: one row per (variant, level, seed)."""
    lines = [
        "| variant | noise (x default) | seed | failed | time (s) | min S | fix entries |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['label']} | {r['noise']:g} (x{r['level']:g}) | {r['seed']} | {r['failed']} | "
            f"{table_number(r['mean_time_s'])} | {table_number(r['min_stability'])} | "
            f"{table_number(r['fix_entries'])} |"
        )
    return "\n".join(lines) + "\n"


# -- figure ----------------------------------------------------------------------------------
def busiest(outcomes: Sequence[Outcome]) -> int:
    """Position of the successful scenario with the most fix-state entries (else the first)."""
    ok = [i for i, o in enumerate(outcomes) if o.metrics["success"]]
    return max(ok, key=lambda i: (fix_entries(outcomes[i]), -i)) if ok else 0


def plot_weights(
    scenario: Scenario,
    config: RunConfig,
    path: str | os.PathLike[str],
    title: str,
    compare_state_machine: bool = True,
) -> dict[str, float]:
    """Behaviour weights over time for one scenario (the paper's Fig. 5 kind of plot).

    Panels: the arbiter weight |w_b| of each behaviour (competitive arbiter), the state
    machine's state on the same scenario (if ``compare_state_machine``), and S of both runs
    with the thresholds, in the scenario figures' palette (:data:`report.BEHAVIOUR_COLOURS`,
    :data:`report.ARBITER_COLOURS`, :data:`report.ENTER_LINE`, :data:`report.LEAVE_LINE`).
    Returns the run's :func:`history_statistics`.
    """
    outcome, history = recorded_run(scenario, config)
    rows = 3 if compare_state_machine else 2
    from ddwmmr.reports.canvas import new_figure
    from ddwmmr.reports.legends import place_legend

    fig = new_figure((10, 2.5 * rows))  # not pyplot's: the caller's backend is left alone
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)
    ax = axes[0, 0]
    for name in BEHAVIOURS:
        values = np.abs(history[f"w_{name}"])
        if name == "obstacle" and not scenario.obstacles:
            continue
        ax.plot(history["t"], values, lw=1.1, color=report.BEHAVIOUR_COLOURS[name], label=name)
    m = outcome.metrics
    ax.set(
        ylabel="arbiter weight",
        ylim=(-0.05, 1.1),
        title=f"{title}: scenario {m['scenario']}, competitive arbiter "
        f"({m['reason']}, {m['time_s']:.1f} s)",
    )
    s_axis = axes[rows - 1, 0]
    colours = report.ARBITER_COLOURS
    s_axis.plot(
        history["t"], history["s"], color=colours["competitive"], lw=1.0, label="S, competitive"
    )
    if compare_state_machine:
        sm = run_scenario(scenario, replace(config, arbiter="state-machine", record=True))
        tr = sm.trace or {}
        ax2 = axes[1, 0]
        ax2.step(tr.get("t", []), tr.get("state", []), where="post", color=colours["state-machine"])
        ax2.set_yticks(range(len(STATES)), [s.replace("_", " ") for s in STATES])
        ax2.set(
            title=f"state machine on the same scenario ({sm.metrics['reason']}, "
            f"{sm.metrics['time_s']:.1f} s)"
        )
        s_machine = colours["state-machine"]
        s_axis.plot(
            tr.get("t", []), tr.get("s", []), color=s_machine, lw=1.0, label="S, state machine"
        )
    enter, exit_ = config.stability
    (enter_colour, enter_style), (exit_colour, exit_style) = report.ENTER_LINE, report.LEAVE_LINE
    s_axis.axhline(enter, color=enter_colour, lw=0.9, ls=enter_style, label=f"enter S < {enter:g}")
    if exit_ != enter:
        s_axis.axhline(
            exit_, color=exit_colour, lw=0.9, ls=exit_style, label=f"leave S >= {exit_:g}"
        )
    s_axis.set(xlabel="time (s)", ylabel="stability S")
    fig.tight_layout()
    place_legend(ax, fontsize=8, ncol=4)
    place_legend(s_axis, fontsize=8, ncol=4)
    report._save(fig, path)
    return history_statistics(history)


# -- the whole study -------------------------------------------------------------------------
def context_line(n: int, seed: int | None, config: RunConfig, noise: bool = True) -> str:
    """What the study ran: e.g. "2 scenarios (seed 0), thesis plant, payload 3 kg, step
    0.01 s, 60 s limit; competitive arbiter seed 0 (noise study: seeds 0, 1, 2, 3, 4)."
    (``seed`` None: not stated; the noise study's seeds only when it ran)."""
    scenarios, limit = studies.scenarios_and_limit(n, seed, config)
    seeds = ", ".join(str(s) for s in NOISE_SEEDS)
    study = f" (noise study: seeds {seeds})" if noise else ""
    return (
        f"{scenarios}, {config.plant} plant, payload {config.payload:g} kg, step "
        f"{config.dt:g} s, {limit:g} s limit; competitive arbiter seed "
        f"{config.arbiter_seed}{study}."
    )


def write_study(
    folder: str | os.PathLike[str],
    scenarios: list[Scenario],
    config: RunConfig,
    run: Runner,
    jobs: int = 1,
    noise: bool = True,
    seed: int | None = None,
) -> dict[str, Any]:
    """Run the study and write ``arbiters.md``, per-run CSVs and the weight figures.

    ``arbiters.md`` opens with :func:`context_line` (``seed``: the scenarios' seed, None:
    not stated). Returns the JSON-ready summary (the CLI writes it as ``summary.json``).
    """
    from pathlib import Path

    folder = Path(folder)
    results = compare_variants(scenarios, config, run)
    for result in results:
        for arbiter, _ in ARBITER_COLUMNS:
            name = f"{result.variant.key}-{arbiter}.csv"
            write_atomic(folder / name, report.metrics_csv(result.outcomes[arbiter]))
    by_key = {r.variant.key: r for r in results}
    baseline = by_key["baseline"]
    sections = [
        "# State machine vs competitive dynamics\n",
        context_line(len(scenarios), seed, config, noise) + "\n",
        "## Thesis Table 5.2, baseline thresholds\n",
        table_52([(label, baseline.summaries[a]) for a, label in ARBITER_COLUMNS]),
        "## Threshold variants (cells: state machine / competitive)\n",
        variants_table(results),
    ]
    claims = []
    for key in WEIGHT_FIGURE_KEYS:
        result = by_key[key]
        cfg = replace(
            config,
            stability=result.variant.stability,
            manipulability=result.variant.manipulability,
        )
        stats = weight_statistics(scenarios, cfg, jobs)
        claims.append((result.variant.label, stats, result.summaries))
        focus = scenarios[busiest(result.outcomes["competitive"])]
        plot_weights(focus, cfg, folder / f"competitive_weights_{key}.png", result.variant.label)
    sections += ["## Smoothness and chattering\n", claims_table(claims)]
    rows: list[dict[str, Any]] = []
    if noise:
        chosen = variants(("baseline", "stab-1.50-1.70", "stab-nohyst-1.50"))
        rows = noise_study(scenarios, config, run, chosen)
        sections += ["## Noise seeds and levels (competitive)\n", noise_table(rows)]
    text = "\n".join(sections)
    write_atomic(folder / "arbiters.md", text)
    return {
        "study": "arbiters",
        "n": len(scenarios),
        "variants": [
            {
                "variant": r.variant.key,
                **{
                    a: {k: v for k, v in r.summaries[a].items() if k != "failures"}
                    for a, _ in ARBITER_COLUMNS
                },
            }
            for r in results
        ],
        "weights": [{"variant": label, "scenarios": stats} for label, stats, _ in claims],
        "noise": rows,
        "table": text,
    }
