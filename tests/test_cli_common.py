"""What every tool does the same way at its command line: --version, "did you mean" for a
mistyped option, and the records' git field."""

import subprocess
from pathlib import Path

import pytest

import ddwmmr
from ddwmmr import provenance
from ddwmmr.cli import bench, compare, gui, scenarios, track

ROOT = Path(__file__).resolve().parents[1]
TOOLS = {"track": track, "compare": compare, "scenarios": scenarios, "bench": bench, "gui": gui}


@pytest.mark.parametrize("tool", sorted(TOOLS))
def test_every_tool_answers_version(tool, capsys):
    with pytest.raises(SystemExit) as stop:
        TOOLS[tool].main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out == f"ddwmmr {ddwmmr.__version__}\n"


def test_the_package_answers_version(capsys):
    from ddwmmr.__main__ import main

    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"ddwmmr {ddwmmr.__version__}\n"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["track", "--method", "ats", "--out", "my runs"],
            "the tools are modules of their own, not subcommands: "
            "run python -m ddwmmr.track --method ats --out 'my runs'",
        ),
        (
            ["bounds"],
            "the tools are modules of their own, not subcommands: run python -m ddwmmr.bounds",
        ),
        (
            ["trak"],
            "no tool 'trak'; run python -m ddwmmr.<tool> "
            "(track, compare, scenarios, bench, bounds, gui)",
        ),
    ],
)
def test_the_package_given_a_tool_name_says_how_to_run_that_tool(capsys, argv, message):
    from ddwmmr.__main__ import main

    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.err == f"python -m ddwmmr: error: {message}\n"
    assert captured.out == ""


@pytest.mark.parametrize(
    ("tool", "argv", "message"),
    [
        (
            "track",
            ["--methd", "ats", "--traj", "ellipse"],
            "python -m ddwmmr.track: error: unrecognized arguments: --methd "
            "(did you mean --method?) ats\n",
        ),
        (
            "compare",
            ["--studdy=none"],
            "python -m ddwmmr.compare: error: unrecognized arguments: --studdy=none "
            "(did you mean --study?)\n",
        ),
        (
            "scenarios",
            ["--payloda", "2"],
            "python -m ddwmmr.scenarios: error: unrecognized arguments: --payloda "
            "(did you mean --payload?) 2\n",
        ),
        (
            "bench",
            ["--jbos", "2"],
            "python -m ddwmmr.bench: error: unrecognized arguments: --jbos "
            "(did you mean --jobs?) 2\n",
        ),
        (
            "gui",
            ["--snapshot", "x.png", "--xyzzy"],  # nothing close: no suggestion
            "python -m ddwmmr.gui: error: unrecognized arguments: --xyzzy\n",
        ),
    ],
)
def test_a_mistyped_option_gets_the_closest_one(tool, argv, message, capsys):
    with pytest.raises(SystemExit) as stop:
        TOOLS[tool].main(argv)
    assert stop.value.code == 2
    assert capsys.readouterr().err == message


@pytest.mark.parametrize(
    ("tool", "argv", "hint"),
    [
        ("bench", ["--method", "ats", "pi"], "pi (--method takes one value, repeat it)"),
        ("track", ["--method=ats", "pi", "--traj", "ellipse"], "pi (--method takes one value)"),
        ("scenarios", ["--controller", "qp", "mpc"], "mpc (--controller takes one value)"),
        (
            "track",
            ["--offset", "1", "2", "-3e-2", "--method", "ats"],
            "-3e-2 (--offset takes 2 values)",
        ),
        (
            "track",
            ["--method", "ats", "ats", "--traj", "ellipse"],
            "ats (--method takes one value)",
        ),
        ("track", ["--methd", "ats", "--traj", "ellipse"], "(did you mean --method?) ats\n"),
    ],
)
def test_a_second_value_names_the_option_that_takes_one(tool, argv, hint, capsys):
    """`bench --method ats pi` said only "unrecognized arguments: pi"; a newcomer reads
    which option took one value (the value of an unknown option gets no such hint)."""
    with pytest.raises(SystemExit) as stop:
        TOOLS[tool].main(argv)
    assert stop.value.code == 2
    error = capsys.readouterr().err
    assert error.startswith(f"python -m ddwmmr.{tool}: error: unrecognized arguments: ")
    assert error.endswith(hint if hint.endswith("\n") else f"{hint}\n")
    assert error.count("takes") <= 1


