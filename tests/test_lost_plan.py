"""A bounds run's best-known trajectory lost from its cache (deleted, or damaged) gets a
message saying how to get it back, for plan=DIR and for the file itself."""

from __future__ import annotations

import json

import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.mpc.min_time import Guess, plan_path


def _record(cache, kept: bool) -> None:
    cache.mkdir(parents=True)
    record = {"replay_ok": kept, "start": "pattern-3" if kept else None, "best_known_s": 13.2}
    (cache / "scenario-003-best.json").write_text(json.dumps(record))


def test_a_deleted_trajectory_says_to_search_again(tmp_path):
    _record(tmp_path / "run" / "cache", kept=True)
    with pytest.raises(ParameterError) as info:
        plan_path(tmp_path / "run", 3)
    message = str(info.value)
    assert "is missing, though its search kept one: the trajectory of that bounds run is lost" in (
        message
    )
    assert f"--out {tmp_path / 'run'} --scenarios 3 again" in message
    assert "\n" not in message


def test_a_search_that_kept_nothing_still_says_so(tmp_path):
    _record(tmp_path / "run" / "cache", kept=False)
    with pytest.raises(ParameterError, match="found no trajectory for scenario 3"):
        plan_path(tmp_path / "run", 3)


def test_a_damaged_trajectory_says_to_search_again(tmp_path):
    cache = tmp_path / "run" / "cache"
    _record(cache, kept=True)
    (cache / "scenario-003-best.npz").write_bytes(b"PK\x03\x04xx")
    with pytest.raises(ParameterError) as info:
        Guess.load(plan_path(tmp_path / "run", 3))
    message = str(info.value)
    assert message.startswith(f"plan {cache / 'scenario-003-best.npz'} must be a .npz with")
    assert message.endswith("without --lower-only: it searches the scenario again")


def test_a_damaged_file_elsewhere_gets_no_bounds_advice(tmp_path):
    path = tmp_path / "mine.npz"
    path.write_bytes(b"PK\x03\x04xx")
    with pytest.raises(ParameterError) as info:
        Guess.load(path)
    assert "bounds" not in str(info.value)


def test_a_damaged_file_of_another_name_in_a_cache_folder_is_one_line(tmp_path):
    """A user's own plan file in a folder named cache (not a bounds run's name): the
    damaged-archive line, without bounds advice and without a traceback."""
    cache = tmp_path / "cache"
    cache.mkdir()
    (cache / "best.json").write_text(json.dumps({"replay_ok": True, "start": "x"}))
    (cache / "best.npz").write_bytes(b"PK\x03\x04xx")
    with pytest.raises(ParameterError) as info:
        Guess.load(cache / "best.npz")
    assert "bounds" not in str(info.value)


@pytest.mark.parametrize(
    ("name", "reason"), [("a" * 10_000, "File name too long"), ("a\x00b", "invalid file name")]
)
def test_a_plan_name_the_system_cannot_look_up_is_named_as_the_plan(name, reason):
    """A 10,000-character plan path raised the OS's own error (no `plan`, a traceback at
    the API) from the folder check before the file was read."""
    with pytest.raises(ParameterError) as info:
        Guess.load(name)
    message = str(info.value)
    assert message.startswith("plan: ") and reason in message
