"""At most MAX_OBSTACLES (1000) circles per run: an obstacle file with more ``[[obstacle]]``
tables, or a longer ``obstacles=`` list, is refused in one line naming ``obstacles``, the
count and the allowed range, from the command line (status 2), the API and the window
alike. Each circle is one more row of the qp's problem at every step: 100,000 far-away
circles took seconds per step and were not refused. Up to the limit nothing changes."""

import re
from pathlib import Path

import pytest

from ddwmmr import Robot, make_controller
from ddwmmr.cli.track import main as track
from ddwmmr.errors import MAX_OBSTACLES, ParameterError
from ddwmmr.gui import Settings
from ddwmmr.gui.settings import check_settings
from ddwmmr.qp.limits.obstacles import Circle, load_obstacles

RANGE = f"(1 to {MAX_OBSTACLES}; each is checked at every control step)"


def refusal_before_parsing(path: Path) -> str:
    """``load_obstacles(path)``'s refusal, with the TOML parser made to fail if it runs."""
    import tomllib

    def not_parsed(*args, **kwargs):
        raise AssertionError("parsed before the count was checked")

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(tomllib, "loads", not_parsed)
        with pytest.raises(ParameterError) as info:
            load_obstacles(path)
    return str(info.value)


def far_circles(count: int) -> list[tuple[float, float, float]]:
    """``count`` posts of 0.1 m, 0.5 m apart, 100 m from the ellipse: never in the way."""
    return [(100.0 + 0.5 * (i % 50), 100.0 + 0.5 * (i // 50), 0.1) for i in range(count)]


def obstacle_file(folder: Path, count: int) -> Path:
    path = folder / f"posts_{count}.toml"
    tables = (f"[[obstacle]]\nx = {x}\ny = {y}\nradius = {r}\n" for x, y, r in far_circles(count))
    path.write_text("\n".join(tables), encoding="utf-8")
    return path


def refused(path: Path) -> str:
    """The start of the refusal of ``path`` with one table too many, as a pattern."""
    return (
        f"^obstacles: {re.escape(str(path))} has {MAX_OBSTACLES + 1} obstacles, more than allowed"
    )


def test_a_file_at_the_limit_is_read_whole(tmp_path):
    circles = load_obstacles(obstacle_file(tmp_path, MAX_OBSTACLES))
    assert len(circles) == MAX_OBSTACLES
    assert circles[-1] == Circle(124.5, 109.5, 0.1)


def test_a_file_over_the_limit_is_refused_naming_the_count(tmp_path):
    path = obstacle_file(tmp_path, MAX_OBSTACLES + 1)
    with pytest.raises(ParameterError) as info:
        load_obstacles(path)
    too_many = f"has {MAX_OBSTACLES + 1} obstacles, more than allowed {RANGE}"
    assert str(info.value) == f"obstacles: {path} {too_many}"


def test_a_file_far_over_the_limit_is_refused_before_it_is_parsed(tmp_path):
    """A file of 100,000 tables was parsed (seconds) before its count was refused: its
    [[obstacle]] headers are counted in the text first. Headers spelt with quotes, spaces
    and a comment count too; a file the headers' count admits is parsed as before."""
    path = tmp_path / "many.toml"
    headers = ["[[obstacle]]", '[[ "obstacle" ]]  # quoted', "  [['obstacle']]"]
    tables = (f"{headers[i % 3]}\nx = {i}\ny = 0\nradius = 0.1\n" for i in range(100_000))
    path.write_text("\n".join(tables), encoding="utf-8")

    refusal = refusal_before_parsing(path)
    assert refusal == f"obstacles: {path} has 100000 obstacles, more than allowed {RANGE}"
    three = tmp_path / "three.toml"
    three.write_text("\n".join(f"{h}\nx = 1\ny = 0\nradius = 0.1\n" for h in headers))
    assert len(load_obstacles(three)) == 3


def inline_file(folder: Path, count: int) -> Path:
    """``count`` circles as one array of inline tables, with comments holding ``{``."""
    path = folder / f"inline_{count}.toml"
    rows = (
        f"  {{x = {x}, y = {y}, radius = {r}}},  # {{ post {{\n" for x, y, r in far_circles(count)
    )
    path.write_text("# posts {x, y, radius}\nobstacle = [\n" + "".join(rows) + "]\n")
    return path


def test_inline_tables_far_over_the_limit_are_refused_before_they_are_parsed(tmp_path):
    """``obstacle = [{...}, ...]`` was parsed (seconds for 100,000) before its count was
    refused: its inline tables are counted by their "{" outside comments first. Exact for
    a file that loads: one at the limit is read whole, one over it refused by count."""
    many = inline_file(tmp_path, 100_000)
    refusal = refusal_before_parsing(many)
    assert refusal == f"obstacles: {many} has 100000 obstacles, more than allowed {RANGE}"
    circles = load_obstacles(inline_file(tmp_path, MAX_OBSTACLES))
    assert len(circles) == MAX_OBSTACLES and circles[-1] == Circle(124.5, 109.5, 0.1)
    over = inline_file(tmp_path, MAX_OBSTACLES + 1)
    with pytest.raises(ParameterError, match=refused(over)):
        load_obstacles(over)


def test_a_crlf_file_over_the_limit_is_refused_before_it_is_parsed(tmp_path):
    """Lines ended by CRLF (a Windows editor's) are counted as LF ones are: the headers'
    count refuses the file before the parser sees it; below the limit it parses."""
    path = tmp_path / "crlf.toml"
    tables = "".join(
        f"[[obstacle]]{' # post' * (i % 2)}\r\nx = {x}\r\ny = {y}\r\nradius = {r}\r\n"
        for i, (x, y, r) in enumerate(far_circles(MAX_OBSTACLES + 1))
    )
    path.write_bytes(tables.encode())

    too_many = f"has {MAX_OBSTACLES + 1} obstacles, more than allowed {RANGE}"
    assert refusal_before_parsing(path) == f"obstacles: {path} {too_many}"
    two = tmp_path / "two.toml"
    two.write_bytes(b"[[obstacle]]\r\nx = 1\r\ny = 0\r\nradius = 0.1\r\n" * 2)
    assert len(load_obstacles(two)) == 2


def test_track_refuses_it_in_one_line_with_status_2(tmp_path, capsys):
    path = obstacle_file(tmp_path, 3000)
    args = ["--method", "qp", "--traj", "ellipse", "--obstacles", str(path)]
    assert track([*args, "--duration", "0.1", "--out", str(tmp_path / "run")]) == 2
    assert capsys.readouterr().err == (
        f"error: obstacles: {path} has 3000 obstacles, more than allowed {RANGE}\n"
    )
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("method", ["qp", "mpc"])
def test_the_api_refuses_a_file_or_a_list_over_the_limit(tmp_path, method):
    path = obstacle_file(tmp_path, MAX_OBSTACLES + 1)
    with pytest.raises(ParameterError, match=refused(path)):
        make_controller(method, Robot(), obstacles=str(path))
    with pytest.raises(ParameterError) as info:
        make_controller(method, Robot(), obstacles=far_circles(MAX_OBSTACLES + 1))
    assert str(info.value) == (
        f"obstacles: {MAX_OBSTACLES + 1} obstacles, more than allowed (0 to {MAX_OBSTACLES}; "
        "each is checked at every control step)"
    )


def test_a_list_at_the_limit_is_taken():
    # The qp only: the mpc builds its problem with every circle (seconds at the limit).
    controller = make_controller("qp", Robot(), obstacles=far_circles(MAX_OBSTACLES))
    assert len(controller.obstacles) == MAX_OBSTACLES


def test_the_window_refuses_it_as_a_method_option(tmp_path):
    path = obstacle_file(tmp_path, MAX_OBSTACLES + 1)
    settings = Settings(methods=("qp", None), options=({"obstacles": str(path)}, {}))
    with pytest.raises(ParameterError, match=refused(path)):
        check_settings(settings)
