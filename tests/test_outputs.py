"""Output folders (ddwmmr.outputs): a user's file survives every case, for every tool.

Cases per tool: a new folder, the tool's own earlier folder, another tool's folder, a
user's folder, and --force into each. A folder is replaced only when it holds nothing but
the files its manifest lists for the same tool; --force deletes only listed files.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
from pathlib import Path

import pytest

from ddwmmr.cli.compare import main as compare_main
from ddwmmr.cli.scenarios import main as scenarios_main
from ddwmmr.cli.track import main as track_main
from ddwmmr.errors import ParameterError
from ddwmmr.outputs import (
    KEPT_PREFIX,
    MANIFEST,
    STAGING_PREFIX,
    check_output_folder,
    first_free,
    output_folder,
    owner_token,
)

TOOLS = {
    "track": (
        track_main,
        ["--method", "pi", "--traj", "ellipse", "--duration", "0.2", "--no-plots"],
    ),
    "compare": (
        compare_main,
        ["--methods", "pi", "--only", "ellipse", "--study", "none", "--duration", "0.2"],
    ),
    "scenarios": (scenarios_main, ["--n", "1", "--time-limit", "0.3"]),
}
FAST = ["--no-progress"]
#: A file each tool writes (a user's file of that name must not be overwritten).
WRITES = {"track": "summary.json", "compare": "report.md", "scenarios": "summary.json"}
OTHER = {"track": "scenarios", "compare": "track", "scenarios": "compare"}


def run(tool: str, out: Path, *extra: str) -> int:
    """Run ``tool`` (in-process, small and fast) into ``out``; its exit status."""
    main, args = TOOLS[tool]
    jobs = [] if tool == "track" else ["--jobs", "1"]
    return main([*args, *FAST, *jobs, "--out", str(out), *extra])


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file below ``folder`` (relative path -> bytes)."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()
    }


def leftovers(parent: Path) -> list[str]:
    """Hidden staging/old folders the tools must never leave behind."""
    return [p.name for p in parent.iterdir() if p.name.startswith(".ddwmmr-")]


def spy_on_checks(monkeypatch, tool: str) -> list[str]:
    """The names ``tool`` checks before its run (filled as it checks them)."""
    import importlib

    module = importlib.import_module(f"ddwmmr.cli.{tool}")
    checked: list[str] = []
    real = module.check_output_folder

    def spy(target, name, force=False, writes=()):
        checked.extend(writes)
        return real(target, name, force, writes)

    monkeypatch.setattr(module, "check_output_folder", spy)
    return checked


@pytest.fixture(scope="module")
def made_runs(tmp_path_factory) -> tuple[dict[str, Path], dict[str, list[str]]]:
    """One output folder per tool, made once (tests copy them): each a new folder ``out``
    made next to a user's file, alone with it in a folder of its own; and the names each
    run checked before it ran."""
    base = tmp_path_factory.mktemp("made")
    folders, checked = {}, {}
    for tool in TOOLS:
        (base / tool).mkdir()
        (base / tool / "thesis.tex").write_text("mine")
        with pytest.MonkeyPatch.context() as monkeypatch:
            checked[tool] = spy_on_checks(monkeypatch, tool)
            assert run(tool, base / tool / "out") == 0
        folders[tool] = base / tool / "out"
    return folders, checked


@pytest.fixture(scope="module")
def made(made_runs) -> dict[str, Path]:
    return made_runs[0]


def copy_of(made: dict[str, Path], tool: str, where: Path) -> Path:
    target = where / "out"
    shutil.copytree(made[tool], target)
    return target


def listed(folder: Path) -> list[str]:
    return json.loads((folder / MANIFEST).read_text())["files"]


@pytest.mark.parametrize("tool", TOOLS)
def test_manifest_lists_every_file_and_names_the_tool(made, tool):
    manifest = json.loads((made[tool] / MANIFEST).read_text())
    assert manifest["tool"] == tool
    files = sorted(p.name for p in made[tool].iterdir() if p.name != MANIFEST)
    assert manifest["files"] == files and WRITES[tool] in files


@pytest.mark.parametrize("tool", TOOLS)
def test_new_folder_next_to_a_user_file(made, tool):
    parent = made[tool].parent  # the fixture's run: a new folder next to thesis.tex
    assert (parent / "thesis.tex").read_text() == "mine"
    assert sorted(p.name for p in parent.iterdir()) == ["out", "thesis.tex"]


@pytest.mark.parametrize("tool", TOOLS)
def test_own_folder_is_replaced(made, tmp_path, tool):
    out = copy_of(made, tool, tmp_path)
    (tmp_path / "thesis.tex").write_text("mine")
    stale = out / WRITES[tool]
    stale.write_bytes(stale.read_bytes() + b"\nstale")  # still a listed file
    assert run(tool, out) == 0
    assert not stale.read_bytes().endswith(b"stale")  # replaced by the new run
    assert sorted(listed(out)) == sorted(p for p in snapshot(out) if p != MANIFEST)
    assert (tmp_path / "thesis.tex").read_text() == "mine"
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize("tool", TOOLS)
def test_own_folder_with_a_user_file_is_refused(made, tmp_path, tool, capsys):
    out = copy_of(made, tool, tmp_path)
    (out / "thesis.tex").write_text("mine")
    before = snapshot(out)
    assert run(tool, out) == 2
    assert "thesis.tex" in capsys.readouterr().err
    assert snapshot(out) == before and leftovers(tmp_path) == []


@pytest.mark.parametrize("tool", TOOLS)
def test_other_tools_folder_is_refused(made, tmp_path, tool, capsys):
    out = copy_of(made, OTHER[tool], tmp_path)
    before = snapshot(out)
    assert run(tool, out) == 2
    err = capsys.readouterr().err
    assert f"was written by ddwmmr {OTHER[tool]}" in err and len(err.splitlines()) == 1
    assert snapshot(out) == before and leftovers(tmp_path) == []


@pytest.mark.parametrize("tool", TOOLS)
def test_user_folder_is_refused(tmp_path, tool, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text("{}")  # the old guard only looked for this name
    (out / "thesis.tex").write_text("mine")
    assert run(tool, out) == 2
    assert "--force" in capsys.readouterr().err
    assert snapshot(out) == {"summary.json": b"{}", "thesis.tex": b"mine"}


@pytest.mark.parametrize("tool", TOOLS)
def test_force_into_a_user_folder_keeps_the_user_files(tmp_path, tool):
    out = tmp_path / "out"
    (out / "notes").mkdir(parents=True)
    (out / "notes" / "thesis.tex").write_text("mine")
    assert run(tool, out, "--force") == 0
    files = snapshot(out)
    assert files["notes/thesis.tex"] == b"mine"
    assert sorted(listed(out)) == sorted(
        f for f in files if f not in (MANIFEST, "notes/thesis.tex")
    )


@pytest.mark.parametrize("tool", TOOLS)
def test_force_into_another_tools_folder_deletes_only_its_listed_files(made, tmp_path, tool):
    out = copy_of(made, OTHER[tool], tmp_path)
    old_files = set(listed(out))
    (out / "thesis.tex").write_text("mine")
    assert run(tool, out, "--force") == 0
    files = set(snapshot(out))
    assert (out / "thesis.tex").read_text() == "mine"
    assert json.loads((out / MANIFEST).read_text())["tool"] == tool
    # The other tool's files are gone unless this tool wrote one of the same name.
    assert files - {MANIFEST, "thesis.tex"} == set(listed(out))
    assert not (old_files - set(listed(out))) & files


@pytest.mark.parametrize("tool", TOOLS)
def test_force_never_overwrites_a_user_file(tmp_path, tool, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / WRITES[tool]).write_text("mine")
    assert run(tool, out, "--force") == 2
    assert "would be overwritten" in capsys.readouterr().err
    assert snapshot(out) == {WRITES[tool]: b"mine"} and leftovers(tmp_path) == []


@pytest.mark.parametrize("tool", TOOLS)
def test_force_refuses_a_clash_with_a_user_file_before_the_run(tmp_path, tool, capsys, monkeypatch):
    """The clash is found before anything runs (the run never starts), in one line."""
    import importlib

    module = importlib.import_module(f"ddwmmr.cli.{tool}")

    def never(*args, **kwargs):
        raise AssertionError("the run started")

    monkeypatch.setattr(module, "output_folder", never)
    out = tmp_path / "out"
    out.mkdir()
    (out / WRITES[tool]).write_text("mine")
    (out / "notes.txt").write_text("mine too")
    assert run(tool, out, "--force") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"{WRITES[tool]} is not a file a ddwmmr manifest lists" in err
    assert snapshot(out) == {WRITES[tool]: b"mine", "notes.txt": b"mine too"}


def test_a_figure_name_is_no_clash_when_track_draws_no_figures(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "path.png").write_text("mine")
    assert run("track", out, "--force") == 0  # --no-plots: path.png is not written
    assert (out / "path.png").read_text() == "mine"
    with pytest.raises(ParameterError, match=r"out/path.png is not a file a ddwmmr manifest"):
        check_output_folder(out, "track", True, ("timeseries.csv", "path.png"))


def test_force_keeps_user_files_that_only_look_like_outputs(tmp_path):
    """Only the exact names a run writes are refused before it: a user's paths_mine.png,
    a folder study_old/ with a figure in it, and a stability.png next to a qp batch
    are kept."""
    compare = tmp_path / "compare"
    (compare / "study_old").mkdir(parents=True)
    (compare / "paths_mine.png").write_text("mine")
    (compare / "study_old" / "notes.png").write_text("mine")
    assert run("compare", compare, "--force") == 0
    assert (compare / "paths_mine.png").read_text() == "mine"
    assert (compare / "study_old" / "notes.png").read_text() == "mine"
    batch = tmp_path / "batch"
    batch.mkdir()
    (batch / "stability.png").write_text("mine")  # qp batches do not draw it
    assert run("scenarios", batch, "--force", "--controller", "qp") == 0
    assert (batch / "stability.png").read_text() == "mine"


def test_force_refuses_the_animation_and_study_files_before_the_run(tmp_path, capsys, monkeypatch):
    import ddwmmr.cli.scenarios as scenarios_cli
    import ddwmmr.cli.track as track_cli

    def never(*args, **kwargs):
        raise AssertionError("the run started")

    for module in (track_cli, scenarios_cli):
        monkeypatch.setattr(module, "output_folder", never)
    out = tmp_path / "out"
    out.mkdir()
    (out / "animation.gif").write_text("mine")
    (out / "baseline.csv").write_text("mine")
    assert run("track", out, "--force", "--animate") == 2
    assert "animation.gif is not a file a ddwmmr manifest lists" in capsys.readouterr().err
    main, _ = TOOLS["scenarios"]
    argv = ["--n", "1", "--study", "thresholds", "--no-progress", "--out", str(out), "--force"]
    assert main(argv) == 2
    assert "baseline.csv is not a file a ddwmmr manifest lists" in capsys.readouterr().err


# -- the module itself --------------------------------------------------------------------
def test_manifest_entries_outside_the_folder_are_never_deleted(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("mine")
    out = tmp_path / "out"
    out.mkdir()
    (out / MANIFEST).write_text(json.dumps({"tool": "track", "files": ["../victim.txt"]}))
    with pytest.raises(ParameterError, match="holds files"):
        check_output_folder(out, "track")
    refused = pytest.raises(ParameterError, match="would be overwritten")  # bad manifest
    with refused, output_folder(out, "track", force=True) as staging:
        (staging / "a.txt").write_text("new")
    assert victim.read_text() == "mine"
    assert snapshot(out) == {MANIFEST: (out / MANIFEST).read_bytes()}


def test_error_in_the_block_removes_staging_and_created_parents(tmp_path):
    with pytest.raises(RuntimeError), output_folder(tmp_path / "a" / "b" / "out", "x") as staging:
        (staging / "f.txt").write_text("half")
        assert staging.name.startswith(STAGING_PREFIX)
        raise RuntimeError
    assert list(tmp_path.iterdir()) == []


def _dead_pid() -> int:
    """The id of a process that has just ended (and was reaped)."""
    import subprocess
    import sys

    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)  # fmt: skip
    return int(child.stdout)


def test_stale_folders_of_ended_runs_are_removed_with_one_line(tmp_path, capsys):
    host, pid, start = owner_token().rsplit("-", 2)
    other_start = int(start) + 1  # this process id with another start: an id reused
    dead = [
        f"{STAGING_PREFIX}{host}-{_dead_pid()}-0-abcd1234",
        f"{STAGING_PREFIX}{host}-{pid}-{other_start}-efgh5678",
    ]
    kept = [
        f"{STAGING_PREFIX}{owner_token()}-live0000",  # a run of this very process
        f"{STAGING_PREFIX}elsewhere-{_dead_pid()}-0-abcd1234",  # another host's run
        ".ddwmmr-staging-unparsable",  # no owner in the name: never guessed
    ]
    for name in dead + kept:
        (tmp_path / name).mkdir()
        (tmp_path / name / "timeseries.csv").write_text("half")
    old = tmp_path / f".ddwmmr-old-{host}-{_dead_pid()}-0-oldfold1"
    (old / "plots").mkdir(parents=True)
    for name in ("summary.json", "plots/a.png", "mine.txt"):
        (old / name).write_text("x")
    (old / MANIFEST).write_text(
        json.dumps({"tool": "track", "files": ["summary.json", "plots/a.png"]})
    )
    with output_folder(tmp_path / "out", "track") as staging:
        (staging / "r.txt").write_text("new")
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("note: removed 2 folders left in"), err
    aside = [p for p in tmp_path.iterdir() if p.name.startswith(KEPT_PREFIX)]
    assert len(aside) == 1 and err[0].endswith(f"; kept files no manifest lists in {aside[0].name}")
    # The replace's leftovers: a user's file, kept under a name no later run sweeps.
    assert snapshot(aside[0]) == {"mine.txt": b"x"}
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*kept, aside[0].name, "out"])
    with output_folder(tmp_path / "out", "track") as staging:
        (staging / "r.txt").write_text("again")
    assert capsys.readouterr().err == ""  # nothing left to say


def test_a_fresh_folder_never_replaces_one_that_appeared_during_the_run(tmp_path):
    """Two runs with the same default (time-stamped) name: the later one goes to -2, and a
    third that finishes together with a second still gets its own (-3)."""
    target = tmp_path / "runs" / "ats-ellipse-20261201-120000"
    first = output_folder(target, "x", fresh=True)
    second = output_folder(target, "x", fresh=True)  # both looked before either finished
    third = output_folder(target, "x", fresh=True)
    for n, writer in enumerate((first, second, third), start=1):
        with writer as staging:
            (staging / "r.txt").write_text(f"run {n}")
    names = [w.path.name for w in (first, second, third)]
    assert names == [target.name, f"{target.name}-2", f"{target.name}-3"]
    assert [(w.path / "r.txt").read_text() for w in (first, second, third)] == [
        "run 1",
        "run 2",
        "run 3",
    ]
    assert first_free(target) == target.with_name(f"{target.name}-4")
    assert leftovers(target.parent) == []


def test_a_fresh_commit_takes_the_next_name_when_its_own_is_taken_meanwhile(tmp_path, monkeypatch):
    """Between the look for a free name and the mkdir another run takes it: the commit
    goes on to the next free one (the FileExistsError branch)."""
    from ddwmmr.outputs import commit

    target = tmp_path / "runs" / "my.track-20261201"  # a dot in the name: -2 at the end
    real = commit.first_free
    taken = []

    def racing(path, folder=False):
        free = real(path, folder)
        if not taken:  # the first answer: another run makes that folder now
            free.mkdir(parents=True)
            (free / "theirs.txt").write_text("theirs")
            taken.append(free)
        return free

    writer = output_folder(target, "x", fresh=True)
    monkeypatch.setattr(commit, "first_free", racing)
    with writer as staging:
        (staging / "r.txt").write_text("mine")
    assert taken == [target] and writer.path == target.with_name(f"{target.name}-2")
    assert (target / "theirs.txt").read_text() == "theirs"
    assert (writer.path / "r.txt").read_text() == "mine"


def test_an_interrupt_just_after_the_fresh_mkdir_leaves_nothing(tmp_path, monkeypatch):
    target = tmp_path / "runs" / "track-20261201"
    real_mkdir = os.mkdir

    def interrupted(path, mode=0o777):
        real_mkdir(path, mode)
        if Path(path) == target:
            raise KeyboardInterrupt

    writer = output_folder(target, "x", fresh=True)
    with pytest.raises(KeyboardInterrupt), writer as staging:
        (staging / "r.txt").write_text("half")
        monkeypatch.setattr(os, "mkdir", interrupted)
    assert list(tmp_path.iterdir()) == []


def test_a_parent_another_run_makes_at_the_same_moment_is_used(tmp_path, monkeypatch):
    from ddwmmr.outputs import commit

    runs = tmp_path / "runs"
    real = commit.missing_folders

    def late(folder):
        missing = real(folder)
        runs.mkdir()  # the other run, between the look and our mkdir
        return missing

    monkeypatch.setattr(commit, "missing_folders", late)
    writer = output_folder(runs / "scenarios-1", "x", fresh=True)
    with writer as staging:
        (staging / "r.txt").write_text("mine")
    assert (runs / "scenarios-1" / "r.txt").read_text() == "mine"


def test_an_output_folder_is_one_with_block(tmp_path):
    writer = output_folder(tmp_path / "out", "x")
    with writer as staging:
        (staging / "r.txt").write_text("first")
    with pytest.raises(RuntimeError, match="one with-block only"), writer:
        pass
    assert (tmp_path / "out" / "r.txt").read_text() == "first"


def test_a_fresh_run_that_fails_leaves_nothing(tmp_path):
    target = tmp_path / "runs" / "scenarios-20261201-120000"
    with pytest.raises(RuntimeError), output_folder(target, "x", fresh=True) as staging:
        (staging / "f.txt").write_text("half")
        raise RuntimeError
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("tool", ["track", "compare", "scenarios"])
def test_default_output_names_are_never_reused(made, tmp_path, monkeypatch, tool, capsys):
    """Without --out, runs within the same second wrote to the same folder: the later
    replaced the earlier (here every run gets the same stamp)."""
    stamped = Path("runs") / f"{tool}-20261201-120000"
    monkeypatch.setattr(f"ddwmmr.cli.{tool}.default_out", lambda *names: stamped)
    monkeypatch.chdir(tmp_path)
    # The first run of that second: the fixture's run of the same arguments, as written.
    shutil.copytree(made[tool], stamped)
    first = snapshot(stamped)
    main, args = TOOLS[tool]
    jobs = [] if tool == "track" else ["--jobs", "1"]
    for _ in range(2):
        assert main([*args, *FAST, *jobs]) == 0
    folders = sorted(p.name for p in (tmp_path / "runs").iterdir())
    assert len(folders) == 3 and folders[1:] == [f"{folders[0]}-2", f"{folders[0]}-3"]
    assert snapshot(stamped) == first
    assert capsys.readouterr().out.endswith(f"\nwrote runs/{folders[0]}-3/\n")


def test_keyboard_interrupt_removes_staging(tmp_path):
    with pytest.raises(KeyboardInterrupt), output_folder(tmp_path / "out", "x") as staging:
        (staging / "f.txt").write_text("half")
        raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []


def test_cannot_create_staging_is_one_parameter_error(tmp_path, monkeypatch):
    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr("tempfile.mkdtemp", refuse)
    refused = pytest.raises(ParameterError, match=r"cannot write in .*Permission denied")
    with refused, output_folder(tmp_path / "new" / "out", "x"):
        pass
    assert list(tmp_path.iterdir()) == []


def test_read_only_parent_is_refused(tmp_path):
    parent = tmp_path / "ro"
    parent.mkdir()
    parent.chmod(0o555)
    try:
        if os.access(parent, os.W_OK):  # root may write anyway: then writing must work
            with output_folder(parent / "out", "x") as staging:
                (staging / "f.txt").write_text("ok")
            assert (parent / "out" / "f.txt").read_text() == "ok"
        else:
            with pytest.raises(ParameterError, match="permission denied"):
                check_output_folder(parent / "out", "x")
    finally:
        parent.chmod(0o755)


@pytest.mark.parametrize("mask", [0o022, 0o027, 0o077])
def test_files_and_folders_follow_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        assert track_main([*TOOLS["track"][1], *FAST, "--out", str(tmp_path / "out")]) == 0
    finally:
        os.umask(old)
    out = tmp_path / "out"
    assert stat.S_IMODE(out.stat().st_mode) == 0o777 & ~mask
    for path in out.iterdir():
        assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask, path.name


# -- the compare and scenarios records ---------------------------------------------------
def test_compare_records_everything_to_rerun(made):
    record = json.loads((made["compare"] / "run.json").read_text())
    assert record["tool"] == "compare" and record["methods"] == ["pi"]
    assert record["options"] == {"pi": {"singularity_threshold": None, "damping": None}}
    assert record["robot"]["payload"] == 1.25 and record["duration"] == 0.2
    ellipse = record["trajectories"]["ellipse"]
    assert ellipse["type"] == "ellipse" and ellipse["parameters"]["a"] == 2.0
    assert ellipse["sha256"] and record["studies"] == [] and record["jobs"] == 1
    assert record["argv"][:2] == ["--methods", "pi"] and "--only ellipse" in record["command"]


def test_scenarios_records_everything_to_rerun(made):
    summary = json.loads((made["scenarios"] / "summary.json").read_text())
    record = summary["run"]
    assert record["tool"] == "scenarios" and record["n"] == 1 and record["seed"] == 0
    assert record["config"]["time_limit"] == 0.3 and record["config"]["payload"] == 3.0
    assert record["robot"]["payload"] == 3.0 and record["plant"] == {"name": "thesis"}
    assert record["command"].startswith("python -m ddwmmr.scenarios --n 1")


def test_an_empty_user_folder_inside_an_own_folder_is_named(made, tmp_path, capsys):
    out = copy_of(made, "track", tmp_path)
    (out / "notes").mkdir()
    assert run("track", out) == 2
    error = capsys.readouterr().err
    assert "notes/" in error and "()" not in error
    assert (out / "notes").is_dir() and leftovers(tmp_path) == []


@pytest.mark.parametrize("force", [False, True])
def test_a_folder_whose_files_cannot_be_replaced_is_refused_before_the_run(
    made, tmp_path, capsys, monkeypatch, force
):
    # Root writes anywhere, so the permission is denied through os.access, as for a user
    # whose earlier output folder is read-only (chmod 500).
    out = copy_of(made, "track", tmp_path)
    before = snapshot(out)
    real_access = os.access
    monkeypatch.setattr(
        "ddwmmr.outputs.checks.os.access",
        lambda path, mode: False if Path(path) == out else real_access(path, mode),
    )
    assert run("track", out, *(["--force"] if force else [])) == 2
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and "cannot replace files in" in error[0], error
    assert snapshot(out) == before and leftovers(tmp_path) == []


def assert_checked_before(checked: list[str], out: Path) -> None:
    written = set(listed(out))
    assert written and written <= set(checked), sorted(written - set(checked))


@pytest.mark.parametrize(
    ("tool", "extra"),
    [
        ("track", ["--method", "qp", "--traj", "ellipse", "--duration", "0.2", "--animate"]),
        ("compare", ["--plant", "thesis"]),
        ("scenarios", ["--arbiter", "competitive"]),
    ],
)
def test_the_names_checked_before_the_run_are_the_files_it_writes(
    tmp_path, tool, extra, monkeypatch
):
    """Every file a run writes is among the names its tool checks before the run (so a
    user's file of that name is refused then, not after the run). The tools' base runs
    (scenarios with its default figures among them) are the next test's."""
    checked = spy_on_checks(monkeypatch, tool)
    main, args = TOOLS[tool]
    if tool == "track":
        args = []  # draws its figures: the base arguments say --no-plots
    jobs = [] if tool == "track" else ["--jobs", "1"]
    out = tmp_path / "out"
    assert main([*args, *extra, *FAST, *jobs, "--out", str(out)]) == 0
    assert_checked_before(checked, out)


@pytest.mark.parametrize("tool", TOOLS)
def test_the_names_the_fixtures_runs_checked_are_the_files_they_write(made_runs, tool):
    folders, checked = made_runs
    assert_checked_before(checked[tool], folders[tool])


def _commit_together(target: str, number: int, barrier, results) -> None:
    """One run (a process) writing into the default name ``target`` at the same moment as
    the others; puts where its files went on ``results``."""
    writer = output_folder(target, "x", fresh=True)
    with writer as staging:
        (staging / "r.txt").write_text(f"run {number}")
        barrier.wait()  # every run commits at once
    results.put(str(writer.path))


def test_runs_finishing_at_the_same_moment_each_keep_their_folder(tmp_path):
    """Four processes with the same default name, none of whose folders exist yet (not even
    runs/), committing at once: four folders, each run's file in its own."""
    import multiprocessing

    context = multiprocessing.get_context("fork")
    target = str(tmp_path / "runs" / "track-20261201-120000")
    barrier, results = context.Barrier(4), context.Queue()
    runs = [
        context.Process(target=_commit_together, args=(target, n, barrier, results))
        for n in range(4)
    ]
    for run_ in runs:
        run_.start()
    paths = [results.get(timeout=60) for _ in runs]
    for run_ in runs:
        run_.join(timeout=60)
        assert run_.exitcode == 0
    assert len(set(paths)) == 4
    contents = sorted(Path(p, "r.txt").read_text() for p in paths)
    assert contents == [f"run {n}" for n in range(4)]
    assert sorted(Path(p).name for p in paths)[0] == Path(target).name
    assert leftovers(tmp_path / "runs") == []


def test_a_default_track_folder_taken_meanwhile_is_numbered_from_the_default(tmp_path, monkeypatch):
    """The default name existed, so the run aimed at name-2; another run took name-2
    meanwhile: this one goes to name-3 (it went to name-2-2, and one more to name-2-2-2)."""
    import ddwmmr.cli.track as track

    monkeypatch.chdir(tmp_path)
    base = Path("runs") / "ats-ellipse-20261201-120000"
    base.mkdir(parents=True)
    monkeypatch.setattr(track, "default_out", lambda method, traj: base)
    real_simulate = track.simulate

    def racing(*args, **kwargs):
        Path(f"{base}-2").mkdir()  # another default run finished first
        return real_simulate(*args, **kwargs)

    monkeypatch.setattr(track, "simulate", racing)
    args = ["--method", "ats", "--traj", "ellipse", "--duration", "0.1", "--no-plots"]
    assert track.main([*args, "--no-progress"]) == 0
    assert sorted(p.name for p in base.parent.iterdir()) == [
        base.name,
        f"{base.name}-2",
        f"{base.name}-3",
    ]
    assert (base.parent / f"{base.name}-3" / "summary.json").is_file()
