"""Both ends of the bracket for a batch of scenarios, cached per scenario.

Each scenario's results are kept in ``<folder>/cache/`` as soon as they are known:
``scenario-NNN-best.json`` (the best-known time and how it was found) with the winning
trajectory in ``scenario-NNN-best.npz``, and ``scenario-NNN-lower.json`` (the lower
bound). A cached result is used again when its key (the scenario's waypoints, payload,
S floor, tolerance and the method's settings) matches, so an interrupted batch resumes
where it stopped and a changed method recomputes only its own part. A run of some scenarios
keeps the cache of the others made for the same seed and payload (:func:`reusable_cache`).
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ddwmmr.bounds.lower import lower_bound
from ddwmmr.bounds.search import Settings, best_known
from ddwmmr.errors import (
    DURATION_RANGE_S,
    MAX_SCENARIOS,
    ParameterError,
    plain_float,
    read_text_file,
    shown,
)
from ddwmmr.model import Robot
from ddwmmr.model.stability import check_stability_floor
from ddwmmr.mpc.min_time import PLAN_FOLDER, PLAN_NAME, Guess, kept_trajectory
from ddwmmr.outputs import write_atomic
from ddwmmr.scenarios.generator import Scenario
from ddwmmr.sim.result import json_safe

#: Version of each method's results: a change invalidates the cached results of that part.
LOWER_VERSION = "budget-stops-1"
BEST_VERSION = "multistart-7"
#: Columns of bounds.csv.
COLUMNS = ("scenario", "lower_bound_s", "best_known_s", "starts", "spread_s", "replay_ok")
CACHE = PLAN_FOLDER


@dataclasses.dataclass(frozen=True)
class Job:
    """One scenario to bracket (picklable)."""

    scenario: Scenario
    payload: float
    settings: Settings
    need_best: bool
    need_lower: bool


def keys(scenario: Scenario, payload: float, settings: Settings) -> dict[str, dict[str, Any]]:
    """The cache keys of a scenario's two parts."""
    common = {
        "waypoints": [list(w) for w in scenario.waypoints],
        "payload": payload,
        "tolerance": settings.tolerance,
    }
    return {
        "best": {**common, "version": BEST_VERSION, "settings": dataclasses.asdict(settings)},
        "lower": {**common, "version": LOWER_VERSION},
    }


#: Cache file names (relative to the output folder) of each part of a scenario, with
#: ``{:03d}`` for the scenario number (from 1): the one naming of the cache, which
#: :func:`cache_names` builds and :func:`cache_entry` parses.
_CACHE_NAMES = {
    "best": f"{CACHE}/scenario-{{:03d}}-best.json",
    "trajectory": f"{CACHE}/{PLAN_NAME}",
    "lower": f"{CACHE}/scenario-{{:03d}}-lower.json",
}
#: The record a part's file goes with: the trajectory with its best-known record.
_RECORD_OF = {"best": "best", "trajectory": "best", "lower": "lower"}


def cache_names(index: int) -> dict[str, str]:
    """Cache file names (relative to the output folder) of scenario ``index`` (1-based)."""
    return {part: name.format(index) for part, name in _CACHE_NAMES.items()}


def _name_pattern(name: str) -> re.Pattern[str]:
    """The names ``name.format(n)`` gives for whole numbers n >= 0, the number in the
    group ``index`` (``name`` holds ``{:03d}`` once)."""
    before, after = name.split("{:03d}")
    return re.compile(rf"{re.escape(before)}(?P<index>\d{{3,}}){re.escape(after)}")


_CACHE_PATTERNS = {part: _name_pattern(name) for part, name in _CACHE_NAMES.items()}


def cache_entry(name: str) -> tuple[int, str] | None:
    """``(index, part)`` if ``name`` (relative to the output folder) is the name
    ``cache_names(index)[part]`` for a scenario number ``index``, else None: the inverse
    of :func:`cache_names`, by the same naming."""
    for part, pattern in _CACHE_PATTERNS.items():
        match = pattern.fullmatch(name)
        if match is not None:
            index = int(match["index"])
            return (index, part) if cache_names(index)[part] == name else None
    return None


