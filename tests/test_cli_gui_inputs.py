"""``python -m ddwmmr.gui`` bad input: the snapshot path, --force, --dpi, --export and the
geometry caps are checked before the window is built or anything runs; one line on stderr,
exit status 2, the user's files untouched and nothing created."""

import errno
import os
from pathlib import Path

import pytest
from PIL import Image

import ddwmmr.gui.app as gui_app
import ddwmmr.gui.settings as gui_settings
from ddwmmr.cli import gui as cli
from ddwmmr.cli.gui import DPI_RANGE, check_dpi, main
from ddwmmr.errors import ParameterError
from ddwmmr.gui.paths import SNAPSHOT_FORMATS, check_export_root, check_snapshot_path
from in_process import call_main

#: A fast real run: a fifth of a second, a 160 x 100 px snapshot.
FAST = ["--duration", "0.2", "--dpi", "10"]
USER_TEXT = b"USER\n"


@pytest.fixture
def no_window(monkeypatch):
    """Fail the test if the window is built (a refused input must not get that far)."""

    def built(*args, **kwargs):
        raise AssertionError("the window was built: the input was not checked up front")

    monkeypatch.setattr(gui_app, "App", built)


def files_below(folder):
    return sorted(str(p.relative_to(folder)) for p in Path(folder).rglob("*"))


def refused(argv, capsys, *fragments):
    """Run ``argv``: exit 2 and one stderr line holding every fragment; return the line."""
    status, out, err = call_main(main, argv, capsys)
    assert status == 2, err
    # "error: ..." from the tool, "python -m ddwmmr.gui: error: ..." from argparse
    assert err.count("\n") == 1 and "error: " in err, err
    assert "Traceback" not in err and out == ""
    for fragment in fragments:
        assert fragment in err, err
    return err


# -- an existing file is never replaced without --force ---------------------------------
@pytest.mark.parametrize("name", ["user_notes.txt", "user_pic.png", "USER.PDF"])
def test_an_existing_file_is_refused_and_kept(name, tmp_path, capsys, no_window):
    user = tmp_path / name
    user.write_bytes(USER_TEXT)
    refused(["--snapshot", str(user), *FAST], capsys, f"snapshot: {user}")
    assert user.read_bytes() == USER_TEXT
    assert files_below(tmp_path) == [name]


def test_an_existing_image_file_names_force(tmp_path, capsys, no_window):
    user = tmp_path / "user_pic.png"
    user.write_bytes(USER_TEXT)
    refused(["--snapshot", str(user), *FAST], capsys, "exists", "--force")
    assert user.read_bytes() == USER_TEXT


def test_force_does_not_allow_a_suffix_that_is_not_an_image(tmp_path, capsys, no_window):
    user = tmp_path / "user_notes.txt"
    user.write_bytes(USER_TEXT)
    refused(["--snapshot", str(user), "--force", *FAST], capsys, "snapshot:", ".txt")
    assert user.read_bytes() == USER_TEXT


def test_force_replaces_an_existing_image_file(tmp_path, capsys):
    user = tmp_path / "user_pic.png"
    user.write_bytes(USER_TEXT)
    status, out, err = call_main(main, ["--snapshot", str(user), "--force", *FAST], capsys)
    assert status == 0, err
    assert out == f"wrote {user}\n"
    with Image.open(user) as image:
        assert image.format == "PNG" and image.size == (160, 100)
    assert files_below(tmp_path) == ["user_pic.png"]  # no temporary file left


@pytest.mark.parametrize("name", ["shot.png", "shot.svg", "shot.pdf", "shot.eps"])
def test_a_rerun_replaces_its_own_snapshot(name, tmp_path, capsys):
    """A file a snapshot wrote carries a mark in its metadata: the rerun may replace it."""
    path = tmp_path / name
    assert call_main(main, ["--snapshot", str(path), *FAST], capsys)[0] == 0
    first = path.read_bytes()
    status, out, err = call_main(main, ["--snapshot", str(path), *FAST, "--method", "ats"], capsys)
    assert status == 0, err
    assert out == f"wrote {path}\n"
    assert path.read_bytes() != first and files_below(tmp_path) == [name]


