"""The compare advice names a method's runs that did not track once, on the first line
naming the method; later lines naming it refer back to that line."""

from __future__ import annotations

import math

from ddwmmr.reports.compare.advice import Profile, recommendations

VERDICT = '(docs/cli.md, "Verdict")'
QP_RUNS = "`qp` on the rectangle (thesis plant)"
ATS_RUNS = "`ats` on the rectangle (kinematic and thesis plants)"


def _profile(method: str, score_m: float, untracked, *, open_loop: bool = False) -> Profile:
    return Profile(
        method=method,
        scores={"ellipse": score_m, "rectangle": 2 * score_m},
        step_us=10.0,
        settle_trajectory="ellipse",
        settle_s=math.nan if open_loop else 1.5,
        open_loop=open_loop,
        stability_floor=None if open_loop else 1.25,
        stability_violations=0,
        min_stability=2.0,
        singularity={"ellipse": ("away", math.nan), "rectangle": ("away", math.nan)},
        min_cos_th1=0.5,
        untracked=tuple(untracked),
    )


def _lines() -> list[str]:
    qp = _profile("qp", 0.003, [("rectangle", "thesis")])
    ats = _profile("ats", 0.04, [("rectangle", None), ("rectangle", "thesis")], open_loop=True)
    return recommendations([qp, ats])


def test_each_caveat_is_written_once_and_referred_back_to():
    lines = _lines()
    text = "\n".join(lines)
    assert text.count(QP_RUNS) == 1 and text.count(ATS_RUNS) == 1
    best, smooth, corners, fastest, stability, singularity, blind = lines
    assert best.endswith(f" Did not track {VERDICT}: {QP_RUNS}.")
    for line in (smooth, corners, fastest, stability):
        assert line.endswith(" Did not track: `qp` (see above).")
    assert singularity.endswith(f" Did not track {VERDICT}: {ATS_RUNS}; `qp` (see above).")
    assert blind.endswith(" Did not track: `ats` (see above).")


def test_a_line_on_its_own_names_every_runs():
    """Without the advice's earlier lines (a caller of one line builder) nothing is
    referred back to."""
    from ddwmmr.reports.compare.advice import _singularity_line

    qp = _profile("qp", 0.003, [("rectangle", "thesis")])
    assert _singularity_line([qp]).endswith(f" Did not track {VERDICT}: {QP_RUNS}.")
