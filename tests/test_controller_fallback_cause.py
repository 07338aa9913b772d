"""A controller of one's own that reports fallbacks (``StepInfo.fallback``) on most of a
run gets them named as the likely cause, as the qp's and the mpc's are
(docs/cli.md, "Verdict")."""

from __future__ import annotations

from ddwmmr.sim.verdict import verdict

FAILED = {
    "final_position_error_m": 1.0,
    "rms_position_error_m": 1.0,
    "max_position_error_m": 1.0,
    "initial_offset_m": 0.0,
}


def _cause(summary: dict) -> str:
    return verdict(summary)["verdict"].split("; likely cause: ", 1)[1]


def test_fallbacks_of_a_plugin_controller_are_the_cause():
    summary = {**FAILED, "method": "fb85", "steps": 500, "fallback_steps": 449}
    assert _cause(summary).startswith(
        "the controller fb85 used its safe fallback on 449 of 500 steps"
    )


def test_a_few_fallbacks_are_not_the_cause():
    summary = {**FAILED, "method": "fb85", "steps": 500, "fallback_steps": 250}
    assert "safe fallback" not in _cause(summary)


def test_the_qp_keeps_its_own_fallback_cause():
    summary = {**FAILED, "method": "qp", "steps": 500, "fallback_steps": 400, "qp_fallbacks": 400}
    assert _cause(summary).startswith("the qp found no solution on 400 of 500 steps")
