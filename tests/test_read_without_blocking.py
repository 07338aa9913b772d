"""Input files are read without blocking and within the size cap even where ``os.stat``
cannot tell: /proc/kmsg (a regular file of size 0 to stat) waited, as root, for the
kernel's next message; a FIFO put in a checked file's place blocked the read."""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Callable
from pathlib import Path

import pytest

from ddwmmr import errors
from ddwmmr.errors import ParameterError, read_text_file

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="FIFOs and /proc are POSIX")


def returns_without_blocking(fifo: Path, read: Callable[[], object]) -> bool:
    """Whether ``read()``, run in a thread, returns within 10 s; a read left waiting on
    ``fifo`` for a writer (the old code) is freed by opening it for writing."""
    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(timeout=10)
    blocked = reader.is_alive()
    if blocked:
        with open(fifo, "wb"):
            pass
        reader.join(timeout=10)
    return not blocked


def test_a_fifo_taken_for_a_regular_file_does_not_block(tmp_path, monkeypatch):
    fifo = tmp_path / "robot.toml"
    os.mkfifo(fifo)
    monkeypatch.setattr(errors, "file_kind", lambda mode: None)  # the check passed it
    result: list[object] = []
    assert returns_without_blocking(fifo, lambda: result.append(read_text_file(fifo, "robot")))
    assert result == [""]


@pytest.mark.skipif(not Path("/proc/self/maps").is_file(), reason="needs Linux's /proc")
def test_a_file_of_size_0_to_stat_is_held_to_the_cap_by_what_it_gives(monkeypatch):
    monkeypatch.setattr(errors, "MAX_INPUT_BYTES", 10)
    with pytest.raises(ParameterError) as info:
        read_text_file("/proc/self/maps", "traj")
    assert str(info.value) == (
        "traj: /proc/self/maps is too large (more than 10 bytes read, at most 10)"
    )


def test_a_plan_that_is_a_fifo_or_proc_file_is_refused_without_waiting(tmp_path):
    """Guess.load (the mpc's plan= option) opened the file with numpy: a FIFO waited for
    a writer forever, as /proc/kmsg did as root."""
    from ddwmmr.mpc.min_time import Guess

    fifo = tmp_path / "plan.npz"
    os.mkfifo(fifo)
    result: list[str] = []

    def load() -> None:
        try:
            Guess.load(fifo)
        except ParameterError as error:
            result.append(str(error))

    assert returns_without_blocking(fifo, load)
    assert result == [f"plan: {fifo} is not a regular file (a FIFO)"]
