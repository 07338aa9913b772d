""" "Which method should I use": a profile of every method from the main runs (accuracy,
step time, offset removal, tip-over stability guarantee, singularity behaviour) and one
recommendation per use case, each computed from the runs of the report (nothing here is
a fixed opinion: another robot or trajectory gives other lines).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ddwmmr.reports.compare.constants import CORNER_TRAJECTORY, SLIDES_ORDER, STUDY_TRAJECTORY
from ddwmmr.reports.compare.diagnosis import convergence_time, keeps_offset, singularity_outcome
from ddwmmr.reports.compare.document import fmt, mm
from ddwmmr.reports.compare.plan import CompareConfig, RunOutput, RunSpec, main_spec
from ddwmmr.reports.compare.ranking import (
    NOT_TRACKED_MARK,
    Ranking,
    at_least_as_good,
    did_not_track,
)


@dataclass
class Profile:
    """What the main runs say about one method.

    Attributes:
        scores: trajectory -> RMS position error (m).
        step_us: median over the trajectories of the run's median step time (us).
        settle_trajectory: the trajectory the offset removal is judged on (the study
            trajectory, the ellipse, when it ran: the rectangle's corners bring the error
            back above 5 % of the offset for every method).
        settle_s: time (s) after which the error stays below 5 % of the initial offset
            there (NaN: never).
        open_loop: it kept the initial offset on some trajectory (no pose feedback).
        stability_floor: the hard floor S_min the method enforces, None if it has none.
        stability_violations: steps below that floor, summed over the runs.
        min_stability: smallest tip-over margin S over the runs.
        singularity: trajectory -> (``away`` | ``passes`` | ``lost``, time in s or NaN).
        min_cos_th1: smallest |cos th1| over the runs.
        start_stability: smallest tip-over margin S of the start poses over the runs (NaN
            if no run recorded it).
        shown: a trajectory key (of ``scores``...) -> the name the report shows
            (:meth:`CompareConfig.shown`).
        untracked: the method's runs that did not track (:func:`did_not_track`), each as
            (trajectory key, plant): plant None for a main run (the kinematic plant), then
            the runs on the extra plants (``--plant``), plant by plant.
    """

    method: str
    scores: dict[str, float]
    step_us: float
    settle_trajectory: str
    settle_s: float
    open_loop: bool
    stability_floor: float | None
    stability_violations: int
    min_stability: float
    singularity: dict[str, tuple[str, float]]
    min_cos_th1: float
    start_stability: float = math.nan
    shown: Callable[[str], str] = str
    untracked: tuple[tuple[str, str | None], ...] = ()

    @property
    def converges(self) -> bool:
        """It removed the initial offset (on :attr:`settle_trajectory`)."""
        return not math.isnan(self.settle_s)


def profiles(
    config: CompareConfig,
    outputs: Mapping[RunSpec, RunOutput],
    ranking: Ranking,
    plants: Mapping[str, Sequence[RunSpec]] | None = None,
) -> list[Profile]:
    """One :class:`Profile` per compared method, best ranked first; ``plants``: plant ->
    the main runs repeated on it (``Plan.plants``), judged for :attr:`Profile.untracked`."""
    on_plants = [
        (s.method, s.trajectory, plant)
        for plant, specs in (plants or {}).items()
        for s in specs
        if did_not_track(outputs[s].summary)
    ]
    result = []
    names = list(config.trajectories)
    settle_on = STUDY_TRAJECTORY if STUDY_TRAJECTORY in names else names[0]
    for method in ranking.order:
        runs = {n: outputs[main_spec(config, method, n)] for n in config.trajectories}
        summaries = [r.summary for r in runs.values()]
        floors = [s["stability_min"] for s in summaries if s.get("stability_min") is not None]
        singularity = {}
        for name, run in runs.items():
            outcome, onset = singularity_outcome(run.timeseries)
            time = math.nan if onset is None else float(run.timeseries["t"][onset])
            singularity[name] = (outcome, time)
        result.append(
            Profile(
                method=method,
                scores={n: ranking.scores[n][method] for n in ranking.scores},
                step_us=float(np.median([s["median_step_us"] for s in summaries])),
                settle_trajectory=settle_on,
                settle_s=convergence_time(
                    runs[settle_on].timeseries["t"], runs[settle_on].timeseries["position_error_m"]
                ),
                open_loop=any(keeps_offset(s) for s in summaries),
                stability_floor=min(floors) if floors else None,
                stability_violations=sum(int(s.get("stability_violations", 0)) for s in summaries),
                min_stability=min(float(s["min_stability"]) for s in summaries),
                singularity=singularity,
                min_cos_th1=min(
                    float(np.min(np.abs(np.cos(r.timeseries["th1"])))) for r in runs.values()
                ),
                start_stability=min(
                    (float(s["start_stability"]) for s in summaries if "start_stability" in s),
                    default=math.nan,
                ),
                shown=config.shown,
                untracked=(
                    *((n, None) for n in ranking.scores if not ranking.tracked(n, method)),
                    *((n, plant) for m, n, plant in on_plants if m == method),
                ),
            )
        )
    return result


ADVICE_HEADERS = [
    "method",
    "RMS per trajectory (mm)",
    "step (us)",
    "initial offset",
    "tip-over stability",
    "shoulder singularity cos th1 = 0",
]
#: Columns of the advice table holding text, left aligned (the step time is a number).
ADVICE_TEXT = (0, 1, 3, 4, 5)


def advice_rows(items: Sequence[Profile]) -> list[list[str]]:
    """One table row per method (see :data:`ADVICE_HEADERS`)."""
    return [
        [
            p.method,
            ", ".join(f"{p.shown(n)} {mm(v)}{_mark(p, n)}" for n, v in p.scores.items()),
            fmt(p.step_us),
            _offset_text(p),
            _stability_text(p),
            _singularity_text(p),
        ]
        for p in items
    ]


def _mark(p: Profile, name: str) -> str:
    """:data:`NOT_TRACKED_MARK` if ``p``'s main run on ``name`` did not track, else ``""``."""
    return NOT_TRACKED_MARK if (name, None) in p.untracked else ""


