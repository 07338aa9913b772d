"""Trajectories: shapes, derivatives, orientation, files (docs/theory.md, "Trajectories")."""

import math
from pathlib import Path

import numpy as np
import pytest

from ddwmmr import Ellipse, ParameterError, Rectangle, load_trajectory
from ddwmmr.qp.limits.obstacles import Circle, as_circles
from ddwmmr.trajectories import SampledTrajectory, read_csv
from ddwmmr.trajectories.files import (
    available_trajectories,
    find_obstacle_file,
    find_trajectory_file,
    is_name,
    package_folder,
)
from ddwmmr.trajectories.sampled import csv_text
from one_line import one_line


def numeric_velocity(trajectory, t, h=1e-5):
    return (trajectory.pose(t + h) - trajectory.pose(t - h)) / (2 * h)


def test_ellipse_shape_and_rotation():
    traj = Ellipse(x0=1.0, y0=-2.0, a=2.0, b=1.0, beta=math.pi / 2, T=10.0)
    np.testing.assert_allclose(traj.pose(0.0)[:2], [1.0, 0.0], atol=1e-12)  # (a, 0) rotated
    np.testing.assert_allclose(traj.pose(2.5)[:2], [0.0, -2.0], atol=1e-12)  # (0, b) rotated


def test_rectangle_corners_and_edges():
    traj = Rectangle(a=2.0, b=1.0, T=8.0)
    corners = [(2.0, 1.0), (-2.0, 1.0), (-2.0, -1.0), (2.0, -1.0)]
    for k, corner in enumerate(corners):
        np.testing.assert_allclose(traj.pose(2.0 * k)[:2], corner, atol=1e-12)
    # Mid-edge of the first side: y = b exactly and x = a cos(2 alpha) (non-uniform timing).
    pose = traj.pose(0.5)
    assert pose[1] == pytest.approx(1.0)
    assert pose[0] == pytest.approx(2.0 * math.cos(2 * (2 * math.pi * 0.5 / 8.0)))


@pytest.mark.parametrize("orientation", ["tangent", "constant"])
def test_ellipse_velocity_matches_finite_differences(orientation):
    phi = 0.3 if orientation == "constant" else 0.0  # phi is refused with "tangent"
    traj = Ellipse(x0=0.5, a=2.0, b=1.2, beta=0.4, T=17.0, orientation=orientation, phi=phi)
    for t in np.linspace(0.0, 34.0, 23):
        np.testing.assert_allclose(traj.velocity(t), numeric_velocity(traj, t), atol=1e-7)


def test_rectangle_velocity_matches_finite_differences_away_from_corners():
    traj = Rectangle(a=1.5, b=0.8, beta=-0.3, T=12.0)
    corner_times = np.arange(0, 25, 3.0)
    for t in np.linspace(0.1, 23.9, 41):
        if np.min(np.abs(corner_times - t)) < 0.05:
            continue
        np.testing.assert_allclose(traj.velocity(t), numeric_velocity(traj, t), atol=1e-6)


def test_tangent_orientation_is_the_direction_of_travel():
    for traj in (Ellipse(a=2.0, b=0.7, beta=0.5), Rectangle(a=2.0, b=0.7, beta=0.5)):
        for t in np.linspace(0.3, 39.7, 37):
            vx, vy, _ = traj.velocity(t)
            if math.hypot(vx, vy) < 1e-6:
                continue
            heading = traj.pose(t)[2]
            assert math.cos(heading) * vx + math.sin(heading) * vy == pytest.approx(
                math.hypot(vx, vy), rel=1e-9
            )


def test_ellipse_tangent_is_continuous_and_turns_once_per_period():
    traj = Ellipse(a=2.0, b=0.5)
    headings = np.array([traj.pose(t)[2] for t in np.linspace(0, traj.T, 4001)])
    assert np.max(np.abs(np.diff(headings))) < 0.02
    assert headings[-1] - headings[0] == pytest.approx(2 * math.pi)


