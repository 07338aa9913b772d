"""The report's "slides' settings and ours" section with the user's ``--option`` values:
the user's value is run under both presets, each "alone" run is labelled by the setting it
applies, and the tables show what was run (no simulation: outputs are stand-ins)."""

import math

import pytest

from ddwmmr import load_trajectory
from ddwmmr.reports.compare import CompareConfig
from ddwmmr.reports.compare.plan import RunOutput, plan_runs
from ddwmmr.reports.compare.settings import (
    effect_rows,
    result_rows,
    same_in_both,
    setting_rows,
)


def _config(options: dict) -> CompareConfig:
    return CompareConfig(
        methods=("ats", "clrrmc-ts"),
        trajectories={"ellipse": load_trajectory("ellipse")},
        studies=(),
        options=options,
    )


def _outputs(plan):
    """Stand-in outputs: run i has an RMS position error of (i + 1) mm."""
    return {
        spec: RunOutput(
            {
                "rms_position_error_m": (i + 1) * 1e-3,
                "final_position_error_m": 0.0,
                "rms_orientation_error_rad": 0.0,
                "singular_steps": 0,
                "saturated_steps": 0,
            },
            {},
        )
        for i, spec in enumerate(plan.all_specs())
    }


def test_alone_runs_are_labelled_by_the_setting_they_apply():
    # an option the presets do not set comes first in every run's options
    config = _config({"clrrmc-ts": {"damping": 0.02}})
    plan = plan_runs(config)
    outputs = _outputs(plan)
    rows = effect_rows(config, plan, outputs)
    assert [row[2].split(" = ")[0] for row in rows] == [
        "auxiliary row of J_aug",
        "time constants (x, y, phi)",
    ]
    assert rows[1][2].startswith("time constants (x, y, phi) = (0.5, 0.5, inf) s")
    for row, spec in zip(rows, plan.preset_effects):
        assert dict(spec.options)["damping"] == pytest.approx(0.02)
        assert float(row[3]) == pytest.approx(outputs[spec].summary["rms_position_error_m"] * 1e3)


def test_the_users_tau_is_run_under_both_presets_and_shown():
    config = _config({"clrrmc-ts": {"tau": 0.3}})
    plan = plan_runs(config)
    taus = {dict(s.options)["tau"] for s in plan.all_specs() if s.method == "clrrmc-ts"}
    assert taus == {0.3}  # no run with the slides' (0.5, 0.5, inf)
    assert plan.preset_effects == []  # only aux still differs: its "alone" run is the slides run
    rows = setting_rows(config.methods, config.options)
    assert [row[:2] for row in rows] == [
        ["ats", "auxiliary row of J_aug"],
        ["clrrmc-ts", "auxiliary row of J_aug"],
    ]
    notes = same_in_both(config.options)
    assert "tau = 0.5 s in both where `--option` does not set it" in notes[1]
    assert "`clrrmc-ts` tau = (0.3, 0.3, 0.3) s" in notes[-1]


def test_the_users_aux_leaves_only_what_still_differs():
    config = _config({"ats": {"aux": "sum"}, "clrrmc-ts": {"aux": "sum"}})
    plan = plan_runs(config)
    auxes = {dict(s.options)["aux"] for s in plan.all_specs()}
    assert auxes == {"sum"}
    rows = setting_rows(config.methods, config.options)
    assert rows == [
        [
            "clrrmc-ts",
            "time constants (x, y, phi)",
            "(0.5, 0.5, inf) s, K = (2, 2, 0) 1/s: no orientation feedback",
            "(0.5, 0.5, 0.5) s, K = (2, 2, 2) 1/s",
        ]
    ]
    # ats runs once (both presets alike): no "slides vs ours" row for it
    results = result_rows(config, plan, _outputs(plan))
    assert [row[0] for row in results] == ["clrrmc-ts"]
    assert "`ats` aux = sum [0 0 0 1 1]" in same_in_both(config.options)[-1]


def test_without_options_the_section_is_unchanged():
    config = _config({})
    plan = plan_runs(config)
    assert len(setting_rows(config.methods)) == 3
    assert len(same_in_both()) == 4
    assert same_in_both()[1] == "time constants: the slides give no numbers; tau = 0.5 s in both"
    labels = [row[2] for row in effect_rows(config, plan, _outputs(plan))]
    assert labels[0].startswith("auxiliary row of J_aug = sum")
    assert math.isinf(dict(plan.preset_effects[1].options)["tau"][2])