def marked(items: Sequence[Profile]) -> bool:
    """A score of :func:`advice_rows` carries :data:`NOT_TRACKED_MARK`."""
    return any(plant is None for p in items for _, plant in p.untracked)


def _offset_text(p: Profile) -> str:
    if p.converges:
        where = p.shown(p.settle_trajectory)
        return f"removed: below 5 % after {fmt(p.settle_s)} s on the {where}"
    if p.open_loop:
        return "kept (open loop, no pose feedback)"
    return f"not removed on the {p.shown(p.settle_trajectory)}"


def _stability_text(p: Profile) -> str:
    if p.stability_floor is not None:
        below = _started_below(p)
        start = f"; {below}" if below else ""
        return (
            f"hard constraint S >= {fmt(p.stability_floor)} "
            f"({p.stability_violations} steps below it{start})"
        )
    return f"not enforced (min S {fmt(p.min_stability)} on this robot)"


def _singularity_text(p: Profile) -> str:
    outcomes = {o for o, _ in p.singularity.values()}
    if outcomes == {"away"}:
        return f"stays away (min |cos th1| {fmt(p.min_cos_th1, 2)})"
    parts = []
    for name, (outcome, time) in p.singularity.items():
        if outcome == "lost":
            parts.append(f"{p.shown(name)}: reaches it at {fmt(time)} s and loses the path")
        elif outcome == "passes":
            parts.append(f"{p.shown(name)}: passes it at {fmt(time)} s, keeps the path")
    return "; ".join(parts)