def test_rectangle_tangent_jumps_by_quarter_turns_at_corners():
    traj = Rectangle(T=8.0)
    assert traj.pose(1.999)[2] == pytest.approx(math.pi)
    assert traj.pose(2.001)[2] == pytest.approx(1.5 * math.pi)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [({"a": 0.0}, "a"), ({"T": -1.0}, "T"), ({"N": 1}, "N"), ({"b": math.nan}, "b")],
)
def test_invalid_trajectory_parameters(kwargs, name):
    with pytest.raises(ParameterError, match=f"^{name} must"):
        Ellipse(**kwargs)


def test_shipped_toml_files_equal_the_defaults():
    assert load_trajectory("ellipse") == Ellipse()
    assert load_trajectory("rectangle") == Rectangle()


def test_sampled_trajectory_reproduces_a_smooth_path():
    # Samples of a circle of radius 1 at 1 rad/s; C1 Hermite interpolation error O(h^3).
    times = np.linspace(0.0, 2 * math.pi, 201)
    points = np.column_stack([np.cos(times), np.sin(times)])
    traj = SampledTrajectory(times, points)
    for t in np.linspace(0.05, 6.2, 17):
        pose, velocity = traj.pose(t), traj.velocity(t)
        np.testing.assert_allclose(pose[:2], [math.cos(t), math.sin(t)], atol=1e-5)
        np.testing.assert_allclose(velocity[:2], [-math.sin(t), math.cos(t)], atol=1e-3)
        # Tangent heading t + pi/2 (unwrapped) and turn rate 1 rad/s.
        assert pose[2] == pytest.approx(t + math.pi / 2, abs=1e-3)
        assert velocity[2] == pytest.approx(1.0, abs=2e-2)
        np.testing.assert_allclose(velocity, numeric_velocity(traj, t), atol=2e-4)


def test_shipped_figure_eight_csv():
    traj = load_trajectory("figure8")
    assert traj.duration == pytest.approx(60.0)
    np.testing.assert_allclose(traj.pose(0.0)[:2], traj.pose(60.0)[:2], atol=1e-9)


