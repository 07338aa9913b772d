"""Compare: shown trajectory names apart from file stems, the measured RK4 sentence of the
integrator study, and the tau sweep built on the compared runs' tau (preset and user)."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from ddwmmr.cli.compare import main
from ddwmmr.errors import ParameterError
from ddwmmr.reports.compare import CompareConfig, plan_runs
from ddwmmr.reports.compare.plan import RunOutput, study_tau
from ddwmmr.reports.compare.report import _integrator_finding
from ddwmmr.trajectories import load_trajectory


def test_a_toml_name_is_shown_as_written_and_files_stay_safe(tmp_path, capsys):
    for folder, name in (("a", "rot rect"), ("b", "rot rect"), ("c", "rot_rect")):
        (tmp_path / folder).mkdir()
        text = f'[trajectory]\nshape = "ellipse"\nname = "{name}"\nT = 40.0\nN = 2000\n'
        (tmp_path / folder / "t.toml").write_text(text)
    files = [str(tmp_path / f / "t.toml") for f in "abc"]
    out = tmp_path / "report"
    argv = ["--methods", "ats", "--study", "none", "--duration", "0.2", "--jobs", "1"]
    assert main([*argv, "--only", *files, "--no-progress", "--out", str(out)]) == 0
    console = capsys.readouterr().out
    with (out / "metrics.csv").open(newline="") as handle:
        shown = [row["trajectory"] for row in csv.DictReader(handle)]
    assert shown == ["rot rect", "rot rect-2", "rot_rect"]
    text = (out / "report.md").read_text()
    for name in shown:
        assert f"## Trajectory: {name}\n" in text and f"{name} RMS (mm)" in text
    assert "on rot rect, rot rect-2, rot_rect:" in console
    for stem in ("rot_rect", "rot_rect-2", "rot_rect-3"):  # figure files: file-safe
        assert (out / f"errors_{stem}.png").exists()


def _output(errors_m: np.ndarray) -> RunOutput:
    t = np.linspace(0.0, 40.0, errors_m.size)
    summary = {
        "max_position_error_m": float(np.max(errors_m)),
        "end_position_error_m": float(errors_m[-1]),
    }
    return RunOutput(summary, {"t": t, "position_error_m": errors_m})


def _integrator_runs(rk4_ats_m: float, rk4_ts_m: float) -> dict[tuple[str, str], RunOutput]:
    ramp = np.linspace(0.0, 1.0, 101)
    return {
        ("ats", "euler"): _output(4.44e-3 * ramp),
        ("clrrmc-ts", "euler"): _output(0.24e-3 * ramp),
        ("ats", "rk4"): _output(rk4_ats_m * ramp),
        ("clrrmc-ts", "rk4"): _output(rk4_ts_m * ramp),
    }


def test_the_rk4_sentence_states_the_measured_errors():
    text = _integrator_finding(_integrator_runs(2e-9, 1e-9))
    assert (
        "With RK4 the largest errors are 2.00e-06 mm for ats and 1.00e-06 mm for clrrmc-ts" in text
    )
    assert "negligible (each below 0.1 x the method's Euler drift)" in text


def test_rk4_is_not_called_negligible_when_it_is_not():
    # clrrmc-ts with RK4 at 0.1 mm: not below a tenth of its 0.24 mm Euler drift
    text = _integrator_finding(_integrator_runs(2e-9, 0.1e-3))
    assert "negligible" not in text
    assert "0.100 mm for clrrmc-ts" in text
    assert "not below 0.1 x the method's Euler drift for clrrmc-ts." in text


def _config(preset: str, options: dict) -> CompareConfig:
    trajectories = {"ellipse": load_trajectory("ellipse")}
    return CompareConfig(
        methods=("clrrmc-ts",),
        trajectories=trajectories,
        studies=("tau",),
        preset=preset,
        options=options,
    )


def test_the_tau_sweep_keeps_the_channels_the_users_tau_feeds_back():
    # the user switches the orientation feedback off: the sweep must not switch it on
    off = _config("default", {"clrrmc-ts": {"tau": (0.5, 0.5, math.inf), "aux": "sum"}})
    assert study_tau(off, "clrrmc-ts", 3.0) == (3.0, 3.0, math.inf)
    specs = plan_runs(off).studies["tau"]
    assert {dict(s.options)["tau"] for s in specs} == {
        (t, t, math.inf) for t in (0.1, 0.3, 1.0, 3.0)
    }
    assert {dict(s.options)["aux"] for s in specs} == {"sum"}  # other options kept
    # the slides switch it off; the user's scalar tau switches it on again in every run
    on = _config("slides", {"clrrmc-ts": {"tau": 0.5}})
    assert study_tau(on, "clrrmc-ts", 3.0) == 3.0
    # without a user tau the preset's channels still decide
    assert study_tau(_config("slides", {}), "clrrmc-ts", 3.0) == (3.0, 3.0, math.inf)


def test_shown_names_must_name_compared_trajectories():
    trajectories = {"ellipse": load_trajectory("ellipse")}
    config = CompareConfig(methods=("ats",), trajectories=trajectories)
    assert config.shown("ellipse") == "ellipse"  # a key without a shown name: itself
    with pytest.raises(ParameterError, match="shown_names must map trajectory keys"):
        CompareConfig(methods=("ats",), trajectories=trajectories, shown_names={"loop": "x"})