def recommendations(
    items: Sequence[Profile], slides: Ranking | None = None, corners_reached: bool = True
) -> list[str]:
    """One line per use case, from the profiles (best ranked first) and the ranking under
    the slides' settings (``slides``). ``corners_reached``: the runs of the corner
    trajectory reach one of its corners (else no method is named for sharp corners). A
    method's runs that did not track are named once, on the first line naming it; later
    lines refer back to it (:func:`_caveat`)."""
    given: set[str] = set()
    lines = [_best_line("Best tracking over all trajectories", items, _overall, given)]
    for name, label in ((STUDY_TRAJECTORY, "Smooth paths"), (CORNER_TRAJECTORY, "Sharp corners")):
        if name == CORNER_TRAJECTORY and not corners_reached:
            lines.append(
                f"**{label} (like the {name})**: not judged: the runs end before the "
                f"{name}'s first corner."
            )
            continue
        if items and name in items[0].scores:
            # ignore: the lambda binds name as a default; _best_line calls it with p alone
            lines.append(
                _best_line(
                    f"{label} (like the {name})",
                    items,
                    lambda p, n=name: p.scores[n],  # type: ignore[misc]
                    given,
                )
            )
    closed = [p for p in items if p.converges]
    if closed:
        fastest = min(closed, key=lambda p: p.step_us)
        lines.append(
            f"**Tightest step-time budget with feedback**: `{fastest.method}` "
            f"({fmt(fastest.step_us)} us per step, {_step_basis(fastest)}, on this machine; "
            f"it removes the initial offset, below 5 % after {fmt(fastest.settle_s)} s on the "
            f"{fastest.shown(fastest.settle_trajectory)})." + _caveat([fastest], given)
        )
    lines.append(_stability_line(items, given))
    lines.append(_singularity_line(items, given))
    open_loop = [p for p in items if p.open_loop and not p.converges]
    if open_loop:
        best = min(open_loop, key=_overall)
        lines.append(
            f"**No pose measurement (feed-forward only)**: `{best.method}` (best open-loop "
            f"score, overall {mm(_overall(best))} mm; it keeps any initial offset)."
            + _caveat([best], given)
        )
    ours = [m for m in slides.order if m in SLIDES_ORDER] if slides is not None else []
    if ours:
        first = ours[0]
        shown = items[0].shown if items else str
        # ignore: ours is empty without slides (mypy does not carry that narrowing here)
        scores = ", ".join(f"{shown(n)} {mm(v[first])} mm" for n, v in slides.scores.items())  # type: ignore[union-attr]
        failed = [(n, None) for n in slides.scores if not slides.tracked(n, first)]  # type: ignore[union-attr]
        lines.append(
            "**Reproducing the slides**: `--preset slides` (their auxiliary row and gains); the "
            f"best of their methods under their settings is `{first}` ({scores})."
            + _did_not_track([(first, failed)], shown, " under `--preset slides`")
        )
    return lines


def _stability_line(items: Sequence[Profile], given: set[str] | None = None) -> str:
    """Which compared methods keep a hard floor on S, and which enforce one but were
    below it (a run that starts below its floor breaks it from the first step); ``given``
    as :func:`_caveat` takes it."""
    label = "**Tip-over stability as a hard guarantee**: "
    floored = [p for p in items if p.stability_floor is not None]
    if not floored:
        return label + "none of the compared methods enforces a floor on S (`qp` and `mpc` do)."
    kept = [p for p in floored if p.stability_violations == 0]
    broken = [p for p in floored if p.stability_violations > 0]
    parts = []
    if kept:
        parts.append(", ".join(f"`{p.method}` (S >= {fmt(p.stability_floor)})" for p in kept))
    if broken:
        texts = ", ".join(_broken_floor_text(p) for p in broken)
        verb = _agree(broken, "enforces", "enforce")
        parts.append(f"{texts} {verb} a floor but did not keep it in these runs")
    others = "no other compared method constrains S."
    return label + "; ".join([*parts, others]) + _caveat(floored, given)


def _broken_floor_text(p: Profile) -> str:
    """``qp`` with its floor, the steps below it and, if so, that it started below it."""
    text = f"`{p.method}` (S >= {fmt(p.stability_floor)}, {p.stability_violations} steps below it"
    below = _started_below(p)
    return text + (f"; it {below}" if below else "") + ")"


def _started_below(p: Profile) -> str:
    """``started below it, at S = 2.18`` if a run of ``p`` started below its floor on S,
    else ``""``."""
    if p.stability_floor is None or not p.start_stability < p.stability_floor:
        return ""
    return f"started below it, at S = {fmt(p.start_stability)}"


def _overall(p: Profile) -> float:
    logs = [math.log(max(v, 1e-15)) for v in p.scores.values()]
    return math.exp(sum(logs) / len(logs))


def _best_line(
    label: str,
    items: Sequence[Profile],
    key: Callable[[Profile], float],
    given: set[str] | None = None,
) -> str:
    """The best method by ``key`` and everything tied with it; the fastest tied one first;
    ``given`` as :func:`_caveat` takes it."""
    best = min(key(p) for p in items)
    tied = sorted((p for p in items if at_least_as_good(key(p), best)), key=lambda p: p.step_us)
    first, others = tied[0], tied[1:]
    text = f"**{label}**: `{first.method}` ({mm(key(first))} mm RMS, {fmt(first.step_us)} us)"
    if others:
        text += "; tied with it within 5 % but slower per step: " + ", ".join(
            f"`{p.method}` ({mm(key(p))} mm, {fmt(p.step_us)} us)" for p in others
        )
    return text + "." + _caveat(tied, given)


def _step_basis(p: Profile) -> str:
    """What :attr:`Profile.step_us` is a median over: ``median over both trajectories``,
    ``median over the 3 trajectories`` or, for one, ``on the ellipse``."""
    names = list(p.scores)
    if len(names) == 1:
        return f"on the {p.shown(names[0])}"
    return "median over " + (
        "both trajectories" if len(names) == 2 else f"the {len(names)} trajectories"
    )