def test_csv_errors(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("t,x\n0,1\n1,2\n2,3\n")
    with pytest.raises(ParameterError, match="lacks column"):
        read_csv(path)
    path.write_text("t,x,y\n0,1,0\n0,2,0\n1,3,0\n")
    with pytest.raises(ParameterError, match="strictly increasing"):
        read_csv(path)
    with pytest.raises(ParameterError, match="unknown trajectory 'nope'"):
        load_trajectory("nope")


def test_csv_with_a_trailing_comma_reads_as_without_it(tmp_path):
    """A spreadsheet's export ends every line with a comma: an unnamed, empty column that is
    left out. An unnamed column with values is refused, naming the header it needs."""
    plain, trailing = tmp_path / "plain.csv", tmp_path / "trailing.csv"
    plain.write_text("t,x,y\n0,0,0\n1,1,0.5\n2,2,0\n")
    trailing.write_text("t,x,y,\n0,0,0,\n1,1,0.5,\n2,2,0,\n")
    a, b = read_csv(plain), read_csv(trailing)
    for t in (0.0, 0.7, 2.0):
        np.testing.assert_array_equal(a.pose(t), b.pose(t))
    trailing.write_text("t,x,y,\n0,0,0,7\n1,1,0.5,7\n2,2,0,7\n")
    with pytest.raises(ParameterError, match=r"blank column name over values \(column 4\); needs"):
        read_csv(trailing)


@pytest.mark.parametrize(
    ("header", "row", "shown"),
    [
        ("t x y", "0 0 0", "'t x y'"),
        ("t;x;y;phi", "0;0;0;0", "'t;x;y;phi'"),
        ("t\tx\ty", "0\t0\t0", "'t\\tx\\ty'"),
        ("t  x   y", "0  0   0", "'t x y'"),  # shown on one line, spaces collapsed
    ],
)
def test_csv_separated_by_something_else_than_commas_says_so(tmp_path, header, row, shown):
    """A header of accepted names joined by spaces, tabs or semicolons reads as one column:
    the refusal names the separator as the fault, not the columns."""
    path = tmp_path / "other.csv"
    path.write_text(f"{header}\n{row}\n1{row[1:]}\n", encoding="utf-8")
    with pytest.raises(ParameterError) as refusal:
        read_csv(path)
    assert one_line(refusal) == (
        f"traj: {path} separates its columns by something else than commas (header {shown}); "
        "needs a header line t,x,y or t,x,y,phi, comma-separated"
    )


def test_a_one_column_header_of_other_names_is_still_unknown_columns(tmp_path):
    path = tmp_path / "other.csv"
    path.write_text("time x y\n0 0 0\n", encoding="utf-8")
    with pytest.raises(ParameterError, match=r"unknown column\(s\) 'time x y' \(accepted"):
        read_csv(path)


# -- shipped files, names and paths ------------------------------------------------------
PROJECT_FOLDER = Path(__file__).resolve().parents[1] / "trajectories"


def _files(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()
    }


def test_package_data_is_identical_to_the_top_level_folder():
    shipped = _files(package_folder())
    assert shipped == _files(PROJECT_FOLDER)
    assert {"ellipse.toml", "rectangle.toml", "figure8.csv", "obstacles/ellipse_post.toml"} <= set(
        shipped
    )


def test_names_load_from_the_package_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no ./trajectories here
    monkeypatch.delenv("DDWMMR_TRAJECTORIES", raising=False)
    assert find_trajectory_file("figure8") == package_folder() / "figure8.csv"
    assert load_trajectory("figure8").duration == pytest.approx(60.0)
    assert (
        find_obstacle_file("ellipse_post") == package_folder() / "obstacles" / "ellipse_post.toml"
    )


def test_a_user_folder_comes_before_the_shipped_one(tmp_path, monkeypatch):
    (tmp_path / "ellipse.toml").write_text('shape = "ellipse"\na = 3.0\n')
    monkeypatch.setenv("DDWMMR_TRAJECTORIES", str(tmp_path))
    assert load_trajectory("ellipse").a == 3.0


@pytest.mark.parametrize(
    "value", ["../trajectories/ellipse", "..", "../../etc/passwd", "sub/figure8", ".hidden", "a/.."]
)
def test_a_name_never_resolves_outside_the_folders(value, tmp_path, monkeypatch):
    # Even when the file the name points at exists (as a .toml next to the folder).
    (tmp_path / "trajectories").mkdir()
    (tmp_path / "ellipse.toml").write_text('shape = "ellipse"\n')
    monkeypatch.chdir(tmp_path / "trajectories")
    assert not is_name(value)
    with pytest.raises(
        ParameterError, match=r"is neither a trajectory name \(.*\) nor a \.toml/\.csv path"
    ):
        load_trajectory(value)


def test_explicit_paths_still_work(tmp_path):
    path = tmp_path / "wide.toml"
    path.write_text('[trajectory]\nshape = "rectangle"\na = 3.0\nb = 1.0\n')
    assert load_trajectory(str(path)) == Rectangle(a=3.0, b=1.0, name="wide")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('shape = "ellipse"\nN = "2000"\n', "N must be a number"),
        ('shape = "ellipse"\na = "2.0"\n', "a must be a number"),
        ('shape = "ellipse"\nN = true\n', "N must be a number"),
        ('shape = "ellipse"\norientation = 1\n', "orientation must be a string"),
        ('shape = "ellipse"\nN = 1e9\n', r"N must be an integer in \[2, 1000000\]"),
        ('shape = "ellipse"\na = 1e300\n', r"a must be in \[1e-06, 1000\] m"),
        ('shape = "ellipse"\nx0 = 1e300\n', r"x0 must be in \[-1e\+06, 1e\+06\] m"),
        ('shape = "ellipse"\nspeed = 1\n', "unknown key 'speed'"),
        ('[[trajectory]]\nshape = "ellipse"\n', "must be one table"),
    ],
)
def test_toml_values_must_have_their_type_and_range(tmp_path, text, message):
    path = tmp_path / "t.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=message):
        load_trajectory(str(path))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        # keys above the [trajectory] table were ignored: the default 40 s ellipse ran
        (
            'a = 3.0\nT = 20.0\n[trajectory]\nshape = "ellipse"\n',
            "key 'a' outside [trajectory] (the keys go at the top or all under one "
            "[trajectory] table)",
        ),
        (
            '[trajectory]\nshape = "ellipse"\n[extra]\nq = 1\n',
            "table [extra] outside [trajectory]",
        ),
        ('shape = "circle"\n', "needs shape = one of ellipse, rectangle (got 'circle')"),
        # an array or a table failed "unhashable" where the shape was looked up
        (
            '[trajectory]\nshape = ["ellipse"]\n',
            "needs shape = one of ellipse, rectangle (got ['ellipse'])",
        ),
        ("shape = {a = 1}\n", "needs shape = one of ellipse, rectangle (got {'a': 1})"),
        (
            '[traj]\nshape = "ellipse"\n',
            "needs shape = one of ellipse, rectangle (no shape key at the top or in a "
            "[trajectory] table)",
        ),
        # phi was ignored with the (default) tangent orientation
        ('shape = "ellipse"\nphi = 1.0\n', 'phi is used only with orientation = "constant"'),
        (
            'shape = "ellipse"\norientation = "tangent"\nphi = 0.5\n',
            'set orientation = "constant" or drop phi',
        ),
    ],
)
def test_toml_keys_that_would_be_ignored_are_refused(tmp_path, text, message):
    path = tmp_path / "t.toml"
    path.write_text(text)
    with pytest.raises(ParameterError) as info:
        load_trajectory(str(path))
    assert str(info.value).startswith(f"traj: {path}") and message in str(info.value)
    assert "\n" not in str(info.value)


