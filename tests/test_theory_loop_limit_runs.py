"""docs/theory.md, section 6, says where the closed loop stops tracking on the ellipse as
K dt grows (K = 1/tau, the default tau = 0.5 s, dt varied): the runs it quotes give its
verdicts and its RMS errors. None of these runs is chaotic (each contracts or diverges
plainly), unlike the dt = 2 s run, whose number the page dates instead."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from ddwmmr import Ellipse, Robot, simulate

THEORY = Path(__file__).resolve().parents[1] / "docs" / "theory.md"
TAU_S = 0.5  # the default: K = 2 1/s


def _sentence() -> str:
    text = re.sub(r"\s+", " ", THEORY.read_text(encoding="utf-8"))
    start = text.index("On the ellipse under RK4 the `qp` tracks at `K dt = 1.8`")
    return text[start : text.index("At dt = 2 s", start)]


def _run(method: str, k_dt: float, integrator: str) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the K dt warning, which these runs are about
        return simulate(Robot(), Ellipse(), method, dt=k_dt * TAU_S, integrator=integrator).summary


@pytest.mark.parametrize(
    ("method", "k_dt", "integrator", "tracked", "quoted"),
    [
        ("qp", 1.8, "rk4", True, "(18.8 mm RMS)"),
        ("qp", 2.0, "rk4", False, None),
        ("clrrmc-ts", 2.2, "rk4", True, None),
        ("clrrmc-ts", 2.3, "rk4", False, None),
        ("clrrmc-ts", 1.8, "euler", False, "(395 mm RMS)"),
        ("clrrmc-ts", 1.7, "euler", True, "(19.5 mm)"),
    ],
)
def test_the_quoted_run(method, k_dt, integrator, tracked, quoted) -> None:
    summary = _run(method, k_dt, integrator)
    assert (summary["verdict"] == "tracked") is tracked, summary["verdict"]
    if quoted:
        assert quoted in _sentence()
        number = float(re.search(r"[\d.]+", quoted)[0])
        digits = len(quoted.split(".")[1].split()[0]) if "." in quoted else 0
        assert round(1000 * summary["rms_position_error_m"], digits) == number
