"""The tools show the library's warnings as one line each, not in Python's default form
(source path, line number and a line of library code, which reads like a traceback)."""

from __future__ import annotations

import os
import subprocess
import sys


def test_a_tool_prints_the_librarys_warning_as_one_line(tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "ddwmmr.track", "--method", "qp", "--traj", "ellipse",
         "--payload", "5", "--duration", "0.2", "--no-plots", "--no-progress",
         "--out", str(tmp_path / "run")],
        capture_output=True, text=True, timeout=300, env={**os.environ, "MPLBACKEND": "Agg"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines() == [
        "warning: stability_min: the start pose has S = 1.056, below the qp's stability "
        "floor stability_min = 1.25, which the run starts by breaking; lower the floor "
        "(stability_min=1.05) or start where S >= 1.25"
    ]


SCRIPT = """
import warnings
from ddwmmr.cli.common import one_line_warnings
from ddwmmr.model import kinematics
warnings.simplefilter("always")
with one_line_warnings():
    warnings.warn_explicit("their\\nmessage", UserWarning, "/elsewhere/lib.py", 7)
    warnings.warn_explicit("ours\\n  split", UserWarning, kinematics.__file__, 1)
    warnings.warn_explicit("numeric", RuntimeWarning, kinematics.__file__, 2)
warnings.warn_explicit("after", UserWarning, kinematics.__file__, 1)
"""


def test_a_warning_from_outside_the_library_keeps_pythons_form():
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120
    )
    lines = done.stderr.splitlines()
    assert lines[:3] == [
        "/elsewhere/lib.py:7: UserWarning: their",
        "message",
        "warning: ours split",
    ]
    assert lines[3].endswith("kinematics.py:2: RuntimeWarning: numeric")  # where it arose
    assert lines[-2].endswith("kinematics.py:1: UserWarning: after")  # restored after
