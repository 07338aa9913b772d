"""The shell commands the pages show run as written: every ``python -m ddwmmr.<tool> ...``
in README.md's and docs/*.md's shell blocks (```sh fences, indented blocks, ``$ ``
lines of ```text fences) passes its tool's argument parser, and every plug-in module a
command names in ``DDWMMR_PLUGINS`` is found on the ``sys.path`` that command gives.

A user copies these lines; an option renamed or removed in a parser, or a plug-in folder
the command does not put on the path, fails here instead of on the user's terminal. The
commands are parsed, not run (tests/test_examples.py runs the Python snippets)."""

from __future__ import annotations

import contextlib
import importlib
import io
import re
import shlex
from importlib.machinery import PathFinder
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: The tools whose command lines are checked (``ddwmmr.cli.<tool>.build_parser``).
TOOLS = ("track", "compare", "scenarios", "bench", "bounds", "gui")
ASSIGNMENT = re.compile(r"^[A-Z_][A-Z0-9_]*=")


def shell_lines(text: str) -> list[str]:
    """The page's shell command lines: ```sh/```bash blocks (a trailing backslash joins
    the next line), the indented lines starting with ``python -m ddwmmr`` and the ``$ ``
    lines of ```text blocks (without the prompt)."""
    lines: list[str] = []
    fence = None
    for line in text.replace("\\\n", " ").splitlines():
        stripped = line.strip()
        if fence is None and stripped.startswith("```"):
            fence = stripped[3:]
        elif fence is not None and stripped.startswith("```"):
            fence = None
        elif fence in ("sh", "bash"):
            lines.append(stripped)
        elif fence == "text" and stripped.startswith("$ "):
            lines.append(stripped[2:])
        elif fence is None and line.startswith("    python -m ddwmmr"):
            lines.append(stripped)
    return lines


def commands(text: str) -> list[tuple[dict[str, str], str, list[str]]]:
    """(environment, tool, arguments) of each ddwmmr tool command in the page's shell
    lines; ``export NAME=VALUE`` holds for the later lines, ``NAME=VALUE cmd`` for its own."""
    found = []
    exported: dict[str, str] = {}
    for line in shell_lines(text):
        words = shlex.split(line, comments=True)
        if words[:1] == ["export"]:
            exported.update(word.split("=", 1) for word in words[1:] if "=" in word)
            continue
        environment = dict(exported)
        while words and ASSIGNMENT.match(words[0]):
            name, value = words.pop(0).split("=", 1)
            environment[name] = value
        if "-m" not in words:
            continue
        module = words[words.index("-m") + 1]
        tool = module.removeprefix("ddwmmr.")
        if module.startswith("ddwmmr.") and tool in TOOLS:
            found.append((environment, tool, words[words.index("-m") + 2 :]))
    return found


ALL = [(page, *command) for page in PAGES for command in commands(page.read_text())]


def test_the_pages_show_commands_of_every_tool() -> None:
    assert {tool for _, _, tool, _ in ALL} >= {"track", "compare", "scenarios", "gui"}
    assert len(ALL) >= 30


@pytest.mark.parametrize(
    ("page", "tool", "arguments"),
    [
        pytest.param(page, tool, arguments, id=f"{page.name}: {tool} {shlex.join(arguments)}")
        for page, environment, tool, arguments in ALL
        if "DDWMMR_PLUGINS" not in environment  # its tool's choices need the plug-ins
    ],
)
def test_command_parses(page: Path, tool: str, arguments: list[str]) -> None:
    parser = importlib.import_module(f"ddwmmr.cli.{tool}").build_parser()
    parser.allow_abbrev = False  # a page spells options out: a prefix of a renamed one fails
    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(said):
            parser.parse_args(arguments)
    except SystemExit as stop:  # --help and --version stop with 0
        assert stop.code == 0, f"{page.name}: {tool} {shlex.join(arguments)}: {said.getvalue()}"


def plugin_commands() -> list[tuple[Path, dict[str, str]]]:
    return [(page, env) for page, env, _, _ in ALL if "DDWMMR_PLUGINS" in env]


def test_some_page_shows_a_plug_in_command() -> None:
    assert plugin_commands()


@pytest.mark.parametrize(
    ("page", "environment"), plugin_commands(), ids=lambda x: x.name if isinstance(x, Path) else ""
)
def test_plug_in_modules_are_on_the_command_s_path(page: Path, environment) -> None:
    """``python -m`` puts the working folder (the project's) first on ``sys.path``, then
    ``PYTHONPATH``'s folders; the modules must be there (not only in an installed
    package's entry points, which a command names no module of)."""
    folders = [str(ROOT)] + [
        str(ROOT / folder) for folder in environment.get("PYTHONPATH", "").split(":") if folder
    ]
    missing = [
        name
        for name in environment["DDWMMR_PLUGINS"].split(",")
        if PathFinder.find_spec(name, folders) is None
    ]
    assert missing == [], f"{page.name}: not on the command's sys.path {folders}"