def test_a_named_file_with_an_array_shape_is_listed_and_refused_as_others(tmp_path, monkeypatch):
    # Listed by its file name as any other file in the folders (which are not read to
    # list them), and refused when loaded, as a file with an unknown shape is.
    (tmp_path / "listed.toml").write_text('shape = ["ellipse"]\n')
    monkeypatch.setenv("DDWMMR_TRAJECTORIES", str(tmp_path))
    assert "listed" in available_trajectories()
    with pytest.raises(ParameterError) as info:
        load_trajectory("listed")
    assert one_line(info) == (
        f"traj: {tmp_path / 'listed.toml'} needs shape = one of ellipse, rectangle "
        "(got ['ellipse'])"
    )


@pytest.mark.parametrize("suffix", [".CSV", ".Csv", ".TOML", ".Toml"])
def test_a_path_suffix_is_matched_in_any_case(tmp_path, monkeypatch, suffix):
    # RUN.CSV was refused as "neither a trajectory name nor a .toml/.csv path", and
    # without a folder in it was looked up as a name.
    source = PROJECT_FOLDER / ("figure8.csv" if suffix.lower() == ".csv" else "ellipse.toml")
    (tmp_path / f"RUN{suffix}").write_bytes(source.read_bytes())
    (tmp_path / f"POST{suffix}").write_bytes(
        (PROJECT_FOLDER / "obstacles" / "ellipse_post.toml").read_bytes()
    )
    monkeypatch.chdir(tmp_path)
    for given in (f"RUN{suffix}", str(tmp_path / f"RUN{suffix}")):
        assert not is_name(given)
        assert find_trajectory_file(given) == Path(given)
        loaded = load_trajectory(given)
        if suffix.lower() == ".csv":
            expected = read_csv(source)
            np.testing.assert_array_equal(loaded.pose(7.25), expected.pose(7.25))
        else:
            assert loaded == Ellipse(name="RUN")
    assert find_obstacle_file(f"POST{suffix}") == Path(f"POST{suffix}")
    assert as_circles(f"POST{suffix}") == [Circle(-0.2, 1.05, 0.3)]


def test_toml_phi_counts_with_the_constant_orientation(tmp_path):
    path = tmp_path / "fixed.toml"
    path.write_text('[trajectory]\nshape = "ellipse"\norientation = "constant"\nphi = 0.5\n')
    assert load_trajectory(str(path)) == Ellipse(orientation="constant", phi=0.5, name="fixed")
    assert load_trajectory(str(path)).pose(3.0)[2] == 0.5


def test_parametric_api_rejects_strings_and_booleans():
    message = r"^a must be a finite number in \[1e-06, 1000\] m \(got '2.0'\)"
    with pytest.raises(ParameterError, match=message):
        Ellipse(a="2.0")
    with pytest.raises(ParameterError, match=r"^N must be an integer"):
        Ellipse(N=True)


