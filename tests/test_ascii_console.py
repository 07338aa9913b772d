"""A tool on an ASCII console (``PYTHONIOENCODING=ascii``, ``LANG=C`` on an old system):
a trajectory name or an output folder outside ASCII is printed with ``?`` for what the
console cannot show, and the run ends with status 0, not a UnicodeEncodeError traceback
after its output was written."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def _track_ovale(folder: Path, out: Path, env: dict[str, str]) -> subprocess.CompletedProcess:
    """``track`` with ``pi`` on an ellipse named "ovale \u00e9" into ``out``, in ``env``."""
    trajectory = folder / "ovale.toml"
    trajectory.write_text('shape = "ellipse"\nname = "ovale \u00e9"\n', encoding="utf-8")
    command = ["-m", "ddwmmr.track", "--method", "pi", "--traj", str(trajectory)]
    command += ["--duration", "0.5", "--no-plots", "--out", str(out)]
    return subprocess.run(
        [sys.executable, *command],
        capture_output=True,
        env={**env, "MPLBACKEND": "Agg"},
        timeout=120,
    )


def test_track_prints_a_non_ascii_name_and_folder_on_an_ascii_console(tmp_path: Path) -> None:
    out = tmp_path / "sortie \u00fc"
    done = _track_ovale(tmp_path, out, {**os.environ, "PYTHONIOENCODING": "ascii"})
    assert done.returncode == 0, done.stderr.decode("ascii", "replace")
    stdout = done.stdout.decode("ascii")
    assert "pi on ovale ? (kinematic plant)" in stdout
    assert f"wrote {tmp_path / 'sortie ?'}/" in stdout
    assert "Traceback" not in done.stderr.decode("ascii", "replace")
    assert (out / "summary.json").is_file()


def test_track_on_an_ascii_locale_without_utf8_mode_keeps_a_file_names_byte(
    tmp_path: Path,
) -> None:
    """``LC_ALL=POSIX PYTHONUTF8=0``: stdout is ASCII with ``surrogateescape``, which writes
    a file name's undecodable byte back but raises on any other non-ASCII character."""
    out = tmp_path / os.fsdecode(b"sortie\xe9")  # a byte that is not UTF-8
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONIOENCODING", "LANG")}
    env.update(LC_ALL="POSIX", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0")
    done = _track_ovale(tmp_path, out, env)
    assert done.returncode == 0, done.stderr.decode("ascii", "replace")
    assert b"pi on ovale ? (kinematic plant)" in done.stdout
    assert b"wrote " + os.fsencode(tmp_path) + b"/sortie\xe9/" in done.stdout
    assert (out / "summary.json").is_file()
