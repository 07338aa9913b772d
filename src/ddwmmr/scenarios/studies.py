"""The thesis's threshold and obstacle studies (Tables 5.5-5.21), with its published numbers.

Thesis figures are transcribed from the seed (1.25 kg payload, 3-D arm, MATLAB); ours come
from the same protocol on the planar robot. Keys of the thesis rows: failed, time, sd_time,
speed, base, arm, time_manip, trans_manip, time_stab, trans_stab (None: not published).
"""

from __future__ import annotations

import math
from dataclasses import astuple, dataclass
from typing import Any

from ddwmmr.arbiters.state_machine import THESIS_MANIPULABILITY, THESIS_STABILITY
from ddwmmr.scenarios.generator import Scenario, place_obstacles
from ddwmmr.scenarios.protocol import TIME_LIMIT_S, RunConfig

#: Scenarios behind each of the thesis's published numbers (thesis 5.1).
THESIS_N = 100


@dataclass(frozen=True)
class Variant:
    """One row of the threshold study: thresholds and the thesis's published result."""

    key: str
    label: str
    table: str
    stability: tuple[float, float]
    manipulability: tuple[float, float]
    thesis: dict[str, float | None]


def _row(failed: float, time: float | None = None, sd: float | None = None,
         speed: float | None = None, base: float | None = None, arm: float | None = None,
         tm: float | None = None, nm: float | None = None, ts: float | None = None,
         ns: float | None = None) -> dict[str, float | None]:  # fmt: skip
    return {
        "failed": failed, "time": time, "sd_time": sd, "speed": speed, "base": base,
        "arm": arm, "time_manip": tm, "trans_manip": nm, "time_stab": ts, "trans_stab": ns,
    }  # fmt: skip


B_S, B_M = astuple(THESIS_STABILITY), astuple(THESIS_MANIPULABILITY)
#: Thesis Tables 5.1/5.2, 5.5/5.6, 5.9/5.10, 5.11/5.12, 5.13/5.14, 5.17/5.18, 5.19/5.20.
THRESHOLD_VARIANTS = (
    Variant("baseline", "Baseline", "5.2", B_S, B_M,
            _row(0, 44.9, 4.22, 0.448, 26.1, 14.8, 1.35, 1.83, 2.67, 4.64)),
    Variant("low-stability", "Low stability 1.10/1.30", "5.6", (1.10, 1.30), B_M,
            _row(0, 41.9, 4.27, 0.480, 26.3, 13.3, 1.97, 2.86, 0.318, 1.53)),
    Variant("high-stability", "High stability 1.40/1.70", "5.6", (1.40, 1.70), B_M,
            _row(0, 46.6, 4.31, 0.431, 25.7, 15.7, 0.637, 0.800, 4.60, 8.57)),
    Variant("no-stability-hysteresis", "No stability hysteresis 1.25", "5.10", (1.25, 1.25),
            B_M, _row(0, 43.6, 4.08, 0.461, 26.3, 14.4, 1.42, 2.48, 1.54, 26.9)),
    Variant("low-manipulability", "Low manipulability 0.60/0.70", "5.14", B_S, (0.60, 0.70),
            _row(0, 44.9, 4.23, 0.448, 25.7, 16.2, 0.0474, 0.11, 3.01, 5.33)),
    Variant("high-manipulability", "High manipulability 0.90/0.95", "5.14", B_S, (0.90, 0.95),
            _row(0, 44.1, 4.24, 0.456, 26.1, 13.3, 2.29, 4.28, 2.32, 4.08)),
    Variant("no-manipulability-hysteresis", "No manipulability hysteresis 0.75", "5.18", B_S,
            (0.75, 0.75), _row(0, 44.9, 4.21, 0.448, 25.8, 15.6, 0.613, 1.79, 2.95, 5.21)),
    Variant("stab-nohyst-1.10", "No stab. hysteresis, thesis threshold no. 1: S = 1.10", "5.12",
            (1.10, 1.10), B_M, _row(0)),
    Variant("stab-nohyst-1.20", "No stab. hysteresis, thesis threshold no. 2: S = 1.20", "5.12",
            (1.20, 1.20), B_M, _row(0)),
    Variant("stab-nohyst-1.30", "No stab. hysteresis, thesis threshold no. 3: S = 1.30", "5.12",
            (1.30, 1.30), B_M, _row(0)),
    Variant("stab-nohyst-1.40", "No stab. hysteresis, thesis threshold no. 4: S = 1.40", "5.12",
            (1.40, 1.40), B_M, _row(6)),
    Variant("stab-nohyst-1.50", "No stab. hysteresis, thesis threshold no. 5: S = 1.50", "5.12",
            (1.50, 1.50), B_M, _row(42)),
    Variant("stab-1.50-1.70", "Stability 1.50 with hysteresis 1.70", "5.3.2 text",
            (1.50, 1.70), B_M, _row(0)),
    Variant("manip-nohyst-0.60", "No manip. hysteresis, thesis threshold no. 1: eta = 0.60",
            "5.20", B_S, (0.60, 0.60), _row(0)),
    Variant("manip-nohyst-0.70", "No manip. hysteresis, thesis threshold no. 2: eta = 0.70",
            "5.20", B_S, (0.70, 0.70), _row(0)),
    Variant("manip-nohyst-0.80", "No manip. hysteresis, thesis threshold no. 3: eta = 0.80",
            "5.20", B_S, (0.80, 0.80), _row(0)),
    Variant("manip-nohyst-0.90", "No manip. hysteresis, thesis threshold no. 4: eta = 0.90",
            "5.20", B_S, (0.90, 0.90), _row(0)),
    Variant("manip-nohyst-0.99", "No manip. hysteresis, thesis threshold no. 5: eta = 0.99",
            "5.20", B_S, (0.99, 0.99), _row(2)),
)  # fmt: skip