def test_a_record_of_a_checkout_has_its_commit_else_says_why(monkeypatch):
    record = provenance.git_record()
    if (ROOT / ".git").exists():  # these tests run from the source checkout
        assert len(record["git"]["commit"]) == 40 and "git_note" not in record
    monkeypatch.setattr(provenance, "_git", _no_git)
    broken = provenance.git_record()
    if (ROOT / ".git").exists():
        assert broken["git"] is None and broken["git_note"].startswith("a git checkout, but")
    header = provenance.header("track", "python -m ddwmmr.track", [])
    assert header["git"] is None and header["git_note"]


def _no_git(*arguments):
    raise FileNotFoundError("git")


def test_pip_install_s_build_folder_is_ignored():
    """`pip install .` leaves build/ (setuptools) in the source tree: git ignores it."""
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    for path in ("build/lib/ddwmmr/__init__.py", "dist/ddwmmr-0.1.0.tar.gz"):
        done = subprocess.run(["git", "-C", str(ROOT), "check-ignore", "-q", path])
        assert done.returncode == 0, path
    done = subprocess.run(["git", "-C", str(ROOT), "check-ignore", "-q", "src/ddwmmr/build.py"])
    assert done.returncode == 1  # only the top-level folders


def test_cli_md_says_how_to_run_before_its_first_command():
    """docs/cli.md's commands fail with the system Python unless the venv is used: the
    page says how, once, before any command."""
    text = (ROOT / "docs" / "cli.md").read_text()
    blocks = text.split("```sh\n")[1:]
    assert blocks[0].startswith(".venv/bin/python -m ddwmmr.")  # the first command shown
    assert blocks[1].startswith("source .venv/bin/activate")
    assert text.index("source .venv/bin/activate") < text.index("## What every tool does")
    assert text.count("source .venv/bin/activate") == 1  # once, at the top


def test_readme_tools_table_gives_each_tool_s_time():
    """Each main tool's row in the README's table says how long it takes on 2 cores."""
    text = (ROOT / "README.md").read_text()
    header = next(line for line in text.splitlines() if line.startswith("| tool ("))
    assert "time, 2 cores" in header
    column = header.split(" | ").index("time, 2 cores (see below)")
    for tool in ("track", "compare", "scenarios", "gui"):
        row = next(
            line for line in text.splitlines() if line.startswith(f"| `python -m ddwmmr.{tool}`")
        )
        cell = row.split(" | ")[column]
        assert any(unit in cell for unit in (" s ", " s", " min")), (tool, cell)
    assert "`make test` (the whole suite)" in text


@pytest.mark.parametrize(
    ("tool", "argv", "message"),
    [
        (
            track,
            ["--method", "pi", "--method", "ats", "--traj", "ellipse"],
            "argument --method: given more than once (first 'pi', then 'ats'); give it once",
        ),
        (
            track,
            ["--traj", "ellipse", "--traj", "rectangle"],
            "argument --traj: given more than once (first 'ellipse', then 'rectangle')",
        ),
        (scenarios, ["--n", "2", "--n", "3"], "argument --n: given more than once"),
        (compare, ["--jobs", "1", "--jobs", "2"], "argument --jobs: given more than once"),
        (bench, ["--repeats", "1", "--repeats", "2"], "argument --repeats: given more than"),
    ],
)
def test_a_repeated_single_valued_option_is_refused(tmp_path, capsys, tool, argv, message):
    """Audit: a repeated --traj or --method silently used the last value (a repeated
    --option was refused); every tool's parser now refuses it, in one line, exit 2."""
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as info:
        tool.main([*argv, "--out", str(out)])
    assert info.value.code == 2 and not out.exists()
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and "Traceback" not in err


def test_repeatable_options_still_repeat():
    args = track.build_parser().parse_args(["--option", "tau=0.3", "--option", "damping=0.1"])
    assert args.option == ["tau=0.3", "damping=0.1"]
    args = compare.build_parser().parse_args(["--methods", "pi", "--methods", "ats"])
    assert args.methods == ["pi", "ats"]