def cached_numbers(names: Sequence[str]) -> set[int]:
    """The scenario numbers (in 1..MAX_SCENARIOS) of the cache files among ``names``."""
    entries = (cache_entry(name) for name in names)
    return {e[0] for e in entries if e is not None and 1 <= e[0] <= MAX_SCENARIOS}


def reusable_cache(
    folder: Path, names: Sequence[str], scenarios: Mapping[int, Scenario], payload: float
) -> tuple[list[str], list[int]]:
    """The cache files among ``names`` (relative to ``folder``) a run of ``payload`` keeps,
    and the scenario numbers whose cache it drops.

    ``scenarios`` maps scenario numbers (from 1) to the run's seed's scenarios; it must
    hold every number of :func:`cached_numbers` of ``names`` (a number it lacks is
    dropped). A scenario's record is kept when its key names that scenario's waypoints and
    ``payload``: the problem the folder's summary.json names, and the one a plan read
    from the folder (``scenarios --option plan=DIR``) is taken for. Its method settings and
    version are not judged here: :func:`read_cached` checks the whole key before any use,
    so a record of other settings (``--quick``) is kept for the run that has them. The
    trajectory goes with its best record. A record for another seed or payload, unreadable,
    or without a key is dropped, with the rest of its scenario's part; so is a best-known
    record of a replayed search whose trajectory is missing or unreadable (a plan read
    from the folder would fail on it; a run of that scenario searches again).
    """
    kept, dropped = [], set()
    for name in names:
        entry = cache_entry(name)
        if entry is None:
            continue
        index, part = entry
        scenario = scenarios.get(index) if 1 <= index <= MAX_SCENARIOS else None
        if scenario is not None and _keeps(folder, index, part, scenario, payload):
            kept.append(name)
        else:
            dropped.add(index)
    return sorted(kept), sorted(dropped)


def _keeps(folder: Path, index: int, part: str, scenario: Scenario, payload: float) -> bool:
    """Whether :func:`reusable_cache` keeps ``part`` of scenario ``index``'s cache."""
    record = folder / cache_names(index)[_RECORD_OF[part]]
    if not _same_problem(record, scenario, payload):
        return False
    return _RECORD_OF[part] != "best" or not _trajectory_lost(
        folder, index, _read_object(record) or {}
    )


def _same_problem(path: Path, scenario: Scenario, payload: float) -> bool:
    """Whether the cache record at ``path`` is for ``scenario``'s waypoints and ``payload``."""
    try:
        key = json.loads(path.read_text(encoding="utf-8"))["key"]
        wanted = json_safe(keys(scenario, payload, Settings())["lower"])
        same: bool = key["waypoints"] == wanted["waypoints"] and key["payload"] == wanted["payload"]
        return same
    except (OSError, ValueError, KeyError, TypeError):
        return False


def read_cached(
    folder: Path, scenario: Scenario, payload: float, settings: Settings
) -> tuple[dict[str, Any] | None, dict[str, Any] | None]:
    """The cached (best, lower) records of a scenario, each None if absent or stale.

    Stale: a key other than ``keys(scenario, payload, settings)``'s; a lower bound that is
    no time in :data:`~ddwmmr.errors.DURATION_RANGE_S` (s); a replayed best-known record
    whose time is none or whose trajectory (``.npz``) is missing or unreadable
    (:func:`usable_best`); and the lower bound when it is above the replayed best-known
    time (one of them is wrong: the lower bound, deterministic and the cheaper to compute,
    is computed again, and :func:`row` refuses the pair if it is still above).
    """
    index = scenario.index + 1
    names = cache_names(index)
    wanted = keys(scenario, payload, settings)
    out = {part: _keyed_record(folder / names[part], wanted[part]) for part in ("best", "lower")}
    best, lower = out["best"], out["lower"]
    if lower is not None and not _is_time(lower.get("lower_bound_s")):
        lower = None
    if best is not None and not usable_best(folder, index, best):
        best = None
    both = best is not None and lower is not None and best["replay_ok"] is True
    # ignore: both rules a missing record out
    if both and best["best_known_s"] < lower["lower_bound_s"]:  # type: ignore[index]
        lower = None  # the cheaper end, computed again: :func:`row` judges the new one
    return best, lower


