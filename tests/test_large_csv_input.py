"""A large sampled trajectory (up to the million rows allowed) is read in memory of the
order of the file, and the quick reading of plain files gives exactly what the full CSV
reader gives, refusals included."""

import math
import tracemalloc
import warnings

import numpy as np
import pytest

import ddwmmr.trajectories.sampled as sampled
from ddwmmr.errors import ParameterError
from ddwmmr.trajectories import read_csv

ROWS = 20_000


def _rows(count: int, phi: bool) -> list[str]:
    return [
        f"{i * 1e-2},{math.cos(i * 1e-4):.9f},{math.sin(i * 1e-4):.9f}"
        + (f",{i * 1e-5:.6f}" if phi else "")
        for i in range(count)
    ]


def _full_reader(path):
    """What read_csv gives without the quick reading (the csv module throughout)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(sampled, "_plain_values", lambda lines: None)
        return _outcome(path)


def _outcome(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            trajectory = read_csv(path)
        except ParameterError as exc:
            return ("refused", str(exc))
    return ("read", trajectory.name, trajectory.times.tobytes(), trajectory.points.tobytes())


def test_a_large_file_is_read_in_memory_of_the_order_of_its_size(tmp_path):
    path = tmp_path / "large.csv"
    path.write_text("# logged\nt,x,y,phi\n" + "\n".join(_rows(ROWS, phi=True)) + "\n")
    size = path.stat().st_size
    tracemalloc.start()
    try:
        trajectory = read_csv(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert trajectory.points.shape == (ROWS, 3)
    assert trajectory.times[-1] == pytest.approx((ROWS - 1) * 1e-2)
    # The csv module's dictionaries of strings took about 15 x the file's bytes (1 GB
    # for a million rows); the numbers and lines alone take under 8 x.
    assert peak < 8 * size


PLAIN = "t,x,y\n0,1.0,0.0\n1,1.5,0.5\n2,2.0,0.0\n"


@pytest.mark.parametrize(
    "text",
    [
        PLAIN,
        PLAIN.replace("\n", "\r\n"),
        "# comment\n" + PLAIN + "# end\n",
        "t,x,y,phi\n0,1,0,3.1\n1,1.5,0.5,-3.1\n2,2,0,3.0\n",
        "t,x,y\n0, 1.0 ,0\n1,+1.5e0,0.5\n2,2,0\n",  # blanks around a number, a sign
        "t,x,y\n" + "\n".join(_rows(500, phi=False)) + "\n",
        # refused alike, each by the full reader's own message
        "t,x,y\n0,1,0\n1,,0\n2,2,0\n",
        "t,x,y\n0,1,0\n1,1_0,0\n2,2,0\n",
        "t,x,y\n0,1,0\n1,\u00a01,0\n2,2,0\n",
        "t,x,y\n0,1,0\n1,1,0,9\n2,2,0\n",
        "t,x,y\n0,1,0\n1,1\n2,2,0\n",
        "t,x,y\n0,1,0\n\n1,1,0\n2,2,0\n",
        't,x,y\n0,1,0\n"1",1,0\n2,2,0\n',
        "t,x,y\n0,1,0\n1,nan,0\n2,2,0\n",
        "t,x,y\n0,1,0\n0,1,0\n2,2,0\n",
        "t,x,y\n0,1,0\n1,0x1,0\n2,2,0\n",
        "t,x,y\n0,1,0\n1,1,0\n",
        "t,x,y\n",
        "t,x,y,\n0,1,0,\n1,1,0,\n2,2,0,\n",
        "t,y,x\n0,1,0\n1,1,0\n2,2,0\n",
        "t,x,y\n0,1,0\n1," + "1" * 140_000 + ",0\n2,2,0\n",
    ],
)
def test_the_quick_reading_gives_what_the_full_reader_gives(tmp_path, text):
    path = tmp_path / "samples.csv"
    path.write_bytes(text.encode())
    assert _outcome(path) == _full_reader(path)


def test_the_quick_reading_takes_plain_files_only():
    assert sampled._plain_values(["t,x,y", "0,1,0", "1,2,0"]).tolist() == [[0, 1, 0], [1, 2, 0]]
    for lines in (["t,x,y"], ["x,y,t", "0,1,0"], ["t,x,y", "0,1"], ["t,x,y", "0,1_0,0"]):
        assert sampled._plain_values(lines) is None
    assert np.array_equal(
        sampled._plain_values(["t,x,y,phi", "0,1,2,3"]), np.array([[0.0, 1.0, 2.0, 3.0]])
    )