#: Thesis Table 5.21: scenario -> (time, speed, base, arm, t_manip, n_manip, t_stab,
#: n_stab, t_obstacle, n_obstacle); all four completed.
THESIS_OBSTACLES = {
    1: (52.3, 0.434, 26.5, 14.1, 0.780, 1, 2.98, 5, 7.90, 5),
    3: (62.0, 0.446, 27.3, 15.8, 0.780, 1, 3.08, 4, 15.0, 9),
    7: (55.3, 0.354, 25.3, 14.5, 1.60, 2, 2.78, 5, 11.1, 26),
    10: (64.6, 0.323, 28.6, 16.6, 1.52, 2, 3.34, 5, 14.5, 4),
}
OBSTACLE_SCENARIOS = tuple(THESIS_OBSTACLES)


def obstacle_scenarios(scenarios: list[Scenario]) -> list[Scenario]:
    """Thesis scenarios 1, 3, 7 and 10 (1-based) of the set, with two obstacles each."""
    return [place_obstacles(scenarios[i - 1]) for i in OBSTACLE_SCENARIOS if i <= len(scenarios)]


def table_number(value: float | None) -> str:
    """One cell of a study table: integers (counts) in full, other numbers to three
    significant figures, as the thesis reports; "–" for a missing (None) or undefined (NaN)
    value. Shared by the threshold, obstacle and arbiter study tables."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    if isinstance(value, int):
        return str(value)
    return f"{value:.3g}"


THRESHOLD_COLUMNS = (
    ("failed", "failed", "failed"),
    ("time", "mean_time_s", "time (s)"),
    ("speed", "mean_speed_m_s", "speed (m/s)"),
    ("base", "time_base_s", "base (s)"),
    ("arm", "time_arm_s", "arm (s)"),
    ("time_manip", "time_manipulability_s", "manip. (s)"),
    ("trans_manip", "transitions_manipulability", "manip. trans."),
    ("time_stab", "time_stability_s", "stab. (s)"),
    ("trans_stab", "transitions_stability", "stab. trans."),
)


def scenarios_and_limit(n: int, seed: int | None, config: RunConfig) -> tuple[str, float]:
    """``"2 scenarios (seed 0)"`` (``seed`` None: not stated) and the run's time limit per
    scenario (s; the protocol's default when ``config`` gives none): what a study's
    context line says of its runs."""
    scenarios = f"{n} scenario{'s' * (n != 1)}" + (f" (seed {seed})" if seed is not None else "")
    return scenarios, config.time_limit if config.time_limit is not None else TIME_LIMIT_S


def context_line(n: int, seed: int | None, config: RunConfig) -> str:
    """What "ours" in a "thesis / ours" cell is: e.g. "ours: 2 scenarios (seed 0), thesis
    controller, thesis plant, payload 3 kg, state-machine arbiter, 60 s limit; the
    thesis: 100 scenarios, 1.25 kg payload" (``seed`` None: not stated). A failure count
    is out of each side's own number of scenarios."""
    scenarios, limit = scenarios_and_limit(n, seed, config)
    arbiter = config.arbiter if isinstance(config.arbiter, str) else type(config.arbiter).__name__
    if arbiter == "competitive":
        arbiter += f" (arbiter seed {config.arbiter_seed})"
    return (
        f"ours: {scenarios}, {config.controller} controller, {config.plant} plant, "
        f"payload {config.payload:g} kg, {arbiter} arbiter, {limit:g} s limit; "
        f"the thesis: {THESIS_N} scenarios, 1.25 kg payload"
    )


#: Heading of thresholds.md: which side of a cell is which.
THRESHOLD_HEADING = "# Threshold study (thesis Tables 5.5-5.20): cells are thesis / ours"
#: What the study's cells hold, below its context line.
THRESHOLD_NOTE = (
    "failed: k of each side's n scenarios; speed: mean over the scenarios that finished; "
    "other columns: means over all scenarios, a failed one up to the instant it stopped; "
    '"–": not published by the thesis.'
)


def threshold_table(results: list[tuple[Variant, dict[str, Any]]], context: str = "") -> str:
    """Markdown table: each variant's thesis row next to ours ("thesis / ours" per cell,
    failures as "k of n" on each side: ``summary["n"]`` is ours). With ``context``
    (:func:`context_line`) the text of thresholds.md: :data:`THRESHOLD_HEADING`, the
    context and :data:`THRESHOLD_NOTE` as paragraphs, then the table."""
    head = "| variant (thesis table) | S enter/exit | eta enter/exit | "
    head += " | ".join(label for _, _, label in THRESHOLD_COLUMNS) + " |"
    lines = [head, "|" + "---|" * (3 + len(THRESHOLD_COLUMNS))]
    for variant, summary in results:
        cells = [
            f"{variant.label} ({variant.table})",
            f"{variant.stability[0]:g}/{variant.stability[1]:g}",
            f"{variant.manipulability[0]:g}/{variant.manipulability[1]:g}",
        ]
        for thesis_key, our_key, _ in THRESHOLD_COLUMNS:
            thesis, ours = table_number(variant.thesis[thesis_key]), table_number(summary[our_key])
            if thesis_key == "failed":
                thesis, ours = f"{thesis} of {THESIS_N}", f"{ours} of {summary['n']}"
            cells.append(f"{thesis} / {ours}")
        lines.append("| " + " | ".join(cells) + " |")
    table = "\n".join(lines) + "\n"
    return f"{THRESHOLD_HEADING}\n\n{context}\n\n{THRESHOLD_NOTE}\n\n{table}" if context else table


OBSTACLE_ROWS = (
    ("Scenario complete", "success", None),
    ("Simulation time (s)", "time_s", 0),
    ("Simulation speed (m/s)", "speed_m_s", 1),
    ("Time spent moving base (s)", "time_base_s", 2),
    ("Time spent moving manipulator (s)", "time_arm_s", 3),
    ("Time in manipulability state (s)", "time_manipulability_s", 4),
    ("No. of manipulability state transitions", "transitions_manipulability", 5),
    ("Time in stability state (s)", "time_stability_s", 6),
    ("No. of stability state transitions", "transitions_stability", 7),
    ("Time in obstacle state (s)", "time_obstacle_s", 8),
    ("No. of obstacle state transitions", "transitions_obstacle", 9),
)


#: Heading of obstacles.md: which side of a cell is which.
OBSTACLE_HEADING = "# Obstacle study (thesis Table 5.21): cells are thesis / ours"


def obstacle_table(metrics: list[dict[str, Any]], title: str = "") -> str:
    """Markdown table in the layout of thesis Table 5.21 ("thesis / ours" per cell; the
    speed of a scenario of ours that did not finish is undefined,
    ``speed_m_s`` of :mod:`ddwmmr.scenarios.protocol`). With ``title`` (what ours ran, e.g.
    "thesis controller, thesis plant, payload 3 kg"), the text of obstacles.md:
    :data:`OBSTACLE_HEADING`, "ours: " ``title``, then the table."""
    numbers = [m["scenario"] for m in metrics]
    lines = ["| | " + " | ".join(f"scenario {n}" for n in numbers) + " |"]
    lines.append("|---|" + "---|" * len(numbers))
    for label, key, thesis_index in OBSTACLE_ROWS:
        cells = []
        for m in metrics:
            ours = m[key]
            if key == "success":
                text = "Yes / " + ("Yes" if ours else f"No ({m['reason']})")
            else:
                thesis = THESIS_OBSTACLES.get(m["scenario"])
                # ignore: every row but "success" has a thesis index
                ref = thesis[thesis_index] if thesis is not None else None  # type: ignore[index]
                text = f"{table_number(ref)} / {table_number(ours)}"
            cells.append(text)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    table = "\n".join(lines) + "\n"
    return f"{OBSTACLE_HEADING}\n\nours: {title}\n\n{table}" if title else table
