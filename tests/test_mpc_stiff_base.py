"""The mpc's force model on a base damped far beyond the thesis's: c1 = 1e12 N s/m (a
time constant of picoseconds) ended in a traceback from python-control's Riccati solver
(c1 = 1e50: "array must not contain infs or NaNs"); now one line naming the damping."""

from __future__ import annotations

import pytest

from ddwmmr.cli.track import main as track


@pytest.mark.parametrize(("name", "value"), [("c1", "1e12"), ("c1", "1e300"), ("c2", "1e300")])
def test_a_damping_the_force_model_cannot_resolve_is_one_line(tmp_path, capsys, name, value):
    out = tmp_path / "run"
    argv = ["--method", "mpc", "--traj", "ellipse", "--plant", "thesis", "--duration", "0.2"]
    argv += ["--plant-option", f"{name}={value}", "--option", "model=thesis"]
    assert track([*argv, "--no-progress", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: mpc: the force model cannot plan for this base: ")
    assert f"{name} = {float(value):g} " in err and "model='kinematic'" in err
    assert err.count("\n") == 1
    assert not out.exists()