def _caveat(named: Sequence[Profile], given: set[str] | None = None) -> str:
    """The runs of the methods a line names (``named``) that did not track
    (:attr:`Profile.untracked`), as :func:`_did_not_track` writes them. ``given``: the
    methods whose runs an earlier line of the advice named; those are only referred back to
    (`` `qp` (see above)``), and the methods named here are added to it (None: a line on
    its own, every method's runs named)."""
    shown = named[0].shown if named else str
    failed = [p for p in named if p.untracked]
    given = set() if given is None else given
    new = [(p.method, p.untracked) for p in failed if p.method not in given]
    again = [p.method for p in failed if p.method in given]
    given.update(method for method, _ in new)
    return _did_not_track(new, shown, again=again)


def _did_not_track(
    named: Sequence[tuple[str, Sequence[tuple[str, str | None]]]],
    shown: Callable[[str], str],
    under: str = "",
    again: Sequence[str] = (),
) -> str:
    """`` Did not track (docs/cli.md, "Verdict"): `ats` on the rectangle (kinematic and
    thesis plants).``: per method of ``named`` its runs, (trajectory key, plant or None
    for the kinematic main run), that did not track, grouped by trajectory; ``""`` when all
    tracked. ``shown`` gives a trajectory key's shown name; ``under`` names the settings of
    the runs when they are not the report's main ones (`` under `--preset slides` ``);
    ``again``: methods whose runs that did not track an earlier line named, referred back to
    last (`` `qp`, `mpc` (see above)``; the verdict reference was given there too)."""
    parts = [
        f"`{method}` on " + _and(_by_trajectory(runs, shown)) for method, runs in named if runs
    ]
    where = ' (docs/cli.md, "Verdict")' if parts else ""  # else the earlier line gave it
    if again:
        parts.append(f"{_names(again)} (see above)")
    if not parts:
        return ""
    return f" Did not track{under}{where}: {'; '.join(parts)}."


def _by_trajectory(
    runs: Sequence[tuple[str, str | None]], shown: Callable[[str], str]
) -> list[str]:
    """``["the rectangle (kinematic and thesis plants)", "the ellipse"]``: each trajectory
    of ``runs`` once, with the plants its runs were on (none named: the kinematic plant
    only)."""
    plants: dict[str, list[str | None]] = {}
    for name, plant in runs:
        plants.setdefault(name, []).append(plant)
    texts = []
    for name, on in plants.items():
        if on == [None]:
            texts.append(f"the {shown(name)}")
            continue
        named = [plant or "kinematic" for plant in on]
        noun = "plant" if len(named) == 1 else "plants"
        texts.append(f"the {shown(name)} ({_and(named)} {noun})")
    return texts


def _and(texts: Sequence[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return texts[0] if len(texts) == 1 else ", ".join(texts[:-1]) + " and " + texts[-1]


def _singularity_line(items: Sequence[Profile], given: set[str] | None = None) -> str:
    """Which methods pass the shoulder singularity, stay away from it or lose the path
    there; the runs that did not track of the first two groups (:func:`_caveat`, with
    ``given``)."""
    lost = [p.method for p in items if any(o == "lost" for o, _ in p.singularity.values())]
    passes = [
        p.method
        for p in items
        if p.method not in lost and any(o == "passes" for o, _ in p.singularity.values())
    ]
    away = [p.method for p in items if p.method not in lost and p.method not in passes]
    text = "**Near the shoulder singularity cos th1 = 0**: "
    parts = []
    if passes:
        parts.append(
            f"{_names(passes)} {_agree(passes, 'passes', 'pass')} it and "
            f"{_agree(passes, 'keeps', 'keep')} the path"
        )
    if away:
        parts.append(
            f"{_names(away)} {_agree(away, 'stays', 'stay')} away from it on these trajectories"
        )
    if lost:
        parts.append(
            f"avoid {_names(lost)}: {_agree(lost, 'it is', 'they are')} driven into it "
            f"and {_agree(lost, 'loses', 'lose')} the path"
        )
    kept = [p for p in items if p.method not in lost]
    return text + "; ".join(parts) + "." + _caveat(kept, given)


def _agree(methods: Sequence[object], one: str, several: str) -> str:
    """``one`` (singular verb form) for a single method, else ``several``."""
    return one if len(methods) == 1 else several


def _names(methods: Sequence[str]) -> str:
    return ", ".join(f"`{m}`" for m in methods)