def _keyed_record(path: Path, key: dict[str, Any]) -> dict[str, Any] | None:
    """The JSON record at ``path`` if it is an object whose ``key`` is ``key``, else None."""
    record = _read_object(path)
    return record if record is not None and record.get("key") == json_safe(key) else None


def _is_time(value: object) -> bool:
    """Whether ``value`` is a number of seconds in :data:`~ddwmmr.errors.DURATION_RANGE_S`."""
    low, high = DURATION_RANGE_S
    return isinstance(value, int | float) and not isinstance(value, bool) and low <= value <= high


def usable_best(folder: Path, index: int, record: dict[str, Any]) -> bool:
    """Whether scenario ``index``'s (from 1) best-known ``record`` in the cache of the
    output folder ``folder`` can be used: a search that replayed nothing (``replay_ok``
    False) always can; a replayed one needs a best-known time (s, in
    :data:`~ddwmmr.errors.DURATION_RANGE_S`) and, from a search that kept one, its
    trajectory beside it, readable (:func:`_trajectory_lost`)."""
    replayed = record.get("replay_ok")
    if replayed is False:
        return True
    if replayed is not True or not _is_time(record.get("best_known_s")):
        return False
    return not _trajectory_lost(folder, index, record)


def _trajectory_lost(folder: Path, index: int, record: dict[str, Any]) -> bool:
    """Whether best-known ``record`` of scenario ``index`` is of a search that kept a
    trajectory (``replay_ok`` true and the ``start`` it came from named: :func:`solve`
    then stores the trajectory beside it) which its ``.npz`` in the cache of ``folder``
    no longer holds: missing, or not readable as ``--option plan=DIR`` reads it
    (:meth:`~ddwmmr.mpc.min_time.Guess.load`: empty, truncated, damaged...)."""
    if not kept_trajectory(record):
        return False
    try:
        Guess.load(folder / cache_names(index)["trajectory"])
    except ParameterError:
        return True
    return False


def other_settings(
    folder: Path, scenario: Scenario, payload: float, settings: Settings
) -> dict[str, Any] | None:
    """The method settings (a dict, as :func:`keys` records them) of scenario
    ``scenario``'s cached best-known record when it is for the same problem and method
    version but other settings than ``settings`` (a ``--quick`` search, another S floor);
    None when there is no such record."""
    wanted = json_safe(keys(scenario, payload, settings)["best"])
    record = _read_object(folder / cache_names(scenario.index + 1)["best"])
    key = record.get("key") if record is not None else None
    if not isinstance(key, dict) or key.get("settings") == wanted["settings"]:
        return None
    same = all(key.get(name) == wanted[name] for name in wanted if name != "settings")
    return key.get("settings") if same and isinstance(key.get("settings"), dict) else None


def _read_object(path: Path) -> dict[str, Any] | None:
    """The JSON object at ``path``, or None if missing, unreadable, not a regular file or
    not an object."""
    try:
        record = json.loads(read_text_file(path, "bounds"))
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def solve(job: Job) -> dict[str, Any]:
    """Run the parts a job needs (in a worker process); records and the trajectory."""
    robot = Robot().with_payload(job.payload)
    wanted = keys(job.scenario, job.payload, job.settings)
    out: dict[str, Any] = {"index": job.scenario.index + 1}
    if job.need_lower:
        bound = lower_bound(robot, job.scenario.waypoints, tolerance=job.settings.tolerance)
        out["lower"] = {
            "key": wanted["lower"],
            "lower_bound_s": bound.value,
            "cells": bound.cells,
            "arcs": bound.arcs,
            "wall_s": bound.wall_s,
        }
    if job.need_best:
        found = best_known(robot, job.scenario, job.settings)
        out["best"] = {"key": wanted["best"], **found.record()}
        if found.solution is not None:
            out["trajectory"] = found.solution.plan_arrays()
    return out


