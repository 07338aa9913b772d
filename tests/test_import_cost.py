"""The qpsolvers stack (qpsolvers, scipy.sparse, clarabel, OSQP, ProxSuite) takes several
times the rest of the library to import; only a qpsolvers backend needs it, so importing
the simulator, or running the default ``qp`` (DAQP called directly), must not load it."""

import subprocess
import sys

HEAVY = ("qpsolvers", "scipy.sparse", "osqp", "clarabel", "proxsuite")


def loaded_after(code: str) -> dict[str, bool]:
    """Which of :data:`HEAVY` a fresh interpreter has loaded after running ``code``."""
    probe = f"{code}\nimport sys\nprint(*(name in sys.modules for name in {HEAVY!r}))"
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, timeout=120
    )
    return dict(zip(HEAVY, (word == "True" for word in out.stdout.split()), strict=True))


def test_importing_the_simulator_does_not_load_the_qp_solvers():
    assert loaded_after("import ddwmmr.sim") == dict.fromkeys(HEAVY, False)


def test_the_default_qp_on_direct_daqp_does_not_load_qpsolvers():
    code = (
        "from ddwmmr import Robot\nfrom ddwmmr.sim import simulate\n"
        "from ddwmmr.trajectories import Ellipse\n"
        "result = simulate(Robot(), Ellipse(), 'qp', duration=0.1)\n"
        "assert len(result.timeseries['x']) > 1"
    )
    assert loaded_after(code) == dict.fromkeys(HEAVY, False)


def test_a_qpsolvers_backend_still_loads_it():
    """The probe sees the stack when it is really used (the tests above can fail)."""
    code = (
        "from ddwmmr import Robot, make_controller\nmake_controller('qp', Robot(), solver='osqp')"
    )
    loaded = loaded_after(code)
    assert loaded["qpsolvers"] and loaded["osqp"]