def test_csv_text_reads_back_bit_for_bit(tmp_path):
    rng = np.random.default_rng(2)
    times = np.cumsum(rng.uniform(0.01, 1.0, 40))
    for columns in (2, 3):
        points = rng.normal(0.0, 3.0, (40, columns)) / 7.0  # digits beyond short reprs
        path = tmp_path / f"samples{columns}.csv"
        path.write_text(csv_text(SampledTrajectory(times, points, name="x")))
        back = read_csv(path)
        assert back.times.tobytes() == times.tobytes()
        assert back.points.tobytes() == points.tobytes()


PHI_REFUSED = (
    'phi is used only with orientation = "constant" (the orientation here is tangent, the '
    'direction of travel); set orientation = "constant" or drop phi'
)


@pytest.mark.parametrize("shape", [Ellipse, Rectangle])
def test_phi_with_the_tangent_orientation_is_refused_as_the_files_refuse_it(shape):
    # It was ignored: the heading stayed the direction of travel.
    for kwargs in ({"phi": 0.5}, {"phi": -1e-9, "orientation": "tangent"}):
        with pytest.raises(ParameterError) as info:
            shape(**kwargs)
        text = str(info.value)
        assert text == f"{PHI_REFUSED} (got phi = {kwargs['phi']:g})"
    with pytest.raises(ParameterError) as info:
        load_trajectory(shape.name, phi=0.5)
    assert str(info.value).endswith(f": {PHI_REFUSED}")


@pytest.mark.parametrize("shape", [Ellipse, Rectangle])
def test_phi_sets_the_constant_orientation(shape):
    trajectory = shape(a=1.2, b=0.8, beta=0.3, orientation="constant", phi=0.5)
    for t in (0.0, 3.3, 17.0, 39.9):
        assert trajectory.pose(t)[2] == 0.5
        assert trajectory.velocity(t)[2] == 0.0
    poses, velocities = trajectory.sample(np.linspace(0.0, 40.0, 9))
    assert np.all(poses[:, 2] == 0.5) and np.all(velocities[:, 2] == 0.0)
    assert load_trajectory(shape.name, orientation="constant", phi=0.5).pose(3.3)[2] == 0.5


def test_the_default_phi_still_goes_with_the_tangent_orientation():
    # dataclasses.replace and a recorded run pass phi = 0 back in: that is no request.
    import dataclasses

    tangent = Ellipse(a=2.0, b=1.0, T=20.0)
    assert Ellipse(a=2.0, b=1.0, T=20.0, phi=0.0) == tangent
    slower = dataclasses.replace(tangent, T=40.0)
    assert slower.pose(10.0)[2] == pytest.approx(math.pi, abs=1e-12)  # alpha = pi/2: -x


@pytest.mark.parametrize(("name", "other"), [("ellipse", "rectangle"), ("rectangle", "ellipse")])
def test_the_shape_of_a_file_cannot_be_overridden(name, other):
    with pytest.raises(ParameterError) as info:
        load_trajectory(name, shape=other)
    text = str(info.value)
    assert "\n" not in text and "unknown key" not in text
    assert text.endswith(
        f".toml: shape cannot be overridden (got {other!r}): the file sets it to {name}; "
        "load another shape by its own name or file"
    )


def test_the_built_in_shapes_check_their_overrides_like_the_files(monkeypatch, tmp_path):
    # Without ellipse.toml in any folder the name falls back to the built-in class.
    import ddwmmr.trajectories.files as files

    monkeypatch.setattr(files, "trajectory_folders", lambda: [tmp_path])
    assert files.find_trajectory_file("ellipse") is None
    assert load_trajectory("ellipse", T=20.0) == Ellipse(T=20.0)
    cases = {
        "shape": (
            {"shape": "rectangle"},
            "traj: ellipse: shape cannot be overridden (got 'rectangle'): the name sets it to "
            "ellipse; load another shape by its own name or file",
        ),
        "unknown": (
            {"speed": 1.0},
            "traj: ellipse: unknown key 'speed' (known: x0, y0, a, b, beta, N, T, "
            "orientation, phi, name)",
        ),
        "phi": ({"phi": 0.0}, f"traj: ellipse: {PHI_REFUSED}"),
    }
    for overrides, message in cases.values():
        with pytest.raises(ParameterError) as info:
            load_trajectory("ellipse", **overrides)
        assert str(info.value) == message