def store(folder: Path, result: dict[str, Any]) -> list[str]:
    """Write a solved job's records into the cache; returns the names written."""
    names = cache_names(result["index"])
    written = []
    for part in ("best", "lower"):
        if part in result:
            write_atomic(folder / names[part], json.dumps(json_safe(result[part]), indent=1) + "\n")
            written.append(names[part])
    if "trajectory" in result:
        buffer = io.BytesIO()
        np.savez(buffer, **result["trajectory"])
        write_atomic(folder / names["trajectory"], buffer.getvalue())
        written.append(names["trajectory"])
    return written


def row(index: int, best: dict[str, Any] | None, lower: dict[str, Any] | None) -> dict[str, Any]:
    """One line of bounds.csv; a one-line :class:`ParameterError` naming the scenario's
    cache files when its replayed best-known time is below its lower bound (bounds.csv's
    readers refuse such a row: no achieved time is below its lower bound)."""
    best = best or {}
    out = {
        "scenario": index,
        "lower_bound_s": (lower or {}).get("lower_bound_s", math.nan),
        "best_known_s": best.get("best_known_s", math.nan),
        "starts": best.get("starts", 0),
        "spread_s": best.get("spread_s", math.nan),
        "replay_ok": bool(best.get("replay_ok", False)),
    }
    if out["replay_ok"] and out["best_known_s"] < out["lower_bound_s"]:
        names = cache_names(index)
        raise ParameterError(
            f"bounds: scenario {index}'s best-known time {out['best_known_s']:.6g} s is below "
            f"its lower bound {out['lower_bound_s']:.6g} s (no achieved time is below its "
            f"lower bound): one of {names['best']}, {names['lower']} is wrong; delete both "
            "and run again"
        )
    return out


