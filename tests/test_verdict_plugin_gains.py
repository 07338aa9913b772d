"""The verdict of a plug-in method that did not converge asks to check what that method
has: ``p-only`` (tests/plugins) takes a ``gain``, not ``tau``, and the verdict said
"check tau, dt and the integrator"."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from ddwmmr.sim.verdict import _convergence_checks

ROOT = Path(__file__).resolve().parents[1]


def test_a_plug_in_without_tau_is_asked_for_its_own_options(tmp_path: Path) -> None:
    env = {
        **os.environ,
        "DDWMMR_PLUGINS": "p_only",
        "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(ROOT / "tests" / "plugins")]),
        "MPLBACKEND": "Agg",
    }
    command = ["-m", "ddwmmr.track", "--method", "p-only", "--traj", "ellipse"]
    command += ["--duration", "10", "--no-plots", "--out", str(tmp_path / "run")]
    done = subprocess.run(
        [sys.executable, *command], capture_output=True, text=True, env=env, timeout=300
    )
    assert done.returncode == 0, done.stderr
    verdict = json.loads((tmp_path / "run" / "summary.json").read_text())["verdict"]
    assert verdict.startswith("did not track")
    assert "check its options (gain), dt and the integrator" in verdict
    assert "check tau" not in verdict


def test_the_built_in_methods_keep_their_words() -> None:
    """tau for the closed-loop methods and the open-loop ones (whose runs name them),
    the mpc's weights, and tau for a method no registry knows (a summary from elsewhere)."""
    for method in ("pi", "ats", "ap", "clrrmc-ts", "clrrmc-cs", "qp", "not-a-method"):
        assert _convergence_checks({"method": method}) == "tau, dt and the integrator"
    assert _convergence_checks({"method": "mpc", "integrator": None}) == (
        "position_weight, horizon and dt"
    )