def test_the_snapshot_mark_is_in_the_png_metadata_and_nowhere_else(tmp_path, capsys):
    from ddwmmr.gui.paths import SNAPSHOT_MARK, written_by_snapshot

    path = tmp_path / "shot.png"
    assert call_main(main, ["--snapshot", str(path), *FAST], capsys)[0] == 0
    with Image.open(path) as image:
        assert image.info["Software"] == SNAPSHOT_MARK
    assert written_by_snapshot(path, "png")
    # a user's PNG, even one naming the mark outside a PNG, or a JPEG snapshot: not ours
    user = tmp_path / "user.png"
    Image.new("RGB", (4, 4)).save(user, pnginfo=None)
    assert not written_by_snapshot(user, "png")
    text = tmp_path / "notes.png"
    text.write_text(SNAPSHOT_MARK)
    assert not written_by_snapshot(text, "png")
    jpeg = tmp_path / "shot.jpg"
    assert call_main(main, ["--snapshot", str(jpeg), *FAST], capsys)[0] == 0
    refused(["--snapshot", str(jpeg), *FAST], capsys, "a .jpg file cannot show", "--force")


def test_the_suffix_picks_the_format_and_missing_folders_are_made(tmp_path, capsys):
    path = tmp_path / "new" / "sub" / "gui.SVG"
    status, _, err = call_main(main, ["--snapshot", str(path), *FAST], capsys)
    assert status == 0, err
    assert path.read_bytes().lstrip().startswith(b"<?xml") and b"<svg" in path.read_bytes()
    assert files_below(tmp_path) == ["new", "new/sub", "new/sub/gui.SVG"]


def test_a_file_that_appears_during_the_run_is_kept(tmp_path, capsys, monkeypatch):
    user = tmp_path / "shot.png"
    simulate = gui_settings.simulate

    def user_saves_a_file_meanwhile(*args, **kwargs):
        if not user.exists():
            user.write_bytes(USER_TEXT)
        return simulate(*args, **kwargs)

    monkeypatch.setattr(gui_settings, "simulate", user_saves_a_file_meanwhile)
    refused(["--snapshot", str(user), *FAST], capsys, f"snapshot: {user} exists", "--force")
    assert user.read_bytes() == USER_TEXT
    assert files_below(tmp_path) == ["shot.png"]


def test_a_failed_write_names_the_snapshot_and_leaves_nothing(tmp_path, capsys, monkeypatch):
    path = tmp_path / "made" / "shot.png"

    def disk_full(target, data):
        Path(target).parent.mkdir(parents=True, exist_ok=True)  # as write_atomic does
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(target.parent / ".x.tmp"))

    monkeypatch.setattr(cli, "write_atomic", disk_full)
    status, _, err = call_main(main, ["--snapshot", str(path), *FAST], capsys)
    assert status == 1
    assert err == f"error: snapshot: cannot write {path} ({os.strerror(errno.ENOSPC)})\n"
    assert files_below(tmp_path) == []  # the folder made for it is gone too


# -- paths that cannot be written: refused before the run --------------------------------
def test_a_folder_is_refused_even_with_force(tmp_path, capsys, no_window):
    folder = tmp_path / "pics.png"
    folder.mkdir()
    (folder / "mine.txt").write_bytes(USER_TEXT)
    for extra in ([], ["--force"]):
        refused(["--snapshot", str(folder), *extra, *FAST], capsys, "snapshot:", "is a folder")
    assert files_below(tmp_path) == ["pics.png", "pics.png/mine.txt"]
    assert (folder / "mine.txt").read_bytes() == USER_TEXT