def bounds_csv(rows: list[dict[str, Any]]) -> str:
    """bounds.csv text: one row per scenario (times in s, floats in full precision)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: (repr(float(v)) if isinstance(v, float) else v) for k, v in r.items()})
    return buffer.getvalue()


#: The columns :func:`read_bounds` reads from a bounds.csv (of :data:`COLUMNS`).
READ_COLUMNS = ("scenario", "lower_bound_s", "best_known_s", "replay_ok")


def read_bounds(path: str | Path) -> dict[int, tuple[float, float]]:
    """``{scenario: (lower_bound_s, best_known_s)}`` from a bounds.csv (1-based scenarios).

    An end the file does not give is NaN: ``nan`` in its column (as the bounds tool writes
    an end it has not computed, e.g. the best-known times of a ``--lower-only`` run), and
    the best-known time of a row whose replay failed (``replay_ok`` False; that column is
    then not read). Refused with a one-line :class:`ParameterError` naming the file, the
    line (and scenario) and the column: a file without one of :data:`READ_COLUMNS` or
    with one twice; a row with more fields than the header; a scenario that is not a whole
    number in 1..``MAX_SCENARIOS`` or appears twice; a ``replay_ok`` other than True or
    False; a time that is neither ``nan`` nor a number of seconds in
    :data:`~ddwmmr.errors.DURATION_RANGE_S` (0, negative, inf, 1e-300); a best-known time
    below the lower bound of its row (a lower bound is at most any time achieved). A UTF-8
    byte-order mark (a spreadsheet's "CSV UTF-8") is read as none.
    """
    out = {}
    # read_text_file refuses a FIFO or a device (which would block) and text that is not
    # UTF-8 in one line; the csv module then reads the text as it would the file.
    text = read_text_file(path, "bounds")
    reader = csv.DictReader(io.StringIO(text, newline=""))
    missing = [c for c in READ_COLUMNS if c not in (reader.fieldnames or ())]
    if missing:
        raise ParameterError(
            f"bounds: {path} lacks the column{'s' * (len(missing) > 1)} "
            f"{', '.join(missing)} (a bounds.csv of python -m ddwmmr.bounds has "
            f"{', '.join(READ_COLUMNS)})"
        )
    twice = sorted({c for c in READ_COLUMNS if list(reader.fieldnames or ()).count(c) > 1})
    if twice:  # the csv module reads the last of them, silently
        raise ParameterError(
            f"bounds: {path} has the column{'s' * (len(twice) > 1)} {', '.join(twice)} "
            "more than once (a bounds.csv of python -m ddwmmr.bounds has each once)"
        )
    for r in reader:
        where = f"bounds: {path} line {reader.line_num}"
        if None in r:  # the csv module's key of the fields beyond the header's
            raise ParameterError(f"{where} has more fields than the header has columns")
        scenario = _bounds_scenario(where, r)
        if scenario in out:
            raise ParameterError(f"{where}: scenario {scenario} appears twice")
        where = f"{where} (scenario {scenario})"
        replay_ok = _bounds_field(where, r, "replay_ok")
        if replay_ok not in ("True", "False"):
            raise ParameterError(
                f"{where}, column replay_ok: must be True or False (got {shown(replay_ok)})"
            )
        lower = _bounds_time(where, r, "lower_bound_s")
        best = _bounds_time(where, r, "best_known_s") if replay_ok == "True" else math.nan
        if best < lower:
            raise ParameterError(
                f"{where}: best_known_s {r['best_known_s'].strip()} s is below "
                f"lower_bound_s {r['lower_bound_s'].strip()} s (no achieved time is below "
                "its lower bound)"
            )
        out[scenario] = (lower, best)
    return out


def _bounds_field(where: str, row: Mapping[str, str | None], key: str) -> str:
    """The text of column ``key`` of a bounds.csv row, refused if the row has none."""
    text = row.get(key)
    if text is None or not text.strip():
        raise ParameterError(f"{where} has no value in column {key}")
    return text.strip()


def _bounds_scenario(where: str, row: Mapping[str, str | None]) -> int:
    """A bounds.csv row's scenario number, in 1..:data:`~ddwmmr.errors.MAX_SCENARIOS`."""
    text = _bounds_field(where, row, "scenario")
    number = scenario_number(text) if text.isascii() and text.isdigit() else 0
    if not 1 <= number <= MAX_SCENARIOS:
        raise ParameterError(
            f"{where}, column scenario: must be a whole number in 1-{MAX_SCENARIOS} "
            f"(got {shown(text)})"
        )
    return number


def scenario_number(digits: str) -> int:
    """The number the ASCII ``digits`` spell, or ``MAX_SCENARIOS + 1`` when they spell more
    digits than ``MAX_SCENARIOS`` has (compared as text: ``int`` refuses numbers of more
    than 4300 digits, and no larger one needs converting to be out of range)."""
    significant = digits.lstrip("0") or "0"
    if len(significant) > len(str(MAX_SCENARIOS)):
        return MAX_SCENARIOS + 1
    return int(significant)


def _bounds_time(where: str, row: Mapping[str, str | None], key: str) -> float:
    """A time of a bounds.csv row (s): NaN for ``nan`` (no value), else a number in
    :data:`~ddwmmr.errors.DURATION_RANGE_S`."""
    text = _bounds_field(where, row, key)
    low, high = DURATION_RANGE_S
    try:
        value = plain_float(text)
    except ValueError:
        value = None
    if value is None or not (math.isnan(value) or low <= value <= high):
        got = shown(text) if value is None else text
        raise ParameterError(
            f"{where}, column {key}: must be a time in [{low:g}, {high:g}] s, or nan for none "
            f"(got {got})"
        )
    return value


def read_bounds_file(path: str | Path, seed: int, payload: float) -> dict[int, tuple[float, float]]:
    """:func:`read_bounds` of a bounds tool's output, refused (one-line
    :class:`ParameterError`) when ``path`` is a folder (the run's, not its bounds.csv),
    unreadable, or made for another seed or payload (its summary.json beside it says
    which; refused when missing or recording neither; both files may start with a UTF-8
    byte-order mark)."""
    path = Path(path)
    if path.is_dir():  # the folder, not the file in it (a plan=DIR takes the folder)
        raise ParameterError(
            f"bounds must be the bounds.csv file of a bounds run, not its folder (got {path}; "
            f"give {path / 'bounds.csv'})"
        )
    try:
        table = read_bounds(path)
    except ParameterError:  # already one line naming what is wrong
        raise
    except (OSError, ValueError, KeyError, csv.Error) as exc:
        raise ParameterError(f"bounds: cannot read {path} and its summary.json ({exc})") from None
    record = path.parent / "summary.json"
    beside = f"the bounds run's record of the seed and payload {path.name} is for"
    try:
        text = read_text_file(record, "bounds")
    except ParameterError as exc:  # one line naming the file and what is wrong with it
        raise ParameterError(f"{exc}; it is {beside}, which must be beside it") from None
    try:
        summary = json.loads(text)
    except ValueError as exc:
        raise ParameterError(
            f"bounds: cannot read {record}, {beside}, which must be beside it ({exc})"
        ) from None
    if not isinstance(summary, dict) or not {"seed", "payload"} <= summary.keys():
        raise ParameterError(
            f"bounds: {record} records no seed and payload (a bounds run's summary.json "
            f"does; the one beside {path.name} must be its)"
        )
    recorded = summary["seed"], summary["payload"]
    # a boolean equals 0 or 1 and a string prints as the number it spells: neither is the
    # record of a seed or payload, and the message quotes a string
    if any(isinstance(value, bool | str) for value in recorded) or recorded != (seed, payload):
        raise ParameterError(
            f"bounds: {path} is for seed {shown(recorded[0])}, payload "
            f"{shown(recorded[1])} kg, not seed {seed}, payload {payload:g} kg"
        )
    return table


def bounds_floor(path: str | Path) -> float | None:
    """The floor on S the best-known times of the bounds.csv at ``path`` hold (its
    summary.json's ``settings.stability_min``); None when that record holds no number
    there. A number that is no floor on S (NaN, infinite, beyond a float, outside
    ``(0, STABILITY_CAP)``: :func:`~ddwmmr.model.stability.check_stability_floor`) is a
    one-line :class:`ParameterError` naming the record and the range."""
    record = Path(path).parent / "summary.json"
    summary = _read_object(record)
    settings = summary.get("settings") if summary is not None else None
    floor = settings.get("stability_min") if isinstance(settings, dict) else None
    if not isinstance(floor, int | float) or isinstance(floor, bool):
        return None
    return check_stability_floor(floor, f"bounds: {record}: settings.stability_min")


def summarize(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Means of both ends, of the bracket's width (best known / lower bound) and counts.

    Each mean is over the rows that have its value: ``mean_lower_bound_s`` over every row
    with a lower bound, ``mean_best_known_s`` over the ``replay_ok`` rows; the width's,
    and ``mean_lower_bound_bracketed_s``, over the ``bracketed`` rows, which have both
    ends (the mean lower bound to set beside ``mean_best_known_s``).
    """
    lower = np.array([r["lower_bound_s"] for r in rows], dtype=float)
    best = np.array([r["best_known_s"] if r["replay_ok"] else math.nan for r in rows], dtype=float)
    both = np.isfinite(lower) & np.isfinite(best)
    width = best[both] / lower[both]
    spread = np.array([r["spread_s"] for r in rows], dtype=float)
    return {
        "scenarios": len(rows),
        "replay_ok": int(sum(bool(r["replay_ok"]) for r in rows)),
        "mean_lower_bound_s": float(np.nanmean(lower)) if np.isfinite(lower).any() else math.nan,
        "mean_best_known_s": float(np.nanmean(best)) if np.isfinite(best).any() else math.nan,
        "bracketed": int(both.sum()),
        "mean_lower_bound_bracketed_s": float(lower[both].mean()) if width.size else math.nan,
        "mean_width": float(width.mean()) if width.size else math.nan,
        "max_width": float(width.max()) if width.size else math.nan,
        "min_width": float(width.min()) if width.size else math.nan,
        "mean_spread_s": float(np.nanmean(spread)) if np.isfinite(spread).any() else math.nan,
        "lower_method": LOWER_VERSION,
        "best_method": BEST_VERSION,
    }
