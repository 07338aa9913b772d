"""The slides' settings against the library's: the table of settings that differ, the
results of every method under both presets, and the effect of each setting on its own.

The runs come from :class:`~ddwmmr.reports.compare.plan.Plan` (``main`` under the chosen
preset, ``alternative`` under the other one, ``preset_effects`` with one slides setting
applied to the defaults); the settings from :mod:`ddwmmr.controllers.presets`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from ddwmmr.reports.compare.document import fmt, mm
from ddwmmr.reports.compare.plan import (
    CompareConfig,
    Plan,
    RunOutput,
    RunSpec,
    effect_settings,
    run_differences,
)

#: What each option means, for the settings table.
OPTION_NAMES = {"aux": "auxiliary row of J_aug", "tau": "time constants (x, y, phi)"}


def value_text(key: str, value: Any) -> str:
    """A preset value in words (``aux = sum`` -> ``sum [0 0 0 1 1]: th1dot + th2dot = 0``)."""
    if key == "aux":
        return {
            "sum": "sum [0 0 0 1 1]: th1dot + th2dot = 0",
            "shoulder": "shoulder [0 0 0 1 0]: th1dot = 0",
        }.get(value, str(value))
    if key == "tau":
        values = value if isinstance(value, tuple | list) else (value,) * 3
        gains = ", ".join("0" if math.isinf(v) else f"{1.0 / v:g}" for v in values)
        text = f"({', '.join(f'{v:g}' for v in values)}) s, K = ({gains}) 1/s"
        return text + (": no orientation feedback" if math.isinf(values[-1]) else "")
    return fmt(value) if isinstance(value, float) else str(value)


def setting_rows(
    methods: Sequence[str], options: Mapping[str, Mapping[str, Any]] | None = None
) -> list[list[str]]:
    """``[method, setting, slides, ours]`` for every setting in which the runs of a method
    under the two presets differ: the presets' differences less the settings the user's
    ``options`` (method -> ``--option`` values, :attr:`CompareConfig.options`) fix in
    every run (:func:`same_in_both` lists those)."""
    rows = []
    for method in methods:
        for key, (slides, ours) in run_differences(method, _user(options, method)).items():
            rows.append(
                [method, OPTION_NAMES.get(key, key), value_text(key, slides), value_text(key, ours)]
            )
    return rows


def _user(options: Mapping[str, Mapping[str, Any]] | None, method: str) -> Mapping[str, Any]:
    """The user's options of ``method`` (none when ``options`` is None)."""
    return (options or {}).get(method, {})


def runs_by_preset(config: CompareConfig, plan: Plan) -> dict[str, dict[tuple[str, str], RunSpec]]:
    """preset -> (method, trajectory) -> the run of the main comparison under it."""
    return {
        preset: {(s.method, s.trajectory): s for s in specs}
        for preset, specs in ((config.preset, plan.main), (config.other_preset, plan.alternative))
    }


def result_rows(
    config: CompareConfig, plan: Plan, outputs: Mapping[RunSpec, RunOutput]
) -> list[list[str]]:
    """``[method, trajectory, RMS slides, RMS ours, settled-end RMS slides, ours]`` (mm) and
    the singular / saturated steps under both, for every method whose presets differ (the
    others run once and are the same in both)."""
    runs = runs_by_preset(config, plan)
    rows = []
    for name in config.trajectories:
        for method in config.methods:
            if not run_differences(method, _user(config.options, method)):
                continue
            slides = outputs[runs["slides"][(method, name)]].summary
            ours = outputs[runs["default"][(method, name)]].summary
            rows.append(
                [method, config.shown(name)]
                + [mm(s[key]) for key in _ERRORS for s in (slides, ours)]
                + [fmt(s[_ORIENTATION]) for s in (slides, ours)]
                + [f"{fmt(s[key])} / {fmt(o[key])}" for key in _COUNTS for s, o in [(slides, ours)]]
            )
    return rows


#: Error columns (m, written in mm) and step counts of :func:`result_rows`.
_ERRORS = ("rms_position_error_m", "final_position_error_m")
_ORIENTATION = "rms_orientation_error_rad"
_COUNTS = ("singular_steps", "saturated_steps")
RESULT_HEADERS = [
    "method",
    "trajectory",
    "RMS slides (mm)",
    "RMS ours (mm)",
    "settled-end RMS slides (mm)",
    "settled-end RMS ours (mm)",
    "RMS orient. slides (rad)",
    "RMS orient. ours (rad)",
    "singular steps slides / ours",
    "saturated steps slides / ours",
]
EFFECT_HEADERS = [
    "method",
    "trajectory",
    "ours with only this slides setting",
    "RMS (mm)",
    "RMS ours (mm)",
    "RMS slides (mm)",
    "RMS orient. (rad)",
    "RMS orient. ours (rad)",
]
SETTING_HEADERS = ["method", "setting", "slides", "ours"]


def effect_rows(
    config: CompareConfig, plan: Plan, outputs: Mapping[RunSpec, RunOutput]
) -> list[list[str]]:
    """``[method, trajectory, setting, RMS with it alone, RMS ours, RMS slides]`` (mm) and
    the RMS orientation errors (rad) of every run of :func:`effect_settings`, each labelled
    by the slides setting it applies."""
    runs = runs_by_preset(config, plan)
    rows = []
    for name in config.trajectories:
        for method in config.methods:
            for key, spec in effect_settings(config, method, name):
                alone = outputs[spec].summary
                ours = outputs[runs["default"][(method, name)]].summary
                slides = outputs[runs["slides"][(method, name)]].summary
                value = dict(spec.options)[key]
                rows.append(
                    [
                        method,
                        config.shown(name),
                        f"{OPTION_NAMES.get(key, key)} = {value_text(key, value)}",
                    ]
                    + [mm(s["rms_position_error_m"]) for s in (alone, ours, slides)]
                    + [fmt(s[_ORIENTATION]) for s in (alone, ours)]
                )
    return rows


def same_in_both(options: Mapping[str, Mapping[str, Any]] | None = None) -> list[str]:
    """Settings that are the same in both presets, and why (for the report's notes), with
    the user's ``options`` (method -> ``--option`` values), which every run of the method
    uses under either preset."""
    given = {method: values for method, values in (options or {}).items() if values}
    sets_tau = any("tau" in values for values in given.values())
    notes = [
        "`ap`: the slides' potential V = 0.66 phi^2 + th1^2 + 0.25 th2^2 is also the "
        "library's default (the explanatory run with K3 = 0 shows what it costs)",
        "time constants: the slides give no numbers; tau = 0.5 s in both"
        + (" where `--option` does not set it" if sets_tau else ""),
        "damping near cos th1 = 0: the slides invert J_aug and take J^# undamped, which is "
        "unbounded at the singularity; both presets use the same damped least squares",
        "robot, start configuration, initial offset, integrator (rk4) and step: the same runs",
    ]
    if given:
        notes.append(
            "your `--option` values, over both presets in every run: "
            + ", ".join(
                f"`{method}` {key} = {value_text(key, value)}"
                for method, values in given.items()
                for key, value in values.items()
            )
        )
    return notes