@pytest.mark.parametrize(
    ("target", "fragment"),
    [
        ("user_notes.txt/x.png", "is not a folder"),
        ("", "file name is empty"),
        ("shot", "(no suffix)"),
        ("shot.pgf", "(got .pgf)"),
        ("shot.png.bak", "(got .bak)"),
        ("x" * 300 + ".png", "too long"),
    ],
)
def test_a_path_that_cannot_be_a_snapshot_is_refused(
    target, fragment, tmp_path, capsys, monkeypatch, no_window
):
    (tmp_path / "user_notes.txt").write_bytes(USER_TEXT)
    monkeypatch.chdir(tmp_path)  # relative names, as typed
    refused(["--snapshot", target, *FAST], capsys, "snapshot:", fragment)
    assert files_below(tmp_path) == ["user_notes.txt"]
    assert (tmp_path / "user_notes.txt").read_bytes() == USER_TEXT


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux /proc")
def test_a_virtual_file_system_is_refused(capsys, no_window):
    # ../../../../proc/x.png from the audit: os.access says yes to root, writing does not.
    refused(
        ["--snapshot", "/proc/ddwmmr-x.png", *FAST],
        capsys,
        "snapshot: cannot write in /proc: /proc takes no new files or folders; "
        "choose a folder elsewhere",
    )


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write into a chmod 500 folder")
def test_a_read_only_folder_is_refused(tmp_path, capsys, no_window):
    folder = tmp_path / "locked"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        refused(["--snapshot", str(folder / "x.png"), *FAST], capsys, "snapshot: cannot write in")
        assert list(folder.iterdir()) == []
    finally:
        folder.chmod(0o700)


def test_a_special_file_or_a_link_is_refused_even_with_force(tmp_path, capsys, no_window):
    user = tmp_path / "user_notes.txt"
    user.write_bytes(USER_TEXT)
    link = tmp_path / "link.png"
    link.symlink_to(user)
    refused(["--snapshot", str(link), "--force", *FAST], capsys, "snapshot:", "symbolic link")
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    refused(["--snapshot", str(fifo), "--force", *FAST], capsys, "not a regular file (a FIFO)")
    assert user.read_bytes() == USER_TEXT and link.is_symlink()
    assert files_below(tmp_path) == ["link.png", "pipe.png", "user_notes.txt"]


def test_force_without_a_snapshot_is_refused(capsys, no_window):
    refused(["--force"], capsys, "force needs --snapshot PATH")


# -- numbers ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("dpi", "message"),
    [
        ("inf", "argument --dpi: must be an integer in [10, 600] (got 'inf')"),
        ("nan", "argument --dpi: must be an integer in [10, 600] (got 'nan')"),
        ("1e9", "argument --dpi: must be an integer in [10, 600] (got '1e9')"),
        ("1e-9", "argument --dpi: must be an integer in [10, 600] (got '1e-9')"),
        ("0", "dpi must be in [10, 600] (got 0)"),
        ("-100", "dpi must be in [10, 600] (got -100)"),
        ("601", "dpi must be in [10, 600] (got 601)"),
        ("ten", "argument --dpi: must be an integer in [10, 600] (got 'ten')"),
    ],
)
def test_bad_dpi_is_refused_before_the_run(dpi, message, tmp_path, capsys, no_window):
    path = tmp_path / "shot.png"
    refused(["--snapshot", str(path), "--duration", "1", "--dpi", dpi], capsys, message)
    assert files_below(tmp_path) == []


def test_dpi_range_ends_are_allowed():
    assert check_dpi(DPI_RANGE[0]) == 10.0 and check_dpi(DPI_RANGE[1]) == 600.0


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--traj", "figure8", "--a", "1e300"], "a must be in [1e-06, 1000] m (got 1e+300)"),
        (["--traj", "figure8", "--x0", "1e300"], "x0 must be in [-1e+06, 1e+06] m"),
        (["--traj", "figure8", "--beta=-1e300"], "beta must be in [-1e+06, 1e+06] rad"),
        (["--traj", "figure8", "--T", "1e-9"], "T must be in [1e-06, 1e+09] s (got 1e-09)"),
        (["--traj", "figure8", "--N", "2e6"], "N must be an integer in [2, 1000000]"),
        (["--T", "-1"], "T must be in [1e-06, 1e+09] s (got -1)"),
        (["--b", "inf"], "b must be a finite number in [1e-06, 1000] m (got inf)"),
        (["--duration", "inf"], "duration must be a finite number > 0 (got inf)"),
        (["--duration", "-1"], "duration must be > 0 (got -1)"),
        (["--dt", "nan"], "dt must be a finite number > 0 (got nan)"),
        (["--payload", "1e300"], "payload must be in [0, 100000] kg"),
        (["--offset", "nan", "0"], "offset must be a finite number in [-0.65, 0.65] m"),
    ],
)
def test_bad_numbers_are_refused_before_the_run(argv, message, tmp_path, capsys, no_window):
    path = tmp_path / "shot.png"
    refused(["--snapshot", str(path), *argv], capsys, message)
    assert files_below(tmp_path) == []


