"""``write_summary(path, **extra)`` took an extra key the summary has already and wrote
it over the run's own: ``verdict="x"`` gave a summary.json saying "x" for a run that
tracked (and ``--rerun`` reads that file)."""

from __future__ import annotations

import json

import pytest

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.errors import ParameterError


def test_an_extra_key_may_not_replace_the_runs_own(tmp_path):
    result = simulate(Robot(), Ellipse(), "ats", duration=0.1)
    path = tmp_path / "summary.json"
    for key in ("verdict", "rms_position_error_m", "steps"):
        with pytest.raises(ParameterError) as info:
            result.write_summary(path, **{key: "x"})
        assert str(info.value) == (
            f"summary: the extra key '{key}' is one of the run's own summary keys; give it "
            "another name"
        )
        assert not path.exists()
    result.write_summary(path, run={"method": "ats"}, note="mine")
    written = json.loads(path.read_text())
    assert written["run"] == {"method": "ats"} and written["note"] == "mine"
    assert written["verdict"] == result.summary["verdict"]