# -- the export folder -----------------------------------------------------------------
def test_an_export_folder_that_cannot_be_one_is_refused(tmp_path, capsys, no_window):
    user = tmp_path / "user_notes.txt"
    user.write_bytes(USER_TEXT)
    shot = tmp_path / "shot.png"
    refused(["--snapshot", str(shot), "--export", str(user)], capsys, "export:", "not a folder")
    refused(["--snapshot", str(shot), "--export", str(user / "sub")], capsys, "export:")
    refused(["--snapshot", str(shot), "--export", " "], capsys, "export folder must not be empty")
    assert files_below(tmp_path) == ["user_notes.txt"] and user.read_bytes() == USER_TEXT


def test_the_path_checks_accept_what_can_be_written(tmp_path):
    assert check_export_root(str(tmp_path / "a" / "b")) == tmp_path / "a" / "b"
    assert check_export_root(str(tmp_path)) == tmp_path
    for fmt in SNAPSHOT_FORMATS:
        assert check_snapshot_path(str(tmp_path / f"x.{fmt}")) == tmp_path / f"x.{fmt}"
    (tmp_path / "x.png").write_bytes(USER_TEXT)
    assert check_snapshot_path(str(tmp_path / "x.png"), force=True) == tmp_path / "x.png"
    with pytest.raises(ParameterError, match="exists and no snapshot wrote it; choose another"):
        check_snapshot_path(str(tmp_path / "x.png"))
    assert files_below(tmp_path) == ["x.png"]  # the writability probe left nothing


# -- the audit's command: a name relative to the working folder ---------------------------
# (tests/test_cli_gui.py runs the tool as a real process, a refusal included)
def test_the_audit_command_keeps_the_users_file(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("user_notes.txt", "user_pic.png"):
        user = tmp_path / name
        user.write_bytes(USER_TEXT)
        status, out, err = call_main(main, ["--duration", "1", "--snapshot", name], capsys)
        assert status == 2, err
        assert err.count("\n") == 1 and err.startswith(f"error: snapshot: {name}")
        assert "Traceback" not in err and out == ""
        assert user.read_bytes() == USER_TEXT
    assert files_below(tmp_path) == ["user_notes.txt", "user_pic.png"]


def test_a_run_that_starts_tipped_or_in_an_obstacle_is_refused(tmp_path, capsys, no_window):
    """What track refuses, the window's settings refuse too (it ran them before)."""
    snap = str(tmp_path / "s.png")
    refused(
        ["--snapshot", snap, *FAST, "--payload", "20"],
        capsys,
        "payload: a 20 kg payload tips the robot over",
        "S = 0.57 <= 1",
    )
    obstacles = tmp_path / "start.toml"
    obstacles.write_text("[[obstacle]]\nx = 2.0\ny = 0.0\nradius = 0.5\n")
    refused(
        ["--snapshot", snap, *FAST, "--method", "qp", "--option", f"obstacles={obstacles}"],
        capsys,
        "obstacles: obstacle 1",
        "overlaps the robot's start pose by 0.104 m",
    )
    assert files_below(tmp_path) == ["start.toml"]


def test_a_deeply_nested_obstacle_file_is_refused(tmp_path, capsys, no_window):
    obstacles = tmp_path / "deep.toml"
    obstacles.write_text("[[obstacle]]\nx = 2.0\ny = 0.0\nradius = " + "[" * 5000 + "]" * 5000)
    refused(
        ["--snapshot", str(tmp_path / "s.png"), *FAST, "--method", "qp",
         "--option", f"obstacles={obstacles}"],
        capsys,
        f"obstacles: {obstacles} nests arrays or tables more than 32 levels deep",
    )  # fmt: skip
    assert files_below(tmp_path) == ["deep.toml"]
